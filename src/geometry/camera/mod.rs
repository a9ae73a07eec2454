//! Cameras: the one pinhole camera model with radial distortion ([`Camera`]), its JSON file
//! format ([`mod@file`]), and the eye/target/up placement the renderer and scripts use
//! ([`LookAtCamera`], which converts to a [`Camera`]).
//!
//! # Model
//!
//! A world point `p` is moved into the camera frame by `pc = R p + t` ([`Camera::rotation`] is
//! world→camera, [`Camera::translation`] is `t`); the camera looks down `+z`, `x` to the right
//! and `y` down in the image. The ideal normalised coordinates `(x, y) = (pc.x / pc.z, pc.y / pc.z)`
//! are distorted radially, `(x, y) · (1 + k1 r² + k2 r⁴)` with `r² = x² + y²`, then mapped to
//! pixels by `u = fx · xd + cx`, `v = fy · yd + cy` (no skew). Pixel `(0, 0)` is the centre of
//! the top-left pixel.
//!
//! # File format
//!
//! A camera file is one JSON object with two parts; every number is a finite JSON number:
//!
//! ```json
//! {
//!   "intrinsics": { "fx": 400.0, "fy": 400.0, "cx": 162.0, "cy": 118.0,
//!                   "k1": -0.08, "k2": 0.02, "width": 320, "height": 240 },
//!   "extrinsics": { "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
//!                   "translation": [0.0, 0.0, 3.0] }
//! }
//! ```
//!
//! `fx, fy, cx, cy` are in pixels, `k1, k2` are dimensionless, `width, height` are positive
//! integers (pixels). `rotation` is the world→camera matrix, row-major (three rows of three), and
//! must be a proper rotation (orthonormal within 1e-6, determinant +1). `translation` is `t` in
//! world units (metres in this crate). Unknown keys are ignored. [`Camera::load`] reports errors
//! naming the file and the field (for example `intrinsics.fx`).

pub mod file;
pub mod look_at;
pub mod model;

pub use file::{CameraError, ExtrinsicsFile, IntrinsicsFile, JsonCamera, ORTHONORMAL_TOLERANCE};
pub use look_at::LookAtCamera;
pub use model::Camera;
