//! Everything a tracking run writes: the tracked motion (BVH and joint CSV), the broadcast
//! overlay pictures (every camera with the skeleton drawn, the ground truth too when known)
//! and their slow-motion animation (`broadcast.png`, an animated PNG a browser plays),
//! the swing metrics (CSV and plots), per-frame errors against the ground truth, and a
//! JSON summary with the time per stage.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::bvh_export::{write_bvh, write_joints_csv, TrackingOutputError};
use super::joints::{joint_index, JOINT_COUNT, TRACKING_JOINTS};
use super::loss::FrameStatus;
use super::overlay::{draw_club, write_overlay_png_with};
use super::sequence_files::{Sequence, SequenceError};
use super::swing_metrics::{swing_metrics, write_swing_metrics};
use super::tracker::TrackResult;
use crate::geometry::Vec3;
use crate::render::animated_png::{AnimatedPng, AnimatedPngError};

/// How many times slower than life the broadcast animation plays.
pub const SLOW_MOTION: f64 = 5.0;
/// Largest width of the broadcast animation's frames (pixels).
const ANIMATION_WIDTH: u32 = 640;

/// What to write.
#[derive(Clone, Debug)]
pub struct TrackOutputOptions {
    /// Write an overlay picture every this many frames (0: none).
    pub overlay_every: usize,
}

impl Default for TrackOutputOptions {
    fn default() -> Self {
        TrackOutputOptions { overlay_every: 1 }
    }
}

/// Errors of writing the outputs.
#[derive(Debug, thiserror::Error)]
pub enum TrackOutputError {
    /// A tracking output failed (names the file).
    #[error(transparent)]
    Output(#[from] TrackingOutputError),
    /// Reading the sequence's images failed.
    #[error(transparent)]
    Sequence(#[from] SequenceError),
    /// The broadcast animation could not be written.
    #[error(transparent)]
    Animation(#[from] AnimatedPngError),
    /// A folder or file could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The path.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> TrackOutputError + '_ {
    move |source| TrackOutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The arm joints (elbows and wrists), the seed report's focus.
pub fn arm_joints() -> Vec<usize> {
    ["l_elbow", "l_wrist", "r_elbow", "r_wrist"]
        .iter()
        .filter_map(|n| joint_index(n))
        .collect()
}

/// The summary of a run as JSON text.
pub fn summary_json(seq: &Sequence, result: &TrackResult) -> String {
    let stages: serde_json::Map<String, serde_json::Value> = result
        .stage_seconds
        .iter()
        .map(|(k, v)| {
            (
                k.clone(),
                serde_json::json!(v / result.frame_seconds.len().max(1) as f64),
            )
        })
        .collect();
    let v = serde_json::json!({
        "sequence": seq.dir.display().to_string(),
        "frames": result.joints.len(),
        "cameras": seq.cameras.len(),
        "mpjpe_mm": result.mpjpe_mm(),
        "max_frame_mm": result.errors_mm.as_ref().map(|e| e.iter().cloned().fold(0.0, f64::max)),
        "arm_mm": result.joints_error_mm(&arm_joints()),
        "first_frame": result.first_frame,
        "lost_frames": result.frames_with(FrameStatus::Lost),
        "recovered_frames": result.frames_with(FrameStatus::Recovered),
        "seconds_per_frame": result.seconds_per_frame(),
        "seconds_per_frame_by_stage": stages,
        "io_seconds_per_frame": result.io_seconds / result.joints.len().max(1) as f64,
        "start_seconds": result.start_seconds,
        "proportions": result.proportions.map(|p| p.to_json()),
        "evaluations_per_frame": result.evaluations as f64 / result.frame_seconds.len().max(1) as f64,
    });
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// Writes the outputs of `result` (tracked from `seq`) under `out`; returns the files.
pub fn write_track_outputs(
    seq: &Sequence,
    result: &TrackResult,
    out: &Path,
    options: &TrackOutputOptions,
) -> Result<Vec<PathBuf>, TrackOutputError> {
    std::fs::create_dir_all(out).map_err(io(out))?;
    let mut files = Vec::new();
    let joints = out.join("tracked_joints.csv");
    write_joints_csv(&joints, &result.joints, seq.fps)?;
    files.push(joints);
    let bvh = out.join("tracked.bvh");
    write_bvh(&bvh, &result.joints, seq.fps)?;
    files.push(bvh);
    files.extend(write_swing_metrics(
        out,
        "swing_metrics",
        &swing_metrics(&result.joints, seq.fps),
    )?);
    if let (Some(frames), Some(joints)) = (&result.errors_mm, &result.joint_errors_mm) {
        let path = out.join("errors.csv");
        let mut s = String::from("frame,mpjpe_mm");
        for t in &TRACKING_JOINTS {
            let _ = write!(s, ",{}_mm", t.name);
        }
        s.push('\n');
        for (k, (e, j)) in frames.iter().zip(joints).enumerate() {
            let _ = write!(s, "{},{e:.3}", result.first_frame + k);
            for x in j {
                let _ = write!(s, ",{x:.3}");
            }
            s.push('\n');
        }
        std::fs::write(&path, s).map_err(io(&path))?;
        files.push(path);
    }
    files.push(write_status_csv(out, result)?);
    if options.overlay_every > 0 {
        let frames: Vec<usize> = (0..result.joints.len())
            .step_by(options.overlay_every)
            .map(|k| result.first_frame + k)
            .collect();
        files.extend(write_broadcast(
            seq,
            out,
            result.first_frame,
            &result.joints,
            &frames,
            None,
        )?);
    }
    let path = out.join("summary.json");
    std::fs::write(&path, summary_json(seq, result)).map_err(io(&path))?;
    files.push(path);
    Ok(files)
}

/// A tracked club to draw over the broadcast pictures: grip and head per tracked frame.
#[derive(Clone, Copy, Debug)]
pub struct ClubOverlay<'a> {
    /// Grip point per tracked frame (from the first tracked frame).
    pub grip: &'a [Vec3],
    /// Head centre per tracked frame.
    pub head: &'a [Vec3],
}

/// Head positions of the frames before shown as the club's path.
const CLUB_TRAIL: usize = 12;

/// Writes the broadcast pictures `out/overlay/NNNN.png` of the sequence's `frames` (every
/// camera with the tracked skeleton `joints[f − first]`, the truth beneath when known, the
/// club with its head's path over the last frames when given) and their slow-motion
/// animation `out/broadcast.png` (at most 640 px wide, [`SLOW_MOTION`] times slower than
/// life, frames evenly spaced as given). Returns the files.
pub fn write_broadcast(
    seq: &Sequence,
    out: &Path,
    first: usize,
    joints: &[[Vec3; JOINT_COUNT]],
    frames: &[usize],
    club: Option<ClubOverlay>,
) -> Result<Vec<PathBuf>, TrackOutputError> {
    let dir = out.join("overlay");
    std::fs::create_dir_all(&dir).map_err(io(&dir))?;
    let mut files = Vec::new();
    let step = match frames {
        [a, b, ..] => b.saturating_sub(*a).max(1),
        _ => 1,
    };
    let frames: Vec<usize> = (frames.iter().copied())
        .filter(|f| f.checked_sub(first).is_some_and(|k| k < joints.len()))
        .collect();
    let mut movie: Option<AnimatedPng> = None;
    for &f in &frames {
        let k = f - first;
        let tracked = &joints[k];
        let images = seq.frame_images(f)?;
        let truth = seq.ground_truth.as_ref().and_then(|g| g.get(f));
        let path = dir.join(format!("{f:04}.png"));
        let draw = |tile: &mut image::RgbImage, cam: &crate::geometry::Camera| {
            if let Some(c) = club.filter(|c| k < c.grip.len().min(c.head.len())) {
                let trail = &c.head[k.saturating_sub(CLUB_TRAIL)..=k];
                draw_club(tile, cam, c.grip[k], c.head[k], trail);
            }
        };
        let pic = write_overlay_png_with(&path, &images, &seq.cameras, tracked, truth, draw)?;
        files.push(path);
        let pic = if pic.width() > ANIMATION_WIDTH {
            let h = (pic.height() as u64 * ANIMATION_WIDTH as u64 / pic.width() as u64).max(1);
            image::imageops::resize(
                &pic,
                ANIMATION_WIDTH,
                h as u32,
                image::imageops::FilterType::Triangle,
            )
        } else {
            pic
        };
        if movie.is_none() {
            let fps = (seq.fps / (SLOW_MOTION * step as f64)).max(0.1);
            let path = out.join("broadcast.png");
            let n = frames.len() as u32;
            movie = Some(AnimatedPng::create(
                &path,
                pic.width(),
                pic.height(),
                n,
                fps,
            )?);
        }
        if let Some(m) = movie.as_mut() {
            m.add(&pic)?;
        }
    }
    if let Some(m) = movie {
        files.push(m.finish()?);
    }
    Ok(files)
}

/// Writes `track_status.csv`: per tracked frame (the sequence's numbering) its state
/// (`tracked`, `lost`, `recovered`), the overlap of the pose with the foreground and the
/// final cost of its search.
pub fn write_status_csv(out: &Path, result: &TrackResult) -> Result<PathBuf, TrackOutputError> {
    let path = out.join("track_status.csv");
    let mut s = String::from("frame,status,overlap,cost\n");
    for (k, st) in result.status.iter().enumerate() {
        let o = result.overlaps.get(k).copied().unwrap_or(f64::NAN);
        let c = result.costs.get(k).copied().unwrap_or(f64::NAN);
        let _ = writeln!(s, "{},{},{o:.4},{c:.4}", result.first_frame + k, st.word());
    }
    std::fs::write(&path, s).map_err(io(&path))?;
    Ok(path)
}
