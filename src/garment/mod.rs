//! Garments from 2D sewing patterns: pattern pieces and seams ([`pattern`]), their files
//! (JSON, SVG, DXF-AAMA), meshing of the pieces, automatic pre-positioning around a
//! mannequin and sewing into one cloth.

pub mod body_frame;
mod centre_seams;
pub mod dress;
pub mod dxf;
pub mod dxf_write;
pub mod error;
pub mod expand;
mod hierarchy;
pub mod json;
mod layers;
pub mod mesh;
mod mesh_boundary;
mod mesh_graph;
pub mod outline;
mod over_the_top;
pub mod patch;
pub mod pattern;
pub mod preposition;
mod relax;
mod rows;
pub mod seam_hinges;
pub mod shell;
pub mod silhouette;
pub mod svg;
mod svg_path;
mod svg_shape;
mod svg_transform;
pub mod table;
pub mod validate;
mod xml;

pub use self::dxf::{parse_pattern_dxf, read_pattern_dxf};
pub use body_frame::BodyFrame;
pub use dress::{dress, DressParameters, DressReport, Dressed};
pub use dxf_write::{pattern_to_dxf, write_pattern_dxf};
pub use error::PatternError;
pub use json::{read_pattern_json, write_pattern_json};
pub use mesh::{mesh_pattern, GarmentMesh, MeshParameters, PieceMesh, SeamMesh};
pub use outline::{FlatOutline, FlatPoint};
pub use pattern::{
    Copies, Corner, EdgeRef, Outline, Pattern, Piece, Placement, Seam, Segment, Side, P2,
};
pub use preposition::{preposition, PrepositionParameters, PrepositionReport};
pub use silhouette::{Landmarks, Silhouettes};
pub use svg::{read_pattern_svg, SvgOptions};
pub use table::{read_garment, GarmentTable, PartUse};
