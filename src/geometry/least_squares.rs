//! The one damped Gauss–Newton (Levenberg–Marquardt) solver of the crate.
//!
//! Two levels:
//!
//! - [`Damping`]: the damped step itself. Given the normal equations `A δ = −g` (`A = JᵀJ`, or
//!   any symmetric positive semi-definite approximation such as an IRLS-weighted one), it adds
//!   the damping to `A`'s diagonal ([`DiagonalDamping`]), solves by Cholesky, and moves the
//!   damping factor `λ` after an accepted or rejected step ([`DampingUpdate`]: fixed factors,
//!   or Nielsen's gain-ratio rule). [`Damping::try_steps`] runs the usual "try steps, raising
//!   `λ`, until one lowers the cost" loop; callers with their own loop use [`Damping::solve`],
//!   [`Damping::accept`] and [`Damping::reject`].
//! - [`minimize`]: the whole Levenberg–Marquardt iteration for a [`LeastSquares`] problem
//!   (residuals, Jacobian, how a step moves the state), with the cost `½ ‖r‖²` and the
//!   schedule ([`Schedule`]: iterations, damping, tries per iteration, when an accepted step
//!   still counts as progress) as parameters. [`ForwardDifferences`] makes a problem out of a
//!   residual closure and a step closure with a forward-difference Jacobian.
//!
//! The callers (face view fitting, puppet pre-positioning, camera calibration, the face
//! tracker's pose and FAP polish) each keep the damping rules they were tuned with; the
//! arithmetic of each rule is exactly that of the solver it replaced.

use nalgebra::allocator::Allocator;
use nalgebra::{DMatrix, DVector, DefaultAllocator, Dim, OMatrix, OVector};

/// How the damping term is added to the diagonal of the normal matrix `A`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DiagonalDamping {
    /// `A_kk + λ (A_kk + floor)`.
    Shifted {
        /// Added to each diagonal entry before scaling by `λ`.
        floor: f64,
    },
    /// `A_kk + λ (A_kk + relative · s)` with `s = max(max_k A_kk, 1e-300)`.
    ShiftedRelative {
        /// The shift as a fraction of the largest diagonal entry.
        relative: f64,
    },
    /// `A_kk + (λ max(A_kk, floor) + extra)` (Marquardt's scaling with a floor).
    Clamped {
        /// Smallest diagonal entry used for the scaling.
        floor: f64,
        /// Absolute term added to the damping.
        extra: f64,
    },
}

/// How the damping factor `λ` moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DampingUpdate {
    /// Accepted step: `λ ← max(λ / down, min)`; rejected step: `λ ← λ · up`; `A + damping` not
    /// positive definite: `λ ← λ · singular`.
    Factors {
        /// Divisor after an accepted step.
        down: f64,
        /// Smallest `λ`.
        min: f64,
        /// Factor after a rejected step.
        up: f64,
        /// Factor after a failed Cholesky factorisation.
        singular: f64,
    },
    /// Nielsen's rule: an accepted step of gain ratio `ρ` (actual over predicted cost
    /// reduction) gives `λ ← λ · max(1/3, 1 − (2ρ − 1)³)` and `ν ← 2`; a rejected step or a
    /// failed factorisation gives `λ ← λ ν`, `ν ← 2ν`.
    Nielsen,
}

/// How many damped steps one iteration tries before giving up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tries {
    /// At most this many (failed factorisations included).
    Count(usize),
    /// As long as `λ` is below this.
    WhileBelow(f64),
}

/// The outcome of trying one damped step (see [`Damping::try_steps`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Attempt {
    /// The step lowered the cost and was kept; the gain ratio is used by
    /// [`DampingUpdate::Nielsen`] only.
    Accepted {
        /// Actual over predicted reduction of the cost.
        gain_ratio: f64,
    },
    /// The step did not lower the cost; the caller has restored its state.
    Rejected,
}

/// The damping state: `λ`, Nielsen's `ν`, and the rules of [`DiagonalDamping`] and
/// [`DampingUpdate`].
#[derive(Debug, Clone, PartialEq)]
pub struct Damping {
    /// The current damping factor `λ`.
    pub lambda: f64,
    /// Nielsen's growth factor (2 after an accepted step).
    nu: f64,
    /// How `λ` enters the diagonal.
    pub diagonal: DiagonalDamping,
    /// How `λ` moves.
    pub update: DampingUpdate,
}

impl Damping {
    /// Damping starting at `lambda`.
    pub fn new(lambda: f64, diagonal: DiagonalDamping, update: DampingUpdate) -> Damping {
        Damping {
            lambda,
            nu: 2.0,
            diagonal,
            update,
        }
    }

    /// Solves `(A + damping) δ = −g` by Cholesky. `None` when the damped matrix is not
    /// positive definite; `λ` has then been raised (see [`DampingUpdate`]).
    pub fn solve<D: Dim>(
        &mut self,
        a: &OMatrix<f64, D, D>,
        g: &OVector<f64, D>,
    ) -> Option<OVector<f64, D>>
    where
        DefaultAllocator: Allocator<D, D> + Allocator<D>,
    {
        let n = a.nrows();
        let mut damped = a.clone();
        let lambda = self.lambda;
        match self.diagonal {
            DiagonalDamping::Shifted { floor } => {
                for k in 0..n {
                    damped[(k, k)] += lambda * (a[(k, k)] + floor);
                }
            }
            DiagonalDamping::ShiftedRelative { relative } => {
                let scale = a.diagonal().max().max(1e-300);
                for k in 0..n {
                    damped[(k, k)] += lambda * (a[(k, k)] + relative * scale);
                }
            }
            DiagonalDamping::Clamped { floor, extra } => {
                for k in 0..n {
                    damped[(k, k)] += lambda * a[(k, k)].max(floor) + extra;
                }
            }
        }
        match damped.cholesky() {
            Some(c) => Some(c.solve(&(-g))),
            None => {
                self.singular();
                None
            }
        }
    }

    /// Moves `λ` after an accepted step of gain ratio `gain_ratio`.
    pub fn accept(&mut self, gain_ratio: f64) {
        match self.update {
            DampingUpdate::Factors { down, min, .. } => {
                self.lambda = (self.lambda / down).max(min);
            }
            DampingUpdate::Nielsen => {
                self.lambda *= (1.0f64 / 3.0).max(1.0 - (2.0 * gain_ratio - 1.0).powi(3));
                self.nu = 2.0;
            }
        }
    }

    /// Moves `λ` after a rejected step.
    pub fn reject(&mut self) {
        match self.update {
            DampingUpdate::Factors { up, .. } => self.lambda *= up,
            DampingUpdate::Nielsen => self.grow(),
        }
    }

    fn singular(&mut self) {
        match self.update {
            DampingUpdate::Factors { singular, .. } => self.lambda *= singular,
            DampingUpdate::Nielsen => self.grow(),
        }
    }

    fn grow(&mut self) {
        self.lambda *= self.nu;
        self.nu *= 2.0;
    }

    /// Tries damped steps of `A δ = −g` until `attempt(δ)` accepts one (true) or `tries` runs
    /// out (false), moving `λ` after each.
    pub fn try_steps<D: Dim>(
        &mut self,
        a: &OMatrix<f64, D, D>,
        g: &OVector<f64, D>,
        tries: Tries,
        mut attempt: impl FnMut(&OVector<f64, D>) -> Attempt,
    ) -> bool
    where
        DefaultAllocator: Allocator<D, D> + Allocator<D>,
    {
        let mut count = 0;
        loop {
            match tries {
                Tries::Count(n) if count >= n => return false,
                Tries::WhileBelow(max) if self.lambda >= max || self.lambda.is_nan() => {
                    return false
                }
                _ => {}
            }
            count += 1;
            let Some(delta) = self.solve(a, g) else {
                continue;
            };
            match attempt(&delta) {
                Attempt::Accepted { gain_ratio } => {
                    self.accept(gain_ratio);
                    return true;
                }
                Attempt::Rejected => self.reject(),
            }
        }
    }
}

/// A nonlinear least-squares problem for [`minimize`]: residuals, their Jacobian, and how a
/// step moves the state.
pub trait LeastSquares {
    /// What is optimised.
    type State: Clone;
    /// Number of parameters (columns of the Jacobian).
    fn parameter_count(&self) -> usize;
    /// The residuals of `state` into `out` (resized when its length is wrong).
    fn residuals(&mut self, state: &Self::State, out: &mut DVector<f64>);
    /// The Jacobian of the residuals at `state` (whose residuals are `r`) into `jac`
    /// (`r.len()` × [`parameter_count`](Self::parameter_count)).
    fn jacobian(&mut self, state: &Self::State, r: &DVector<f64>, jac: &mut DMatrix<f64>);
    /// `state` moved by the step `delta`.
    fn step(&mut self, state: &Self::State, delta: &DVector<f64>) -> Self::State;
}

/// The schedule of [`minimize`].
#[derive(Debug, Clone, Copy)]
pub struct Schedule {
    /// Most iterations (Jacobian evaluations).
    pub iterations: usize,
    /// Starting damping and its rules.
    pub damping: (f64, DiagonalDamping, DampingUpdate),
    /// Damped steps tried per iteration.
    pub tries: Tries,
    /// Whether an accepted step from cost `old` to `new` (both `½ ‖r‖²`) is progress enough
    /// to go on; the iteration stops after the first one that is not.
    pub progress: fn(old: f64, new: f64) -> bool,
}

/// The result of [`minimize`].
#[derive(Debug, Clone)]
pub struct Minimum<S> {
    /// The best state found.
    pub state: S,
    /// Its cost `½ ‖r‖²`.
    pub cost: f64,
    /// Iterations done.
    pub iterations: usize,
}

/// Levenberg–Marquardt from `start`: per iteration the Jacobian `J` at the current state, the
/// normal equations `JᵀJ δ = −Jᵀr`, then damped steps ([`Damping::try_steps`]) until one lowers
/// the cost `½ ‖r‖²`; stops after `schedule.iterations`, when no step lowers the cost, or when
/// the accepted step fails `schedule.progress`.
pub fn minimize<P: LeastSquares>(
    problem: &mut P,
    start: P::State,
    schedule: &Schedule,
) -> Minimum<P::State> {
    let np = problem.parameter_count();
    let mut state = start;
    let mut r = DVector::zeros(0);
    problem.residuals(&state, &mut r);
    let mut cost = 0.5 * r.norm_squared();
    let (lambda, diagonal, update) = schedule.damping;
    let mut damping = Damping::new(lambda, diagonal, update);
    let mut jac = DMatrix::zeros(r.len(), np);
    let mut rc = DVector::zeros(r.len());
    let mut done = 0;
    for it in 0..schedule.iterations {
        done = it + 1;
        if jac.nrows() != r.len() {
            jac = DMatrix::zeros(r.len(), np);
        }
        problem.jacobian(&state, &r, &mut jac);
        let a = jac.tr_mul(&jac);
        let g = jac.tr_mul(&r);
        let mut progress = false;
        damping.try_steps(&a, &g, schedule.tries, |delta| {
            let cand = problem.step(&state, delta);
            problem.residuals(&cand, &mut rc);
            let cc = 0.5 * rc.norm_squared();
            if cc < cost {
                progress = (schedule.progress)(cost, cc);
                state = cand;
                std::mem::swap(&mut r, &mut rc);
                cost = cc;
                Attempt::Accepted { gain_ratio: 1.0 }
            } else {
                Attempt::Rejected
            }
        });
        if !progress {
            break;
        }
    }
    Minimum {
        state,
        cost,
        iterations: done,
    }
}

/// A [`LeastSquares`] problem from closures: `residual(state)` and `apply(state, delta)`, with
/// a forward-difference Jacobian of step `steps[k]` for parameter `k` (column `k` is
/// `(r(apply(state, h_k e_k)) − r(state)) / h_k`).
pub struct ForwardDifferences<'a, S> {
    /// Difference step per parameter.
    pub steps: &'a [f64],
    /// The state moved by a parameter step.
    pub apply: &'a dyn Fn(&S, &[f64]) -> S,
    /// The residuals of a state.
    pub residual: &'a dyn Fn(&S) -> Vec<f64>,
}

impl<S: Clone> LeastSquares for ForwardDifferences<'_, S> {
    type State = S;

    fn parameter_count(&self) -> usize {
        self.steps.len()
    }

    fn residuals(&mut self, state: &S, out: &mut DVector<f64>) {
        *out = DVector::from_vec((self.residual)(state));
    }

    fn jacobian(&mut self, state: &S, r: &DVector<f64>, jac: &mut DMatrix<f64>) {
        let mut delta = vec![0.0; self.steps.len()];
        for (k, &h) in self.steps.iter().enumerate() {
            delta.iter_mut().for_each(|d| *d = 0.0);
            delta[k] = h;
            let rk = (self.residual)(&(self.apply)(state, &delta));
            for i in 0..r.len() {
                jac[(i, k)] = (rk[i] - r[i]) / h;
            }
        }
    }

    fn step(&mut self, state: &S, delta: &DVector<f64>) -> S {
        (self.apply)(state, delta.as_slice())
    }
}

/// Forward-difference Jacobian columns over a parameter vector with upper bounds, for problems
/// that evaluate their residuals themselves: parameter `k` moves by `1e-6`, or by `−1e-6` where
/// that would pass its upper bound, and the column is `(r(p + h e_k) − r(p)) / h`. Holds the
/// scratch (the moved vector, its residuals, the column) so a Jacobian allocates once.
pub struct BoundedDifferences {
    moved: Vec<f64>,
    moved_residuals: DVector<f64>,
    column: DVector<f64>,
}

impl BoundedDifferences {
    /// The difference step (before the sign for the upper bound).
    pub const STEP: f64 = 1e-6;

    /// Scratch for `rows` residuals.
    pub fn new(rows: usize) -> BoundedDifferences {
        BoundedDifferences {
            moved: Vec::new(),
            moved_residuals: DVector::zeros(rows),
            column: DVector::zeros(rows),
        }
    }

    /// The column of parameter `k` of `p` (upper bound `hi`), `r` being the residuals at `p` and
    /// `residuals` the problem's residual function.
    pub fn column(
        &mut self,
        p: &[f64],
        k: usize,
        hi: f64,
        r: &DVector<f64>,
        mut residuals: impl FnMut(&Vec<f64>, &mut DVector<f64>),
    ) -> &DVector<f64> {
        self.moved.clear();
        self.moved.extend_from_slice(p);
        let h = if p[k] + Self::STEP > hi {
            -Self::STEP
        } else {
            Self::STEP
        };
        self.moved[k] += h;
        residuals(&self.moved, &mut self.moved_residuals);
        self.column.copy_from(&self.moved_residuals);
        self.column -= r;
        self.column /= h;
        &self.column
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock as residuals `(1 − x, 10 (y − x²))`.
    fn rosenbrock(update: DampingUpdate, diagonal: DiagonalDamping) -> Minimum<Vec<f64>> {
        let residual = |s: &Vec<f64>| vec![1.0 - s[0], 10.0 * (s[1] - s[0] * s[0])];
        let apply = |s: &Vec<f64>, d: &[f64]| vec![s[0] + d[0], s[1] + d[1]];
        let mut problem = ForwardDifferences {
            steps: &[1e-7, 1e-7],
            apply: &apply,
            residual: &residual,
        };
        let schedule = Schedule {
            iterations: 200,
            damping: (1e-3, diagonal, update),
            tries: Tries::WhileBelow(1e12),
            progress: |old, new| (old - new) / old.max(1e-300) > 1e-14,
        };
        minimize(&mut problem, vec![-1.2, 1.0], &schedule)
    }

    #[test]
    fn every_rule_finds_the_rosenbrock_minimum() {
        let factors = DampingUpdate::Factors {
            down: 3.0,
            min: 1e-12,
            up: 4.0,
            singular: 10.0,
        };
        for (update, diagonal) in [
            (factors, DiagonalDamping::ShiftedRelative { relative: 1e-9 }),
            (factors, DiagonalDamping::Shifted { floor: 1e-6 }),
            (
                DampingUpdate::Nielsen,
                DiagonalDamping::Clamped {
                    floor: 1e-12,
                    extra: 0.0,
                },
            ),
        ] {
            let m = rosenbrock(update, diagonal);
            assert!(
                (m.state[0] - 1.0).abs() < 1e-5 && (m.state[1] - 1.0).abs() < 1e-5,
                "{update:?} {diagonal:?}: {:?}",
                m.state
            );
            assert!(m.cost < 1e-10 && m.iterations < 200);
        }
    }

    #[test]
    fn tries_stop_and_lambda_moves() {
        let mut d = Damping::new(
            1.0,
            DiagonalDamping::Shifted { floor: 0.0 },
            DampingUpdate::Factors {
                down: 3.0,
                min: 0.5,
                up: 4.0,
                singular: 10.0,
            },
        );
        let a = nalgebra::Matrix2::new(2.0, 0.0, 0.0, 2.0);
        let g = nalgebra::Vector2::new(-4.0, 0.0);
        let mut seen = Vec::new();
        let ok = d.try_steps(&a, &g, Tries::Count(3), |delta| {
            seen.push(delta[0]);
            Attempt::Rejected
        });
        assert!(!ok);
        // λ = 1, 4, 16: δ = 4 / (2 + 2λ)
        assert_eq!(seen.len(), 3);
        for (d, e) in seen.iter().zip([1.0, 0.4, 4.0 / 34.0]) {
            assert!((d - e).abs() < 1e-15, "{seen:?}");
        }
        assert_eq!(d.lambda, 64.0);
        assert!(d.try_steps(&a, &g, Tries::Count(1), |_| Attempt::Accepted {
            gain_ratio: 1.0
        }));
        assert_eq!(d.lambda, 64.0 / 3.0);
        // a matrix no damping makes positive definite raises λ by the singular factor
        let neg = nalgebra::Matrix2::new(-1.0, 0.0, 0.0, -1.0);
        assert!(d.solve(&neg, &g).is_none());
        assert_eq!(d.lambda, 64.0 / 3.0 * 10.0);
        let mut n = Damping::new(
            1.0,
            DiagonalDamping::Shifted { floor: 0.0 },
            DampingUpdate::Nielsen,
        );
        n.reject();
        n.reject();
        assert_eq!(n.lambda, 8.0);
        n.accept(0.5);
        assert_eq!(n.lambda, 8.0);
        n.reject();
        assert_eq!(n.lambda, 16.0);
    }
}
