//! A cloth's contact settings (thickness, friction, self-collision) with their checks, and the
//! contact statistics of one step.

use serde::{Deserialize, Serialize};

use super::body::FrictionCoefficients;
use super::ContactError;

/// Contact settings of a cloth, SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ContactSettings {
    /// Distance kept between the cloth and bodies (m).
    pub thickness: f64,
    /// The fabric's friction, combined with each body's (mean of the coefficients); its two
    /// coefficients appear as `mu_static` and `mu_kinetic` among the settings.
    #[serde(flatten)]
    pub friction: FrictionCoefficients,
    /// Whether the cloth collides with itself.
    pub self_collision: bool,
    /// Distance kept between two layers of cloth (m).
    pub self_thickness: f64,
    /// Kinetic friction coefficient of cloth on cloth.
    pub self_friction: f64,
    /// Largest speed (m/s) at which a vertex found inside the thickness is pushed out.
    pub max_push_speed: f64,
    /// Count intersecting (edge, triangle) pairs of the cloth after every step (statistics).
    pub count_intersections: bool,
}

impl Default for ContactSettings {
    fn default() -> Self {
        ContactSettings {
            thickness: 0.005,
            friction: FrictionCoefficients::default(),
            self_collision: false,
            self_thickness: 0.004,
            self_friction: 0.3,
            max_push_speed: 1.0,
            count_intersections: true,
        }
    }
}

impl ContactSettings {
    /// Checks every value, naming the first bad one.
    pub fn validate(&self) -> Result<(), ContactError> {
        let bad = |name: &str, v: f64| {
            ContactError::Parameter(format!("contact setting `{name}` is invalid: {v}"))
        };
        for (name, v) in [
            ("thickness", self.thickness),
            ("self_thickness", self.self_thickness),
            ("max_push_speed", self.max_push_speed),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(name, v));
            }
        }
        if !(self.self_friction.is_finite() && self.self_friction >= 0.0) {
            return Err(bad("self_friction", self.self_friction));
        }
        self.friction.validate("fabric friction")
    }
}

/// Contact statistics of one step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactStats {
    /// Vertices constrained against a body during the step.
    pub contacts: usize,
    /// Cloth–cloth pairs closer than the self thickness at the start of the step.
    pub self_contacts: usize,
    /// Continuous cloth–cloth hits resolved.
    pub ccd_hits: usize,
    /// Impact-zone rounds needed.
    pub zone_rounds: usize,
    /// Free vertices the cloth–cloth response stopped as a last resort.
    pub self_stopped: usize,
    /// Smallest signed distance of a cloth vertex to a body at the end of the step (m;
    /// infinite without bodies near).
    pub min_distance: f64,
    /// Vertices inside a body at the end of the step.
    pub penetrating: usize,
    /// Intersecting (edge, triangle) pairs of the cloth at the end of the step (when counted).
    pub intersections: usize,
    /// Time in collision detection and response (ms).
    pub collision_ms: f64,
    /// Time spent counting intersections for these statistics (ms, not in `collision_ms`).
    pub stats_ms: f64,
}
