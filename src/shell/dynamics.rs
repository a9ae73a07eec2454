//! Time-accurate implicit dynamics of the shell: M ü + R(u, λ) = 0, M the mass matrix
//! (consistent, ρ ∫ φ_J φ_K dA, or lumped by rows), R the static residual of
//! [`super::assembly`] (internal forces, penalties, edge moments, minus the load at factor λ)
//! plus the sphere's contact if any. Each step solves for the end displacement u₁ by Newton,
//! every linear system M/(β Δt²) + K by `faer`'s sparse Cholesky (LU where it is not positive
//! definite), the symbolic factorisation computed once.
//!
//! Two integrators: Newmark's average acceleration (β = ¼, γ = ½: second-order, no numerical
//! damping, energy-conserving on a linear system, a period lengthened by about (ω Δt)²/12) and
//! backward Euler (first order, damps the high frequencies and, more slowly, everything). The
//! energy of a state, ½ vᵀ M v plus the potential Π(u) = ∫₀¹ R(s u)·u ds (Gauss–Legendre along
//! the straight path from rest: R is the gradient of Π), checks the integration.

use faer::sparse::{SparseColMat, Triplet};

use super::assembly::{residual, residual_and_triplets, tangent_matrix, Entry};
use super::discretisation::Discretisation;
use super::error::ShellError;
use super::obstacle::SphereObstacle;
use super::problem::gauss_legendre;
use super::relax::lumped_masses;
use super::solve::{newton_step, Symbolic};
use crate::limits;

/// The time integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Integrator {
    /// Newmark's average acceleration (β = ¼, γ = ½).
    Newmark,
    /// Backward Euler.
    BackwardEuler,
}

/// The mass matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum MassMatrix {
    /// ρ ∫ φ_J φ_K dA: the Galerkin mass, with the shape functions' own accuracy.
    Consistent,
    /// Its rows summed onto the diagonal, ρ ∫ φ_J dA.
    Lumped,
}

/// How the dynamics proceeds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DynamicsParameters {
    /// Time step (s).
    pub dt: f64,
    /// The integrator.
    pub integrator: Integrator,
    /// The mass matrix.
    pub mass: MassMatrix,
    /// A step has converged when |M a + R| ≤ this × the largest of |M a|, |R| and |M v|/Δt (or when Newton
    /// stalls, at the rounding floor, under a hundred times this).
    pub tolerance: f64,
    /// Most Newton iterations per step.
    pub newton_iterations: usize,
}

impl Default for DynamicsParameters {
    fn default() -> Self {
        DynamicsParameters {
            dt: 1e-3,
            integrator: Integrator::Newmark,
            mass: MassMatrix::Consistent,
            tolerance: 1e-8,
            newton_iterations: 20,
        }
    }
}

/// What the steps so far took.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DynamicsReport {
    /// Steps taken.
    pub steps: usize,
    /// Newton iterations in all (each one assembly and one factorisation).
    pub newton_iterations: usize,
}

/// A shell in motion: its state (displacement, velocity, acceleration at `time`), its mass
/// matrix and its factorisation's symbolic part.
pub struct ShellDynamics<'a> {
    disc: &'a Discretisation,
    obstacle: Option<&'a SphereObstacle>,
    params: DynamicsParameters,
    mass: SparseColMat<usize, f64>,
    /// M/(β Δt²) as tangent entries (Δt and β are fixed for the run).
    mass_entries: Vec<Entry>,
    symbolic: Symbolic,
    /// Displacement (3 per node).
    pub u: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
    /// Acceleration.
    pub a: Vec<f64>,
    /// Time (s).
    pub time: f64,
    /// Steps and Newton iterations so far.
    pub report: DynamicsReport,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Newmark's β of the integrator (u₁ = ũ + β Δt² a₁; backward Euler is β = 1 about its own
/// predictor).
fn beta(integrator: Integrator) -> f64 {
    match integrator {
        Integrator::Newmark => 0.25,
        Integrator::BackwardEuler => 1.0,
    }
}

/// The mass matrix of `disc` (3 rows per node, the identity in each node block).
pub fn mass_matrix(
    disc: &Discretisation,
    kind: MassMatrix,
) -> Result<SparseColMat<usize, f64>, ShellError> {
    let n = disc.len();
    let mut trip: Vec<Entry> = Vec::new();
    match kind {
        MassMatrix::Lumped => {
            for (j, m) in lumped_masses(disc).into_iter().enumerate() {
                for c in 0..3 {
                    trip.push(Triplet::new(3 * j + c, 3 * j + c, m));
                }
            }
        }
        MassMatrix::Consistent => {
            let rho = disc.problem.material.density;
            let pairs: usize = disc.quad.iter().map(|q| q.nodes.len().pow(2)).sum();
            limits::check_alloc("shell mass entries", 3 * pairs as u64, 24)?;
            trip.reserve(3 * pairs);
            for q in &disc.quad {
                for (a, &j) in q.nodes.iter().enumerate() {
                    for (b, &k) in q.nodes.iter().enumerate() {
                        let m = rho * q.weight * q.values[a][0] * q.values[b][0];
                        for c in 0..3 {
                            trip.push(Triplet::new(3 * j + c, 3 * k + c, m));
                        }
                    }
                }
            }
        }
    }
    SparseColMat::try_new_from_triplets(3 * n, 3 * n, &trip)
        .map_err(|e| ShellError::Solver(format!("mass matrix: {e:?}")))
}

/// y = M x.
fn mass_times(m: &SparseColMat<usize, f64>, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; x.len()];
    let (ptr, rows, vals) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
    for (col, &xc) in x.iter().enumerate() {
        for k in ptr[col]..ptr[col + 1] {
            y[rows[k]] += vals[k] * xc;
        }
    }
    y
}

/// The potential energy Π(u) − Π(0) at load factor `lambda`: ∫₀¹ R(s u)·u ds by composite
/// Gauss–Legendre (four panels of six points). Contact is not included.
pub fn potential_energy(disc: &Discretisation, u: &[f64], lambda: f64) -> f64 {
    let (xs, ws) = gauss_legendre(6);
    let panels = 4;
    let mut total = 0.0;
    let mut us = vec![0.0; u.len()];
    for p in 0..panels {
        for (x, w) in xs.iter().zip(ws) {
            let s = (p as f64 + 0.5 * (x + 1.0)) / panels as f64;
            for (a, b) in us.iter_mut().zip(u) {
                *a = s * b;
            }
            let r = residual(disc, &us, lambda);
            let dot: f64 = r.iter().zip(u).map(|(a, b)| a * b).sum();
            total += 0.5 * w / panels as f64 * dot;
        }
    }
    total
}

impl<'a> ShellDynamics<'a> {
    /// Starts from displacement `u` and velocity `v` (the rest state and zero if empty) at time
    /// 0 under load factor `lambda`: the acceleration is M⁻¹(−R). Errors: a bad parameter or
    /// state length (named), a singular mass matrix.
    pub fn new(
        disc: &'a Discretisation,
        obstacle: Option<&'a SphereObstacle>,
        params: DynamicsParameters,
        u: Vec<f64>,
        v: Vec<f64>,
        lambda: f64,
    ) -> Result<ShellDynamics<'a>, ShellError> {
        if !(params.dt.is_finite() && params.dt > 0.0) {
            return Err(ShellError::Invalid(format!(
                "dynamics time step `dt` must be positive and finite, got {}",
                params.dt
            )));
        }
        if !(params.tolerance > 0.0 && params.tolerance < 1.0) || params.newton_iterations == 0 {
            return Err(ShellError::Invalid(format!(
                "dynamics needs 0 < tolerance < 1 and newton_iterations ≥ 1, got {params:?}"
            )));
        }
        if disc.problem.material.density.is_nan() || disc.problem.material.density <= 0.0 {
            return Err(ShellError::Invalid(
                "dynamics needs a material with positive density".into(),
            ));
        }
        if let Some(o) = obstacle {
            o.validate()?;
        }
        let n = 3 * disc.len();
        let fill = |x: Vec<f64>, what: &str| -> Result<Vec<f64>, ShellError> {
            match x.len() {
                0 => Ok(vec![0.0; n]),
                l if l == n && x.iter().all(|v| v.is_finite()) => Ok(x),
                l if l == n => Err(ShellError::Invalid(format!(
                    "initial {what} holds a non-finite value"
                ))),
                l => Err(ShellError::Invalid(format!(
                    "initial {what} has {l} values, expected {n} (3 per point)"
                ))),
            }
        };
        let u = fill(u, "displacement")?;
        let v = fill(v, "velocity")?;
        let mass = mass_matrix(disc, params.mass)?;
        let mut r = residual(disc, &u, lambda);
        if let Some(o) = obstacle {
            o.add_terms(disc, &u, &mut r, None);
        }
        let mut a = vec![0.0; n];
        let mut symbolic = Symbolic::default();
        newton_step(&r, &mass, &mut a, &mut symbolic)?;
        let c = 1.0 / (beta(params.integrator) * params.dt * params.dt);
        let s = mass.symbolic();
        let mut mass_entries = Vec::with_capacity(mass.val().len());
        for col in 0..n {
            for k in s.col_ptr()[col]..s.col_ptr()[col + 1] {
                mass_entries.push(Triplet::new(s.row_idx()[k], col, c * mass.val()[k]));
            }
        }
        Ok(ShellDynamics {
            disc,
            obstacle,
            params,
            mass_entries,
            mass,
            symbolic: Symbolic::default(),
            u,
            v,
            a,
            time: 0.0,
            report: DynamicsReport::default(),
        })
    }

    /// ½ vᵀ M v (J).
    pub fn kinetic_energy(&self) -> f64 {
        let mv = mass_times(&self.mass, &self.v);
        0.5 * mv.iter().zip(&self.v).map(|(a, b)| a * b).sum::<f64>()
    }

    /// One step of `dt` to the load factor `lambda`. Errors name the step and time: Newton not
    /// converging within its iterations, a non-finite state, a singular system. The state is
    /// left at the step's start on error.
    pub fn step(&mut self, lambda: f64) -> Result<(), ShellError> {
        limits::check_cancelled().map_err(ShellError::Solver)?;
        let dt = self.params.dt;
        let n = self.u.len();
        // u₁ = ũ + β Δt² a₁: the predictor ũ and c = 1/(β Δt²)
        let beta = beta(self.params.integrator);
        let gamma = match self.params.integrator {
            Integrator::Newmark => 0.5,
            Integrator::BackwardEuler => 1.0,
        };
        let predictor: Vec<f64> = (0..n)
            .map(|i| match self.params.integrator {
                Integrator::Newmark => {
                    self.u[i] + dt * self.v[i] + (0.5 - beta) * dt * dt * self.a[i]
                }
                Integrator::BackwardEuler => self.u[i] + dt * self.v[i],
            })
            .collect();
        let c = 1.0 / (beta * dt * dt);
        // the force that would stop the motion in one step: the scale near a rest point
        let momentum = norm(&mass_times(&self.mass, &self.v)) / dt;
        let mut u1 = self.u.clone();
        let mut converged = false;
        let mut last = f64::NAN;
        let mut previous = f64::INFINITY;
        for it in 0..=self.params.newton_iterations {
            let (mut res, mut trip) = residual_and_triplets(self.disc, &u1, lambda)?;
            if let Some(o) = self.obstacle {
                o.add_terms(self.disc, &u1, &mut res, Some(&mut trip));
            }
            let accel: Vec<f64> = (0..n).map(|i| c * (u1[i] - predictor[i])).collect();
            let ma = mass_times(&self.mass, &accel);
            let scale = norm(&ma)
                .max(norm(&res))
                .max(momentum)
                .max(f64::MIN_POSITIVE);
            for (r, m) in res.iter_mut().zip(&ma) {
                *r += m;
            }
            last = norm(&res) / scale;
            if !last.is_finite() {
                break;
            }
            // converged, or stalled at the rounding floor within a hundred times the tolerance
            // (the penalties' large, cancelling forces set that floor)
            if last <= self.params.tolerance
                || (last <= 100.0 * self.params.tolerance && last > 0.5 * previous)
            {
                converged = true;
                break;
            }
            previous = last;
            if it == self.params.newton_iterations {
                break;
            }
            trip.extend_from_slice(&self.mass_entries);
            let k = tangent_matrix(self.disc, &trip)?;
            self.report.newton_iterations += 1;
            newton_step(&res, &k, &mut u1, &mut self.symbolic).map_err(|e| {
                ShellError::Solver(format!(
                    "dynamics step {} (t = {:.6} s): {e}",
                    self.report.steps + 1,
                    self.time + dt
                ))
            })?;
        }
        if !converged {
            return Err(ShellError::Solver(format!(
                "dynamics step {} (t = {:.6} s): Newton did not converge in {} iterations (relative residual {last:.3e}, tolerance {:.1e}); use a smaller dt",
                self.report.steps + 1,
                self.time + dt,
                self.params.newton_iterations,
                self.params.tolerance
            )));
        }
        for i in 0..n {
            let a1 = c * (u1[i] - predictor[i]);
            self.v[i] = match self.params.integrator {
                Integrator::Newmark => self.v[i] + dt * ((1.0 - gamma) * self.a[i] + gamma * a1),
                Integrator::BackwardEuler => (u1[i] - self.u[i]) / dt,
            };
            self.a[i] = a1;
        }
        self.u = u1;
        self.time += dt;
        self.report.steps += 1;
        Ok(())
    }
}
