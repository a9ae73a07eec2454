//! Aggregation multigrid preconditioner for cloths of any mesh (garments). The particles are
//! grouped into aggregates along the mesh edges (see [`super::aggregation`]), level after
//! level; the transfer is the piecewise-constant one smoothed by a damped Jacobi step of the
//! graph Laplacian (smoothed aggregation, fixed per topology); each coarse operator is the
//! Galerkin product Pᵀ A P, refilled every step from the implicit matrix through precomputed
//! gather lists. Block Gauss–Seidel smooths, on coloured blocks of rows in parallel and in
//! single precision, forward before and backward after the coarse correction, so the V-cycle
//! is symmetric; a dense Cholesky factor solves the coarsest level. Fixed particles drop out
//! of every level; at a contact the transfer projects out the normal direction, so coarse
//! corrections never push a particle along its constrained direction (stiff penalty springs
//! instead more than doubled the A-shirt's iteration count). Built once per topology; no
//! allocation per step.

use rayon::prelude::*;

use super::aggregation::{aggregate, Graph};
use super::bcsr::{Bcsr3, Mat3f};
use super::parallel::{for_each_mut, SyncPtr, PAR_MIN};
use super::vcycle::{self, Hierarchy};
use crate::cloth::constraints::{Filter, ParticleFilter};
use crate::cloth::model::ClothModel;
use crate::geometry::{Mat3, Vec3};

/// Coarsening stops at this many particles or fewer (the coarsest level is factorised).
const COARSEST: usize = 64;
/// Rows per smoothing block: the rows are cut into blocks of consecutive rows, coloured so
/// that no two coupled blocks share a colour; a Gauss–Seidel sweep runs the colours in turn
/// and the blocks of a colour in parallel. The partition is fixed, so results do not depend on
/// the thread count.
const GS_BLOCK: usize = 512;
/// Relative shift of the coarsest level's diagonal: keeps its factor defined when an
/// aggregate's particles all lie on the body with one contact normal (a singular direction).
const COARSEST_SHIFT: f64 = 1e-9;

/// One level: its operator (coarse levels own it), the transfer to the next coarser level, the
/// inverse diagonal blocks and scratch vectors.
#[derive(Debug)]
struct Level {
    /// Galerkin operator (`None` on the finest level, which reads the simulation's matrix).
    a: Option<Bcsr3>,
    /// Row of each stored block of this level's operator.
    row_of: Vec<u32>,
    fixed: Vec<bool>,
    /// Projection onto each particle's free directions, I − n nᵀ at a contact of normal n
    /// (finest level only: the transfers from coarser levels project, so coarse operators
    /// never move a particle along its contact normal), and which particles have one.
    proj: Vec<Mat3>,
    projected: Vec<bool>,
    /// The smoothing blocks of each colour.
    colours: Vec<Vec<u32>>,
    /// Single-precision copy of the operator's blocks, read by the smoother and the
    /// residual, which are bound by memory traffic.
    values32: Vec<Mat3f>,
    /// Inverse of each diagonal block on the free directions (zero at fixed particles).
    dinv: Vec<Mat3>,
    /// Prolongation from the next coarser level (empty on the coarsest): node `i` takes
    /// `Σ w e_c[c]` over `(c, w)` in `p[p_ptr[i]..p_ptr[i + 1]]`.
    p_ptr: Vec<usize>,
    p: Vec<(u32, f64)>,
    /// Its transpose, the restriction: coarse node `c` gathers `(i, w)` in
    /// `rt[rt_ptr[c]..rt_ptr[c + 1]]`.
    rt_ptr: Vec<usize>,
    rt: Vec<(u32, f64)>,
    /// Members of each aggregate: `members[members_ptr[c]..members_ptr[c + 1]]`.
    members_ptr: Vec<usize>,
    members: Vec<u32>,
    /// For each stored block of the next coarser operator, the blocks of this level's operator
    /// that sum into it and their weights: `gather[gather_ptr[s]..gather_ptr[s + 1]]`.
    gather_ptr: Vec<usize>,
    gather: Vec<(u32, f64)>,
    r: Vec<Vec3>,
    e: Vec<Vec3>,
    d: Vec<Vec3>,
}

/// Dense Cholesky factor of the coarsest operator, in place.
#[derive(Debug, Default)]
struct DenseCholesky {
    n: usize,
    l: Vec<f64>,
    ok: bool,
    y: Vec<f64>,
}

/// The aggregation multigrid hierarchy of one cloth.
#[derive(Debug)]
pub struct AggregationMultigrid {
    levels: Vec<Level>,
    coarsest: DenseCholesky,
    /// Accumulated wall time in `setup` and `apply` (s), and the number of applications.
    pub timing: (f64, f64, u64),
}

impl AggregationMultigrid {
    /// Builds the hierarchy for `model`, whose implicit matrix has pattern `a`.
    pub fn new(model: &ClothModel, a: &Bcsr3) -> Self {
        let n = model.particle_count();
        // aggregation follows the mesh edges: not the wider stencil of the bending elements,
        // nor the seam threads (aggregates across an open seam cost CG 2.5 times the
        // iterations on the A-shirt's first step)
        let edges = model
            .mesh
            .triangles
            .iter()
            .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]);
        let mut graph = Graph::from_pairs(n, edges);
        let mut levels = vec![Level::new(n, a, None)];
        while levels.last().expect("level").fixed.len() > COARSEST {
            let fine = levels.last_mut().expect("level");
            let (agg, count) = aggregate(&graph);
            if count * 5 > fine.fixed.len() * 4 {
                break; // coarsening stalled
            }
            let fa = fine.a.as_ref().unwrap_or(a);
            let (p_ptr, p) = smoothed_prolongation(&graph, &agg);
            let taps = |i: usize| &p[p_ptr[i]..p_ptr[i + 1]];
            // the Galerkin product's terms: fine block k = (i, j) adds w_i w_j A_k to the
            // coarse block (c_i, c_j) for every tap (c_i, w_i) of i and (c_j, w_j) of j
            let mut terms: Vec<(usize, usize, u32, f64)> = Vec::new();
            for k in 0..fa.nnz_blocks() {
                let (i, j) = (fine.row_of[k] as usize, fa.cols[k] as usize);
                for &(ci, wi) in taps(i) {
                    for &(cj, wj) in taps(j) {
                        terms.push((ci as usize, cj as usize, k as u32, wi * wj));
                    }
                }
            }
            let pairs: Vec<(usize, usize)> = terms.iter().map(|t| (t.0, t.1)).collect();
            let ca = Bcsr3::with_pattern(count, &pairs);
            let slot_of: Vec<usize> = terms
                .iter()
                .map(|t| ca.slot(t.0, t.1).expect("coarse pattern holds every pair"))
                .collect();
            let (gather_ptr, order) = bucket(ca.nnz_blocks(), &slot_of);
            fine.gather = order
                .iter()
                .map(|&t| (terms[t as usize].2, terms[t as usize].3))
                .collect();
            fine.gather_ptr = gather_ptr;
            let tap_of: Vec<usize> = p.iter().map(|&(c, _)| c as usize).collect();
            let (rt_ptr, order) = bucket(count, &tap_of);
            let node_of_tap: Vec<u32> = (0..graph.nodes())
                .flat_map(|i| std::iter::repeat_n(i as u32, p_ptr[i + 1] - p_ptr[i]))
                .collect();
            fine.rt = order
                .iter()
                .map(|&t| (node_of_tap[t as usize], p[t as usize].1))
                .collect();
            fine.rt_ptr = rt_ptr;
            fine.p_ptr = p_ptr;
            fine.p = p;
            let member_of: Vec<usize> = agg.iter().map(|&c| c as usize).collect();
            let (members_ptr, members) = bucket(count, &member_of);
            fine.members_ptr = members_ptr;
            fine.members = members;
            graph = graph.coarsen(&agg, count);
            levels.push(Level::new(count, &ca, Some(ca.clone())));
        }
        let nc = levels.last().expect("level").fixed.len();
        AggregationMultigrid {
            levels,
            coarsest: DenseCholesky {
                n: 3 * nc,
                l: vec![0.0; 9 * nc * nc],
                ok: false,
                y: vec![0.0; 3 * nc],
            },
            timing: (0.0, 0.0, 0),
        }
    }

    /// Number of levels including the finest.
    pub fn depth(&self) -> usize {
        self.levels.len()
    }

    /// Particles on each level, finest first.
    pub fn sizes(&self) -> Vec<usize> {
        self.levels.iter().map(|l| l.fixed.len()).collect()
    }

    /// Refills every level for the current step's matrix `a` and constraints `filter`.
    pub fn setup(&mut self, a: &Bcsr3, filter: &Filter) {
        let t0 = std::time::Instant::now();
        {
            let l0 = &mut self.levels[0];
            for (i, k) in filter.kind.iter().enumerate() {
                l0.fixed[i] = matches!(k, ParticleFilter::Fixed { .. });
                (l0.proj[i], l0.projected[i]) = match k {
                    ParticleFilter::Normal { normal, .. } => {
                        (Mat3::identity() - normal * normal.transpose(), true)
                    }
                    _ => (Mat3::identity(), false),
                };
            }
            l0.invert_diagonal(a);
            l0.mirror(a);
        }
        for l in 1..self.levels.len() {
            let (fine, coarse) = self.levels.split_at_mut(l);
            let f = &fine[l - 1];
            let c = &mut coarse[0];
            let fa = f.a.as_ref().unwrap_or(a);
            for (ci, fx) in c.fixed.iter_mut().enumerate() {
                *fx = f.members[f.members_ptr[ci]..f.members_ptr[ci + 1]]
                    .iter()
                    .all(|&m| f.fixed[m as usize]);
            }
            let ca = c.a.as_mut().expect("coarse operator");
            let (gp, g, rows, cols) = (&f.gather_ptr, &f.gather, &f.row_of, &fa.cols);
            let (fixed, proj, projected) = (&f.fixed, &f.proj, &f.projected);
            let par = ca.values.len() >= PAR_MIN;
            for_each_mut(&mut ca.values, par, |s, out| {
                let mut acc = Mat3::zeros();
                for &(k, w) in &g[gp[s]..gp[s + 1]] {
                    let k = k as usize;
                    let (i, j) = (rows[k] as usize, cols[k] as usize);
                    if fixed[i] || fixed[j] {
                        continue;
                    }
                    match (projected[i], projected[j]) {
                        (false, false) => acc += fa.values[k] * w,
                        (true, false) => acc += proj[i] * fa.values[k] * w,
                        (false, true) => acc += fa.values[k] * proj[j] * w,
                        (true, true) => acc += proj[i] * fa.values[k] * proj[j] * w,
                    }
                }
                *out = acc;
            });
            let ca = c.a.take().expect("coarse operator");
            c.invert_diagonal(&ca);
            c.mirror(&ca);
            c.a = Some(ca);
        }
        let last = self.levels.last().expect("level");
        self.coarsest
            .factor(last.a.as_ref().unwrap_or(a), &last.fixed);
        self.timing.0 += t0.elapsed().as_secs_f64();
    }

    /// Applies one V-cycle to residual `r` (finest level, matrix `a`), writing `s ≈ A⁻¹ r`.
    pub fn apply(&mut self, a: &Bcsr3, r: &[Vec3], s: &mut [Vec3]) {
        vcycle::apply(self, a, r, s);
    }
}

impl Hierarchy for AggregationMultigrid {
    fn depth(&self) -> usize {
        self.levels.len()
    }

    fn finest_rhs(&mut self) -> &mut [Vec3] {
        &mut self.levels[0].r
    }

    fn finest_correction(&self) -> &[Vec3] {
        &self.levels[0].e
    }

    fn cycle_timing(&mut self) -> (&mut f64, &mut u64) {
        (&mut self.timing.1, &mut self.timing.2)
    }

    /// The dense Cholesky factor, or symmetric block Gauss–Seidel sweeps where the level is
    /// not positive definite.
    fn solve_coarsest(&mut self, l: usize, a0: &Bcsr3) {
        let lv = &mut self.levels[l];
        if self.coarsest.ok {
            self.coarsest.solve(&lv.r, &mut lv.e, &lv.fixed);
        } else {
            lv.e.fill(Vec3::zeros());
            lv.with_operator(a0, |lv, a| {
                for _ in 0..4 {
                    lv.sweep(a, true);
                    lv.sweep(a, false);
                }
            });
        }
    }

    fn pre_smooth(&mut self, l: usize, a0: &Bcsr3) {
        let lv = &mut self.levels[l];
        lv.e.fill(Vec3::zeros());
        lv.with_operator(a0, |lv, a| {
            lv.sweep(a, true);
            lv.residual(a);
        });
    }

    fn restrict(&mut self, l: usize) {
        let (fine, coarse) = self.levels.split_at_mut(l + 1);
        let (f, c) = (&fine[l], &mut coarse[0]);
        let (cfixed, rt, ptr, d) = (&c.fixed, &f.rt, &f.rt_ptr, &f.d);
        let par = c.r.len() >= PAR_MIN;
        for_each_mut(&mut c.r, par, |ci, out| {
            *out = Vec3::zeros();
            if !cfixed[ci] {
                for &(i, w) in &rt[ptr[ci]..ptr[ci + 1]] {
                    *out += d[i as usize] * w;
                }
            }
        });
    }

    fn prolong(&mut self, l: usize) {
        let (fine, coarse) = self.levels.split_at_mut(l + 1);
        let (f, c) = (&mut fine[l], &coarse[0]);
        let (p, ptr, fixed, proj, projected) = (&f.p, &f.p_ptr, &f.fixed, &f.proj, &f.projected);
        let par = f.e.len() >= PAR_MIN;
        for_each_mut(&mut f.e, par, |i, e| {
            if !fixed[i] {
                let mut de = Vec3::zeros();
                for &(c_, w) in &p[ptr[i]..ptr[i + 1]] {
                    de += c.e[c_ as usize] * w;
                }
                *e += if projected[i] { proj[i] * de } else { de };
            }
        });
    }

    fn post_smooth(&mut self, l: usize, a0: &Bcsr3) {
        self.levels[l].with_operator(a0, |f, a| f.sweep(a, false));
    }
}

impl Level {
    fn new(n: usize, a: &Bcsr3, own: Option<Bcsr3>) -> Self {
        let mut row_of = vec![0u32; a.nnz_blocks()];
        for i in 0..a.rows() {
            row_of[a.row_ptr[i]..a.row_ptr[i + 1]].fill(i as u32);
        }
        Level {
            colours: colour_blocks(a),
            a: own,
            row_of,
            fixed: vec![false; n],
            proj: vec![Mat3::identity(); n],
            values32: vec![Mat3f::zeros(); a.nnz_blocks()],
            projected: vec![false; n],
            dinv: vec![Mat3::zeros(); n],
            p_ptr: Vec::new(),
            p: Vec::new(),
            rt_ptr: Vec::new(),
            rt: Vec::new(),
            members_ptr: Vec::new(),
            members: Vec::new(),
            gather_ptr: Vec::new(),
            gather: Vec::new(),
            r: vec![Vec3::zeros(); n],
            e: vec![Vec3::zeros(); n],
            d: vec![Vec3::zeros(); n],
        }
    }

    /// Calls `f` with this level and its operator (its own, or `a0` on the finest level).
    fn with_operator(&mut self, a0: &Bcsr3, f: impl FnOnce(&mut Level, &Bcsr3)) {
        let own = self.a.take();
        f(self, own.as_ref().unwrap_or(a0));
        self.a = own;
    }

    fn invert_diagonal(&mut self, a: &Bcsr3) {
        let (fixed, proj, projected) = (&self.fixed, &self.proj, &self.projected);
        let par = self.dinv.len() >= PAR_MIN;
        for_each_mut(&mut self.dinv, par, |i, out| {
            let d = a.values[a.diag[i]];
            *out = if fixed[i] {
                Mat3::zeros()
            } else if projected[i] {
                // the block on the free directions, the normal direction kept apart by an
                // identity term: (S D S + n nᵀ)⁻¹ S
                let s = proj[i];
                let m = s * d * s + (Mat3::identity() - s);
                sym_inverse(&m) * s
            } else {
                sym_inverse(&d)
            };
        });
    }

    /// Refills the single-precision copy of the operator `a`.
    fn mirror(&mut self, a: &Bcsr3) {
        let par = self.values32.len() >= PAR_MIN;
        for_each_mut(&mut self.values32, par, |k, out| {
            *out = a.values[k].cast::<f32>();
        });
    }

    /// One block Gauss–Seidel sweep on `A e = r`, forward (smoothing blocks colour by colour,
    /// rows in increasing order) or backward (the exact reverse, so that a forward sweep
    /// before and a backward one after the coarse correction make a symmetric V-cycle).
    fn sweep(&mut self, a: &Bcsr3, forward: bool) {
        let n = self.e.len();
        let (r, fixed, dinv, values) = (&self.r, &self.fixed, &self.dinv, &self.values32);
        let e = SyncPtr(self.e.as_mut_ptr());
        let block = |b: u32| {
            let (lo, hi) = (b as usize * GS_BLOCK, ((b as usize + 1) * GS_BLOCK).min(n));
            let row = |i: usize| {
                // SAFETY: rows of one block are written by this task only; the blocks that
                // run meanwhile have the same colour, so none of them is coupled to this one:
                // every entry read here is either this block's or not written in this phase.
                unsafe {
                    if fixed[i] {
                        *e.at(i) = Vec3::zeros();
                        return;
                    }
                    let mut s = r[i];
                    for q in a.row_ptr[i]..a.row_ptr[i + 1] {
                        let j = a.cols[q] as usize;
                        if j != i {
                            s -= mul32(&values[q], &*e.at(j));
                        }
                    }
                    *e.at(i) = dinv[i] * s;
                }
            };
            if forward {
                (lo..hi).for_each(row);
            } else {
                (lo..hi).rev().for_each(row);
            }
        };
        let par = n >= PAR_MIN;
        let run = |colour: &[u32]| {
            if par && colour.len() > 1 {
                colour.par_iter().for_each(|&b| block(b));
            } else {
                colour.iter().for_each(|&b| block(b));
            }
        };
        if forward {
            self.colours.iter().for_each(|c| run(c));
        } else {
            self.colours.iter().rev().for_each(|c| {
                // within a colour the blocks are independent: their order is moot
                run(c)
            });
        }
    }

    /// d = S (r − A e), zero at fixed particles.
    fn residual(&mut self, a: &Bcsr3) {
        let (r, e, fixed, proj, projected, values) = (
            &self.r,
            &self.e,
            &self.fixed,
            &self.proj,
            &self.projected,
            &self.values32,
        );
        self.d
            .par_chunks_mut(super::parallel::CHUNK)
            .enumerate()
            .for_each(|(c, ds)| {
                for (k, out) in ds.iter_mut().enumerate() {
                    let i = c * super::parallel::CHUNK + k;
                    *out = if fixed[i] {
                        Vec3::zeros()
                    } else {
                        let mut di = r[i];
                        for q in a.row_ptr[i]..a.row_ptr[i + 1] {
                            di -= mul32(&values[q], &e[a.cols[q] as usize]);
                        }
                        if projected[i] {
                            proj[i] * di
                        } else {
                            di
                        }
                    };
                }
            });
    }
}

impl DenseCholesky {
    /// Factorises the (3n × 3n) dense form of `a`, identity rows at fixed particles; `ok`
    /// false when the matrix is not positive definite.
    fn factor(&mut self, a: &Bcsr3, fixed: &[bool]) {
        let m = self.n;
        let l = &mut self.l;
        l.fill(0.0);
        for i in 0..a.rows() {
            if fixed[i] {
                for c in 0..3 {
                    l[(3 * i + c) * m + 3 * i + c] = 1.0;
                }
                continue;
            }
            for k in a.row_ptr[i]..a.row_ptr[i + 1] {
                let j = a.cols[k] as usize;
                if fixed[j] {
                    continue;
                }
                let b = &a.values[k];
                for r in 0..3 {
                    for c in 0..3 {
                        l[(3 * i + r) * m + 3 * j + c] = b[(r, c)];
                    }
                }
            }
        }
        let shift = COARSEST_SHIFT * (0..m).map(|j| l[j * m + j].abs()).fold(0.0, f64::max);
        for j in 0..m {
            l[j * m + j] += shift;
        }
        // lower-triangular Cholesky, row-major, in place
        self.ok = true;
        for j in 0..m {
            let mut d = l[j * m + j];
            for k in 0..j {
                d -= l[j * m + k] * l[j * m + k];
            }
            if d.is_nan() || d <= 0.0 {
                self.ok = false;
                return;
            }
            let d = d.sqrt();
            l[j * m + j] = d;
            for i in j + 1..m {
                let mut s = l[i * m + j];
                for k in 0..j {
                    s -= l[i * m + k] * l[j * m + k];
                }
                l[i * m + j] = s / d;
            }
        }
    }

    /// e = A⁻¹ r with the factor, zero at fixed particles.
    fn solve(&mut self, r: &[Vec3], e: &mut [Vec3], fixed: &[bool]) {
        let m = self.n;
        let (l, y) = (&self.l, &mut self.y);
        for i in 0..m {
            let mut s = if fixed[i / 3] { 0.0 } else { r[i / 3][i % 3] };
            for k in 0..i {
                s -= l[i * m + k] * y[k];
            }
            y[i] = s / l[i * m + i];
        }
        for i in (0..m).rev() {
            let mut s = y[i];
            for k in i + 1..m {
                s -= l[k * m + i] * y[k];
            }
            y[i] = s / l[i * m + i];
        }
        for (i, ei) in e.iter_mut().enumerate() {
            *ei = if fixed[i] {
                Vec3::zeros()
            } else {
                Vec3::new(y[3 * i], y[3 * i + 1], y[3 * i + 2])
            };
        }
    }
}

/// Greedy colouring of the `GS_BLOCK`-row blocks of `a`'s pattern: two blocks coupled by a
/// stored entry get different colours. Returns the blocks of each colour.
fn colour_blocks(a: &Bcsr3) -> Vec<Vec<u32>> {
    let nb = a.rows().div_ceil(GS_BLOCK);
    let pairs = (0..a.rows()).flat_map(|i| {
        a.cols[a.row_ptr[i]..a.row_ptr[i + 1]]
            .iter()
            .map(move |&j| (i / GS_BLOCK, j as usize / GS_BLOCK))
    });
    let g = Graph::from_pairs(nb, pairs);
    let mut colour = vec![usize::MAX; nb];
    let mut colours: Vec<Vec<u32>> = Vec::new();
    for b in 0..nb {
        let mut c = 0;
        while g.neighbours(b).iter().any(|&o| colour[o as usize] == c) {
            c += 1;
        }
        colour[b] = c;
        if c == colours.len() {
            colours.push(Vec::new());
        }
        colours[c].push(b as u32);
    }
    colours
}

/// `m x` with a single-precision block, accumulated in double precision.
#[inline]
fn mul32(m: &Mat3f, x: &Vec3) -> Vec3 {
    Vec3::new(
        f64::from(m[(0, 0)]) * x.x + f64::from(m[(0, 1)]) * x.y + f64::from(m[(0, 2)]) * x.z,
        f64::from(m[(1, 0)]) * x.x + f64::from(m[(1, 1)]) * x.y + f64::from(m[(1, 2)]) * x.z,
        f64::from(m[(2, 0)]) * x.x + f64::from(m[(2, 1)]) * x.y + f64::from(m[(2, 2)]) * x.z,
    )
}

/// The inverse of a symmetric block that should be positive definite; where it is singular
/// (all of an aggregate's particles held along one contact normal), the inverse on the
/// directions it does not annihilate.
fn sym_inverse(m: &Mat3) -> Mat3 {
    if let Some(c) = m.cholesky() {
        return c.inverse();
    }
    let sym = (m + m.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let top = eig.eigenvalues.amax();
    let mut inv = Mat3::zeros();
    for k in 0..3 {
        let l = eig.eigenvalues[k];
        if l > 1e-10 * top {
            let v = eig.eigenvectors.column(k);
            inv += v * v.transpose() / l;
        }
    }
    inv
}

/// Weight of the Jacobi step that smooths the piecewise-constant prolongation.
const SMOOTHING: f64 = 2.0 / 3.0;

/// The smoothed-aggregation prolongation of `agg` on `g`: the piecewise-constant one after a
/// damped Jacobi step of the graph Laplacian, P = (I − ω D⁻¹ L) P₀. Node `i` keeps `1 − ω` of
/// its own aggregate and shares `ω` among its neighbours' aggregates by the number of
/// neighbours in each; each row sums to one (constants are prolongated exactly).
fn smoothed_prolongation(g: &Graph, agg: &[u32]) -> (Vec<usize>, Vec<(u32, f64)>) {
    let mut ptr = Vec::with_capacity(g.nodes() + 1);
    let mut p: Vec<(u32, f64)> = Vec::new();
    ptr.push(0);
    for i in 0..g.nodes() {
        let start = p.len();
        let nb = g.neighbours(i);
        if nb.is_empty() {
            p.push((agg[i], 1.0));
        } else {
            let share = SMOOTHING / nb.len() as f64;
            p.push((agg[i], 1.0 - SMOOTHING));
            for &j in nb {
                let c = agg[j as usize];
                match p[start..].iter_mut().find(|t| t.0 == c) {
                    Some(t) => t.1 += share,
                    None => p.push((c, share)),
                }
            }
            p[start..].sort_unstable_by_key(|t| t.0);
        }
        ptr.push(p.len());
    }
    (ptr, p)
}

/// Groups indices `0..keys.len()` by key (`keys[k] < buckets`), each bucket in increasing
/// index order: returns the bucket starts and the grouped indices.
fn bucket(buckets: usize, keys: &[usize]) -> (Vec<usize>, Vec<u32>) {
    let mut ptr = vec![0usize; buckets + 1];
    for &k in keys {
        ptr[k + 1] += 1;
    }
    for b in 0..buckets {
        ptr[b + 1] += ptr[b];
    }
    let mut next = ptr.clone();
    let mut out = vec![0u32; keys.len()];
    for (idx, &k) in keys.iter().enumerate() {
        out[next[k]] = idx as u32;
        next[k] += 1;
    }
    (ptr, out)
}
