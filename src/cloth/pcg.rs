//! Baraff & Witkin's modified preconditioned conjugate gradient: solves `A Δv = b` on the
//! free directions (filter S) while the constrained directions take the prescribed velocity
//! change z. Block-Jacobi preconditioned, fused deterministic parallel passes, no allocation.

use rayon::prelude::*;

use super::bcsr::Bcsr3;
use super::constraints::Filter;
use super::parallel::{chunks, ordered_sum, CHUNK};
use crate::geometry::{Mat3, Vec3};

/// Scratch vectors of the solver, allocated once per topology.
#[derive(Debug, Clone, Default)]
pub struct PcgWorkspace {
    r: Vec<Vec3>,
    c: Vec<Vec3>,
    q: Vec<Vec3>,
    s: Vec<Vec3>,
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
    /// Whether `residual ≤ tolerance`.
    pub converged: bool,
}

impl PcgWorkspace {
    /// Scratch for `n` particles.
    pub fn new(n: usize) -> Self {
        let z = vec![Vec3::zeros(); n];
        let nc = chunks(n.max(1), CHUNK);
        PcgWorkspace { r: z.clone(), c: z.clone(), q: z.clone(), s: z, p1: vec![0.0; nc], p2: vec![0.0; nc] }
    }

    /// Solves for `dv`. On entry `dv` holds the initial guess for the free directions (e.g. the
    /// previous step's solution); `z` the prescribed change in constrained directions.
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &mut self,
        a: &Bcsr3,
        b: &[Vec3],
        pinv: &[Mat3],
        filter: &Filter,
        z: &[Vec3],
        dv: &mut [Vec3],
        tolerance: f64,
        max_iterations: u32,
    ) -> PcgResult {
        let n = b.len();
        let nc = chunks(n, CHUNK);
        let (r, c, q, s) = (&mut self.r, &mut self.c, &mut self.q, &mut self.s);
        let (p1, p2) = (&mut self.p1[..nc], &mut self.p2[..nc]);
        // Δv = S Δv0 + z
        dv.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, d)| {
            for k in 0..d.len() {
                let i = ci * CHUNK + k;
                d[k] = filter.apply(i, d[k]) + z[i];
            }
        });
        // denominator: ‖S(b − A z)‖²; q = A z as scratch
        if filter.any {
            a.mul_vec(z, q);
        } else {
            q.fill(Vec3::zeros());
        }
        p1.par_iter_mut().enumerate().for_each(|(ci, p)| {
            let mut acc = 0.0;
            for i in ci * CHUNK..((ci + 1) * CHUNK).min(n) {
                acc += filter.apply(i, b[i] - q[i]).norm_squared();
            }
            *p = acc;
        });
        let bnorm2 = ordered_sum(p1);
        // r = S(b − A Δv), c = S P⁻¹ r, δ = r·c, ρ = r·r
        let dvr: &[Vec3] = dv;
        r.par_chunks_mut(CHUNK)
            .zip(c.par_chunks_mut(CHUNK))
            .zip(p1.par_iter_mut().zip(p2.par_iter_mut()))
            .enumerate()
            .for_each(|(ci, ((rs, cs), (pd, pr)))| {
                let (mut d, mut rr) = (0.0, 0.0);
                for k in 0..rs.len() {
                    let i = ci * CHUNK + k;
                    let ri = filter.apply(i, b[i] - a.row_times(i, dvr));
                    let ci_ = filter.apply(i, pinv[i] * ri);
                    d += ri.dot(&ci_);
                    rr += ri.norm_squared();
                    rs[k] = ri;
                    cs[k] = ci_;
                }
                *pd = d;
                *pr = rr;
            });
        let mut delta = ordered_sum(p1);
        let mut rr = ordered_sum(p2);
        let target = tolerance * tolerance * bnorm2;
        let mut it = 0;
        while rr > target && it < max_iterations && delta > 0.0 {
            // q = S A c, cq = c·q
            let cr: &[Vec3] = c;
            q.par_chunks_mut(CHUNK).zip(p1.par_iter_mut()).enumerate().for_each(|(ci, (qs, p))| {
                let mut acc = 0.0;
                for k in 0..qs.len() {
                    let i = ci * CHUNK + k;
                    let qi = filter.apply(i, a.row_times(i, cr));
                    acc += cr[i].dot(&qi);
                    qs[k] = qi;
                }
                *p = acc;
            });
            let cq = ordered_sum(p1);
            if cq <= 0.0 {
                break;
            }
            let alpha = delta / cq;
            // Δv += α c; r −= α q; s = P⁻¹ r; δ' = r·s; ρ = r·r
            dv.par_chunks_mut(CHUNK)
                .zip(r.par_chunks_mut(CHUNK))
                .zip(s.par_chunks_mut(CHUNK))
                .zip(p1.par_iter_mut().zip(p2.par_iter_mut()))
                .enumerate()
                .for_each(|(ci, (((ds, rs), ss), (pd, pr)))| {
                    let (mut d, mut rrl) = (0.0, 0.0);
                    for k in 0..ds.len() {
                        let i = ci * CHUNK + k;
                        ds[k] += cr[i] * alpha;
                        let ri = rs[k] - q[i] * alpha;
                        rs[k] = ri;
                        let si = pinv[i] * ri;
                        ss[k] = si;
                        d += ri.dot(&si);
                        rrl += ri.norm_squared();
                    }
                    *pd = d;
                    *pr = rrl;
                });
            let dnew = ordered_sum(p1);
            rr = ordered_sum(p2);
            let beta = dnew / delta;
            delta = dnew;
            let sr: &[Vec3] = s;
            c.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, cs)| {
                for k in 0..cs.len() {
                    let i = ci * CHUNK + k;
                    cs[k] = filter.apply(i, sr[i] + cs[k] * beta);
                }
            });
            it += 1;
        }
        let residual = if bnorm2 > 0.0 { (rr / bnorm2).sqrt() } else { 0.0 };
        PcgResult { iterations: it, residual, converged: rr <= target }
    }
}
