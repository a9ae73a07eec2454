//! Synthetic face sequences with ground truth: the textured model with known shape, head pose
//! and expression trajectories (MPEG-4 FAP curves), rendered from several cameras over real
//! photos, with lighting change and sensor noise.
//!
//! Layout of a sequence folder (all written by [`make_face_sequence`], read by
//! [`FaceSequence::open`](super::sequence_files::FaceSequence::open)):
//! - `sequence.json`: frame count, frame rate, image size, camera names, the FAP numbers with
//!   their names and ranges, and the settings used;
//! - `cameras/camN.json`: the cameras (the project's camera format);
//! - `images/camN/NNNN.png`: the frames;
//! - `model.obj`: the neutral face (metres, with texture coordinates) — the "adapted model"
//!   a tracker starts from;
//! - `init.csv`: pose and FAP values of frame 0 (the pre-positioning);
//! - `ground_truth.csv`: pose and FAP values of every frame (columns `frame`, `time`,
//!   `yaw_deg`, `pitch_deg`, `roll_deg`, `tx`, `ty`, `tz` (m), then `fap_N` in FAP units);
//! - `truth/texture.png`: the texture used (not needed by a tracker).
//!
//! Trajectories: yaw ±`yaw_deg`, pitch ±½·`yaw_deg`, roll ±⅓·`yaw_deg` and a translation of
//! ±1.5 cm, as sums of slow sines; each FAP moves between its range's ends as a raised cosine
//! of its own frequency (0.3–0.9 Hz), starting from the neutral face after its own delay (up to
//! 0.2 s), so expressions build up and relax. Lighting:
//! a global gain of 1 ± `light` per frame (slow), then Gaussian noise of σ = `noise`.

use std::path::Path;

use image::RgbImage;

use super::fap::FapRig;
use super::head_pose::{head_pivot, HeadPose};
use super::model::FaceMesh;
use super::render::{FaceRenderer, Texture};
use super::sequence_files::{write_pose_csv, PoseRow, SequenceInfo};
use super::sequence_options::FaceSequenceOptions;
use super::skin::procedural_face_texture;
use super::FaceError;
use crate::geometry::Camera;
use crate::geometry::{write_obj, ExportFrame, SplitMix64, Vec3};

/// The cameras of a sequence: `n` cameras at yaw angles spread over ±30° (one camera:
/// frontal), at `distance` from `pivot`, level with it, looking at it.
pub fn face_cameras(
    n: usize,
    width: u32,
    height: u32,
    focal: f64,
    distance: f64,
    pivot: Vec3,
) -> Vec<Camera> {
    (0..n)
        .map(|k| {
            let yaw = if n == 1 {
                0.0
            } else {
                (-30.0 + 60.0 * k as f64 / (n - 1) as f64).to_radians()
            };
            let eye = pivot + distance * Vec3::new(yaw.sin(), 0.05, yaw.cos());
            Camera::looking_at(eye, pivot, focal, width, height)
        })
        .collect()
}

/// Ground-truth pose and FAP values of frame `k` (see the [module docs](self)).
pub fn trajectory(
    options: &FaceSequenceOptions,
    ranges: &[(f64, f64)],
    k: usize,
) -> (HeadPose, Vec<f64>) {
    let t = k as f64 / options.fps;
    let tau = std::f64::consts::TAU;
    let mut rng = SplitMix64::new(options.seed.wrapping_mul(0x9E37_79B9) ^ 0xFACE);
    let mut phase = || rng.range(0.0, tau);
    let a = options.yaw_deg.to_radians();
    let (p1, p2, p3, p4, p5, p6) = (phase(), phase(), phase(), phase(), phase(), phase());
    let yaw = a * (0.8 * (tau * 0.31 * t + p1).sin() + 0.2 * (tau * 0.83 * t + p2).sin());
    let pitch = 0.5 * a * (tau * 0.47 * t + p3).sin();
    let roll = a / 3.0 * (tau * 0.37 * t + p4).sin();
    let tr = Vec3::new(
        0.015 * (tau * 0.23 * t + p5).sin(),
        0.01 * (tau * 0.29 * t + p6).sin(),
        0.015 * (tau * 0.19 * t + p1 + p2).sin(),
    );
    let faps = ranges
        .iter()
        .enumerate()
        .map(|(i, &(lo, hi))| {
            let f = 0.3 + 0.6 * ((i as f64 * 0.618_034) % 1.0);
            // every expression starts from the neutral face (the first frame textures the
            // model, as in the seed's protocol), with its own delay
            let ph = -tau * f * 0.2 * phase() / tau; // a delay of up to 0.2 s
                                                     // rest value: 0 when inside the range, else the nearer end
            let rest = 0.0f64.clamp(lo, hi);
            let peak = if (hi - rest).abs() >= (lo - rest).abs() {
                hi
            } else {
                lo
            };
            let s = if t + ph / (tau * f) <= 0.0 {
                0.0
            } else {
                0.5 - 0.5 * (tau * f * t + ph).cos()
            };
            rest + (peak - rest) * s
        })
        .collect();
    (HeadPose::from_angles(yaw, pitch, roll, tr), faps)
}

/// Writes a sequence into `out` (see the [module docs](self)); returns its description.
pub fn make_face_sequence(
    out: &Path,
    options: &FaceSequenceOptions,
) -> Result<SequenceInfo, FaceError> {
    options.validate()?;
    let mesh = match &options.model {
        Some(m) => FaceMesh::load_obj(Path::new(m), 1.0)?,
        None => FaceMesh::mediapipe()?,
    };
    mesh.validate("model")?;
    let rig = FapRig::new(&mesh)?;
    let mut fap_index = Vec::new();
    for &n in &options.faps {
        fap_index.push(
            rig.index_of(n).ok_or_else(|| {
                FaceError::parameter("faps", format!("FAP {n} is not in the rig"))
            })?,
        );
    }
    let ranges: Vec<(f64, f64)> = fap_index.iter().map(|&i| rig.faps[i].range).collect();
    let texture = match &options.texture {
        Some(t) => Texture::load(Path::new(t))?,
        None => procedural_face_texture(&mesh, options.texture_size, options.seed),
    };
    let pivot = head_pivot(&mesh);
    let cameras = face_cameras(
        options.cameras,
        options.width,
        options.height,
        options.focal,
        options.distance,
        pivot,
    );
    let mut rng = SplitMix64::new(options.seed ^ 0x00BA_C60D);
    let backgrounds = backgrounds(options, &mut rng)?;

    let mkdir = |p: &Path| std::fs::create_dir_all(p).map_err(|e| FaceError::io(p, e));
    mkdir(&out.join("cameras"))?;
    mkdir(&out.join("truth"))?;
    let names: Vec<String> = (0..cameras.len()).map(|k| format!("cam{k}")).collect();
    for (cam, name) in cameras.iter().zip(&names) {
        mkdir(&out.join("images").join(name))?;
        let path = out.join("cameras").join(format!("{name}.json"));
        cam.save(&path).map_err(|e| FaceError::io(&path, e))?;
    }
    let model_path = out.join("model.obj");
    let tris: Vec<[usize; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| i as usize))
        .collect();
    // the face model is +Y up already: through the engine's frame and back, exactly
    let frame = ExportFrame::Y_UP_METRES;
    let engine: Vec<Vec3> = mesh.positions.iter().map(|p| frame.to_engine(p)).collect();
    write_obj(&model_path, &engine, &tris, Some(&mesh.uvs), frame)
        .map_err(|e| FaceError::io(&model_path, e))?;
    texture.save(&out.join("truth").join("texture.png"))?;

    let mut rows = Vec::with_capacity(options.frames);
    let mut renderer = FaceRenderer::new(options.width as usize, options.height as usize);
    let mut values = vec![0.0; rig.len()];
    let (mut deformed, mut posed) = (Vec::new(), Vec::new());
    let mut light_rng = SplitMix64::new(options.seed ^ 0x11_6470);
    let lp = [light_rng.range(0.0, 6.3), light_rng.range(0.0, 6.3)];
    for k in 0..options.frames {
        let (pose, faps) = trajectory(options, &ranges, k);
        values.iter_mut().for_each(|v| *v = 0.0);
        for (&i, &v) in fap_index.iter().zip(&faps) {
            values[i] = v;
        }
        rig.apply(&mesh.positions, &values, &mut deformed);
        pose.apply(&pivot, &deformed, &mut posed);
        let t = k as f64 / options.fps;
        let gain =
            1.0 + options.light * (0.7 * (1.3 * t + lp[0]).sin() + 0.3 * (3.1 * t + lp[1]).sin());
        for (c, cam) in cameras.iter().enumerate() {
            renderer.render(cam, &posed, &mesh.uvs, &mesh.triangles, &texture);
            let mut img = renderer.composite(&backgrounds[c])?;
            let mut noise = SplitMix64::new(options.seed ^ ((k as u64) << 8) ^ c as u64 ^ 0x0153);
            for p in img.pixels_mut() {
                for ch in p.0.iter_mut() {
                    let v = *ch as f64 * gain + options.noise * noise.normal();
                    *ch = v.round().clamp(0.0, 255.0) as u8;
                }
            }
            let path = out
                .join("images")
                .join(&names[c])
                .join(format!("{k:04}.png"));
            img.save(&path).map_err(|e| FaceError::io(&path, e))?;
        }
        rows.push(PoseRow {
            frame: k,
            time: t,
            pose,
            faps,
        });
    }
    write_pose_csv(&out.join("ground_truth.csv"), &options.faps, &rows)?;
    write_pose_csv(&out.join("init.csv"), &options.faps, &rows[..1])?;
    let info = SequenceInfo {
        frames: options.frames,
        fps: options.fps,
        width: options.width,
        height: options.height,
        cameras: names,
        faps: options.faps.clone(),
        fap_names: fap_index
            .iter()
            .map(|&i| rig.faps[i].name.clone())
            .collect(),
        fap_ranges: ranges,
        options: Some(options.clone()),
    };
    info.save(&out.join("sequence.json"))?;
    Ok(info)
}

/// One background per camera: the first photo of the folder cropped at a seeded place, or grey.
fn backgrounds(
    options: &FaceSequenceOptions,
    rng: &mut SplitMix64,
) -> Result<Vec<RgbImage>, FaceError> {
    let (w, h) = (options.width, options.height);
    let grey = || RgbImage::from_pixel(w, h, image::Rgb([110, 115, 120]));
    let Some(dir) = &options.backgrounds else {
        return Ok(vec![grey(); options.cameras]);
    };
    let dir = Path::new(dir);
    let photos = crate::geometry::photo_files(dir).map_err(|e| FaceError::io(dir, e))?;
    if photos.is_empty() {
        return Err(FaceError::io(
            dir,
            format!(
                "no background photos ({}) in the folder",
                crate::geometry::image::photo_formats::photo_extensions_list()
            ),
        ));
    }
    (0..options.cameras)
        .map(|c| {
            let path = &photos[(options.seed as usize + c) % photos.len()];
            let img = crate::geometry::image::read_photo(path)?;
            let s = (w as f64 / img.width() as f64).max(h as f64 / img.height() as f64);
            let (nw, nh) = (
                ((img.width() as f64 * s).ceil() as u32).max(w),
                ((img.height() as f64 * s).ceil() as u32).max(h),
            );
            let big = image::imageops::resize(&img, nw, nh, image::imageops::FilterType::Triangle);
            let ox = rng.below((nw - w + 1) as usize) as u32;
            let oy = rng.below((nh - h + 1) as usize) as u32;
            Ok(image::imageops::crop_imm(&big, ox, oy, w, h).to_image())
        })
        .collect()
}
