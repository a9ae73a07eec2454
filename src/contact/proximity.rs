//! `Proximity`: where a point is relative to a collision body's surface (signed distance,
//! normal, surface velocity), the answer every body shape gives.

use crate::geometry::Vec3;

/// Where a point is relative to a body's surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proximity {
    /// Signed distance (m): negative inside the body.
    pub distance: f64,
    /// Outward unit normal of the surface at the closest point.
    pub normal: Vec3,
    /// Velocity of the surface at the closest point (m/s).
    pub velocity: Vec3,
}
