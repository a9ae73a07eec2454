//! Faces: a generic face mesh adapted to a person from a few photos, expressions (muscles and
//! MPEG-4 FAPs), texture from the photos, and tracking of pose and expression in image sequences
//! (seed report §3.2, §5.2).
//!
//! - [`error`]: the module's error type;
//! - [`model`]: the generic face mesh (MediaPipe canonical mesh, metres) and its measures;
//! - [`landmarks`]: the 68-point iBUG landmark scheme mapped onto the mesh, `.pts` files;
//! - [`render`]: textured, z-buffered rendering of a face mesh through a camera; [`preview`]:
//!   shaded pictures and the expression gallery;
//! - [`candide`], [`fap`], [`muscles`], [`expressions`], [`blendshapes`]: animation — the
//!   CANDIDE-3 model, MPEG-4 FAPs on the mesh, Bézier muscles, named sliders, ARKit-52 export;
//! - [`regions`], [`rbf`], [`contour`], [`view_fit`], [`adapt`], [`align`], [`fit_run`]:
//!   adaptation of the generic mesh to a person's photos, and its outputs; [`people`],
//!   [`fit_people`]: which photos show which person, one fit per person;
//! - [`texture_bake`], [`export`], [`error_map`]: texture from photos, OBJ+MTL and glTF files,
//!   the signed error map between two surfaces;
//! - [`head_pose`], [`skin`], [`sequence`], [`sequence_options`], [`sequence_files`]: synthetic
//!   sequences with ground truth (pose and FAP trajectories) and reading sequence folders;
//! - [`samples`], [`tracker`], [`track_run`]: tracking of head pose and expression (on the grey
//!   images of [`crate::geometry::image`]), and its outputs.

pub mod adapt;
pub mod align;
pub mod blendshapes;
pub mod candide;
pub mod contour;
pub mod error;
pub mod error_map;
pub mod export;
pub mod expressions;
pub mod fap;
pub mod fit_people;
pub mod fit_run;
pub mod head_pose;
pub mod landmarks;
pub mod model;
pub mod muscles;
pub mod people;
pub mod preview;
pub mod rbf;
pub mod regions;
pub mod render;
pub mod samples;
pub mod sequence;
pub mod sequence_files;
pub mod sequence_options;
pub mod skin;
pub mod texture_bake;
pub mod track_run;
pub mod tracker;
pub mod view_fit;

pub use error::FaceError;
pub use model::FaceMesh;
