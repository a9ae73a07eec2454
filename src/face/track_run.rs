//! Tracking a whole face sequence folder and writing what came out: the tracked pose and FAPs
//! per frame (`tracked.csv`, the ground-truth CSV format), errors against the ground truth
//! when the folder has it (`errors.csv`, `summary.json`), and overlay pictures of the tracked
//! mesh on the first camera's frames (`overlay/NNNN.png`).

use std::path::Path;
use std::time::Instant;

use super::head_pose::HeadPose;
use super::sequence_files::{write_pose_csv, FaceSequence, PoseRow};
use super::tracker::{FaceTracker, FaceTrackerOptions};
use super::FaceError;
use crate::tracking::overlay::draw_line;

/// Result of [`track_face_sequence`].
#[derive(Clone, Debug, PartialEq)]
pub struct FaceTrackResult {
    /// Tracked pose and FAPs per frame.
    pub rows: Vec<PoseRow>,
    /// Rotation error per frame (degrees), with ground truth.
    pub pose_err_deg: Option<Vec<f64>>,
    /// Translation error per frame (m), with ground truth.
    pub translation_err: Option<Vec<f64>>,
    /// Per FAP (sequence order): mean absolute error over the frames as a fraction of the
    /// FAP's range, with ground truth.
    pub fap_err: Option<Vec<f64>>,
    /// Seconds of tracking (images read and tracked), all frames.
    pub seconds: f64,
    /// Mean photometric cost per frame.
    pub cost: Vec<f64>,
    /// Seconds per frame in each stage: reading the image files, then the tracker's
    /// [`STAGES`](super::tracker::STAGES).
    pub stage_seconds: Vec<(String, f64)>,
}

impl FaceTrackResult {
    /// Frames per second of the tracking.
    pub fn fps(&self) -> f64 {
        self.rows.len() as f64 / self.seconds.max(1e-12)
    }

    /// Mean rotation error (degrees).
    pub fn mean_pose_err_deg(&self) -> Option<f64> {
        self.pose_err_deg
            .as_ref()
            .map(|e| e.iter().sum::<f64>() / e.len().max(1) as f64)
    }

    /// Largest per-frame rotation error (degrees).
    pub fn max_pose_err_deg(&self) -> Option<f64> {
        self.pose_err_deg
            .as_ref()
            .map(|e| e.iter().cloned().fold(0.0, f64::max))
    }

    /// Mean over FAPs of their mean error (fraction of range).
    pub fn mean_fap_err(&self) -> Option<f64> {
        self.fap_err
            .as_ref()
            .map(|e| e.iter().sum::<f64>() / e.len().max(1) as f64)
    }

    /// The worst FAP's mean error (fraction of range).
    pub fn max_fap_err(&self) -> Option<f64> {
        self.fap_err
            .as_ref()
            .map(|e| e.iter().cloned().fold(0.0, f64::max))
    }
}

/// Tracks the first `frames` frames (all when `None`) of `seq` from its `init.csv` pose;
/// `progress(done, total)` is called after each frame.
pub fn track_face_sequence(
    seq: &FaceSequence,
    options: &FaceTrackerOptions,
    frames: Option<usize>,
    mut progress: impl FnMut(usize, usize),
) -> Result<FaceTrackResult, FaceError> {
    let total = frames.map_or(seq.info.frames, |f| f.min(seq.info.frames));
    let mut tracker = FaceTracker::new(
        &seq.model,
        &seq.cameras,
        &seq.info.faps,
        seq.init.pose,
        &seq.init.faps,
        options,
    )?;
    let start = Instant::now();
    let mut reading = 0.0;
    let mut rows = Vec::with_capacity(total);
    let mut cost = Vec::with_capacity(total);
    for k in 0..total {
        let t = Instant::now();
        let images = seq.frame_images(k)?;
        reading += t.elapsed().as_secs_f64();
        let r = tracker.track(&images)?;
        if !(r.pose.translation.iter().all(|v| v.is_finite())
            && r.faps.iter().all(|v| v.is_finite()))
        {
            return Err(FaceError::Failed(format!(
                "tracking lost at frame {k}: the pose or FAP values are not finite"
            )));
        }
        cost.push(r.cost);
        rows.push(PoseRow {
            frame: k,
            time: k as f64 / seq.info.fps,
            pose: r.pose,
            faps: r.faps,
        });
        progress(k + 1, total);
    }
    let seconds = start.elapsed().as_secs_f64();
    let n = rows.len().max(1) as f64;
    let mut stage_seconds = vec![("read".to_string(), reading / n)];
    for (name, s) in super::tracker::STAGES.iter().zip(tracker.stage_seconds()) {
        stage_seconds.push((name.to_string(), s / n));
    }
    let (mut pose_err_deg, mut translation_err, mut fap_err) = (None, None, None);
    if let Some(truth) = &seq.truth {
        let n = rows.len().min(truth.len());
        pose_err_deg = Some(
            (0..n)
                .map(|k| rows[k].pose.angle_to(&truth[k].pose).to_degrees())
                .collect(),
        );
        translation_err = Some(
            (0..n)
                .map(|k| (rows[k].pose.translation - truth[k].pose.translation).norm())
                .collect(),
        );
        fap_err = Some(
            seq.info
                .fap_ranges
                .iter()
                .enumerate()
                .map(|(j, (lo, hi))| {
                    (0..n)
                        .map(|k| (rows[k].faps[j] - truth[k].faps[j]).abs() / (hi - lo))
                        .sum::<f64>()
                        / n.max(1) as f64
                })
                .collect(),
        );
    }
    Ok(FaceTrackResult {
        rows,
        pose_err_deg,
        translation_err,
        fap_err,
        seconds,
        cost,
        stage_seconds,
    })
}

/// Writes `tracked.csv`, `errors.csv` and `summary.json` (with ground truth), and one overlay
/// picture every `overlay_every` frames (0: none) under `out`. Returns the files written.
pub fn write_face_track_outputs(
    seq: &FaceSequence,
    result: &FaceTrackResult,
    out: &Path,
    overlay_every: usize,
) -> Result<Vec<std::path::PathBuf>, FaceError> {
    std::fs::create_dir_all(out).map_err(|e| FaceError::io(out, e))?;
    let mut files = Vec::new();
    let tracked = out.join("tracked.csv");
    write_pose_csv(&tracked, &seq.info.faps, &result.rows)?;
    files.push(tracked);
    if let (Some(pe), Some(te), Some(truth)) =
        (&result.pose_err_deg, &result.translation_err, &seq.truth)
    {
        let mut s = String::from("frame,rotation_err_deg,translation_err_mm");
        for f in &seq.info.faps {
            s.push_str(&format!(",fap_{f}_err_pct"));
        }
        s.push('\n');
        for (k, row) in result.rows.iter().enumerate().take(pe.len()) {
            s.push_str(&format!("{k},{:.4},{:.3}", pe[k], te[k] * 1000.0));
            for (j, (lo, hi)) in seq.info.fap_ranges.iter().enumerate() {
                s.push_str(&format!(
                    ",{:.2}",
                    100.0 * (row.faps[j] - truth[k].faps[j]).abs() / (hi - lo)
                ));
            }
            s.push('\n');
        }
        let path = out.join("errors.csv");
        std::fs::write(&path, s).map_err(|e| FaceError::io(&path, e))?;
        files.push(path);
    }
    let summary = serde_json::json!({
        "frames": result.rows.len(),
        "fps": result.fps(),
        "pose_err_deg": result.mean_pose_err_deg(),
        "pose_err_max_deg": result.max_pose_err_deg(),
        "fap_err_fraction_of_range": result.mean_fap_err(),
        "fap_err_by_fap": result.fap_err.as_ref().map(|e| seq.info.faps.iter().zip(e).map(|(f, v)| (format!("fap_{f}"), *v)).collect::<std::collections::BTreeMap<_, _>>()),
        "seconds": result.seconds,
        "seconds_per_frame_by_stage": result.stage_seconds.iter().cloned().collect::<std::collections::BTreeMap<_, _>>(),
    });
    let path = out.join("summary.json");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&summary).unwrap_or_default(),
    )
    .map_err(|e| FaceError::io(&path, e))?;
    files.push(path);
    if overlay_every > 0 {
        let dir = out.join("overlay");
        std::fs::create_dir_all(&dir).map_err(|e| FaceError::io(&dir, e))?;
        let rig = super::fap::FapRig::new(&seq.model)?;
        let tracked_idx: Vec<usize> = seq
            .info
            .faps
            .iter()
            .filter_map(|&n| rig.index_of(n))
            .collect();
        let pivot = super::head_pose::head_pivot(&seq.model);
        let edges = seq.model.edges();
        let (mut values, mut deformed, mut posed) = (vec![0.0; rig.len()], Vec::new(), Vec::new());
        for row in result.rows.iter().step_by(overlay_every) {
            let mut img = crate::geometry::image::read_photo(&seq.image_path(0, row.frame))?;
            values.iter_mut().for_each(|v| *v = 0.0);
            for (&i, &v) in tracked_idx.iter().zip(&row.faps) {
                values[i] = v;
            }
            rig.apply(&seq.model.positions, &values, &mut deformed);
            draw_mesh(
                &mut img,
                &seq.cameras[0],
                &row.pose,
                &pivot,
                &deformed,
                &edges,
                &mut posed,
            );
            let path = dir.join(format!("{:04}.png", row.frame));
            img.save(&path).map_err(|e| FaceError::io(&path, e))?;
            files.push(path);
        }
    }
    Ok(files)
}

/// Draws the posed mesh's edges (thin, green) on `img`.
fn draw_mesh(
    img: &mut image::RgbImage,
    cam: &crate::geometry::Camera,
    pose: &HeadPose,
    pivot: &crate::geometry::Vec3,
    vertices: &[crate::geometry::Vec3],
    edges: &[(usize, usize)],
    posed: &mut Vec<crate::geometry::Vec3>,
) {
    pose.apply(pivot, vertices, posed);
    let px: Vec<Option<[f64; 2]>> = posed.iter().map(|p| cam.project(p)).collect();
    for &(a, b) in edges {
        if let (Some(pa), Some(pb)) = (px[a], px[b]) {
            draw_line(img, pa, pb, 1.0, [60, 255, 90]);
        }
    }
}
