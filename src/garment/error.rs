//! Errors of the garment module: pattern files that cannot be read, pieces and seams that are
//! invalid. Every message names the file, the piece and the edge or seam concerned.

use std::path::PathBuf;

/// What can go wrong while reading, checking or meshing a pattern.
#[derive(Debug, thiserror::Error)]
pub enum PatternError {
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file was read but its content is malformed or unsupported.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 when unknown).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A syntax error at a known line and column of a text file (JSON, XML).
    #[error("{path}:{line}:{column}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// 1-based column number.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A piece is invalid (open or self-intersecting outline, bad grain line, …).
    #[error("{source_name}: piece '{piece}': {message}")]
    Piece {
        /// The file (or other origin) of the pattern.
        source_name: String,
        /// The piece.
        piece: String,
        /// What is wrong, naming the edge or corner where it applies.
        message: String,
    },
    /// A seam is invalid (unknown piece or corner, lengths that do not match, …).
    #[error("{source_name}: seam '{seam}': {message}")]
    Seam {
        /// The file (or other origin) of the pattern.
        source_name: String,
        /// The seam's name.
        seam: String,
        /// What is wrong, naming the pieces and edges.
        message: String,
    },
    /// A parameter (target edge length, distance, …) is invalid.
    #[error("invalid parameter: {0}")]
    Parameter(String),
}
