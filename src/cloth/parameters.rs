//! Settings of a simulation: the time integrator, the implicit solve's preconditioner and
//! tolerances, the step, gravity and the divergence guard, each checked when set.

use serde::{Deserialize, Serialize};

use super::ClothError;

/// Time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// Linearised backward Euler with the modified PCG (Baraff & Witkin).
    Implicit,
    /// Symplectic Euler with `explicit_substeps` substeps per step.
    Explicit,
}

/// Which preconditioner the implicit solve uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PreconditionerKind {
    /// Multigrid on grid cloths of at least 16 × 16 particles, aggregation multigrid on other
    /// cloths of at least `AGGREGATION_MIN` particles, block-Jacobi otherwise.
    Auto,
    /// Inverse diagonal 3×3 blocks.
    BlockJacobi,
    /// Geometric multigrid V-cycle with line smoothing (grid cloths only).
    Multigrid,
    /// Aggregation (algebraic) multigrid V-cycle with block Gauss–Seidel smoothing (any mesh).
    Aggregation,
}

/// Shortest accepted step (s): 0.1 µs, far below what any cloth needs (the stiffest
/// explicit runs use 10⁻⁴ s) and far above where a run's step count stops fitting
/// `max_steps`.
pub const MIN_DT: f64 = 1e-7;
/// Longest accepted step (s): one second, the coarsest step an implicit drape is ever run at.
pub const MAX_DT: f64 = 1.0;
/// Most explicit substeps per step: 10,000 (a 1 µs substep at dt = 1/100 s, more than the
/// stiffest fabric on the finest grid asks for).
pub const MAX_EXPLICIT_SUBSTEPS: u32 = 10_000;

/// Smallest non-grid cloth that [`PreconditionerKind::Auto`] preconditions with aggregation
/// multigrid.
pub const AGGREGATION_MIN: usize = 1000;

/// Settings of a simulation, SI units; every field settable on its own.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SimulationParameters {
    /// Step length (s), in [`MIN_DT`, `MAX_DT`].
    pub dt: f64,
    /// Which integrator advances the state.
    pub integrator: Integrator,
    /// Gravity (m/s²).
    pub gravity: [f64; 3],
    /// CG relative residual tolerance.
    pub cg_tolerance: f64,
    /// CG iteration cap.
    pub cg_max_iterations: u32,
    /// Start CG from the previous step's velocity change.
    pub warm_start: bool,
    /// Substeps per step for the explicit integrator, 1 to [`MAX_EXPLICIT_SUBSTEPS`].
    pub explicit_substeps: u32,
    /// A particle faster than this (m/s) means the simulation blew up.
    pub max_speed: f64,
    /// Preconditioner of the implicit solve.
    pub preconditioner: PreconditionerKind,
}

impl Default for SimulationParameters {
    fn default() -> Self {
        SimulationParameters {
            dt: 1.0 / 120.0,
            integrator: Integrator::Implicit,
            gravity: [0.0, 0.0, -9.81],
            cg_tolerance: 1e-3,
            cg_max_iterations: 500,
            warm_start: true,
            explicit_substeps: 1,
            max_speed: 200.0,
            preconditioner: PreconditionerKind::Auto,
        }
    }
}

impl SimulationParameters {
    /// Checks the values, naming the first bad parameter: `dt` in [`MIN_DT`, `MAX_DT`] s,
    /// `explicit_substeps` in 1..=[`MAX_EXPLICIT_SUBSTEPS`].
    pub fn validate(&self) -> Result<(), ClothError> {
        let bad = |name: &str, v: f64| {
            ClothError::Parameter(format!("simulation parameter `{name}` is invalid: {v}"))
        };
        if !(self.dt.is_finite() && (MIN_DT..=MAX_DT).contains(&self.dt)) {
            return Err(ClothError::Parameter(format!(
                "simulation parameter `dt` is {} s, outside the accepted range [{MIN_DT:e}, {MAX_DT}] s",
                short_number(self.dt)
            )));
        }
        if !(self.cg_tolerance.is_finite() && self.cg_tolerance > 0.0) {
            return Err(bad("cg_tolerance", self.cg_tolerance));
        }
        if self.max_speed.is_nan() || self.max_speed <= 0.0 {
            return Err(bad("max_speed", self.max_speed));
        }
        if let Some(g) = self.gravity.iter().find(|g| !g.is_finite()) {
            return Err(bad("gravity", *g));
        }
        if !(1..=MAX_EXPLICIT_SUBSTEPS).contains(&self.explicit_substeps) {
            return Err(ClothError::Parameter(format!(
                "simulation parameter `explicit_substeps` is {}, outside the accepted range 1..={MAX_EXPLICIT_SUBSTEPS}",
                self.explicit_substeps
            )));
        }
        Ok(())
    }
}

/// `x` as a short number: plain between 10⁻⁴ and 10⁹, otherwise in exponent form with at most
/// six significant digits (`2e300` rather than 301 digits).
pub(crate) fn short_number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&x.abs()) {
        return format!("{x}");
    }
    let s = format!("{x:.5e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => s,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn short_numbers() {
        use super::short_number;
        assert_eq!(short_number(2.0 / 1e-300), "2e300");
        assert_eq!(short_number(1.2e11), "1.2e11");
        assert_eq!(short_number(1e-300), "1e-300");
        assert_eq!(short_number(0.5), "0.5");
        assert_eq!(short_number(-3.25e-9), "-3.25e-9");
    }
}
