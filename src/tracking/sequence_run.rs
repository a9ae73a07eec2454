//! Tracking a whole sequence: the background models, the tracker's start on frame 0 and the
//! frames one by one, each followed by a hook that may checkpoint the run; a run resumed from
//! a [`TrackCheckpoint`] continues after the frames it holds.

use std::time::Instant;

use super::checkpoint::TrackCheckpoint;
use super::cost::Robust;
use super::joints::{mpjpe, JOINT_COUNT};
use super::pyramid::Level;
use super::sequence_files::Sequence;
use super::tracker::{
    changing_pixels, sequence_backgrounds, TrackError, TrackResult, Tracker, TrackerOptions, STAGES,
};
use crate::body::Mannequin;
use crate::geometry::Vec3;

/// Tracks a whole sequence (or its first `options.frames` frames). `progress(done, total)`
/// is called after each frame.
pub fn track_sequence(
    seq: &Sequence,
    mannequin: &Mannequin,
    options: &TrackerOptions,
    approx: Option<&[Vec3; JOINT_COUNT]>,
    mut progress: impl FnMut(usize, usize),
) -> Result<TrackResult, TrackError> {
    track_sequence_from(seq, mannequin, options, approx, None, |done, total, _| {
        progress(done, total);
        Ok(())
    })
}

/// [`track_sequence`] from a checkpoint `resume` of the same sequence and options (frames
/// already tracked are not tracked again), calling `after(done, total, checkpoint)` after each
/// frame, where `checkpoint()` makes the run's [`TrackCheckpoint`] at that frame; an error
/// from `after` stops the run.
pub fn track_sequence_from(
    seq: &Sequence,
    mannequin: &Mannequin,
    options: &TrackerOptions,
    approx: Option<&[Vec3; JOINT_COUNT]>,
    resume: Option<TrackCheckpoint>,
    mut after: impl FnMut(usize, usize, &dyn Fn() -> TrackCheckpoint) -> Result<(), TrackError>,
) -> Result<TrackResult, TrackError> {
    let t_start = Instant::now();
    let frames = options.frames.map_or(seq.frames, |f| f.min(seq.frames));
    if frames == 0 {
        return Err(TrackError::Invalid(format!(
            "{}: no frames to track",
            seq.dir.display()
        )));
    }
    let approx = approx.or(seq.init_joints.as_ref()).ok_or_else(|| {
        TrackError::Invalid(format!(
            "{}: no init_joints.csv, and no approximate first pose given",
            seq.dir.display()
        ))
    })?;
    let backgrounds = match seq.background_plates()? {
        Some(plates) => plates.iter().map(Level::from_image).collect(),
        None => sequence_backgrounds(seq, seq.frames, options.background_frames)?,
    };
    let mut tracker = Tracker::new(mannequin, &seq.cameras, &backgrounds, options.clone())?;
    let robust = Robust {
        sigma: options.robust_sigma,
    };
    let masks = changing_pixels(seq, &backgrounds, options.background_frames, robust, 0.2)?;
    tracker.views.set_active(&masks);
    let (first_frame, mut result) = match resume {
        Some(ck) => {
            ck.restore(&mut tracker).map_err(TrackError::Invalid)?;
            (ck.frames_done.max(1), ck.result)
        }
        None => {
            let mut result = TrackResult::default();
            let t_io = Instant::now();
            let images = seq.frame_images(0)?;
            result.io_seconds += t_io.elapsed().as_secs_f64();
            let first = tracker.start(&images, approx)?;
            tracker.stage_seconds.iter_mut().for_each(|s| *s = 0.0);
            tracker.evaluations = 0;
            result.start_seconds = t_start.elapsed().as_secs_f64();
            result.joints.push(tracker.joints(&first));
            result.params.push(first);
            result.costs.push(0.0);
            after(1, frames, &|| TrackCheckpoint::of(&tracker, &result, 1))?;
            (1, result)
        }
    };
    for k in first_frame..frames {
        let t0 = Instant::now();
        let images = seq.frame_images(k)?;
        result.io_seconds += t0.elapsed().as_secs_f64();
        let (params, cost) = tracker.track(&images)?;
        result.joints.push(tracker.joints(&params));
        result.params.push(params);
        result.costs.push(cost);
        result.frame_seconds.push(t0.elapsed().as_secs_f64());
        after(k + 1, frames, &|| {
            TrackCheckpoint::of(&tracker, &result, k + 1)
        })?;
    }
    result.stage_seconds = STAGES
        .iter()
        .zip(&tracker.stage_seconds)
        .map(|(s, &t)| (s.name.to_string(), t))
        .collect();
    result.evaluations = tracker.evaluations;
    if let Some(gt) = &seq.ground_truth {
        let mut per_frame = Vec::new();
        let mut per_joint = Vec::new();
        for (k, j) in result.joints.iter().enumerate() {
            if let Some(t) = gt.get(k) {
                per_frame.push(1000.0 * mpjpe(j, t));
                per_joint.push(std::array::from_fn(|i| 1000.0 * (j[i] - t[i]).norm()));
            }
        }
        result.errors_mm = Some(per_frame);
        result.joint_errors_mm = Some(per_joint);
    }
    Ok(result)
}
