//! The settings of a synthetic face sequence ([`make_face_sequence`](super::sequence::make_face_sequence)),
//! with their defaults and checks; written into and read back from the sequence's
//! `sequence.json` ([`SequenceInfo`](super::sequence_files::SequenceInfo)).

use serde::{Deserialize, Serialize};

use super::FaceError;
use crate::geometry::files::data_dir;

/// Settings of [`make_face_sequence`](super::sequence::make_face_sequence).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FaceSequenceOptions {
    /// Number of frames (1..=10000). Default 50.
    pub frames: usize,
    /// Frame rate (Hz). Default 25.
    pub fps: f64,
    /// Image width (pixels). Default 640.
    pub width: u32,
    /// Image height (pixels). Default 480.
    pub height: u32,
    /// Number of cameras (1..=8), spread over ±30° of yaw around the face. Default 3.
    pub cameras: usize,
    /// Distance of the cameras from the head pivot (m). Default 0.6.
    pub distance: f64,
    /// Focal length (pixels). Default 1000.
    pub focal: f64,
    /// Amplitude of the yaw (degrees); pitch and roll are half and a third. Default 20.
    pub yaw_deg: f64,
    /// FAPs animated (MPEG-4 numbers; each must be in the rig). Default: the tracked set.
    pub faps: Vec<u8>,
    /// Sensor noise σ (grey levels). Default 2.
    pub noise: f64,
    /// Lighting change: the gain varies in `1 ± light`. Default 0.04.
    pub light: f64,
    /// Texture size (texels). Default 512.
    pub texture_size: usize,
    /// A texture image to use instead of the procedural one (for the MediaPipe UV layout).
    pub texture: Option<String>,
    /// A neutral model OBJ (metres, MediaPipe vertex order) instead of the canonical face.
    pub model: Option<String>,
    /// Folder of background photos (the first is used, cropped per camera); none: grey.
    pub backgrounds: Option<String>,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for FaceSequenceOptions {
    fn default() -> Self {
        FaceSequenceOptions {
            frames: 50,
            fps: 25.0,
            width: 640,
            height: 480,
            cameras: 3,
            distance: 0.6,
            focal: 1000.0,
            yaw_deg: 20.0,
            faps: super::fap::TRACKED_FAPS.to_vec(),
            noise: 2.0,
            light: 0.04,
            texture_size: 512,
            texture: None,
            model: None,
            backgrounds: Some(
                data_dir()
                    .join("facades/labelmefacade/images")
                    .to_string_lossy()
                    .into_owned(),
            ),
            seed: 1,
        }
    }
}

impl FaceSequenceOptions {
    /// Checks every setting; the error names the parameter.
    pub fn validate(&self) -> Result<(), FaceError> {
        let p = FaceError::parameter;
        if !(1..=10_000).contains(&self.frames) {
            return Err(p(
                "frames",
                format!("must be 1..=10000, got {}", self.frames),
            ));
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(p("fps", format!("must be positive, got {}", self.fps)));
        }
        if !(32..=8192).contains(&self.width) || !(32..=8192).contains(&self.height) {
            return Err(p(
                "width/height",
                format!("must be 32..=8192, got {}×{}", self.width, self.height),
            ));
        }
        if !(1..=8).contains(&self.cameras) {
            return Err(p("cameras", format!("must be 1..=8, got {}", self.cameras)));
        }
        for (name, v) in [("distance", self.distance), ("focal", self.focal)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(p(name, format!("must be finite and positive, got {v}")));
            }
        }
        for (name, v) in [
            ("yaw_deg", self.yaw_deg),
            ("noise", self.noise),
            ("light", self.light),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(p(name, format!("must be finite and ≥ 0, got {v}")));
            }
        }
        if self.yaw_deg > 60.0 {
            return Err(p("yaw_deg", format!("at most 60°, got {}", self.yaw_deg)));
        }
        if self.light >= 0.5 {
            return Err(p("light", format!("must be below 0.5, got {}", self.light)));
        }
        if !(16..=4096).contains(&self.texture_size) {
            return Err(p(
                "texture_size",
                format!("must be 16..=4096, got {}", self.texture_size),
            ));
        }
        Ok(())
    }
}
