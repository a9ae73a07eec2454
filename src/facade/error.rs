//! Errors of the facade module.

use std::path::PathBuf;

use crate::geometry::GeometryError;

/// What can go wrong reading or scoring facades.
#[derive(Debug, thiserror::Error)]
pub enum FacadeError {
    /// A file could not be read or decoded.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A label map holds a colour its colour map does not know.
    #[error("{path}: pixel ({x}, {y}) has colour {rgb:?}, which is not in the colour map")]
    UnknownColour {
        /// The file.
        path: PathBuf,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// The colour.
        rgb: [u8; 3],
    },
    /// Two maps that must match in size do not.
    #[error("size mismatch: {what}")]
    Size {
        /// Which maps.
        what: String,
    },
    /// A photo could not be rectified automatically (too few line segments, no consistent
    /// vanishing point, or a horizon through the image).
    #[error("automatic rectification failed: {message}")]
    Rectification {
        /// Why.
        message: String,
    },
}

impl From<GeometryError> for FacadeError {
    /// A geometry-layer error (a photo or label image that cannot be read) as a file error
    /// naming the file.
    fn from(e: GeometryError) -> Self {
        match e {
            GeometryError::Image { path, message } => FacadeError::File { path, message },
            GeometryError::Io { path, source } => FacadeError::File {
                path,
                message: source.to_string(),
            },
            GeometryError::Parse {
                path,
                line,
                message,
            } => FacadeError::File {
                path,
                message: format!("line {line}: {message}"),
            },
            GeometryError::Invalid(message) => FacadeError::File {
                path: PathBuf::new(),
                message,
            },
        }
    }
}
