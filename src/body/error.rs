//! Errors of the body module: mannequin and motion files that cannot be read or parsed, and
//! skeletons or clips that do not fit together.

use std::path::PathBuf;

/// What can go wrong while loading a mannequin or a motion clip, or retargeting one onto the
/// other. Every variant names the file (or the clip) concerned; syntax errors also name the
/// 1-based line.
#[derive(Debug, thiserror::Error)]
pub enum BodyError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file was read but its syntax is malformed (OBJ, BVH or JSON).
    #[error("{file}:{line}: {message}")]
    Parse {
        /// The file (or the name given for an in-memory text).
        file: String,
        /// 1-based line number of the offending token (0 when unknown).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The file is well-formed but its content is inconsistent (an unknown bone, an index
    /// out of range, a vertex without weight, ...).
    #[error("{file}: {message}")]
    Invalid {
        /// The file (or the clip) concerned.
        file: String,
        /// What is wrong.
        message: String,
    },
}

impl BodyError {
    /// A syntax error at `line` of `file`.
    pub(crate) fn parse(file: &str, line: usize, message: impl Into<String>) -> Self {
        BodyError::Parse {
            file: file.to_string(),
            line,
            message: message.into(),
        }
    }

    /// A content error in `file`.
    pub(crate) fn invalid(file: &str, message: impl Into<String>) -> Self {
        BodyError::Invalid {
            file: file.to_string(),
            message: message.into(),
        }
    }

    /// A JSON syntax or shape error, with serde's line number.
    pub(crate) fn json(file: &str, err: &serde_json::Error) -> Self {
        BodyError::parse(file, err.line(), err.to_string())
    }
}

/// Reads a whole text file, naming it in the error.
pub(crate) fn read_text(path: &std::path::Path) -> Result<String, BodyError> {
    crate::limits::read_to_string(path).map_err(|source| BodyError::Io {
        path: path.to_path_buf(),
        source,
    })
}
