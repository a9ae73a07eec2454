//! Synthetic multi-camera sequences with ground truth: the MakeHuman mannequin, dressed by
//! [`clothing_colours`], animated by a BVH clip (on a treadmill), filmed by a ring of cameras
//! in front of real photos, with a static occluder, changing light and sensor noise.
//!
//! # Output layout (read back by [`Sequence::open`](super::sequence_files::Sequence::open))
//!
//! ```text
//! DIR/sequence.json          fps, frames, width, height, cameras ["cam0", …], motion file
//!                            name, joint names, noise / lighting / occluder settings (and
//!                            each camera's occluder rectangle and photos), seed
//! DIR/cameras/cam0.json …    Camera::to_json of each camera
//! DIR/images/cam0/0000.png … one PNG per camera and frame (4-digit frame numbers from 0)
//! DIR/backgrounds/cam0.png … the empty scene of each camera (the "clean plate" shot before
//!                            the athlete walks in): photo and occluder, frame 0's light,
//!                            its own noise
//! DIR/ground_truth.csv       frame,time,pelvis_x,pelvis_y,pelvis_z,spine_x,… (metres, world
//!                            frame, TRACKING_JOINTS order), one row per frame
//! DIR/init_joints.csv        same columns, one row: frame 0's joints plus seeded Gaussian
//!                            noise of 2 cm per coordinate (the pose "a user would click")
//! ```
//!
//! # What is rendered
//!
//! Frame `k` is animation time `t = k / fps`. Its pose is `Animation::pose_at(t)`; the skin is
//! skinned by linear blending (or rigidly by dominant bone, [`SequenceOptions::lbs`] false),
//! shaded per vertex (Lambert from a fixed light, ambient 0.55) and rasterized by
//! [`draw_triangles`] over the camera's background photo (scaled to cover the image, then
//! cropped). A static rectangle textured with another photo covers
//! [`SequenceOptions::occluder_fraction`] of each image, over one side of the body or its legs.
//! The light then varies: every pixel is multiplied by
//! `(1 + A sin(2π t / 2 s)) · (1 + A/2 · sin(2π t / 7 s + 2π c / N) · (2 (x + 0.5) / W − 1))`
//! for camera `c` of `N` (`A` = [`SequenceOptions::lighting_amplitude`]), Gaussian noise of
//! [`SequenceOptions::noise_sigma`] grey levels is added per channel (drawn from a seeded table
//! of 65 536 normal samples of exact mean 0 and variance 1), and values are rounded to 8 bits. The ground truth is [`JointSet::positions`] of the same pose.
//!
//! Cameras form a ring around the body (azimuths `30° + k · 360° / N`, ~4.5 m away, ~1.5 m
//! high, looking at the body's mid-height) with a focal length such that 1.9 m fills 70% of
//! the image height, and radial distortion `k1 = −0.03`.
//!
//! Every random choice (photos, crops, palette, occluders, noise) comes from
//! [`SequenceOptions::seed`] through per-camera and per-frame [`SplitMix64`] streams: the same
//! options write the same files, bit for bit, whatever the number of threads.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use image::RgbImage;
use indicatif::ProgressBar;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::clothing::{clothing_colours, dominant_bone, shaded_colours, skin_positions};
use super::joints::{JointSet, TRACKING_JOINTS};
use super::sequence_files::{
    cover, image_path, io_err, list_photos, write_joints_csv, write_png, JointFrame, SequenceError,
};
use crate::body::bvh::{MAX_FRAME_TIME, MIN_FRAME_TIME};
use crate::body::{Animation, BodyError, Mannequin, Motion, RetargetOptions};
use crate::geometry::files::data_dir;
use crate::geometry::Camera;
use crate::geometry::{SplitMix64, Vec3};
use crate::limits;
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget};

/// Settings of [`make_sequence`]; see the [module docs](self) for what each does.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SequenceOptions {
    /// Number of cameras on the ring (1..=64). Default 4.
    pub cameras: usize,
    /// Image width, pixels (16..=8192). Default 320.
    pub width: u32,
    /// Image height, pixels (16..=8192). Default 240.
    pub height: u32,
    /// Frames per second, 0.1 to 10,000 (a BVH's frame time range). Default 50.
    pub fps: f64,
    /// Number of frames, at most the limit `max_frames`; `None` (default) = the whole clip at
    /// `fps`.
    pub frames: Option<usize>,
    /// Clip time (seconds) of frame 0. Default 0.
    pub start_time: f64,
    /// Standard deviation of the per-channel Gaussian noise, grey levels. Default 4.
    pub noise_sigma: f64,
    /// Amplitude `A` of the lighting changes (0..=0.9). Default 0.15.
    pub lighting_amplitude: f64,
    /// Fraction of each image covered by the static occluder (0..=0.5; 0 = none). Default 0.10.
    pub occluder_fraction: f64,
    /// Folder of background photos (any of the
    /// [`PHOTO_EXTENSIONS`](crate::geometry::image::PHOTO_EXTENSIONS)). Default
    /// `$EMILION_DATA/facades/labelmefacade/images`.
    pub backgrounds: PathBuf,
    /// MakeHuman data folder. Default `$EMILION_DATA/bodies/makehuman`.
    pub makehuman: PathBuf,
    /// Seed of every random choice. Default 1.
    pub seed: u64,
    /// Lambert shading (false: flat clothing colours). Default true.
    pub shading: bool,
    /// Linear blend skinning (false: every vertex follows its dominant bone rigidly). Default true.
    pub lbs: bool,
    /// Draw the body (false renders the empty scene, for checks). Default true.
    pub body: bool,
}

impl Default for SequenceOptions {
    fn default() -> Self {
        let data = data_dir();
        SequenceOptions {
            cameras: 4,
            width: 320,
            height: 240,
            fps: 50.0,
            frames: None,
            start_time: 0.0,
            noise_sigma: 4.0,
            lighting_amplitude: 0.15,
            occluder_fraction: 0.10,
            backgrounds: data.join("facades/labelmefacade/images"),
            makehuman: data.join("bodies/makehuman"),
            seed: 1,
            shading: true,
            lbs: true,
            body: true,
        }
    }
}

impl SequenceOptions {
    /// Checks the ranges given in the field docs.
    pub fn validate(&self) -> Result<(), SequenceError> {
        let bad = |m: String| Err(SequenceError::Options(m));
        if !(1..=64).contains(&self.cameras) {
            return bad(format!("cameras must be in 1..=64, got {}", self.cameras));
        }
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if !(16..=8192).contains(&v) {
                return bad(format!("{name} must be in 16..=8192 pixels, got {v}"));
            }
        }
        let (min_fps, max_fps) = (1.0 / MAX_FRAME_TIME, 1.0 / MIN_FRAME_TIME);
        if !(self.fps.is_finite() && (min_fps..=max_fps).contains(&self.fps)) {
            return bad(format!(
                "fps must be in [{min_fps}, {max_fps}] frames per second, got {}",
                self.fps
            ));
        }
        let max_frames = limits::get().max_frames;
        if matches!(self.frames, Some(0)) || self.frames.is_some_and(|f| f as u64 > max_frames) {
            return bad(format!(
                "frames must be in 1..={max_frames} (the limit max_frames), got {:?}",
                self.frames
            ));
        }
        let ranges = [
            ("start_time", self.start_time, 0.0, 1e9),
            ("noise_sigma", self.noise_sigma, 0.0, 100.0),
            ("lighting_amplitude", self.lighting_amplitude, 0.0, 0.9),
            ("occluder_fraction", self.occluder_fraction, 0.0, 0.5),
        ];
        for (name, v, lo, hi) in ranges {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return bad(format!("{name} must be in [{lo}, {hi}], got {v}"));
            }
        }
        Ok(())
    }
}

/// What [`make_sequence`] wrote.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SequenceSummary {
    /// The output folder.
    pub dir: PathBuf,
    /// Frames written.
    pub frames: usize,
    /// Cameras.
    pub cameras: usize,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Wall time, seconds.
    pub seconds: f64,
    /// Wall time per frame (all cameras), seconds.
    pub seconds_per_frame: f64,
}

/// A static occluding rectangle `[x0, x1) × [y0, y1)` in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Occluder {
    /// Left column.
    pub x0: u32,
    /// Top row.
    pub y0: u32,
    /// Right end (exclusive).
    pub x1: u32,
    /// Bottom end (exclusive).
    pub y1: u32,
}

impl Occluder {
    /// Whether pixel `(x, y)` is covered.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        x >= self.x0 && x < self.x1 && y >= self.y0 && y < self.y1
    }

    /// Covered pixels.
    pub fn area(&self) -> u64 {
        u64::from(self.x1 - self.x0) * u64::from(self.y1 - self.y0)
    }
}

/// A ring of `n` cameras around `centre` (see the [module docs](self)), validated.
pub fn ring_cameras(
    n: usize,
    width: u32,
    height: u32,
    centre: Vec3,
) -> Result<Vec<Camera>, SequenceError> {
    (0..n)
        .map(|k| {
            let az = (30.0 + k as f64 * 360.0 / n as f64).to_radians();
            let radius = 4.5 + 0.25 * (1.7 * k as f64).cos();
            let h = 1.5 + 0.1 * (2.3 * k as f64).sin();
            let eye = Vec3::new(
                centre.x + radius * az.cos(),
                centre.y + radius * az.sin(),
                h,
            );
            let dist = (centre - eye).norm();
            let focal = 0.7 * height as f64 * dist / 1.9;
            let cam = Camera {
                k1: -0.03,
                ..Camera::looking_at_up(eye, centre, Vec3::z(), focal, width, height)
            };
            cam.validate_named(&format!("cam{k}"))?;
            Ok(cam)
        })
        .collect()
}

/// The occluder of one camera: `fraction` of the image, over one side of the body's image
/// region `bbox` (x0, y0, x1, y1) or over its legs, inside the image.
fn place_occluder(bbox: [f64; 4], w: u32, h: u32, fraction: f64, rng: &mut SplitMix64) -> Occluder {
    let area = fraction * w as f64 * h as f64;
    let (bw, bh) = ((bbox[2] - bbox[0]).max(4.0), (bbox[3] - bbox[1]).max(4.0));
    let legs = rng.uniform() < 0.4;
    let (ow, oh, cx, cy) = if legs {
        let ow = (1.6 * bw).clamp(area / h as f64, w as f64).round();
        let oh = (area / ow).round().min(h as f64);
        let cx = 0.5 * (bbox[0] + bbox[2]) + rng.range(-0.25, 0.25) * bw;
        (ow, oh, cx, bbox[1] + 0.78 * bh + 0.5 * oh)
    } else {
        let oh = (0.75 * bh).clamp(area / w as f64, h as f64).round();
        let ow = (area / oh).round().min(w as f64);
        // the inner edge a little past the body's middle: one side hidden, the other seen
        let (xc, half) = (0.5 * (bbox[0] + bbox[2]), (0.5 * bw).max(0.04 * w as f64));
        let inner = 0.25 * half;
        let cx = if rng.bit() {
            xc - inner - 0.5 * ow
        } else {
            xc + inner + 0.5 * ow
        };
        (
            ow,
            oh,
            cx,
            0.5 * (bbox[1] + bbox[3]) + rng.range(-0.1, 0.1) * bh,
        )
    };
    let (ow, oh) = (ow.max(1.0) as u32, oh.max(1.0) as u32);
    let x0 = (cx - 0.5 * ow as f64).round().clamp(0.0, (w - ow) as f64) as u32;
    let y0 = (cy - 0.5 * oh as f64).round().clamp(0.0, (h - oh) as f64) as u32;
    Occluder {
        x0,
        y0,
        x1: x0 + ow,
        y1: y0 + oh,
    }
}

/// Everything fixed about one camera, and its reusable render buffers.
struct CameraSlot {
    name: String,
    camera: Camera,
    background: RgbImage,
    occluder: Option<(Occluder, RgbImage)>,
    phase: f64,
    target: RasterTarget,
    projected: Vec<[f32; 3]>,
    image: RgbImage,
    noise_seed: u64,
}

/// A seed for stream `a`, `b` of `seed`.
fn mix(seed: u64, a: u64, b: u64) -> u64 {
    let mut r = SplitMix64::new(
        seed ^ a.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ b.wrapping_mul(0xD1B5_4A32_D192_ED03),
    );
    r.next_u64()
}

/// Renders one camera's image of the current frame into `slot.image`.
#[allow(clippy::too_many_arguments)]
fn render(
    slot: &mut CameraSlot,
    skin: &[Vec3],
    colours: &[[f32; 3]],
    triangles: &[[u32; 3]],
    noise: &[f32],
    t: f64,
    frame: usize,
    o: &SequenceOptions,
) {
    slot.target.clear();
    if o.body {
        project_vertices(&slot.camera, skin, &mut slot.projected);
        draw_triangles(&mut slot.target, &slot.projected, colours, triangles);
    }
    let (w, h) = (slot.camera.width, slot.camera.height);
    let a = o.lighting_amplitude;
    let tau = std::f64::consts::TAU;
    let gain = 1.0 + a * (tau * t / 2.0).sin();
    let slope = 0.5 * a * (tau * t / 7.0 + slot.phase).sin();
    let mut rng = SplitMix64::new(mix(slot.noise_seed, frame as u64, 7));
    let sigma = o.noise_sigma as f32;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let base = match &slot.occluder {
                Some((r, tex)) if r.contains(x, y) => {
                    tex.get_pixel(x - r.x0, y - r.y0).0.map(f32::from)
                }
                _ if slot.target.depth[i].is_finite() => slot.target.rgb[i],
                _ => slot.background.get_pixel(x, y).0.map(f32::from),
            };
            let g = (gain * (1.0 + slope * (2.0 * (x as f64 + 0.5) / w as f64 - 1.0))) as f32;
            // three 16-bit draws from the normal table, one per channel
            let bits = if sigma > 0.0 { rng.next_u64() } else { 0 };
            let mut px = [0u8; 3];
            for (c, out) in px.iter_mut().enumerate() {
                let n = if sigma > 0.0 {
                    sigma * noise[(bits >> (16 * c)) as usize & 0xFFFF]
                } else {
                    0.0
                };
                *out = (base[c] * g + n).round().clamp(0.0, 255.0) as u8;
            }
            slot.image.put_pixel(x, y, image::Rgb(px));
        }
    }
}

/// 65 536 standard normal samples (Box–Muller from `seed`), shifted and scaled to mean 0 and
/// variance 1 exactly: the sensor noise draws from this table with 16 random bits, which is
/// several times faster than drawing normals per pixel.
fn normal_table(seed: u64) -> Vec<f32> {
    let mut rng = SplitMix64::new(seed);
    let mut v: Vec<f64> = (0..1 << 16).map(|_| rng.normal()).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n).sqrt();
    v.iter_mut().for_each(|x| *x = (*x - mean) / sd);
    v.into_iter().map(|x| x as f32).collect()
}

/// Makes a synthetic sequence of `motion` (a BVH clip) into folder `out` (created; existing
/// files are overwritten): see the [module docs](self) for the layout and what is rendered.
pub fn make_sequence(
    motion: &Path,
    out: &Path,
    options: &SequenceOptions,
) -> Result<SequenceSummary, SequenceError> {
    let start = Instant::now();
    let o = options;
    o.validate()?;
    let mannequin = Mannequin::load_makehuman(&o.makehuman)?;
    let clip = Motion::load_bvh(motion)?;
    let joints = JointSet::new(&mannequin).map_err(|m| BodyError::invalid("mannequin", m))?;
    let base_colours = clothing_colours(&mannequin, o.seed);
    let triangles: Vec<[u32; 3]> = mannequin
        .triangles()
        .iter()
        .map(|t| t.map(|i| i as u32))
        .collect();
    let dominant: Option<Vec<usize>> = (!o.lbs).then(|| {
        (0..mannequin.rest_positions().len())
            .map(|v| dominant_bone(&mannequin, v))
            .collect()
    });
    let retarget = RetargetOptions {
        start_time: o.start_time,
        ..RetargetOptions::default()
    };
    let anim = Animation::new(mannequin, clip, retarget)?;
    let frames = match o.frames {
        Some(f) => f,
        None => {
            let n = (anim.duration() * o.fps + 1e-9).floor() + 1.0;
            let what = format!(
                "the frame count of {} ({} s at {} fps)",
                motion.display(),
                anim.duration(),
                o.fps
            );
            limits::check(&what, n, "max_frames", limits::get().max_frames)
                .map_err(|e| SequenceError::Options(e.to_string()))? as usize
        }
    };
    let time = |k: usize| k as f64 / o.fps;

    // ground truth first: it places the cameras' occluders
    let mut pose = anim.mannequin().rest_pose();
    let truth: Vec<JointFrame> = (0..frames)
        .map(|k| {
            anim.pose_at_into(time(k), &mut pose);
            joints.positions(&pose)
        })
        .collect();
    let top = anim
        .mannequin()
        .rest_positions()
        .iter()
        .map(|p| p.z)
        .fold(0.0f64, f64::max);
    let pelvis_mean = truth.iter().map(|j| j[0]).sum::<Vec3>() / frames as f64;
    let centre = Vec3::new(pelvis_mean.x, pelvis_mean.y, 0.5 * top);
    let (w, h) = (o.width, o.height);
    let cameras = ring_cameras(o.cameras, w, h, centre)?;

    // backgrounds and occluders, one seeded stream per camera
    let photos = list_photos(&o.backgrounds)?;
    let mut order: Vec<usize> = (0..photos.len()).collect();
    let mut rng = SplitMix64::new(mix(o.seed, 1, 0));
    for i in (1..order.len()).rev() {
        order.swap(i, rng.below(i + 1));
    }
    let mut slots = Vec::with_capacity(cameras.len());
    let mut meta_cams = Vec::new();
    for (c, camera) in cameras.into_iter().enumerate() {
        let mut rng = SplitMix64::new(mix(o.seed, 2, c as u64));
        let bg_index = order[c % order.len()];
        let background = cover(&photos[bg_index], w, h, &mut rng)?;
        let mut bbox = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in truth.iter().flatten() {
            if let Some(uv) = camera.project(p) {
                bbox = [
                    bbox[0].min(uv[0]),
                    bbox[1].min(uv[1]),
                    bbox[2].max(uv[0]),
                    bbox[3].max(uv[1]),
                ];
            }
        }
        if !bbox[0].is_finite() {
            bbox = [
                0.25 * w as f64,
                0.1 * h as f64,
                0.75 * w as f64,
                0.9 * h as f64,
            ];
        }
        let occluder = if o.occluder_fraction > 0.0 {
            let rect = place_occluder(bbox, w, h, o.occluder_fraction, &mut rng);
            let mut tex_index = order[(c + o.cameras) % order.len()];
            if tex_index == bg_index && photos.len() > 1 {
                tex_index = order[(c + o.cameras + 1) % order.len()];
            }
            let tex = cover(
                &photos[tex_index],
                rect.x1 - rect.x0,
                rect.y1 - rect.y0,
                &mut rng,
            )?;
            Some((rect, tex, tex_index))
        } else {
            None
        };
        let name = format!("cam{c}");
        let file_name = |i: usize| {
            photos[i]
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
        };
        meta_cams.push(serde_json::json!({
            "name": name,
            "background": file_name(bg_index),
            "occluder": occluder.as_ref().map(|(r, _, _)| r),
            "occluder_texture": occluder.as_ref().map(|o| file_name(o.2)),
        }));
        slots.push(CameraSlot {
            name,
            target: RasterTarget::new(w as usize, h as usize),
            projected: Vec::new(),
            image: RgbImage::new(w, h),
            background,
            occluder: occluder.map(|(r, t, _)| (r, t)),
            phase: std::f64::consts::TAU * c as f64 / o.cameras as f64,
            noise_seed: mix(o.seed, 3, c as u64),
            camera,
        });
    }

    // files that do not depend on the frames
    for dir in [
        out.to_path_buf(),
        out.join("cameras"),
        out.join("backgrounds"),
    ]
    .into_iter()
    .chain(slots.iter().map(|s| out.join("images").join(&s.name)))
    {
        std::fs::create_dir_all(&dir).map_err(io_err(&dir))?;
    }
    for s in &slots {
        s.camera
            .save(out.join("cameras").join(format!("{}.json", s.name)))?;
    }
    let motion_name = motion.file_name().map(|n| n.to_string_lossy().into_owned());
    let meta = serde_json::json!({
        "format": "emilion sequence",
        "version": 1,
        "fps": o.fps,
        "frames": frames,
        "width": w,
        "height": h,
        "cameras": slots.iter().map(|s| s.name.clone()).collect::<Vec<_>>(),
        "motion": motion_name,
        "start_time": o.start_time,
        "joints": TRACKING_JOINTS.map(|j| j.name),
        "noise_sigma": o.noise_sigma,
        "lighting_amplitude": o.lighting_amplitude,
        "occluder_fraction": o.occluder_fraction,
        "shading": o.shading,
        "lbs": o.lbs,
        "body": o.body,
        "seed": o.seed,
        "camera_details": meta_cams,
    });
    let meta_path = out.join("sequence.json");
    let text = serde_json::to_string_pretty(&meta).map_err(|e| SequenceError::Json {
        path: meta_path.clone(),
        message: e.to_string(),
    })?;
    std::fs::write(&meta_path, text + "\n").map_err(io_err(&meta_path))?;
    let rows: Vec<_> = truth
        .iter()
        .enumerate()
        .map(|(k, j)| (k, time(k), *j))
        .collect();
    write_joints_csv(&out.join("ground_truth.csv"), &rows)?;
    let mut rng = SplitMix64::new(mix(o.seed, 4, 0));
    let init = truth[0].map(|p| p + Vec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.02);
    write_joints_csv(&out.join("init_joints.csv"), &[(0, 0.0, init)])?;

    // the clean plates: the scene without the body, with noise of its own
    let noise = normal_table(mix(o.seed, 5, 0));
    let empty = SequenceOptions {
        body: false,
        ..o.clone()
    };
    slots.par_iter_mut().try_for_each(|s| {
        render(s, &[], &[], &[], &noise, 0.0, usize::MAX, &empty);
        write_png(
            &out.join("backgrounds").join(format!("{}.png", s.name)),
            &s.image,
        )
    })?;

    // the frames: cameras rendered in parallel
    let pb = if std::io::stderr().is_terminal() {
        ProgressBar::new(frames as u64)
    } else {
        ProgressBar::hidden()
    };
    let (mut skin, mut normals, mut colours) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..frames {
        let t = time(k);
        anim.pose_at_into(t, &mut pose);
        skin_positions(anim.mannequin(), &pose, dominant.as_deref(), &mut skin);
        shaded_colours(
            &skin,
            &triangles,
            &base_colours,
            &mut normals,
            &mut colours,
            o.shading,
        );
        slots.par_iter_mut().try_for_each(|s| {
            render(s, &skin, &colours, &triangles, &noise, t, k, o);
            write_png(&image_path(out, &s.name, k), &s.image)
        })?;
        pb.inc(1);
    }
    pb.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    Ok(SequenceSummary {
        dir: out.to_path_buf(),
        frames,
        cameras: o.cameras,
        width: w,
        height: h,
        seconds,
        seconds_per_frame: seconds / frames as f64,
    })
}
