//! Tracking a whole sequence: the background models, the tracker's start on frame 0 and the
//! frames one by one, each followed by a hook that may checkpoint the run; a run resumed from
//! a [`TrackCheckpoint`] continues after the frames it holds.

use std::time::Instant;

use super::background_model::{background_models, changing_pixels};
use super::checkpoint::TrackCheckpoint;
use super::cost::Robust;
use super::joints::{mpjpe, JOINT_COUNT};
use super::loss::{FrameStatus, LossDetector, LossSettings};
use super::sequence_files::Sequence;
use super::tracker::{TrackError, TrackResult, Tracker, TrackerOptions, STAGES};
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
    let f0 = options.first_frame;
    let available = seq.frames.saturating_sub(f0);
    let frames = options.frames.map_or(available, |f| f.min(available));
    if frames == 0 {
        return Err(TrackError::Invalid(format!(
            "{}: no frames to track (first frame {f0} of {})",
            seq.dir.display(),
            seq.frames
        )));
    }
    let approx = if options.auto_start {
        None
    } else if f0 > 0 && approx.is_none() {
        return Err(TrackError::Invalid(format!(
            "{}: init_joints.csv is frame 0's pose; starting at frame {f0} needs the \
             automatic start (init=auto)",
            seq.dir.display()
        )));
    } else {
        Some(approx.or(seq.init_joints.as_ref()).ok_or_else(|| {
            TrackError::Invalid(format!(
                "{}: no init_joints.csv, and no approximate first pose given (or use the \
                 automatic start, init=auto)",
                seq.dir.display()
            ))
        })?)
    };
    let backgrounds = background_models(seq, options.background_frames)?;
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
            let images = seq.frame_images(f0)?;
            result.io_seconds += t_io.elapsed().as_secs_f64();
            let mut first = match approx {
                Some(approx) => tracker.start(&images, approx)?,
                None => tracker.start_auto(&images).map_err(|e| {
                    TrackError::Invalid(format!(
                        "{} frame {f0}: automatic start: {e}",
                        seq.dir.display()
                    ))
                })?,
            };
            if options.adapt_body {
                let (pose, proportions) = tracker.adapt_start(&first)?;
                first = pose;
                result.proportions = Some(proportions);
            }
            result.first_frame = f0;
            result.overlaps.push(tracker.overlap(&first));
            tracker.stage_seconds.iter_mut().for_each(|s| *s = 0.0);
            tracker.evaluations = 0;
            result.start_seconds = t_start.elapsed().as_secs_f64();
            result.joints.push(tracker.joints(&first));
            result.params.push(first);
            result.costs.push(0.0);
            result.status.push(FrameStatus::Tracked);
            after(1, frames, &|| TrackCheckpoint::of(&tracker, &result, 1))?;
            (1, result)
        }
    };
    let mut detector = LossDetector::new(LossSettings::default());
    for (o, s) in result.overlaps.iter().zip(&result.status) {
        if *s != FrameStatus::Lost {
            detector.push_good(*o);
        }
    }
    for k in first_frame..frames {
        let t0 = Instant::now();
        let images = seq.frame_images(f0 + k)?;
        result.io_seconds += t0.elapsed().as_secs_f64();
        let (mut params, mut cost) = tracker.track(&images)?;
        let mut overlap = tracker.overlap(&params);
        let mut status = FrameStatus::Tracked;
        if options.recover && detector.is_lost(overlap) {
            (params, cost, overlap, status) =
                recover(&mut tracker, &result, params, cost, overlap, &mut detector)?;
        }
        if status != FrameStatus::Lost {
            detector.push_good(overlap);
        }
        result.joints.push(tracker.joints(&params));
        result.params.push(params);
        result.costs.push(cost);
        result.overlaps.push(overlap);
        result.status.push(status);
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
            if let Some(t) = gt.get(f0 + k) {
                per_frame.push(1000.0 * mpjpe(j, t));
                per_joint.push(std::array::from_fn(|i| 1000.0 * (j[i] - t[i]).norm()));
            }
        }
        result.errors_mm = Some(per_frame);
        result.joint_errors_mm = Some(per_joint);
    }
    Ok(result)
}

/// The search again after frame's fit fell (`params`, `cost`, `overlap` as tracked): the
/// automatic pose search seeded by the last frame not lost; the better fit of the two
/// (image cost at full resolution) is kept. Returns the pose, its cost, overlap and status:
/// recovered when the search's pose fits as well as good frames do, lost otherwise.
fn recover(
    tracker: &mut Tracker,
    result: &TrackResult,
    params: Vec<f64>,
    cost: f64,
    overlap: f64,
    detector: &mut LossDetector,
) -> Result<(Vec<f64>, f64, f64, FrameStatus), TrackError> {
    let last_good = result
        .status
        .iter()
        .rposition(|s| *s != FrameStatus::Lost)
        .map_or_else(|| params.clone(), |i| result.params[i].clone());
    let tracked_cost = tracker.image_cost(&params, 0);
    let Ok((found, found_cost)) = tracker.auto_pose(Some(&last_good)) else {
        return Ok((params, cost, overlap, FrameStatus::Lost));
    };
    if found_cost >= tracked_cost {
        return Ok((params, cost, overlap, FrameStatus::Lost));
    }
    let found_overlap = tracker.overlap(&found);
    tracker.restart_history(&found);
    let status = if detector.is_lost(found_overlap) {
        FrameStatus::Lost
    } else {
        FrameStatus::Recovered
    };
    Ok((found, found_cost, found_overlap, status))
}
