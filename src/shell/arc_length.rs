//! Static paths through buckling and limit points: Crisfield's cylindrical arc length. The load
//! factor λ is an unknown beside u, and each step moves a fixed distance Δs in displacement
//! space, |Δu| = Δs, so the path can pass where the load stops rising (a limit point) or where
//! it barely rises (a bifurcation made smooth by an imperfection), which load-controlled Newton
//! cannot. R(u, λ) = R(u, 0) − λ F(u) ([`super::assembly`]: F the dead loads and edge moments).
//!
//! Each corrector iteration factorises the tangent K once (`faer`'s sparse Cholesky, LU where
//! K is indefinite: past a limit point) and solves it twice, δu_R = −K⁻¹R and δu_F = K⁻¹F; the
//! load change δλ is the root of |Δu + δu_R + δλ δu_F|² = Δs² that keeps the step going the way
//! it went (the larger (Δu + δu)·Δu). The predictor's direction follows the previous step
//! (Δu_prev · δu_F), so the path turns back at a limit point instead of reversing; it reuses
//! the tangent that the corrector reaching the point assembled there. Δs adapts
//! to the corrector's iteration count; a step whose quadratic has no real root or that does not
//! converge is retried at half the length.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, Lu};
use faer::sparse::SparseColMat;
use faer::{Col, Side};

use super::assembly::{residual, residual_and_tangent};
use super::discretisation::Discretisation;
use super::error::ShellError;
use super::solve::Symbolic;
use crate::limits;

/// How the path is followed.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ArcLengthParameters {
    /// First arc length (m, in displacement space).
    pub step: f64,
    /// Largest arc length (m).
    pub max_step: f64,
    /// Corrector iterations aimed at: Δs is scaled by √(aim / taken) after each step.
    pub aim_iterations: usize,
    /// Most corrector iterations before a step is retried at half the length.
    pub max_iterations: usize,
    /// A point has converged when |R| ≤ this × |λ F| (or when the corrector stalls, at the
    /// rounding floor, under a hundred times this).
    pub tolerance: f64,
    /// Most steps (accepted and retried).
    pub max_steps: usize,
}

impl Default for ArcLengthParameters {
    fn default() -> Self {
        ArcLengthParameters {
            step: 0.01,
            max_step: 0.1,
            aim_iterations: 4,
            max_iterations: 12,
            tolerance: 1e-8,
            max_steps: 500,
        }
    }
}

/// One converged point of the path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPoint {
    /// Load factor.
    pub lambda: f64,
    /// Corrector iterations it took.
    pub iterations: usize,
    /// Arc length of the step that reached it.
    pub step: f64,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// K⁻¹ b for each right-hand side b, from one factorisation (Cholesky, LU if K is not
/// positive definite).
fn solve_each(
    k: &SparseColMat<usize, f64>,
    rhs: &[&[f64]],
    symbolic: &mut Symbolic,
) -> Result<Vec<Vec<f64>>, ShellError> {
    let cols: Vec<Col<f64>> = rhs
        .iter()
        .map(|b| Col::<f64>::from_fn(b.len(), |i| b[i]))
        .collect();
    let xs: Vec<Col<f64>> =
        match Llt::try_new_with_symbolic(symbolic.llt(k)?, k.as_ref(), Side::Lower) {
            Ok(llt) => cols.iter().map(|c| llt.solve(c)).collect(),
            Err(_) => {
                let lu = Lu::try_new_with_symbolic(symbolic.lu(k)?, k.as_ref()).map_err(|e| {
                    ShellError::Solver(format!("sparse LU of the tangent failed: {e:?}"))
                })?;
                cols.iter().map(|c| lu.solve(c)).collect()
            }
        };
    let xs: Vec<Vec<f64>> = xs
        .iter()
        .map(|x| (0..x.nrows()).map(|i| x[i]).collect())
        .collect();
    if !xs.iter().flatten().all(|v| v.is_finite()) {
        return Err(ShellError::Solver(
            "the tangent is singular (a rigid-body motion left free? add supports or pins)".into(),
        ));
    }
    Ok(xs)
}

/// F(u) = R(u, 0) − R(u, 1): the load the factor multiplies (dead loads, edge moments).
fn load_vector(disc: &Discretisation, u: &[f64]) -> Vec<f64> {
    let r0 = residual(disc, u, 0.0);
    let r1 = residual(disc, u, 1.0);
    r0.iter().zip(&r1).map(|(a, b)| a - b).collect()
}

/// Follows the equilibrium path from (`u`, `lambda`) (the rest state if `u` is empty) for as
/// long as `on_point(λ, u)` returns true, at most `max_steps` steps. Returns the converged
/// points. Errors: bad parameters (named), no load, a step that fails at a thousandth of the
/// first arc length (the message gives the load factor reached).
pub fn arc_length(
    disc: &Discretisation,
    u: &mut Vec<f64>,
    lambda: &mut f64,
    params: &ArcLengthParameters,
    on_point: &mut dyn FnMut(f64, &[f64]) -> bool,
) -> Result<Vec<PathPoint>, ShellError> {
    if !(params.step > 0.0 && params.max_step >= params.step && params.tolerance > 0.0)
        || params.aim_iterations == 0
        || params.max_iterations < params.aim_iterations
    {
        return Err(ShellError::Invalid(format!(
            "arc length needs 0 < step <= max_step, tolerance > 0 and 1 <= aim_iterations <= max_iterations, got {params:?}"
        )));
    }
    let n = 3 * disc.len();
    if u.len() != n {
        *u = vec![0.0; n];
    }
    let f_norm = disc.external_load_norm();
    if f_norm.is_nan() || f_norm <= 0.0 {
        return Err(ShellError::Invalid(
            "arc length needs a load (area, point or edge moment)".into(),
        ));
    }
    let mut symbolic = Symbolic::default();
    let mut ds = params.step;
    let mut previous: Option<Vec<f64>> = None;
    let mut path = Vec::new();
    let mut tries = 0;
    // the tangent and load vector at the current point (kept from the corrector that reached it)
    let mut point: Option<(SparseColMat<usize, f64>, Vec<f64>)> = None;
    while tries < params.max_steps {
        limits::check_cancelled().map_err(ShellError::Solver)?;
        tries += 1;
        let (u0, l0) = (u.clone(), *lambda);
        // predictor along the tangent, the way the path went
        if point.is_none() {
            let (_, k) = residual_and_tangent(disc, u, *lambda)?;
            point = Some((k, load_vector(disc, u)));
        }
        let (k0, f0) = point.as_ref().expect("set above");
        let uf = solve_each(k0, &[f0], &mut symbolic)?.remove(0);
        let norm_uf = dot(&uf, &uf).sqrt();
        let sign = match &previous {
            Some(p) if dot(p, &uf) < 0.0 => -1.0,
            _ => 1.0,
        };
        let mut dl = sign * ds / norm_uf;
        let mut du: Vec<f64> = uf.iter().map(|x| dl * x).collect();
        let mut done = None;
        let mut previous_rel = f64::INFINITY;
        for it in 1..=params.max_iterations {
            for i in 0..n {
                u[i] = u0[i] + du[i];
            }
            *lambda = l0 + dl;
            let (r, k) = residual_and_tangent(disc, u, *lambda)?;
            let rel = dot(&r, &r).sqrt() / (f_norm * lambda.abs().max(1e-3));
            if !rel.is_finite() {
                break;
            }
            // converged, or stalled at the rounding floor within a hundred times the tolerance
            // (the penalties' large, cancelling forces set that floor where λ is small)
            if rel <= params.tolerance
                || (rel <= 100.0 * params.tolerance && rel > 0.5 * previous_rel)
            {
                done = Some((it - 1, k));
                break;
            }
            previous_rel = rel;
            let f = load_vector(disc, u);
            let minus_r: Vec<f64> = r.iter().map(|x| -x).collect();
            let (ur, uf) = match solve_each(&k, &[&minus_r, &f], &mut symbolic) {
                Ok(mut x) => (x.remove(0), x.remove(0)),
                Err(_) => break,
            };
            // |du + ur + δλ uf|² = ds²
            let w: Vec<f64> = (0..n).map(|i| du[i] + ur[i]).collect();
            let (a, b, c) = (dot(&uf, &uf), 2.0 * dot(&uf, &w), dot(&w, &w) - ds * ds);
            let disc2 = b * b - 4.0 * a * c;
            if disc2 < 0.0 || a == 0.0 {
                break;
            }
            let roots = [
                (-b + disc2.sqrt()) / (2.0 * a),
                (-b - disc2.sqrt()) / (2.0 * a),
            ];
            let keeps = |dlam: f64| -> f64 { (0..n).map(|i| (w[i] + dlam * uf[i]) * du[i]).sum() };
            let dlam = if keeps(roots[0]) >= keeps(roots[1]) {
                roots[0]
            } else {
                roots[1]
            };
            for i in 0..n {
                du[i] = w[i] + dlam * uf[i];
            }
            dl += dlam;
        }
        match done {
            Some((iterations, k)) => {
                point = Some((k, load_vector(disc, u)));
                path.push(PathPoint {
                    lambda: *lambda,
                    iterations,
                    step: ds,
                });
                previous = Some(du);
                ds = (ds * (params.aim_iterations as f64 / iterations.max(1) as f64).sqrt())
                    .clamp(0.25 * ds, 2.0 * ds)
                    .min(params.max_step);
                if !on_point(*lambda, u) {
                    return Ok(path);
                }
            }
            None => {
                u.copy_from_slice(&u0);
                *lambda = l0;
                ds *= 0.5;
                if ds < 1e-3 * params.step {
                    return Err(ShellError::Solver(format!(
                        "arc length failed at load factor {l0:.6} after {} points: no step converges down to an arc length of {ds:.3e}",
                        path.len()
                    )));
                }
            }
        }
    }
    Ok(path)
}
