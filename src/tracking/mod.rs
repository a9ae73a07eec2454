//! Tracking: the tracking module owns cameras now, and the model-based tracker later.
//!
//! - [`camera`]: the pinhole camera with radial distortion used by every vision part, its
//!   projection, and its JSON file format;
//! - [`dlt`]: linear resection (normalised DLT) and the RQ split of a projection matrix;
//! - [`calibration`]: camera calibration from 3D–2D correspondences (DLT, then
//!   Levenberg–Marquardt refinement of intrinsics, distortion and pose).

pub mod calibration;
pub mod camera;
pub mod dlt;
