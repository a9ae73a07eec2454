//! The settings of a synthetic body sequence ([`SequenceOptions`], for
//! [`make_sequence`](super::sequence::make_sequence) and, as its base,
//! [`make_golf_sequence`](super::golf_sequence::make_golf_sequence)), with their ranges.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::sequence_files::SequenceError;
use crate::body::bvh::{MAX_FRAME_TIME, MIN_FRAME_TIME};
use crate::geometry::files::data_dir;
use crate::limits;

/// Settings of [`make_sequence`](super::sequence::make_sequence); see the [`super::sequence`] module docs for what each
/// does.
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
