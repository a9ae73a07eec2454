//! Relaxation to a stable equilibrium: overdamped implicit steps (backward Euler with the
//! velocity dropped after every step), each solving M (u − u₀)/Δt² + R(u) = 0 by Newton with
//! `faer`'s sparse Cholesky (LU where the tangent is not positive definite), M the lumped mass (ρ ∫ φ_J dA per node). A converged equilibrium of the
//! static problem is reached when the static residual |R(u)| (contact included) falls under the
//! tolerance. Unlike Newton on R alone, the inertia term makes every step a descent of the
//! energy, so a drape that must buckle into folds leaves the symmetric (unstable) equilibrium
//! instead of converging to it. The step grows after easy steps and shrinks after a step that
//! does not converge (the step is then retried from its start).

use std::time::Instant;

use faer::sparse::Triplet;

use super::assembly::{residual_and_triplets, tangent_matrix, Entry};
use super::discretisation::Discretisation;
use super::error::ShellError;
use super::obstacle::SphereObstacle;
use super::solve::{newton_step, Symbolic};
use crate::limits;

/// How a relaxation proceeds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelaxParameters {
    /// First pseudo-time step (s).
    pub dt: f64,
    /// Largest pseudo-time step (s).
    pub dt_max: f64,
    /// Done when |R(u)| ≤ this × |load|.
    pub tolerance: f64,
    /// Most steps (accepted and rejected).
    pub max_steps: usize,
    /// Most Newton iterations per step before it is rejected and retried with Δt/4.
    pub newton_iterations: usize,
}

impl Default for RelaxParameters {
    fn default() -> Self {
        RelaxParameters {
            dt: 0.01,
            dt_max: 1.0,
            tolerance: 1e-6,
            max_steps: 400,
            newton_iterations: 8,
        }
    }
}

/// How a relaxation went.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RelaxReport {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// Newton iterations in all (each one assembly and one LU factorisation).
    pub newton_iterations: usize,
    /// Final static residual relative to the load.
    pub residual: f64,
    /// Wall time (s).
    pub seconds: f64,
}

/// The lumped mass per node: ρ Σ_q w_q φ_J(q) (kg), at least a millionth of the mean.
pub fn lumped_masses(disc: &Discretisation) -> Vec<f64> {
    let rho = disc.problem.material.density;
    let mut m = vec![0.0; disc.len()];
    for q in &disc.quad {
        for (jj, &j) in q.nodes.iter().enumerate() {
            m[j] += rho * q.weight * q.values[jj][0];
        }
    }
    let mean = m.iter().sum::<f64>() / m.len().max(1) as f64;
    let floor = 1e-6 * mean.abs().max(f64::MIN_POSITIVE);
    m.iter().map(|&v| v.max(floor)).collect()
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Relaxes `u` (the rest state if empty) under the full load to a stable equilibrium, with the
/// sphere `obstacle` if any. `on_step(step, u)` is called after each accepted step. Errors: a
/// step that fails at the smallest Δt, or no equilibrium within `max_steps` (the message gives
/// the residual reached).
pub fn relax(
    disc: &Discretisation,
    obstacle: Option<&SphereObstacle>,
    u: &mut Vec<f64>,
    params: &RelaxParameters,
    on_step: &mut dyn FnMut(usize, &[f64]),
) -> Result<RelaxReport, ShellError> {
    let t0 = Instant::now();
    if !(params.dt > 0.0 && params.dt_max >= params.dt && params.tolerance > 0.0) {
        return Err(ShellError::Invalid(format!(
            "relaxation needs 0 < dt <= dt_max and tolerance > 0, got {params:?}"
        )));
    }
    if let Some(o) = obstacle {
        o.validate()?;
    }
    let n = 3 * disc.len();
    if u.len() != n {
        *u = vec![0.0; n];
    }
    let mass = lumped_masses(disc);
    let f_norm = disc.external_load_norm().max(f64::MIN_POSITIVE);
    let mut report = RelaxReport::default();
    let mut symbolic = Symbolic::default();
    let mut dt = params.dt;
    let mut start = u.clone();
    // the static residual and tangent entries of the state the last accepted step ended on
    let mut assembled: Option<(Vec<f64>, Vec<Entry>)> = None;
    while report.steps + report.rejected < params.max_steps {
        limits::check_cancelled().map_err(ShellError::Solver)?;
        let inertia = 1.0 / (dt * dt);
        let mut converged = None;
        let mut first = f64::INFINITY;
        for it in 0..=params.newton_iterations {
            // the state a converged step ended on was assembled there: not again here
            let (mut res, mut trip) = match assembled.take() {
                Some(a) => a,
                None => {
                    let (mut res, mut trip) = residual_and_triplets(disc, u, 1.0)?;
                    if let Some(o) = obstacle {
                        o.add_terms(disc, u, &mut res, Some(&mut trip));
                    }
                    (res, trip)
                }
            };
            let static_r = norm(&res) / f_norm;
            if it == 0 && static_r <= params.tolerance {
                report.residual = static_r;
                report.seconds = t0.elapsed().as_secs_f64();
                return Ok(report);
            }
            let static_res = res.clone();
            let static_len = trip.len();
            for (j, &m) in mass.iter().enumerate() {
                for c in 0..3 {
                    let i = 3 * j + c;
                    res[i] += m * inertia * (u[i] - start[i]);
                    trip.push(Triplet::new(i, i, m * inertia));
                }
            }
            let step_r = norm(&res) / f_norm;
            if it == 0 {
                first = step_r;
            }
            // the step's own system solved well below where the static residual stands
            if step_r <= 0.1 * params.tolerance || (it > 0 && step_r <= 1e-4 * first) {
                converged = Some(it);
                trip.truncate(static_len);
                assembled = Some((static_res, trip));
                break;
            }
            if it == params.newton_iterations {
                break;
            }
            let k = tangent_matrix(disc, &trip)?;
            report.newton_iterations += 1;
            if newton_step(&res, &k, u, &mut symbolic).is_err() {
                break;
            }
        }
        match converged {
            Some(it) => {
                report.steps += 1;
                start.copy_from_slice(u);
                on_step(report.steps, u);
                if it <= 3 {
                    dt = (dt * 2.0).min(params.dt_max);
                }
            }
            None => {
                report.rejected += 1;
                u.copy_from_slice(&start);
                dt *= 0.25;
                if dt < 1e-6 * params.dt {
                    return Err(ShellError::Solver(format!(
                        "relaxation failed: Newton does not converge even at pseudo-time step {dt:.3e} s (step {})",
                        report.steps + 1
                    )));
                }
            }
        }
    }
    let (mut res, _) = residual_and_triplets(disc, u, 1.0)?;
    if let Some(o) = obstacle {
        o.add_terms(disc, u, &mut res, None);
    }
    Err(ShellError::Solver(format!(
        "relaxation reached no equilibrium in {} steps: relative residual {:.3e} (tolerance {:.1e}; raise max_steps)",
        params.max_steps,
        norm(&res) / f_norm,
        params.tolerance
    )))
}
