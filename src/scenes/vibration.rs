//! The vibrating strip: the meshless shell's time-accurate dynamics against the mass-spring
//! cloth's implicit solver (the engine's PCG) on a question with an analytic answer. A strip of
//! fabric (length L, width L/4, warp along its length), clamped along one short edge, without
//! gravity, is released at rest from its first clamped–free mode shape with a tip amplitude of
//! L/100; it vibrates at ω₁ = 1.8751² √(B / (ρ L⁴)) (Euler–Bernoulli; B the warp bending
//! rigidity per unit width, ρ the areal density). Each model runs three analytic periods at
//! `steps_per_period` steps; the period is read from the tip's zero crossings and the amplitude
//! kept from its largest excursion in the last period.
//!
//! The shell starts from its static deflection under the first mode's inertial load (which is
//! the mode shape) and runs Newmark's average acceleration with its consistent mass
//! ([`crate::shell::dynamics`]); the mass-spring cloth its own integrator (backward Euler,
//! preconditioned CG), clamped by pinning its first two particle columns (x = −h and 0), with
//! air drag and damping set to zero.

use std::time::Instant;

use crate::cloth::{ClothModel, FabricParameters, Simulation, SimulationParameters};
use crate::shell::dynamics::{DynamicsParameters, Integrator, ShellDynamics};
use crate::shell::solve::solve_static;
use crate::shell::{Discretisation, ShellMaterial, ShellParameters, ShellProblem};

/// β₁ L of the first clamped–free mode.
pub const BETA_L: f64 = 1.875_104_068_711_961;

/// Periods run.
const PERIODS: f64 = 3.0;

/// One model's vibration.
#[derive(Debug, Clone, PartialEq)]
pub struct VibrationRow {
    /// "shell" or "mass-spring".
    pub model: &'static str,
    /// Sample points (or particles) along the strip's length.
    pub along: usize,
    /// Measured period (s).
    pub period: f64,
    /// Analytic period 2π/ω₁ (s).
    pub reference: f64,
    /// (period − reference) / reference, %.
    pub error_pct: f64,
    /// The tip's largest excursion in the last period over its initial one.
    pub amplitude_kept: f64,
    /// Time steps.
    pub steps: usize,
    /// Newton iterations (shell) or CG iterations (mass-spring) in all.
    pub iterations: usize,
    /// Wall time (s).
    pub seconds: f64,
}

/// The first clamped–free mode shape over a strip of length `l`, 0 at the clamp, 2 at the tip
/// for βL = 1.8751.
pub fn mode_one(x: f64, l: f64) -> f64 {
    let b = BETA_L / l;
    let sigma = (BETA_L.cosh() + BETA_L.cos()) / (BETA_L.sinh() + BETA_L.sin());
    (b * x).cosh() - (b * x).cos() - sigma * ((b * x).sinh() - (b * x).sin())
}

/// The analytic period 2π/ω₁ (s) of a strip of length `l` of `fabric` (warp bending).
pub fn reference_period(fabric: &FabricParameters, l: f64) -> f64 {
    let omega = BETA_L * BETA_L * (fabric.bend_warp / (fabric.density * l.powi(4))).sqrt();
    2.0 * std::f64::consts::PI / omega
}

fn check(
    fabric: &FabricParameters,
    l: f64,
    along: usize,
    steps_per_period: usize,
) -> Result<(), String> {
    fabric.validate()?;
    if fabric.bend_warp <= 0.0 {
        return Err("the vibrating strip needs a positive bend_warp".into());
    }
    if !(l.is_finite() && l > 0.0 && l <= 10.0) {
        return Err(format!("strip length must lie in (0, 10] m, got {l}"));
    }
    if !(5..=201).contains(&along) {
        return Err(format!(
            "points along the strip must lie in [5, 201], got {along}"
        ));
    }
    if !(8..=10_000).contains(&steps_per_period) {
        return Err(format!(
            "steps per period must lie in [8, 10000], got {steps_per_period}"
        ));
    }
    Ok(())
}

/// The tip's zero crossings (linear interpolation between samples) and its largest |z| over
/// the last period.
struct Tip {
    z0: f64,
    z: f64,
    crossings: Vec<f64>,
    last_max: f64,
}

impl Tip {
    fn new(z0: f64) -> Tip {
        Tip {
            z0,
            z: z0,
            crossings: Vec::new(),
            last_max: 0.0,
        }
    }

    fn sample(&mut self, t: f64, dt: f64, z1: f64, in_last_period: bool) {
        if self.z.signum() != z1.signum() && z1 != 0.0 {
            self.crossings.push(t - dt * z1 / (z1 - self.z));
        }
        if in_last_period {
            self.last_max = self.last_max.max(z1.abs());
        }
        self.z = z1;
    }

    /// The model's row: the period from the first to the fifth zero crossing (two periods).
    fn row(
        &self,
        model: &'static str,
        along: usize,
        reference: f64,
        steps: usize,
        iterations: usize,
        t0: Instant,
    ) -> Result<VibrationRow, String> {
        if self.crossings.len() < 5 {
            return Err(format!(
                "{model}: the tip crossed zero {} times in {PERIODS} periods (a vibration crosses it six times)",
                self.crossings.len()
            ));
        }
        let period = 0.5 * (self.crossings[4] - self.crossings[0]);
        Ok(VibrationRow {
            model,
            along,
            period,
            reference,
            error_pct: 100.0 * (period - reference) / reference,
            amplitude_kept: self.last_max / self.z0.abs(),
            steps,
            iterations,
            seconds: t0.elapsed().as_secs_f64(),
        })
    }
}

/// The shell strip on `along` × 3..5 points (Newmark, consistent mass).
pub fn shell_vibration(
    fabric: &FabricParameters,
    l: f64,
    along: usize,
    steps_per_period: usize,
) -> Result<VibrationRow, String> {
    check(fabric, l, along, steps_per_period)?;
    let t0 = Instant::now();
    let w = 0.25 * l;
    let across = ((along - 1) / 4 + 1).max(3);
    let problem =
        ShellProblem::clamped_strip(l, w, along, across, ShellMaterial::from_fabric(fabric)?);
    // the start: the static deflection under the first mode's own inertial load
    // ρ ω₁² A φ₁(x)/φ₁(L), point loads at the sample points over their share of the area (the
    // shell's nodal values are not field values, and a start that breaks the clamp's penalty
    // would ring at frequencies that Newmark does not damp)
    let amp = 0.01 * l;
    let omega = 2.0 * std::f64::consts::PI / reference_period(fabric, l);
    let (hx, hy) = (l / (along - 1) as f64, w / (across - 1) as f64);
    let share = |i: usize, n: usize, h: f64| if i == 0 || i == n - 1 { 0.5 * h } else { h };
    let mut problem = problem;
    problem.point_loads = problem
        .nodes
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let area = share(k % along, along, hx) * share(k / along, across, hy);
            let f = fabric.density * omega * omega * amp * mode_one(p[0], l) / mode_one(l, l);
            (*p, [0.0, 0.0, f * area])
        })
        .collect();
    // a soft fabric's bending forces sit eight orders under its membrane stiffness: the static
    // residual stalls near 1e-8 of the load
    let params = ShellParameters {
        tolerance: 1e-6,
        ..Default::default()
    };
    let disc = Discretisation::new(problem, params).map_err(|e| e.to_string())?;
    let mut u = Vec::new();
    solve_static(&disc, &mut u, 0.0, 1.0, &mut |_, _| {}).map_err(|e| e.to_string())?;
    let reference = reference_period(fabric, l);
    let params = DynamicsParameters {
        dt: reference / steps_per_period as f64,
        integrator: Integrator::Newmark,
        ..Default::default()
    };
    let mut d =
        ShellDynamics::new(&disc, None, params, u, Vec::new(), 0.0).map_err(|e| e.to_string())?;
    let tip = |u: &[f64]| -> Result<f64, String> {
        Ok(disc
            .displacement_at([l, 0.5 * w], u)
            .map_err(|e| e.to_string())?[2])
    };
    let mut probe = Tip::new(tip(&d.u)?);
    let total = (PERIODS * steps_per_period as f64).round() as usize;
    for s in 0..total {
        d.step(0.0).map_err(|e| e.to_string())?;
        probe.sample(d.time, params.dt, tip(&d.u)?, s + steps_per_period >= total);
    }
    probe.row(
        "shell",
        along,
        reference,
        d.report.steps,
        d.report.newton_iterations,
        t0,
    )
}

/// The mass-spring strip: `along` particles over its free length (spacing h = L/(along − 1)),
/// one more column at x = −h, both clamped columns pinned; (along − 1)/4 + 1 particles across.
pub fn mass_spring_vibration(
    fabric: &FabricParameters,
    l: f64,
    along: usize,
    steps_per_period: usize,
) -> Result<VibrationRow, String> {
    check(fabric, l, along, steps_per_period)?;
    let t0 = Instant::now();
    let h = l / (along - 1) as f64;
    let nx = along + 1;
    let ny = (along - 1) / 4 + 1;
    let params = FabricParameters {
        air_drag: 0.0,
        stretch_damping: 0.0,
        bend_damping: 0.0,
        ..*fabric
    };
    let mut model = ClothModel::grid(l + h, 0.25 * l, nx, ny, params).map_err(|e| e.to_string())?;
    let amp = 0.01 * l;
    for p in &mut model.mesh.positions {
        // the grid spans [−(L + h)/2, (L + h)/2]: x from −h to L
        let x = p.x + 0.5 * (l + h) - h;
        p.x = x;
        p.z = if x > 0.0 {
            amp * mode_one(x, l) / mode_one(l, l)
        } else {
            0.0
        };
    }
    let reference = reference_period(fabric, l);
    let dt = reference / steps_per_period as f64;
    let sim_params = SimulationParameters {
        dt,
        gravity: [0.0; 3],
        ..Default::default()
    };
    let mut sim = Simulation::new(model, sim_params).map_err(|e| e.to_string())?;
    let clamped: Vec<usize> = (0..ny).flat_map(|i| [i * nx, i * nx + 1]).collect();
    sim.pin(&clamped).map_err(|e| e.to_string())?;
    let tips: Vec<usize> = (0..ny).map(|i| i * nx + nx - 1).collect();
    let tip = |sim: &Simulation| tips.iter().map(|&k| sim.state.x[k].z).sum::<f64>() / ny as f64;
    let mut probe = Tip::new(tip(&sim));
    let total = (PERIODS * steps_per_period as f64).round() as usize;
    let mut iterations = 0;
    for s in 0..total {
        let stats = sim.step().map_err(|e| e.to_string())?;
        iterations += stats.cg_iterations as usize;
        probe.sample(sim.state.time, dt, tip(&sim), s + steps_per_period >= total);
    }
    probe.row("mass-spring", along, reference, total, iterations, t0)
}
