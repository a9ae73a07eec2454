//! Garments from 2D sewing patterns: pattern pieces and seams ([`pattern`]) with their
//! outlines, checks and expansion, their files ([`formats`]: JSON, SVG, DXF-AAMA, pattern
//! sheets), meshing of the pieces ([`mesh`]), automatic placement around a mannequin
//! ([`placement`]) and sewing into one cloth ([`mod@dress`], [`seam_hinges`], seam closure at crossings).

pub mod dress;
pub mod error;
pub mod expand;
pub mod formats;
pub mod grading;
pub mod mesh;
pub mod outline;
pub mod pattern;
pub mod placement;
mod seam_closure;
pub mod seam_hinges;
pub mod validate;

pub use dress::{dress, DressParameters, DressReport, Dressed};
pub use error::PatternError;
pub use formats::dxf::{parse_pattern_dxf, read_pattern_dxf};
pub use formats::dxf_write::{
    pattern_to_dxf, pattern_to_dxf_with, write_pattern_dxf, write_pattern_dxf_with, DxfOptions,
    DxfUnits,
};
pub use formats::json::{read_pattern_json, write_pattern_json};
pub use formats::pattern_sheet::write_pattern_sheet;
pub use formats::svg::{read_pattern_svg, SvgOptions};
pub use formats::table::{read_garment, GarmentTable, PartUse};
pub use mesh::{mesh_pattern, GarmentMesh, MeshParameters, PieceMesh, SeamMesh};
pub use outline::{FlatOutline, FlatPoint};
pub use pattern::{
    Copies, Corner, EdgeRef, Outline, Pattern, Piece, Placement, Seam, Segment, Side, P2,
};
pub use placement::body_frame::BodyFrame;
pub use placement::preposition::{preposition, PrepositionParameters, PrepositionReport};
pub use placement::silhouette::{Landmarks, Silhouettes};
