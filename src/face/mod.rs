//! Faces: a generic face mesh adapted to a person from a few photos, expressions (muscles and
//! MPEG-4 FAPs), texture from the photos, and tracking of pose and expression in image sequences
//! (seed report §3.2, §5.2).
//!
//! - [`error`]: the module's error type;
//! - [`model`]: the generic face mesh (MediaPipe canonical mesh, metres) and its measures;
//! - [`landmarks`]: the 68-point iBUG landmark scheme mapped onto the mesh, `.pts` files;
//! - [`render`]: textured, z-buffered rendering of a face mesh through a camera.

pub mod error;
pub mod landmarks;
pub mod model;
pub mod render;

pub use error::FaceError;
pub use model::FaceMesh;
