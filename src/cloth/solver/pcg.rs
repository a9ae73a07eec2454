//! Baraff & Witkin's modified preconditioned conjugate gradient: solves `A Δv = b` on the
//! free directions (filter S) while the constrained directions take the prescribed velocity
//! change z. Block-Jacobi preconditioned, fused deterministic parallel passes, no allocation.

use rayon::prelude::*;

use super::amg::AggregationMultigrid;
use super::bcsr::Bcsr3;
use super::multigrid::Multigrid;
use super::parallel::{chunks, ordered_sum, CHUNK};
use super::simd::multiversion;
use crate::cloth::constraints::Filter;
use crate::geometry::{Mat3, Vec3};

/// Scratch vectors of the solver, allocated once per topology.
#[derive(Debug, Clone, Default)]
pub struct PcgWorkspace {
    r: Vec<Vec3>,
    c: Vec<Vec3>,
    q: Vec<Vec3>,
    s: Vec<Vec3>,
    s_old: Vec<Vec3>,
    p1: Vec<f64>,
    p2: Vec<f64>,
}

/// Outcome of a solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PcgResult {
    /// Iterations performed.
    pub iterations: u32,
    /// Final relative residual ‖S(b − AΔv)‖ / ‖S(b − Az)‖.
    pub residual: f64,
    /// Whether `residual ≤ tolerance`, as the recurrence of the iteration sees it (the step
    /// checks the true residual, see [`PcgWorkspace::true_residual`]).
    pub converged: bool,
    /// The norm of the right-hand side the residual is relative to, ‖S(b − Az)‖ (infinite or
    /// NaN when the system overflowed).
    pub rhs_norm: f64,
}

impl PcgWorkspace {
    /// Scratch for `n` particles.
    pub fn new(n: usize) -> Self {
        let z = vec![Vec3::zeros(); n];
        let nc = chunks(n.max(1), CHUNK);
        PcgWorkspace {
            r: z.clone(),
            c: z.clone(),
            q: z.clone(),
            s: z.clone(),
            s_old: z,
            p1: vec![0.0; nc],
            p2: vec![0.0; nc],
        }
    }

    /// Solves for `dv`. On entry `dv` holds the initial guess for the free directions (e.g. the
    /// previous step's solution); `z` the prescribed change in constrained directions. The
    /// direction update uses the Polak–Ribière β, so a variable preconditioner is safe.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &mut self,
        a: &Bcsr3,
        b: &[Vec3],
        precond: &mut Preconditioner,
        filter: &Filter,
        z: &[Vec3],
        dv: &mut [Vec3],
        tolerance: f64,
        max_iterations: u32,
    ) -> PcgResult {
        let n = b.len();
        let nc = chunks(n, CHUNK);
        let (r, c, q, s, s_old) = (
            &mut self.r,
            &mut self.c,
            &mut self.q,
            &mut self.s,
            &mut self.s_old,
        );
        let (p1, p2) = (&mut self.p1[..nc], &mut self.p2[..nc]);
        // Δv = S Δv0 + z
        dv.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, d)| {
            for k in 0..d.len() {
                let i = ci * CHUNK + k;
                d[k] = filter.apply(i, d[k]) + z[i];
            }
        });
        // denominator: ‖S(b − A z)‖²; q = A z as scratch
        // z is non-zero only at constrained particles: A z = Σ_i A_{·i} z_i = Σ_i A_{i·}ᵀ z_i
        q.fill(Vec3::zeros());
        if filter.any {
            for (i, zi) in z.iter().enumerate() {
                if *zi != Vec3::zeros() {
                    for k in a.row_ptr[i]..a.row_ptr[i + 1] {
                        q[a.cols[k] as usize] += a.block(k).transpose() * zi;
                    }
                }
            }
        }
        p1.par_iter_mut().enumerate().for_each(|(ci, p)| {
            let mut acc = 0.0;
            for i in ci * CHUNK..((ci + 1) * CHUNK).min(n) {
                acc += filter.apply(i, b[i] - q[i]).norm_squared();
            }
            *p = acc;
        });
        let bnorm2 = ordered_sum(p1);
        // r = S(b − A Δv), ρ = r·r
        let dvr: &[Vec3] = dv;
        filtered_residual(a, filter, b, dvr, r, p2);
        let mut rr = ordered_sum(p2);
        let target = tolerance * tolerance * bnorm2;
        let mut it = 0;
        if rr > target && max_iterations > 0 {
            precond.apply(a, r, s);
            let (delta, _) = dots(r, s, s_old, filter, c, 0.0, p1, p2, false);
            let mut delta = delta;
            while rr > target && it < max_iterations && delta > 0.0 {
                // q = S A c, cq = c·q
                let cr: &[Vec3] = c;
                filtered_product(a, filter, cr, q, p1);
                let cq = ordered_sum(p1);
                if cq <= 0.0 {
                    break;
                }
                let alpha = delta / cq;
                // Δv += α c; r −= α q; ρ = r·r
                dv.par_chunks_mut(CHUNK)
                    .zip(r.par_chunks_mut(CHUNK))
                    .zip(p2.par_iter_mut())
                    .enumerate()
                    .for_each(|(ci, ((ds, rs), pr))| {
                        let mut rrl = 0.0;
                        for k in 0..ds.len() {
                            let i = ci * CHUNK + k;
                            ds[k] += cr[i] * alpha;
                            let ri = rs[k] - q[i] * alpha;
                            rs[k] = ri;
                            rrl += ri.norm_squared();
                        }
                        *pr = rrl;
                    });
                rr = ordered_sum(p2);
                it += 1;
                if rr <= target {
                    break;
                }
                std::mem::swap(s, s_old);
                precond.apply(a, r, s);
                let (dnew, beta) = dots(r, s, s_old, filter, c, delta, p1, p2, true);
                let _ = beta;
                delta = dnew;
            }
        }
        let residual = if bnorm2 > 0.0 {
            (rr / bnorm2).sqrt()
        } else {
            0.0
        };
        PcgResult {
            iterations: it,
            residual,
            converged: rr <= target,
            rhs_norm: bnorm2.sqrt(),
        }
    }

    /// The true residual of `dv`, recomputed from the matrix rather than carried by the
    /// iteration's recurrence (one product with `a`): stores `b − A dv` (unfiltered: in the
    /// constrained directions it is minus the constraint impulse) for [`Self::residual`] and
    /// returns `‖S(b − A dv)‖`, summed in a fixed order (deterministic). NaN or infinite when
    /// the system holds a non-finite or overflowing value.
    pub fn true_residual(&mut self, a: &Bcsr3, b: &[Vec3], filter: &Filter, dv: &[Vec3]) -> f64 {
        let nc = chunks(b.len(), CHUNK);
        let p = &mut self.p2[..nc];
        unfiltered_residual(a, filter, b, dv, &mut self.r, p);
        ordered_sum(p).sqrt()
    }

    /// `b − A dv` of the last [`Self::true_residual`].
    pub fn residual(&self) -> &[Vec3] {
        &self.r
    }
}

multiversion! {
    /// `r = b − A x` and, per chunk of rows, `Σ ‖S r_i‖²` into `p`.
    fn unfiltered_residual(
        a: &Bcsr3,
        filter: &Filter,
        b: &[Vec3],
        x: &[Vec3],
        r: &mut [Vec3],
        p: &mut [f64],
    ) {
        r.par_chunks_mut(CHUNK)
            .zip(p.par_iter_mut())
            .enumerate()
            .for_each(|(ci, (rs, pr))| {
                let mut rr = 0.0;
                for k in 0..rs.len() {
                    let i = ci * CHUNK + k;
                    let ri = b[i] - a.row_times_any(i, x);
                    rr += filter.apply(i, ri).norm_squared();
                    rs[k] = ri;
                }
                *pr = rr;
            });
    }
}

multiversion! {
    /// `r = S(b − A x)` and, per chunk of rows, `Σ ‖r_i‖²` into `p2`.
    fn filtered_residual(
        a: &Bcsr3,
        filter: &Filter,
        b: &[Vec3],
        x: &[Vec3],
        r: &mut [Vec3],
        p2: &mut [f64],
    ) {
        r.par_chunks_mut(CHUNK)
            .zip(p2.par_iter_mut())
            .enumerate()
            .for_each(|(ci, (rs, pr))| {
                let mut rr = 0.0;
                for k in 0..rs.len() {
                    let i = ci * CHUNK + k;
                    let ri = filter.apply(i, b[i] - a.row_times_any(i, x));
                    rr += ri.norm_squared();
                    rs[k] = ri;
                }
                *pr = rr;
            });
    }
}

multiversion! {
    /// `q = S A c` and, per chunk of rows, `Σ c_i · q_i` into `p1`.
    fn filtered_product(a: &Bcsr3, filter: &Filter, c: &[Vec3], q: &mut [Vec3], p1: &mut [f64]) {
        q.par_chunks_mut(CHUNK)
            .zip(p1.par_iter_mut())
            .enumerate()
            .for_each(|(ci, (qs, p))| {
                let mut acc = 0.0;
                for k in 0..qs.len() {
                    let i = ci * CHUNK + k;
                    let qi = filter.apply(i, a.row_times_any(i, c));
                    acc += c[i].dot(&qi);
                    qs[k] = qi;
                }
                *p = acc;
            });
    }
}

/// How the residual is preconditioned.
#[derive(Debug)]
pub enum Preconditioner<'a> {
    /// Inverse 3×3 diagonal blocks.
    BlockJacobi(&'a [Mat3]),
    /// One multigrid V-cycle.
    Multigrid(&'a mut Multigrid),
    /// One aggregation multigrid V-cycle.
    Aggregation(&'a mut AggregationMultigrid),
}

impl Preconditioner<'_> {
    /// s = P⁻¹ r.
    pub fn apply(&mut self, a: &Bcsr3, r: &[Vec3], s: &mut [Vec3]) {
        match self {
            Preconditioner::BlockJacobi(pinv) => {
                s.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, ss)| {
                    for k in 0..ss.len() {
                        let i = ci * CHUNK + k;
                        ss[k] = pinv[i] * r[i];
                    }
                });
            }
            Preconditioner::Multigrid(mg) => mg.apply(a, r, s),
            Preconditioner::Aggregation(mg) => mg.apply(a, r, s),
        }
    }
}

/// δ = r·s and, when `update`, the Polak–Ribière direction c = S(s + β c) with
/// β = (r·s − r·s_old)/δ_old; otherwise c = S s. Returns (δ, β).
#[allow(clippy::too_many_arguments)]
fn dots(
    r: &[Vec3],
    s: &[Vec3],
    s_old: &[Vec3],
    filter: &Filter,
    c: &mut [Vec3],
    delta_old: f64,
    p1: &mut [f64],
    p2: &mut [f64],
    update: bool,
) -> (f64, f64) {
    let n = r.len();
    p1.par_iter_mut()
        .zip(p2.par_iter_mut())
        .enumerate()
        .for_each(|(ci, (a, b))| {
            let (mut x, mut y) = (0.0, 0.0);
            for i in ci * CHUNK..((ci + 1) * CHUNK).min(n) {
                x += r[i].dot(&s[i]);
                if update {
                    y += r[i].dot(&s_old[i]);
                }
            }
            *a = x;
            *b = y;
        });
    let dnew = ordered_sum(p1);
    let beta = if update {
        ((dnew - ordered_sum(p2)) / delta_old).max(0.0)
    } else {
        0.0
    };
    c.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, cs)| {
        for k in 0..cs.len() {
            let i = ci * CHUNK + k;
            cs[k] = filter.apply(i, s[i] + cs[k] * beta);
        }
    });
    (dnew, beta)
}
