//! The files of a sewing pattern: reading and writing [`Pattern`](super::Pattern)s as JSON,
//! SVG (FreeSewing and generic drawings), DXF-AAMA, garment tables that turn an SVG's parts
//! into a garment, and pattern sheets (the pieces drawn at scale, PNG or SVG) for checking.

pub mod dxf;
pub mod dxf_write;
pub mod json;
pub mod pattern_sheet;
pub mod svg;
pub mod table;
