//! Helpers shared by the integration tests.
pub mod inside;
pub mod intersections;
