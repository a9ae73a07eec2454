//! Static solution: Newton's method with load stepping (the load factor raised in equal steps,
//! each step iterated to equilibrium), every linear system solved by `faer`'s sparse LU (the
//! tangent need not be definite away from equilibrium). The tangent's sparsity pattern is fixed
//! by the discretisation, so the symbolic factorisation (fill-reducing ordering, elimination
//! structure) is computed once per solve and reused by every Newton step; only the numeric
//! factorisation is redone. The linear solution is one Newton step from the rest state.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, Lu, SymbolicLlt, SymbolicLu};
use faer::sparse::SparseColMat;
use faer::{Col, Side};

use super::assembly::residual_and_tangent;
use super::discretisation::Discretisation;
use super::error::ShellError;
use crate::limits;

/// How a solve went.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SolveReport {
    /// Newton iterations per load step.
    pub iterations: Vec<usize>,
    /// Final relative residual per load step.
    pub residuals: Vec<f64>,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// One Newton update u += −K⁻¹ r from the residual `r` and tangent `k` at `u`; `symbolic` is
/// the tangent's symbolic LU, computed on the first call and reused after (the pattern does
/// not change).
pub(crate) fn newton_update(
    r: &[f64],
    k: &SparseColMat<usize, f64>,
    u: &mut [f64],
    symbolic: &mut Option<SymbolicLu<usize>>,
) -> Result<f64, ShellError> {
    if symbolic.is_none() {
        *symbolic = Some(SymbolicLu::try_new(k.symbolic()).map_err(|e| {
            ShellError::Solver(format!("symbolic LU of the tangent failed: {e:?}"))
        })?);
    }
    let sym = symbolic.clone().expect("set above");
    let lu = Lu::try_new_with_symbolic(sym, k.as_ref())
        .map_err(|e| ShellError::Solver(format!("sparse LU of the tangent failed: {e:?}")))?;
    apply_update(&lu, r, u)
}

/// u += −K⁻¹ r with a factorisation of K; the largest |Δu|. A non-finite update (a singular
/// tangent) is an error and leaves `u` unchanged.
pub(crate) fn apply_update(
    factor: &impl Solve<f64>,
    r: &[f64],
    u: &mut [f64],
) -> Result<f64, ShellError> {
    let rhs = Col::<f64>::from_fn(r.len(), |i| -r[i]);
    let du = factor.solve(&rhs);
    if !(0..u.len()).all(|i| du[i].is_finite()) {
        return Err(ShellError::Solver(
            "the tangent is singular (a rigid-body motion left free? add supports or pins)".into(),
        ));
    }
    let mut step = 0.0f64;
    for (i, x) in u.iter_mut().enumerate() {
        *x += du[i];
        step = step.max(du[i].abs());
    }
    Ok(step)
}

/// The symbolic factorisations, computed once (the pattern does not change).
#[derive(Default)]
pub(crate) struct Symbolic {
    llt: Option<SymbolicLlt<usize>>,
    lu: Option<SymbolicLu<usize>>,
}

impl Symbolic {
    /// The symbolic Cholesky of `k`'s pattern, computed on the first call.
    pub(crate) fn llt(
        &mut self,
        k: &SparseColMat<usize, f64>,
    ) -> Result<SymbolicLlt<usize>, ShellError> {
        if self.llt.is_none() {
            self.llt = Some(
                SymbolicLlt::try_new(k.symbolic(), Side::Lower).map_err(|e| {
                    ShellError::Solver(format!("symbolic Cholesky of the tangent failed: {e:?}"))
                })?,
            );
        }
        Ok(self.llt.clone().expect("set above"))
    }

    /// The symbolic LU of `k`'s pattern, computed on the first call.
    pub(crate) fn lu(
        &mut self,
        k: &SparseColMat<usize, f64>,
    ) -> Result<SymbolicLu<usize>, ShellError> {
        if self.lu.is_none() {
            self.lu = Some(SymbolicLu::try_new(k.symbolic()).map_err(|e| {
                ShellError::Solver(format!("symbolic LU of the tangent failed: {e:?}"))
            })?);
        }
        Ok(self.lu.clone().expect("set above"))
    }
}

/// One Newton update u −= K⁻¹ r: Cholesky (half the work of LU) while K is positive
/// definite, which the inertia term makes it at small steps; LU when it is not.
pub(crate) fn newton_step(
    r: &[f64],
    k: &SparseColMat<usize, f64>,
    u: &mut [f64],
    symbolic: &mut Symbolic,
) -> Result<(), ShellError> {
    match Llt::try_new_with_symbolic(symbolic.llt(k)?, k.as_ref(), Side::Lower) {
        Ok(llt) => apply_update(&llt, r, u).map(|_| ()),
        Err(_) => newton_update(r, k, u, &mut symbolic.lu).map(|_| ()),
    }
}

/// The linear (small-displacement) solution under the full load: one Newton step from rest.
pub fn solve_linear(disc: &Discretisation) -> Result<Vec<f64>, ShellError> {
    let mut u = vec![0.0; 3 * disc.len()];
    let (r, k) = residual_and_tangent(disc, &u, 1.0)?;
    newton_update(&r, &k, &mut u, &mut None)?;
    Ok(u)
}

/// Newton with load stepping from `u` (the rest state if empty) to load factor `to`, in
/// `disc.params.load_steps` equal steps from `from`. `on_step(load factor, u)` is called after
/// each converged step. A step that does not converge is an error naming it.
pub fn solve_static(
    disc: &Discretisation,
    u: &mut Vec<f64>,
    from: f64,
    to: f64,
    on_step: &mut dyn FnMut(f64, &[f64]),
) -> Result<SolveReport, ShellError> {
    let n = 3 * disc.len();
    if u.len() != n {
        *u = vec![0.0; n];
    }
    let p = disc.params;
    // the residual at rest under the full load is minus the load vector
    let f_norm = disc.external_load_norm().max(f64::MIN_POSITIVE);
    let mut report = SolveReport::default();
    let mut symbolic = None;
    for s in 1..=p.load_steps {
        let lambda = from + (to - from) * s as f64 / p.load_steps as f64;
        let mut it = 0;
        loop {
            limits::check_cancelled().map_err(ShellError::Solver)?;
            // the residual and tangent together: one pass over the quadrature points per
            // iteration (the tangent of the converged state is the only one not used)
            let (res, k) = residual_and_tangent(disc, u, lambda)?;
            let r = norm(&res) / (f_norm * lambda.abs().max(1e-300));
            if r <= p.tolerance {
                report.iterations.push(it);
                report.residuals.push(r);
                break;
            }
            if it >= p.max_iterations {
                return Err(ShellError::Solver(format!(
                    "Newton did not converge at load step {s} of {} (load factor {lambda:.4}): relative residual {r:.3e} after {it} iterations (tolerance {:.1e}; use more load_steps)",
                    p.load_steps, p.tolerance
                )));
            }
            newton_update(&res, &k, u, &mut symbolic)?;
            it += 1;
        }
        on_step(lambda, u);
    }
    Ok(report)
}
