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
use super::elements::{BendLine, SpringKind};
use super::material::Direction;
use super::model::ClothModel;
use super::parallel::{chunks, ordered_sum, stream_copy, stream_fence, SyncPtr, CHUNK};
use super::simd::multiversion;
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
    fric_spring: Vec<[f64; 2]>,
    fric_quad: Vec<[f64; 2]>,
    fric_bend: Vec<[Vec3; 2]>,
    fric_hinge: Vec<[f64; 2]>,
    /// Trial friction states of the last evaluation (committed by [`Assembly::commit_friction`]).
    trial_spring: Vec<[f64; 2]>,
    trial_quad: Vec<[f64; 2]>,
    trial_bend: Vec<[Vec3; 2]>,
    trial_hinge: Vec<[f64; 2]>,
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

    multiversion! {
    fn element_pass / element_pass_avx2(
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
        let (beta_s, beta_b) = (fab.stretch_damping, fab.bend_damping);
        let ns = model.springs.len();
        let nq = model.shear_quads.len();
        let nb = model.bend_lines.len();
        let nsc = chunks(ns, CHUNK);
        let nqc = chunks(nq, CHUNK);
        let nbc = chunks(nb, CHUNK);
        let (blocks_s, rest) = self.blocks.split_at_mut(self.quad_block0);
        let (blocks_q, rest) = rest.split_at_mut(self.bend_block0 - self.quad_block0);
        let blocks_b = rest;
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
        let matrix = inp.matrix;
        let friction = !self.fric_spring.is_empty();
        let fr_warp = law.tension_friction(Direction::Warp).filter(|_| friction);
        let fr_weft = law.tension_friction(Direction::Weft).filter(|_| friction);
        let fr_shear = law.shear_friction().filter(|_| friction);
        let fr_bend_u = law.bending_friction(Direction::Warp).filter(|_| friction);
        let fr_bend_v = law.bending_friction(Direction::Weft).filter(|_| friction);
        let (cm_s, cm_q, cm_b, cm_h) = (
            &self.fric_spring,
            &self.fric_quad,
            &self.fric_bend,
            &self.fric_hinge,
        );
        let st_s = SyncPtr(self.trial_spring.as_mut_ptr());
        let st_q = SyncPtr(self.trial_quad.as_mut_ptr());
        let st_b = SyncPtr(self.trial_bend.as_mut_ptr());
        let st_h = SyncPtr(self.trial_hinge.as_mut_ptr());
        // springs
        model
            .springs
            .par_chunks(CHUNK)
            .zip(blocks_s.par_chunks_mut(CHUNK))
            .zip(g_s.par_chunks_mut(CHUNK))
            .zip(ep_s.par_iter_mut())
            .enumerate()
            .for_each(|(c, (((sp, bl), g), ep))| {
                let mut e = 0.0;
                for k in 0..sp.len() {
                    let s = &sp[k];
                    let mut ev = s.eval(law, &x[s.a], &x[s.b]);
                    e += ev.energy;
                    let fr = match s.kind {
                        SpringKind::Stretch { warp_weight } if warp_weight >= 0.5 => fr_warp,
                        SpringKind::Stretch { .. } => fr_weft,
                        SpringKind::Shear => fr_shear,
                        SpringKind::Seam { .. } | SpringKind::Flexion { .. } => None,
                    };
                    let axial_el = ev.axial;
                    if let Some(f) = fr {
                        // SAFETY: element c·CHUNK + k is visited by this iteration only.
                        let st = unsafe { &mut *st_s.at(c * CHUNK + k) };
                        *st = cm_s[c * CHUNK + k];
                        s.add_friction(&f, st, &x[s.a], &x[s.b], &mut ev);
                    }
                    let rel = v[s.b] - v[s.a];
                    let damp = beta_s * axial_el * ev.dir.dot(&rel);
                    let mut ga = ev.dir * ((ev.tension + damp) * hf);
                    if matrix {
                        let kmat = ev.stiffness();
                        ga += kmat * rel * hk;
                        let c = ev.dir * ev.dir.transpose() * (beta_s * axial_el);
                        bl[k] = Sym3::from_upper(&(kmat * hk + c * inp.dt));
                    }
                    g[k] = ga;
                }
                *ep = e;
            });
        // shear cells: two spring-like diagonals each
        model
            .shear_quads
            .par_chunks(CHUNK)
            .zip(blocks_q.par_chunks_mut(2 * CHUNK))
            .zip(g_q.par_chunks_mut(2 * CHUNK))
            .zip(ep_q.par_iter_mut())
            .enumerate()
            .for_each(|(c, (((qs, bl), g), ep))| {
                let mut e = 0.0;
                for k in 0..qs.len() {
                    let q = &qs[k];
                    let sm = q.measure(x);
                    let gamma = sm.gamma;
                    let (mut hs, mut dhs, w) = law.shear(gamma);
                    let dhs_el = dhs;
                    if let Some(f) = fr_shear {
                        // SAFETY: element c·CHUNK + k is visited by this iteration only.
                        let st = unsafe { &mut *st_q.at(c * CHUNK + k) };
                        *st = cm_q[c * CHUNK + k];
                        if st[0].is_nan() {
                            *st = [gamma, 0.0];
                        }
                        let (z, dz) = f.update(st[0], st[1], gamma, hs, dhs);
                        *st = [gamma, z];
                        hs += z;
                        dhs += dz;
                    }
                    e += q.area * w;
                    for m in 0..2 {
                        let (a, b) = (q.nodes[2 * m], q.nodes[2 * m + 1]);
                        let d = sm.d[m];
                        // γ depends on |d|² with slope dg: ∂γ/∂x_b = 2 dg d
                        let gk = 2.0 * sm.dg[m];
                        let rel = v[b] - v[a];
                        let ddt = d * d.transpose();
                        let axial = ddt * (2.0 * q.area * gk * gk);
                        let cdamp = axial * (beta_s * dhs_el);
                        // force on the diagonal's first node (the second gets the opposite)
                        let mut ga = d * (q.area * hs * gk * hf) + cdamp * rel * hf;
                        if matrix {
                            let kmat = axial * dhs.max(0.0)
                                + Mat3::identity() * (q.area * hs * gk).max(0.0);
                            ga += kmat * rel * hk;
                            bl[2 * k + m] = Sym3::from_upper(&(kmat * hk + cdamp * inp.dt));
                        }
                        g[2 * k + m] = ga;
                    }
                }
                *ep = e;
            });
        // bending lines
        model
            .bend_lines
            .par_chunks(CHUNK)
            .zip(blocks_b.par_chunks_mut(CHUNK))
            .zip(g_b.par_chunks_mut(3 * CHUNK))
            .zip(ep_b.par_iter_mut())
            .enumerate()
            .for_each(|(c, (((els, bl), g), ep))| {
                let mut e = 0.0;
                for k in 0..els.len() {
                    let el = &els[k];
                    let geo = el.geometry(x);
                    let kappa = geo.qn.norm();
                    let (m_el, dm, en) = law.bending(el.dir, kappa);
                    let (mut mv, mut s) = BendLine::elastic(&geo, m_el, dm);
                    let f2 = el.area * geo.scale * geo.scale;
                    let s_el = s * f2;
                    let fr = match el.dir {
                        Direction::Warp => fr_bend_u,
                        Direction::Weft => fr_bend_v,
                    };
                    if let Some(f) = fr {
                        // SAFETY: element c·CHUNK + k is visited by this iteration only.
                        let st = unsafe { &mut *st_b.at(c * CHUNK + k) };
                        *st = cm_b[c * CHUNK + k];
                        // scalar friction on the signed curvature, its sign kept continuous
                        // through the reference direction st[1] (rotation does not slide it)
                        let r_old = st[1];
                        let sgn = if r_old.dot(&geo.qn) < 0.0 { -1.0 } else { 1.0 };
                        let ks = sgn * kappa;
                        if st[0].x.is_nan() {
                            st[0] = Vec3::new(ks, 0.0, 0.0);
                        }
                        let (z, dz) = f.update(st[0].x, st[0].y, ks, sgn * m_el, dm);
                        if kappa > 1e-9 {
                            let qh = geo.qn / kappa;
                            let qq = qh * qh.transpose();
                            mv += qh * (sgn * z);
                            s += qq * dz.max(0.0)
                                + (Mat3::identity() - qq) * (sgn * z / kappa).max(0.0);
                            st[1] = qh * sgn;
                        } else {
                            mv += r_old * z;
                            s += Mat3::identity() * dz.max(0.0);
                        }
                        st[0] = Vec3::new(ks, z, 0.0);
                    }
                    let s = s * f2;
                    e += el.area * en;
                    let forces = el.forces(&geo, &mv);
                    let [a, b, cc] = el.nodes;
                    let w = v[a] * el.coef[0] + v[b] * el.coef[1] + v[cc] * el.coef[2];
                    let sw = s * w;
                    let dw = s_el * w * beta_b;
                    // f_m − β c_m S_el w (damping), and the K v term c_m S w
                    for m in 0..3 {
                        let cm = el.coef[m];
                        g[3 * k + m] = (forces[m] - dw * cm) * hf - sw * (cm * hk);
                    }
                    if matrix {
                        bl[k] = Sym3::from_upper(&(s * hk + s_el * (inp.dt * beta_b)));
                    }
                }
                *ep = e;
            });
        // hinges
        let hinge_e: f64 = if model.hinges.is_empty() {
            0.0
        } else {
            model
                .hinges
                .par_chunks(CHUNK)
                .zip(blocks_h.par_chunks_mut(16 * CHUNK))
                .zip(g_h.par_chunks_mut(4 * CHUNK))
                .zip(ep_h.par_iter_mut())
                .enumerate()
                .for_each(|(c, (((els, bl), g), ep))| {
                    let mut e = 0.0;
                    for k in 0..els.len() {
                        let el = &els[k];
                        let angle = if el.weight > 0.0 {
                            el.angle_and_gradient(x)
                        } else {
                            None
                        };
                        let Some((theta, grad)) = angle else {
                            clear_four_node_element(g, bl, k);
                            continue;
                        };
                        let kappa = theta.abs() * el.edge / el.area;
                        let (mo, dm, w) = el.law(law, kappa);
                        let (mo, dm, w) = (mo * el.weight, dm * el.weight, w * el.weight);
                        e += el.area * w;
                        // signed moment per width and its tangent in signed curvature
                        let (mut ms, mut dms) = (mo * theta.signum(), dm);
                        let fr = if el.warp_weight >= 0.5 {
                            fr_bend_u
                        } else {
                            fr_bend_v
                        };
                        if let Some(f) = fr {
                            // SAFETY: element c·CHUNK + k is visited by this iteration only.
                            let st = unsafe { &mut *st_h.at(c * CHUNK + k) };
                            *st = cm_h[c * CHUNK + k];
                            let ks = theta * el.edge / el.area;
                            if st[0].is_nan() {
                                *st = [ks, 0.0];
                            }
                            let (z, dz) = f.update(st[0], st[1], ks, ms, dms);
                            *st = [ks, z];
                            ms += z;
                            dms += dz;
                        }
                        let dedtheta = el.edge * ms;
                        let stiff_el = dm * el.edge * el.edge / el.area;
                        let stiff = dms.max(0.0) * el.edge * el.edge / el.area;
                        let gv: f64 = (0..4).map(|m| grad[m].dot(&v[el.nodes[m]])).sum();
                        for m in 0..4 {
                            g[4 * k + m] = -grad[m]
                                * (dedtheta * hf + stiff_el * gv * beta_b * hf + stiff * gv * hk);
                            if matrix {
                                for q in 0..4 {
                                    bl[16 * k + 4 * m + q] = grad[m]
                                        * grad[q].transpose()
                                        * (stiff * hk + stiff_el * inp.dt * beta_b);
                                }
                            }
                        }
                    }
                    *ep = e;
                });
            ordered_sum(&ep_h[..chunks(model.hinges.len(), CHUNK)])
        };
        // Choi–Ko's arc connections: the stable part axial · ∇l ∇lᵀ, stretch damping
        let arc_e: f64 = if model.arcs.is_empty() {
            0.0
        } else {
            model
                .arcs
                .par_chunks(CHUNK)
                .zip(blocks_a.par_chunks_mut(16 * CHUNK))
                .zip(g_a.par_chunks_mut(4 * CHUNK))
                .zip(ep_a.par_iter_mut())
                .for_each(|(((els, bl), g), ep)| {
                    let mut e = 0.0;
                    for k in 0..els.len() {
                        let el = &els[k];
                        let Some(ev) = el.eval(law, x) else {
                            clear_four_node_element(g, bl, k);
                            continue;
                        };
                        e += ev.energy;
                        let grad = ev.grad;
                        // the matrix's part of the gradient: along the chord, on the ends
                        let gc = [-ev.chord, ev.chord, Vec3::zeros(), Vec3::zeros()];
                        let rate: f64 = (0..4).map(|m| grad[m].dot(&v[el.nodes[m]])).sum();
                        let rate_c = ev.chord.dot(&(v[el.nodes[1]] - v[el.nodes[0]]));
                        let force = (ev.tension + beta_s * ev.axial * rate) * hf;
                        let kv = ev.axial * rate_c * hk;
                        let kc = ev.axial * (hk + beta_s * inp.dt);
                        // the arc's bending stiffness acts on the middle's offset from the
                        // ends' midpoint, m − (a + c)/2: weights −½, −½, ½, ½
                        const W: [f64; 4] = [-0.5, -0.5, 0.5, 0.5];
                        let vr =
                            (v[el.nodes[2]] + v[el.nodes[3]] - v[el.nodes[0]] - v[el.nodes[1]])
                                * 0.5;
                        let mv = ev.middle * vr * hk;
                        for m in 0..4 {
                            g[4 * k + m] = -grad[m] * force - gc[m] * kv - mv * W[m];
                            if matrix {
                                for q in 0..4 {
                                    bl[16 * k + 4 * m + q] = gc[m] * gc[q].transpose() * kc
                                        + ev.middle * (W[m] * W[q] * hk);
                                }
                            }
                        }
                    }
                    *ep = e;
                });
            ordered_sum(&ep_a[..chunks(model.arcs.len(), CHUNK)])
        };
        ordered_sum(&ep_s[..nsc])
            + ordered_sum(&ep_q[..nqc])
            + ordered_sum(&ep_b[..nbc])
            + hinge_e
            + arc_e
    }
    }

    multiversion! {
    fn gather_pass / gather_pass_avx2(
        &mut self,
        model: &ClothModel,
        v: &[Vec3],
        inp: AssemblyInputs,
    ) {
        let n = model.particle_count();
        let drag = model.fabric.air_drag;
        let h = inp.dt;
        let matrix = inp.matrix;
        // general blocks in `values`, or symmetric ones in `sym` (or none, single-precision
        // mirrors only), always with a mirror: see `Bcsr3::store_symmetric`
        let general = !self.a.values.is_empty();
        assert!(
            general || !self.a.values32.is_empty(),
            "a matrix without general blocks keeps its single-precision mirror"
        );
        let values = SyncPtr(self.a.values.as_mut_ptr());
        let sym = (!self.a.sym.is_empty()).then_some(SyncPtr(self.a.sym.as_mut_ptr()));
        let mirror = !self.a.values32.is_empty();
        let jacobi = self.jacobi;
        let values32 = SyncPtr(self.a.values32.as_mut_ptr());
        let (perm32, perm_start) = match &mut self.a.permuted {
            Some(pm) => (Some(SyncPtr(pm.values.as_mut_ptr())), &pm.row_start[..]),
            None => (None, &[][..]),
        };
        let (row_ptr, diag) = (&self.a.row_ptr, &self.a.diag);
        let (recs, rec_ptr, grecs, grec_ptr) =
            (&self.recs, &self.rec_ptr, &self.grecs, &self.grec_ptr);
        let (rec_scale, scales, spill) = (&self.rec_scale, &self.scales, &self.scale_spill);
        let scale = |k: usize| match rec_scale[k] {
            SPILL => spill[k],
            t => scales[t as usize],
        };
        let (blocks, hinge_blocks, g) = (&self.blocks, &self.hinge_blocks, &self.g);
        let nsym = self.hinge_block0;
        self.b
            .par_chunks_mut(CHUNK)
            .zip(self.pinv.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(c, (bs, ps))| {
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
            });
        debug_assert_eq!(self.b.len(), n);
    }
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
/// Zeroes the force terms and the 4 × 4 stiffness blocks of four-node element `k` of a chunk
/// (a hinge or an arc that contributes nothing this step).
fn clear_four_node_element(g: &mut [Vec3], blocks: &mut [Mat3], k: usize) {
    g[4 * k..4 * k + 4].fill(Vec3::zeros());
    blocks[16 * k..16 * k + 16].fill(Mat3::zeros());
}

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
