//! `ClothState`: what changes every step, as flat arrays.

use serde::{Deserialize, Serialize};

use crate::geometry::Vec3;

/// Positions, velocities and clock of a cloth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClothState {
    /// Particle positions (m).
    pub x: Vec<Vec3>,
    /// Particle velocities (m/s).
    pub v: Vec<Vec3>,
    /// Simulated time (s).
    pub time: f64,
    /// Steps taken.
    pub step: u64,
}

impl ClothState {
    /// A state at rest at positions `x`, time 0.
    pub fn at_rest(x: Vec<Vec3>) -> Self {
        let n = x.len();
        ClothState {
            x,
            v: vec![Vec3::zeros(); n],
            time: 0.0,
            step: 0,
        }
    }
}
