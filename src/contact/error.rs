//! Errors of the contact module: bad bodies (meshes that are degenerate, non-manifold or
//! inconsistently wound) and bad contact parameters.

/// What can go wrong while building bodies or contact settings.
#[derive(Debug, thiserror::Error)]
pub enum ContactError {
    /// A parameter is out of range (names the parameter and the value).
    #[error("{0}")]
    Parameter(String),
    /// A body mesh cannot be used for collisions (names the body and what is wrong).
    #[error("body `{body}`: {message}")]
    Mesh {
        /// The body's name (its file for meshes read from disk).
        body: String,
        /// What is wrong, with the triangle, edge or vertex concerned.
        message: String,
    },
}
