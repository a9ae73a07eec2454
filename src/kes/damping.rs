//! Damping from a free-oscillation experiment: a strip hangs from a clamp, is stretched and
//! released, and the decay of its axial oscillation gives the logarithmic decrement. The
//! fitting finds the stiffness-proportional (Rayleigh β) damping whose simulated decrement
//! matches a measured one, by iterative minimisation (secant on log β), in the spirit of
//! Charfi, Gagalowicz & Brun's fitting of fabric viscosity. The explicit (symplectic)
//! integrator is used because it adds no numerical damping of its own.

use std::sync::Arc;

use crate::cloth::{
    ClothError, ClothModel, FabricParameters, Integrator, MaterialLaw, Simulation,
    SimulationParameters, Trajectory,
};

/// The free-oscillation experiment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecayExperiment {
    /// Strip length (m); its width is a tenth of it.
    pub length: f64,
    /// Initial stretch imposed before release (strain).
    pub strain: f64,
    /// Simulated time after release (s).
    pub duration: f64,
    /// Particles along the strip.
    pub particles: usize,
}

impl Default for DecayExperiment {
    fn default() -> Self {
        DecayExperiment {
            length: 0.2,
            strain: 0.01,
            duration: 0.08,
            particles: 11,
        }
    }
}

/// Result of one run: the tip's axial displacement from its static position over time, the
/// successive peak amplitudes, the mean logarithmic decrement and the period (s).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Decay {
    /// (t, displacement) of the free end.
    pub trajectory: Vec<[f64; 2]>,
    /// Peak amplitudes of |displacement| (m).
    pub peaks: Vec<f64>,
    /// Mean logarithmic decrement per period.
    pub log_decrement: f64,
    /// Oscillation period (s).
    pub period: f64,
}

/// Runs the experiment for a fabric with law `law` and damping `fabric.stretch_damping`.
pub fn free_oscillation(
    fabric: FabricParameters,
    law: Arc<dyn MaterialLaw>,
    exp: DecayExperiment,
) -> Result<Decay, ClothError> {
    let n = exp.particles.max(4);
    let width = 0.1 * exp.length;
    // strip along the warp (x), no gravity: the axial mode alone
    let mut model = ClothModel::grid(exp.length, width, n, 2, fabric)?;
    model.set_law(law);
    let mut sim = Simulation::new(
        model,
        SimulationParameters {
            dt: 2e-4,
            integrator: Integrator::Explicit,
            explicit_substeps: 20,
            gravity: [0.0; 3],
            max_speed: 1e4,
            ..Default::default()
        },
    )?;
    let root: Vec<usize> = vec![0, n];
    let tip = [n - 1, 2 * n - 1];
    // stretch uniformly, then release with the root clamped
    let x0 = sim.state.x.clone();
    let left = x0[0].x;
    for (i, x) in sim.state.x.iter_mut().enumerate() {
        x.x = left + (x0[i].x - left) * (1.0 + exp.strain);
    }
    sim.attach(&root, Trajectory::Fixed)?;
    let rest_tip = x0[tip[0]].x;
    let steps = (exp.duration / sim.params.dt).ceil() as u64;
    let mut traj = Vec::with_capacity(steps as usize);
    for _ in 0..steps {
        sim.step()?;
        let u = 0.5 * (sim.state.x[tip[0]].x + sim.state.x[tip[1]].x) - rest_tip;
        traj.push([sim.state.time, u]);
    }
    Ok(analyse(traj))
}

/// Peaks of |u| between sign changes, their mean log decrement and the period.
fn analyse(trajectory: Vec<[f64; 2]>) -> Decay {
    let mut peaks = Vec::new();
    let mut times = Vec::new();
    let mut best = (0.0f64, 0.0f64);
    let mut sign = 0.0f64;
    for p in &trajectory {
        let s = p[1].signum();
        if s != sign && sign != 0.0 {
            if best.1 > 0.0 {
                peaks.push(best.1);
                times.push(best.0);
            }
            best = (0.0, 0.0);
        }
        sign = s;
        if p[1].abs() > best.1 {
            best = (p[0], p[1].abs());
        }
    }
    // successive half-periods alternate sign: a full period spans two peaks
    let mut decs = Vec::new();
    for k in 2..peaks.len() {
        if peaks[k] > 0.0 {
            decs.push((peaks[k - 2] / peaks[k]).ln());
        }
    }
    let log_decrement = if decs.is_empty() {
        0.0
    } else {
        decs.iter().sum::<f64>() / decs.len() as f64
    };
    let period = if times.len() >= 3 {
        2.0 * (times[times.len() - 1] - times[0]) / (times.len() - 1) as f64
    } else {
        0.0
    };
    Decay {
        trajectory,
        peaks,
        log_decrement,
        period,
    }
}

/// Finds the stiffness-proportional damping β (s) whose free oscillation decays with
/// `target` logarithmic decrement. Returns β and the decay it gives.
pub fn fit_stretch_damping(
    fabric: FabricParameters,
    law: Arc<dyn MaterialLaw>,
    exp: DecayExperiment,
    target: f64,
) -> Result<(f64, Decay), ClothError> {
    if !(target.is_finite() && target > 0.0) {
        return Err(ClothError::Parameter(format!(
            "target logarithmic decrement must be positive, got {target}"
        )));
    }
    let run = |beta: f64| {
        free_oscillation(
            FabricParameters {
                stretch_damping: beta,
                ..fabric
            },
            law.clone(),
            exp,
        )
    };
    // the decrement is nearly proportional to β at small damping: secant on ln β
    let probe = run(1e-5)?;
    let per_beta = probe.log_decrement.max(1e-12) / 1e-5;
    let mut b0 = (target / per_beta).max(1e-9);
    let mut d0 = run(b0)?;
    let mut b1 = b0 * 1.2;
    let mut d1 = run(b1)?;
    for _ in 0..12 {
        let (f0, f1) = (
            d0.log_decrement.ln() - target.ln(),
            d1.log_decrement.ln() - target.ln(),
        );
        if f1.abs() < 1e-4 || (f1 - f0).abs() < 1e-14 {
            break;
        }
        let l2 = b1.ln() - f1 * (b1.ln() - b0.ln()) / (f1 - f0);
        (b0, d0) = (b1, d1);
        b1 = l2.exp().clamp(0.2 * b0, 5.0 * b0);
        d1 = run(b1)?;
    }
    Ok((b1, d1))
}
