//! Errors of the measured-fabric module: every one names the file, and the field when there is
//! one.

/// A fabric file or lab error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KesError {
    /// A field has a bad value, unit or shape.
    #[error("{file}: field `{field}`: {message}")]
    Field {
        /// The file.
        file: String,
        /// Path of the field, e.g. `kes.warp.B`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The file is not valid JSON.
    #[error("{file}:{line}:{column}: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// Line (1-based).
        line: usize,
        /// Column (1-based).
        column: usize,
        /// Parser message.
        message: String,
    },
    /// Reading or writing failed.
    #[error("{file}: {message}")]
    Io {
        /// The file.
        file: String,
        /// What failed.
        message: String,
    },
    /// A lab run failed (the message names the fabric's file).
    #[error("{0}")]
    Lab(String),
}
