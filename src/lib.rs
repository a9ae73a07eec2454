//! # Emilion
//!
//! A cloth simulation engine with measured fabrics, scripted in Rhai. The engine is usable
//! from Rust without scripting: [`cloth`] holds the model, solver and constraints,
//! [`geometry`] meshes and their files, [`render`] a software rasterizer for pictures.
//! `script` (feature `scripting`) registers all of it with a Rhai engine.
#![warn(missing_docs)]
// hot loops index several flat arrays in step; iterator zips would hide that
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod body;
pub mod cloth;
pub mod contact;
pub mod facade;
pub mod face;
pub mod garment;
pub mod geometry;
pub mod kes;
pub mod limits;
pub mod render;
pub mod scenes;
#[cfg(feature = "scripting")]
pub mod script;
pub mod shell;
pub mod sweep;
pub mod tracking;
