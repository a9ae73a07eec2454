//! A tracking run's checkpoint: the frames tracked so far (joints, parameters, costs,
//! timings) and the tracker's state between frames (its random generator, the last poses the
//! prediction reads, the colours learnt on frame 0, its counters). A run resumed from it skips
//! the start and the frames already tracked and continues bit for bit as the run that wrote it
//! (only the wall-time figures of the summary differ, as they do between any two runs).

use super::joints::JOINT_COUNT;
use super::loss::FrameStatus;
use super::puppet::Proportions;
use super::tracker::{TrackResult, Tracker};
use crate::geometry::checkpoint::{Decoder, Encoder};
use crate::geometry::{GeometryError, SplitMix64, Vec3};

/// What a tracking run has done after some frames.
#[derive(Debug, Clone, Default)]
pub struct TrackCheckpoint {
    /// Frames tracked (frame 0, the start, included).
    pub frames_done: usize,
    /// The result so far (`errors_mm` and the stage times are made at the end).
    pub result: TrackResult,
    rng: u64,
    history: Vec<Vec<f64>>,
    colours: Option<Vec<[f32; 3]>>,
    stage_seconds: Vec<f64>,
    evaluations: usize,
}

impl TrackCheckpoint {
    /// The state of `tracker` after `frames_done` frames that gave `result`.
    pub fn of(tracker: &Tracker, result: &TrackResult, frames_done: usize) -> Self {
        TrackCheckpoint {
            frames_done,
            result: result.clone(),
            rng: tracker.rng.state(),
            history: tracker.history.clone(),
            colours: tracker.colours.clone(),
            stage_seconds: tracker.stage_seconds.clone(),
            evaluations: tracker.evaluations,
        }
    }

    /// Puts the tracker's state back (a tracker built for the same sequence and options).
    pub fn restore(&self, tracker: &mut Tracker) -> Result<(), String> {
        if self.stage_seconds.len() != tracker.stage_seconds.len() {
            return Err("the checkpoint's tracker has other stages".into());
        }
        if let Some(p) = &self.result.proportions {
            tracker.set_proportions(p).map_err(|e| e.to_string())?;
        }
        let params = tracker.puppet().params().len();
        if self.history.iter().any(|h| h.len() != params) {
            return Err("the checkpoint's puppet has other parameters".into());
        }
        tracker.rng = SplitMix64::new(self.rng);
        tracker.history = self.history.clone();
        tracker.colours = self.colours.clone();
        tracker.stage_seconds = self.stage_seconds.clone();
        tracker.evaluations = self.evaluations;
        Ok(())
    }

    /// The checkpoint as bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut e = Encoder::new();
        e.usize(self.frames_done);
        let r = &self.result;
        e.usize(r.joints.len());
        for j in &r.joints {
            j.iter().for_each(|p| e.vec3(p));
        }
        e.usize(r.params.len());
        r.params.iter().for_each(|p| e.f64s(p));
        e.f64s(&r.costs);
        e.f64s(&r.frame_seconds);
        e.f64(r.io_seconds);
        e.f64(r.start_seconds);
        e.usize(r.evaluations);
        e.usize(r.first_frame);
        e.f64s(&r.overlaps);
        e.usize(r.status.len());
        r.status.iter().for_each(|s| e.usize(s.code() as usize));
        e.u64(self.rng);
        e.usize(self.history.len());
        self.history.iter().for_each(|h| e.f64s(h));
        e.bool(self.colours.is_some());
        if let Some(c) = &self.colours {
            e.usize(c.len());
            c.iter().flatten().for_each(|&v| e.f32(v));
        }
        e.f64s(&self.stage_seconds);
        e.usize(self.evaluations);
        e.bool(r.proportions.is_some());
        if let Some(p) = &r.proportions {
            e.f64s(&p.named().map(|x| x.1));
        }
        e.buf
    }

    /// Reads [`TrackCheckpoint::encode`]'s bytes (`file` names them in errors).
    pub fn decode(bytes: &[u8], file: &str) -> Result<Self, GeometryError> {
        let mut d = Decoder::new(bytes, file);
        let frames_done = d.usize("frames tracked")?;
        let n = d.len(24 * JOINT_COUNT, "tracked joints")?;
        let mut result = TrackResult::default();
        for _ in 0..n {
            let mut j = [Vec3::zeros(); JOINT_COUNT];
            for p in &mut j {
                *p = d.vec3("joint")?;
            }
            result.joints.push(j);
        }
        let n = d.len(8, "tracked poses")?;
        result.params = (0..n).map(|_| d.f64s("pose")).collect::<Result<_, _>>()?;
        result.costs = d.f64s("costs")?;
        result.frame_seconds = d.f64s("frame times")?;
        result.io_seconds = d.f64("image time")?;
        result.start_seconds = d.f64("start time")?;
        result.evaluations = d.usize("evaluations")?;
        result.first_frame = d.usize("first frame")?;
        result.overlaps = d.f64s("overlaps")?;
        let n = d.len(8, "frame states")?;
        for _ in 0..n {
            let c = d.usize("frame state")?;
            let s = u8::try_from(c)
                .ok()
                .and_then(FrameStatus::from_code)
                .ok_or_else(|| d.error("unknown frame state"))?;
            result.status.push(s);
        }
        let rng = d.u64("random state")?;
        let n = d.len(8, "last poses")?;
        let history = (0..n).map(|_| d.f64s("pose")).collect::<Result<_, _>>()?;
        let colours = if d.bool("colours")? {
            let n = d.len(12, "colours")?;
            Some(
                (0..n)
                    .map(|_| Ok([d.f32("colour")?, d.f32("colour")?, d.f32("colour")?]))
                    .collect::<Result<_, GeometryError>>()?,
            )
        } else {
            None
        };
        let stage_seconds = d.f64s("stage times")?;
        let evaluations = d.usize("evaluations")?;
        if d.bool("proportions")? {
            let v = d.f64s("proportions")?;
            result.proportions = Some(
                Proportions::from_values(&v)
                    .ok_or_else(|| d.error("proportions: 10 values expected"))?,
            );
        }
        if !d.finished() {
            return Err(d.error("bytes left over after the tracker's state"));
        }
        let frames = result.joints.len();
        if frames_done != frames || result.params.len() != frames || result.costs.len() != frames {
            return Err(d.error("frames tracked and results do not agree"));
        }
        Ok(TrackCheckpoint {
            frames_done,
            result,
            rng,
            history,
            colours,
            stage_seconds,
            evaluations,
        })
    }
}
