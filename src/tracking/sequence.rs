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
//! [`draw_triangles`](crate::render::raster::draw_triangles) over the camera's background photo (scaled to cover the image, then
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

use indicatif::ProgressBar;
use serde::Serialize;

use super::clothing::{clothing_colours, dominant_bone, shaded_colours, skin_positions};
use super::joints::{JointSet, TRACKING_JOINTS};
use super::sequence_files::{write_sequence_json, write_truth_files, JointFrame, SequenceError};
pub use super::sequence_options::SequenceOptions;
pub use super::sequence_render::Occluder;
use super::sequence_render::{mix, SceneMesh, SequenceWriter};
use crate::body::{Animation, BodyError, Mannequin, Motion, RetargetOptions};
use crate::geometry::Camera;
use crate::geometry::{SplitMix64, Vec3};
use crate::limits;

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
    let points: Vec<Vec3> = truth.iter().flatten().copied().collect();
    let mut writer = SequenceWriter::new(out, cameras, &points, o)?;
    writer.write_cameras_and_plates()?;
    let motion_name = motion.file_name().map(|n| n.to_string_lossy().into_owned());
    let meta = serde_json::json!({
        "format": "emilion sequence",
        "version": 1,
        "fps": o.fps,
        "frames": frames,
        "width": w,
        "height": h,
        "cameras": writer.camera_names(),
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
        "camera_details": writer.camera_details,
    });
    write_sequence_json(out, &meta)?;
    let rows: Vec<_> = truth
        .iter()
        .enumerate()
        .map(|(k, j)| (k, time(k), *j))
        .collect();
    write_truth_files(out, &rows, &mut SplitMix64::new(mix(o.seed, 4, 0)))?;

    // the frames: cameras rendered in parallel
    let pb = if std::io::stderr().is_terminal() {
        ProgressBar::new(frames as u64)
    } else {
        ProgressBar::hidden()
    };
    let mut scene = [SceneMesh {
        triangles,
        ..SceneMesh::default()
    }];
    let mut normals = Vec::new();
    for k in 0..frames {
        let t = time(k);
        anim.pose_at_into(t, &mut pose);
        let s = &mut scene[0];
        skin_positions(
            anim.mannequin(),
            &pose,
            dominant.as_deref(),
            &mut s.positions,
        );
        shaded_colours(
            &s.positions,
            &s.triangles,
            &base_colours,
            &mut normals,
            &mut s.colours,
            o.shading,
        );
        writer.write_frame(k, t, &scene)?;
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
