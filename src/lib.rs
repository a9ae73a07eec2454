//! # Emilion
//!
//! A cloth simulation engine with measured fabrics, scripted in Rhai. The engine is usable
//! from Rust without scripting: [`cloth`] holds the model, solver and constraints,
//! [`geometry`] meshes and their files, [`render`] a software rasterizer for pictures.
//! `script` (feature `scripting`) registers all of it with a Rhai engine.
#![warn(missing_docs)]

pub mod bench;
pub mod cloth;
pub mod geometry;
pub mod render;
pub mod scenes;
#[cfg(feature = "scripting")]
pub mod script;
