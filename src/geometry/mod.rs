//! Geometry: triangle meshes with rest (pattern) coordinates, grid generators, edge/hinge
//! adjacency, mesh file I/O (OBJ read/write, binary glTF write), the pinhole camera
//! ([`camera`]), the Levenberg–Marquardt solver ([`least_squares`]), grey images and their
//! filters ([`image`]) and seeded random numbers ([`random`]).

pub mod animation;
pub mod camera;
pub mod checkpoint;
pub mod cone;
pub mod error;
pub mod export_frame;
pub mod files;
pub mod gltf;
pub mod grid;
pub mod image;
pub mod least_squares;
pub mod mesh;
pub mod obj;
pub mod pc2;
pub mod random;
pub mod run_checkpoint;
pub mod topology;
pub mod usd;

pub use camera::{Camera, LookAtCamera};
pub use error::GeometryError;
pub use export_frame::{ExportFrame, Units, UpAxis};
pub use gltf::write_glb;
pub use grid::grid_mesh;
pub use image::photo_files;
pub use mesh::TriMesh;
pub use obj::{read_obj, read_obj_surface, write_obj};
pub use random::{Lcg64, SplitMix64};
pub use topology::{Edge, Hinge, Topology};

/// Three-vector of f64, SI units (metres, m/s, newtons).
pub type Vec3 = nalgebra::Vector3<f64>;
/// 3×3 matrix of f64.
pub type Mat3 = nalgebra::Matrix3<f64>;
