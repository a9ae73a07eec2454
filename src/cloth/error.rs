//! Errors of the cloth module.

use crate::geometry::GeometryError;

/// What can go wrong while building or stepping a cloth.
#[derive(Debug, thiserror::Error)]
pub enum ClothError {
    /// A parameter is out of range (names the parameter).
    #[error("{0}")]
    Parameter(String),
    /// A step stage failed (a collision body or contact setting is invalid).
    #[error(transparent)]
    Stage(Box<dyn std::error::Error + Send + Sync>),
    /// The mesh is invalid or a file could not be read.
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    /// The simulation diverged; the state is left as it was before the failing step.
    #[error("simulation diverged at step {step} (t = {time:.6} s): {cause}")]
    Diverged {
        /// Index of the failing step.
        step: u64,
        /// Time at the start of the failing step (s).
        time: f64,
        /// What was detected, with the particle concerned.
        cause: String,
    },
    /// Writing an output failed.
    #[error("{path}: {message}")]
    Output {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}
