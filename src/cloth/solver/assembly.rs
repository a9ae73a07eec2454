//! Assembly of forces and of the implicit system `A Δv = b` with
//! `A = M − h ∂f/∂v − h² ∂f/∂x` and `b = h (f + h ∂f/∂x v)` (Baraff & Witkin 1998).
//!
//! Two deterministic parallel passes, no allocation: (1) every element writes its per-node
//! right-hand-side contributions (a two-node element only its first node's: the second takes
//! the opposite) and its stiffness blocks (symmetric, except a hinge's) into its own slots of
//! flat buffers; (2) every matrix row gathers them, in a fixed order, through contribution
//! records built once per topology. The block-Jacobi preconditioner (inverse diagonal blocks)
//! is formed in pass 2.

use rayon::prelude::*;

use super::bcsr::{Bcsr3, Sym3, Sym3f, SYM_ROW_MAX};
use super::contribution::{contribute_all, Pass};
use super::parallel::{chunks, stream_copy, stream_fence, SyncPtr, CHUNK};
use super::simd::multiversion;
use crate::cloth::elements::material::Direction;
use crate::cloth::model::ClothModel;
use crate::geometry::{Mat3, Vec3};

/// One matrix contribution: `values[slot] += scale · block src`, the scale kept apart (see
/// [`Assembly`]'s `rec_scale`). Eight bytes, not sixteen: the gather streams one record per
/// (row, element, column).
#[derive(Debug, Clone, Copy)]
struct Rec {
    slot: u32,
    /// Index into the symmetric blocks, or, from `hinge_block0` on, into the hinge blocks.
    src: u32,
}

/// A record's scale index meaning "not in the table: see `scale_spill`".
const SPILL: u8 = u8::MAX;

/// Marks a right-hand-side record whose contribution is subtracted: a two-node element
/// stores its first node's contribution only, the second node's being its opposite.
const NEG: u32 = 1 << 31;

/// Preallocated buffers and the contribution records of a model's topology.
#[derive(Debug, Clone)]
pub struct Assembly {
    /// The system matrix (pattern fixed).
    pub a: Bcsr3,
    /// Right-hand side b (or the force, in force-only mode).
    pub b: Vec<Vec3>,
    /// Inverse diagonal blocks (block-Jacobi preconditioner), formed during assembly when
    /// `jacobi` is set, or on demand by [`Assembly::form_block_jacobi`].
    pub pinv: Vec<Mat3>,
    /// Whether assembly forms `pinv` (not needed while multigrid preconditions).
    pub jacobi: bool,
    /// Stiffness blocks of springs, shear diagonals and bending lines (all symmetric).
    blocks: Vec<Sym3>,
    /// Stiffness blocks of hinges (16 per hinge, general).
    hinge_blocks: Vec<Mat3>,
    /// Right-hand-side contributions: one per spring and shear diagonal (its first node's;
    /// the second node's is the opposite), one per node of a bending line or hinge.
    g: Vec<Vec3>,
    recs: Vec<Rec>,
    /// Each record's scale, as an index into `scales` (a model has a handful of distinct
    /// scales: ±1 and the products of its bending lines' coefficients), or [`SPILL`].
    rec_scale: Vec<u8>,
    scales: Vec<f64>,
    /// Every record's scale, kept only when the model has more distinct scales than the table
    /// holds.
    scale_spill: Vec<f64>,
    rec_ptr: Vec<usize>,
    grecs: Vec<u32>,
    grec_ptr: Vec<usize>,
    quad_block0: usize,
    bend_block0: usize,
    hinge_block0: usize,
    quad_g0: usize,
    bend_g0: usize,
    hinge_g0: usize,
    energy_partials: Vec<f64>,
    /// Friction states (committed coordinate, friction force) per element, allocated on the
    /// first assembly with a law that has internal friction; NaN coordinate = not yet seen.
    pub(in crate::cloth) fric_spring: Vec<[f64; 2]>,
    pub(in crate::cloth) fric_quad: Vec<[f64; 2]>,
    pub(in crate::cloth) fric_bend: Vec<[Vec3; 2]>,
    pub(in crate::cloth) fric_hinge: Vec<[f64; 2]>,
    /// Trial friction states of the last evaluation (committed by [`Assembly::commit_friction`]).
    pub(in crate::cloth) trial_spring: Vec<[f64; 2]>,
    pub(in crate::cloth) trial_quad: Vec<[f64; 2]>,
    pub(in crate::cloth) trial_bend: Vec<[Vec3; 2]>,
    pub(in crate::cloth) trial_hinge: Vec<[f64; 2]>,
    /// Commit the friction states after every assembly (true for time stepping, where every
    /// assembly happens at an accepted state); quasi-static solvers set it false and commit
    /// once an increment has converged.
    pub auto_commit: bool,
}

/// What to assemble.
#[derive(Debug, Clone, Copy)]
pub struct AssemblyInputs {
    /// Step length h (s).
    pub dt: f64,
    /// Gravity (m/s²).
    pub gravity: Vec3,
    /// Build the matrix (implicit) or only forces (explicit).
    pub matrix: bool,
}

impl Assembly {
    /// Builds the pattern and the records of `model`.
    pub fn new(model: &ClothModel) -> Self {
        let n = model.particle_count();
        let a = Bcsr3::with_pattern(n, &model.coupled_pairs());
        let ns = model.springs.len();
        let nq = model.shear_quads.len();
        let nb = model.bend_lines.len();
        let nh = model.hinges.len();
        let quad_block0 = ns;
        let bend_block0 = ns + 2 * nq;
        let hinge_block0 = bend_block0 + nb;
        let quad_g0 = ns;
        let bend_g0 = quad_g0 + 2 * nq;
        let hinge_g0 = bend_g0 + 3 * nb;
        let mut rows: Vec<Vec<(Rec, f64)>> = vec![Vec::new(); n];
        let mut grows: Vec<Vec<u32>> = vec![Vec::new(); n];
        let slot = |i: usize, j: usize| a.slot(i, j).expect("pair in pattern") as u32;
        let rec = |slot: u32, src: usize, scale: f64| {
            (
                Rec {
                    slot,
                    src: src as u32,
                },
                scale,
            )
        };
        for (s, sp) in model.springs.iter().enumerate() {
            for (me, other, sign) in [(sp.a, sp.b, 0), (sp.b, sp.a, NEG)] {
                rows[me].push(rec(slot(me, me), s, 1.0));
                rows[me].push(rec(slot(me, other), s, -1.0));
                grows[me].push(s as u32 | sign);
            }
        }
        for (q, quad) in model.shear_quads.iter().enumerate() {
            for k in 0..2 {
                let (a, b) = (quad.nodes[2 * k], quad.nodes[2 * k + 1]);
                let src = quad_block0 + 2 * q + k;
                let gi = (quad_g0 + 2 * q + k) as u32;
                for (me, other, sign) in [(a, b, 0), (b, a, NEG)] {
                    rows[me].push(rec(slot(me, me), src, 1.0));
                    rows[me].push(rec(slot(me, other), src, -1.0));
                    grows[me].push(gi | sign);
                }
            }
        }
        for (e, bl) in model.bend_lines.iter().enumerate() {
            for m in 0..3 {
                let me = bl.nodes[m];
                for k in 0..3 {
                    let scale = bl.coef[m] * bl.coef[k];
                    rows[me].push(rec(slot(me, bl.nodes[k]), bend_block0 + e, scale));
                }
                grows[me].push((bend_g0 + 3 * e + m) as u32);
            }
        }
        // hinges, then Choi–Ko's arc connections (general blocks after the hinges')
        let four = model
            .hinges
            .iter()
            .map(|h| h.nodes)
            .chain(model.arcs.iter().map(|c| c.nodes));
        for (h, nodes) in four.enumerate() {
            for m in 0..4 {
                let me = nodes[m];
                for k in 0..4 {
                    let src = hinge_block0 + 16 * h + 4 * m + k;
                    rows[me].push(rec(slot(me, nodes[k]), src, 1.0));
                }
                grows[me].push((hinge_g0 + 4 * h + m) as u32);
            }
        }
        let (recs, rec_ptr) = flatten(rows);
        let (grecs, grec_ptr) = flatten(grows);
        let (rec_scale, scales, scale_spill) = scale_table(&recs);
        let recs = recs.into_iter().map(|(r, _)| r).collect();
        let na = model.arcs.len();
        let n_elems = ns + nq + nb + nh + na;
        Assembly {
            a,
            b: vec![Vec3::zeros(); n],
            pinv: vec![Mat3::identity(); n],
            jacobi: true,
            blocks: vec![Sym3::default(); hinge_block0],
            hinge_blocks: vec![Mat3::zeros(); 16 * (nh + na)],
            g: vec![Vec3::zeros(); hinge_g0 + 4 * (nh + na)],
            recs,
            rec_scale,
            scales,
            scale_spill,
            rec_ptr,
            grecs,
            grec_ptr,
            quad_block0,
            bend_block0,
            hinge_block0,
            quad_g0,
            bend_g0,
            hinge_g0,
            energy_partials: vec![0.0; chunks(n_elems.max(1), CHUNK) + 5],
            fric_spring: Vec::new(),
            fric_quad: Vec::new(),
            fric_bend: Vec::new(),
            fric_hinge: Vec::new(),
            trial_spring: Vec::new(),
            trial_quad: Vec::new(),
            trial_bend: Vec::new(),
            trial_hinge: Vec::new(),
            auto_commit: true,
        }
    }

    /// Evaluates all elements at (x, v) and assembles. In matrix mode, fills `a`, `b`, `pinv`
    /// for the implicit step of length `dt`; in force-only mode, `b` receives the total force.
    /// Returns the elastic energy at x.
    pub fn assemble(
        &mut self,
        model: &ClothModel,
        x: &[Vec3],
        v: &[Vec3],
        inp: AssemblyInputs,
    ) -> f64 {
        if model.law.has_friction() && self.fric_spring.len() != model.springs.len() {
            // once per topology: friction states start unseen (taken at the first evaluation)
            self.fric_spring = vec![[f64::NAN, 0.0]; model.springs.len()];
            self.fric_quad = vec![[f64::NAN, 0.0]; model.shear_quads.len()];
            self.fric_bend = vec![[Vec3::repeat(f64::NAN), Vec3::zeros()]; model.bend_lines.len()];
            self.fric_hinge = vec![[f64::NAN, 0.0]; model.hinges.len()];
            self.trial_spring = self.fric_spring.clone();
            self.trial_quad = self.fric_quad.clone();
            self.trial_bend = self.fric_bend.clone();
            self.trial_hinge = self.fric_hinge.clone();
        }
        let energy = self.element_pass(model, x, v, inp);
        if self.auto_commit {
            self.commit_friction();
        }
        self.gather_pass(model, v, inp);
        energy
    }

    /// Evaluates every element, kind by kind, into its slots of the flat buffers; returns the
    /// elastic energy (each kind's sum, in the order springs, shear cells, bending lines,
    /// hinges, arcs).
    fn element_pass(
        &mut self,
        model: &ClothModel,
        x: &[Vec3],
        v: &[Vec3],
        inp: AssemblyInputs,
    ) -> f64 {
        let law = &*model.law;
        let fab = &model.fabric;
        // factors: g = hf·(f + f_damp) − hk·(K v); blocks = bk·K (+ bc·K_axial)
        let (hf, hk) = if inp.matrix {
            (inp.dt, inp.dt * inp.dt)
        } else {
            (1.0, 0.0)
        };
        let friction = !self.fric_spring.is_empty();
        let p = Pass {
            law,
            x,
            v,
            hf,
            hk,
            dt: inp.dt,
            matrix: inp.matrix,
            beta_s: fab.stretch_damping,
            beta_b: fab.bend_damping,
            fr_warp: law.tension_friction(Direction::Warp).filter(|_| friction),
            fr_weft: law.tension_friction(Direction::Weft).filter(|_| friction),
            fr_shear: law.shear_friction().filter(|_| friction),
            fr_bend_u: law.bending_friction(Direction::Warp).filter(|_| friction),
            fr_bend_v: law.bending_friction(Direction::Weft).filter(|_| friction),
        };
        let nsc = chunks(model.springs.len(), CHUNK);
        let nqc = chunks(model.shear_quads.len(), CHUNK);
        let nbc = chunks(model.bend_lines.len(), CHUNK);
        let (blocks_s, rest) = self.blocks.split_at_mut(self.quad_block0);
        let (blocks_q, blocks_b) = rest.split_at_mut(self.bend_block0 - self.quad_block0);
        let nh = model.hinges.len();
        let (blocks_h, blocks_a) = self.hinge_blocks.split_at_mut(16 * nh);
        let (g_s, rest) = self.g.split_at_mut(self.quad_g0);
        let (g_q, rest) = rest.split_at_mut(self.bend_g0 - self.quad_g0);
        let (g_b, rest) = rest.split_at_mut(self.hinge_g0 - self.bend_g0);
        let (g_h, g_a) = rest.split_at_mut(4 * nh);
        let (ep_s, rest) = self.energy_partials.split_at_mut(nsc);
        let (ep_q, rest) = rest.split_at_mut(nqc);
        let (ep_b, rest) = rest.split_at_mut(nbc);
        let (ep_h, ep_a) = rest.split_at_mut(chunks(nh, CHUNK));
        let trial_s = SyncPtr(self.trial_spring.as_mut_ptr());
        let trial_q = SyncPtr(self.trial_quad.as_mut_ptr());
        let trial_b = SyncPtr(self.trial_bend.as_mut_ptr());
        let trial_h = SyncPtr(self.trial_hinge.as_mut_ptr());
        let no_state = SyncPtr(std::ptr::null_mut());
        let els = &model.springs;
        let e_s = contribute_all(els, &p, blocks_s, g_s, ep_s, &self.fric_spring, trial_s);
        let els = &model.shear_quads;
        let e_q = contribute_all(els, &p, blocks_q, g_q, ep_q, &self.fric_quad, trial_q);
        let els = &model.bend_lines;
        let e_b = contribute_all(els, &p, blocks_b, g_b, ep_b, &self.fric_bend, trial_b);
        let els = &model.hinges;
        let e_h = contribute_all(els, &p, blocks_h, g_h, ep_h, &self.fric_hinge, trial_h);
        let els = &model.arcs;
        let e_a = contribute_all(els, &p, blocks_a, g_a, ep_a, &[], no_state);
        e_s + e_q + e_b + e_h + e_a
    }

    fn gather_pass(&mut self, model: &ClothModel, v: &[Vec3], inp: AssemblyInputs) {
        let n = model.particle_count();
        // general blocks in `values`, or symmetric ones in `sym` (or none, single-precision
        // mirrors only), always with a mirror: see `Bcsr3::store_symmetric`
        let general = !self.a.values.is_empty();
        assert!(
            general || !self.a.values32.is_empty(),
            "a matrix without general blocks keeps its single-precision mirror"
        );
        let (perm32, perm_start) = match &mut self.a.permuted {
            Some(pm) => (Some(SyncPtr(pm.values.as_mut_ptr())), &pm.row_start[..]),
            None => (None, &[][..]),
        };
        let rows = RowGather {
            model,
            v,
            inp,
            drag: model.fabric.air_drag,
            general,
            values: SyncPtr(self.a.values.as_mut_ptr()),
            sym: (!self.a.sym.is_empty()).then_some(SyncPtr(self.a.sym.as_mut_ptr())),
            mirror: !self.a.values32.is_empty(),
            jacobi: self.jacobi,
            values32: SyncPtr(self.a.values32.as_mut_ptr()),
            perm32,
            perm_start,
            row_ptr: &self.a.row_ptr,
            diag: &self.a.diag,
            recs: &self.recs,
            rec_ptr: &self.rec_ptr,
            grecs: &self.grecs,
            grec_ptr: &self.grec_ptr,
            rec_scale: &self.rec_scale,
            scales: &self.scales,
            spill: &self.scale_spill,
            blocks: &self.blocks,
            hinge_blocks: &self.hinge_blocks,
            g: &self.g,
            nsym: self.hinge_block0,
        };
        gather_rows(&rows, &mut self.b, &mut self.pinv);
        debug_assert_eq!(self.b.len(), n);
    }
}

multiversion! {
    /// Pass 2 over all rows, in parallel chunks (see [`RowGather::chunk`]).
    fn gather_rows(rows: &RowGather<'_>, b: &mut [Vec3], pinv: &mut [Mat3]) {
        b.par_chunks_mut(CHUNK)
            .zip(pinv.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (bs, ps))| rows.chunk(c, bs, ps));
    }
}

/// What pass 2 reads and where it writes: the model, the step's inputs, the element buffers
/// of pass 1 with their records, and the matrix storage (raw pointers: each row writes its own
/// slots only).
#[derive(Clone, Copy)]
struct RowGather<'a> {
    model: &'a ClothModel,
    v: &'a [Vec3],
    inp: AssemblyInputs,
    drag: f64,
    general: bool,
    values: SyncPtr<Mat3>,
    sym: Option<SyncPtr<Sym3>>,
    mirror: bool,
    jacobi: bool,
    values32: SyncPtr<Sym3f>,
    perm32: Option<SyncPtr<Sym3f>>,
    perm_start: &'a [usize],
    row_ptr: &'a [usize],
    diag: &'a [usize],
    recs: &'a [Rec],
    rec_ptr: &'a [usize],
    grecs: &'a [u32],
    grec_ptr: &'a [usize],
    rec_scale: &'a [u8],
    scales: &'a [f64],
    spill: &'a [f64],
    blocks: &'a [Sym3],
    hinge_blocks: &'a [Mat3],
    g: &'a [Vec3],
    nsym: usize,
}

impl RowGather<'_> {
    /// Record `k`'s scale.
    #[inline(always)]
    fn scale(&self, k: usize) -> f64 {
        match self.rec_scale[k] {
            SPILL => self.spill[k],
            t => self.scales[t as usize],
        }
    }

    /// Rows `c · CHUNK ..` (as many as `bs` holds): right-hand side into `bs`, matrix rows
    /// into the storage, inverse diagonal blocks into `ps` when block Jacobi is on.
    #[inline(always)]
    fn chunk(&self, c: usize, bs: &mut [Vec3], ps: &mut [Mat3]) {
        let RowGather {
            model,
            v,
            inp,
            drag,
            general,
            values,
            sym,
            mirror,
            jacobi,
            values32,
            perm32,
            perm_start,
            row_ptr,
            diag,
            recs,
            rec_ptr,
            grecs,
            grec_ptr,
            blocks,
            hinge_blocks,
            g,
            nsym,
            ..
        } = *self;
        let (h, matrix) = (inp.dt, inp.matrix);
        let scale = |k: usize| self.scale(k);
        for k in 0..bs.len() {
            let i = c * CHUNK + k;
            let m = model.mass[i];
            let da = drag * model.area[i];
            let mut rhs = inp.gravity * m - v[i] * da;
            if matrix {
                rhs *= h;
            }
            for &src in &grecs[grec_ptr[i]..grec_ptr[i + 1]] {
                if src & NEG == 0 {
                    rhs += g[src as usize];
                } else {
                    rhs -= g[(src & !NEG) as usize];
                }
            }
            bs[k] = rhs;
            if !matrix {
                continue;
            }
            let (s0, s1) = (row_ptr[i], row_ptr[i + 1]);
            let dm = m + h * da;
            // SAFETY: row i's slots belong to this iteration only.
            unsafe {
                if general {
                    for s in s0..s1 {
                        *values.at(s) = Mat3::zeros();
                    }
                    *values.at(diag[i]) = Mat3::identity() * dm;
                    for k in rec_ptr[i]..rec_ptr[i + 1] {
                        let (r, src) = (recs[k], recs[k].src as usize);
                        let blk = if src < nsym {
                            blocks[src].to_mat3()
                        } else {
                            hinge_blocks[src - nsym]
                        };
                        *values.at(r.slot as usize) += blk * scale(k);
                    }
                    if mirror {
                        for s in s0..s1 {
                            *values32.at(s) = Sym3f::from_upper(&*values.at(s));
                        }
                    }
                    if jacobi {
                        ps[k] = block_inverse(&*values.at(diag[i]));
                    }
                    if let Some(p) = perm32 {
                        let at = perm_start[i];
                        for s in s0..s1 {
                            *p.at(at + s - s0) = *values32.at(s);
                        }
                    }
                } else {
                    // symmetric blocks: the row summed here, then written once to each
                    // stored copy
                    let mut buf = [std::mem::MaybeUninit::<Sym3>::uninit(); SYM_ROW_MAX];
                    for b in &mut buf[..s1 - s0] {
                        b.write(Sym3::default());
                    }
                    // SAFETY: the first s1 − s0 entries were just written (a row has
                    // at most SYM_ROW_MAX blocks: `Bcsr3::store_symmetric` checked).
                    let row = &mut *(&mut buf[..s1 - s0] as *mut [_] as *mut [Sym3]);
                    row[diag[i] - s0] = Sym3([dm, 0.0, 0.0, dm, 0.0, dm]);
                    for k in rec_ptr[i]..rec_ptr[i + 1] {
                        let (r, src) = (recs[k], recs[k].src as usize);
                        let to = &mut row[r.slot as usize - s0];
                        if src < nsym {
                            to.add_scaled_sym(&blocks[src], scale(k));
                        } else {
                            to.add_scaled(&hinge_blocks[src - nsym], scale(k));
                        }
                    }
                    let row = &*row;
                    if let Some(sp) = sym {
                        stream_copy(sp.at(s0), row);
                    }
                    let mut buf32 = [Sym3f::default(); SYM_ROW_MAX];
                    for (o, b) in buf32.iter_mut().zip(row) {
                        *o = b.to_f32();
                    }
                    let row32 = &buf32[..s1 - s0];
                    stream_copy(values32.at(s0), row32);
                    if let Some(p) = perm32 {
                        stream_copy(p.at(perm_start[i]), row32);
                    }
                    if jacobi {
                        ps[k] = block_inverse(&row[diag[i] - s0].to_mat3());
                    }
                }
            }
        }
        stream_fence();
    }
}

impl Assembly {
    /// Makes the friction states of the last evaluation the committed ones.
    pub fn commit_friction(&mut self) {
        self.fric_spring.copy_from_slice(&self.trial_spring);
        self.fric_quad.copy_from_slice(&self.trial_quad);
        self.fric_bend.copy_from_slice(&self.trial_bend);
        self.fric_hinge.copy_from_slice(&self.trial_hinge);
    }

    /// Forms the block-Jacobi preconditioner from the assembled matrix.
    pub fn form_block_jacobi(&mut self) {
        let a = &self.a;
        self.pinv
            .par_iter_mut()
            .enumerate()
            .for_each(|(i, p)| *p = block_inverse(&a.block(a.diag[i])));
    }
}

/// Inverse of a diagonal block, or a scaled identity if it is singular.
#[inline]
fn block_inverse(d: &Mat3) -> Mat3 {
    d.try_inverse()
        .unwrap_or_else(|| Mat3::identity() / d.trace().max(1e-300))
}

/// The records' scales as indices into a table of the distinct ones (compared bit for bit),
/// or, when there are more than the indices can name, all of them spilled to a plain array.
fn scale_table(recs: &[(Rec, f64)]) -> (Vec<u8>, Vec<f64>, Vec<f64>) {
    let mut table: Vec<f64> = Vec::new();
    let mut idx = Vec::with_capacity(recs.len());
    for &(_, s) in recs {
        match table.iter().position(|t| t.to_bits() == s.to_bits()) {
            Some(k) => idx.push(k as u8),
            None if table.len() < SPILL as usize => {
                idx.push(table.len() as u8);
                table.push(s);
            }
            None => {
                let spill = recs.iter().map(|&(_, s)| s).collect();
                return (vec![SPILL; recs.len()], Vec::new(), spill);
            }
        }
    }
    (idx, table, Vec::new())
}

/// Concatenates per-row lists into one array plus row offsets.
fn flatten<T>(rows: Vec<Vec<T>>) -> (Vec<T>, Vec<usize>) {
    let mut ptr = vec![0];
    let mut flat = Vec::new();
    for r in rows {
        flat.extend(r);
        ptr.push(flat.len());
    }
    (flat, ptr)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recs(scales: &[f64]) -> Vec<(Rec, f64)> {
        scales
            .iter()
            .map(|&s| (Rec { slot: 0, src: 0 }, s))
            .collect()
    }

    #[test]
    fn scale_table_names_each_distinct_scale_once() {
        let s = [1.0, -1.0, 0.25, 1.0, -0.0, 0.0, 0.25];
        let (idx, table, spill) = scale_table(&recs(&s));
        assert!(spill.is_empty());
        // 0.0 and −0.0 differ bit for bit, so both are kept
        assert_eq!(table.len(), 5);
        for (k, &v) in s.iter().enumerate() {
            assert_eq!(table[idx[k] as usize].to_bits(), v.to_bits());
        }
    }

    #[test]
    fn scale_table_spills_when_scales_outnumber_the_indices() {
        let s: Vec<f64> = (0..300).map(|k| 1.0 + k as f64).collect();
        let (idx, table, spill) = scale_table(&recs(&s));
        assert!(table.is_empty());
        assert!(idx.iter().all(|&i| i == SPILL));
        assert_eq!(spill, s);
    }
}
