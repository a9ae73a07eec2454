//! Errors of the face module: unreadable or malformed files, bad landmarks, bad parameters.

use std::path::PathBuf;

/// What can go wrong while reading, fitting, animating, texturing or tracking a face.
#[derive(Debug, thiserror::Error)]
pub enum FaceError {
    /// A file could not be opened, read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error, in words.
        message: String,
    },
    /// A file was read but its content is malformed.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 when no single line is at fault).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Landmarks that cannot be used (wrong count, outside the image, not finite).
    #[error("{source_name}: {message}")]
    Landmarks {
        /// The landmark file or image they belong to.
        source_name: String,
        /// What is wrong.
        message: String,
    },
    /// A parameter is out of range, not finite, or inconsistent with the others.
    #[error("parameter `{name}`: {message}")]
    Parameter {
        /// The parameter.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// A computation failed (a singular system, a fit that cannot start).
    #[error("{0}")]
    Failed(String),
}

impl From<crate::geometry::GeometryError> for FaceError {
    /// A geometry error (an unreadable photo, a malformed mesh file) as the face module's
    /// file error, naming the same file.
    fn from(e: crate::geometry::GeometryError) -> Self {
        use crate::geometry::GeometryError as G;
        match e {
            G::Image { path, message } => FaceError::Io { path, message },
            G::Io { path, source } => FaceError::io(path, source),
            other => FaceError::Failed(other.to_string()),
        }
    }
}

impl FaceError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, e: impl std::fmt::Display) -> Self {
        FaceError::Io {
            path: path.into(),
            message: e.to_string(),
        }
    }

    /// `Ok` when `value` is finite and positive, else a parameter error naming `name`.
    pub fn require_positive(name: &str, value: f64) -> Result<(), FaceError> {
        if value.is_finite() && value > 0.0 {
            Ok(())
        } else {
            Err(FaceError::parameter(
                name,
                format!("must be finite and positive, got {value}"),
            ))
        }
    }

    /// A parameter error.
    pub fn parameter(name: &str, message: impl Into<String>) -> Self {
        FaceError::Parameter {
            name: name.to_string(),
            message: message.into(),
        }
    }
}
