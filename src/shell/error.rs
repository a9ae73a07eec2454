//! The shell's error type: bad parameters, shape functions that cannot be built at a point, and
//! solver failures, each naming the parameter, the point or the load step.

/// What went wrong in the meshless shell.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShellError {
    /// A parameter is out of its range (the message names it and the range).
    #[error("shell: {0}")]
    Invalid(String),
    /// The MLS shape functions cannot be built at a point: too few neighbours in its support, or
    /// a singular moment matrix (nodes on a line, a basis too rich for the sampling).
    #[error("shell: MLS shape functions at {what} ({x:.6}, {y:.6}): {reason}")]
    ShapeFunctions {
        /// Which point: `node 12`, `quadrature point of node 12`, `evaluation point`.
        what: String,
        /// First parameter coordinate.
        x: f64,
        /// Second parameter coordinate.
        y: f64,
        /// Why.
        reason: String,
    },
    /// The Newton iteration or the sparse factorisation failed.
    #[error("shell: {0}")]
    Solver(String),
    /// A stated limit was passed.
    #[error("{0}")]
    Limit(#[from] crate::limits::LimitError),
}
