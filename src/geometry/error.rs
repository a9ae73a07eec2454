//! Errors of the geometry module: files that cannot be read or parsed (meshes, images), meshes
//! that are invalid.

use std::path::PathBuf;

/// What can go wrong while building, reading or writing a mesh or reading an image.
#[derive(Debug, thiserror::Error)]
pub enum GeometryError {
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file was read but its content is malformed.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 when unknown).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// An image file could not be opened or decoded.
    #[error("{path}: {message}")]
    Image {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A mesh or a parameter is invalid.
    #[error("invalid mesh: {0}")]
    Invalid(String),
}
