//! Each force element's contribution to the implicit system, behind one trait
//! ([`Contribution`]) and evaluated by one deterministic parallel loop ([`contribute_all`]):
//! a spring, a shear cell, a bending line, a hinge or a Choi–Ko arc connection writes its
//! right-hand-side terms and, in matrix mode, its stiffness blocks into its own slots of the
//! assembly's flat buffers, and returns its elastic energy. The energy is summed per chunk in
//! element order and the chunks' sums in chunk order.

use rayon::prelude::*;

use super::bcsr::Sym3;
use super::parallel::{chunks, ordered_sum, SyncPtr, CHUNK};
#[cfg(target_arch = "x86_64")]
use super::simd::Level;
use crate::cloth::buckling::arc_connection::ArcConnection;
use crate::cloth::elements::material::{Direction, Friction, MaterialLaw};
use crate::cloth::elements::{BendLine, Hinge, ShearQuad, Spring, SpringKind};
use crate::geometry::{Mat3, Vec3};

/// What every element sees during one evaluation: the state, the step's factors and the
/// material's friction (`None` where the law has none or friction states are off).
pub(crate) struct Pass<'a> {
    /// The material law.
    pub law: &'a dyn MaterialLaw,
    /// Positions.
    pub x: &'a [Vec3],
    /// Velocities.
    pub v: &'a [Vec3],
    /// Force factor: h in matrix mode, 1 for forces only.
    pub hf: f64,
    /// Stiffness factor: h² in matrix mode, 0 for forces only.
    pub hk: f64,
    /// Step length h (s).
    pub dt: f64,
    /// Whether the stiffness blocks are wanted.
    pub matrix: bool,
    /// Stretch damping coefficient.
    pub beta_s: f64,
    /// Bending damping coefficient.
    pub beta_b: f64,
    /// Internal friction of warp tension.
    pub fr_warp: Option<Friction>,
    /// Internal friction of weft tension.
    pub fr_weft: Option<Friction>,
    /// Internal friction of shear.
    pub fr_shear: Option<Friction>,
    /// Internal friction of warp bending.
    pub fr_bend_u: Option<Friction>,
    /// Internal friction of weft bending.
    pub fr_bend_v: Option<Friction>,
}

/// One element's friction state: its committed value and its trial slot.
pub(crate) struct FrictionSlot<'a, T> {
    committed: &'a [T],
    trial: SyncPtr<T>,
    index: usize,
}

impl<T: Copy> FrictionSlot<'_, T> {
    /// The element's trial state, reset to its committed one.
    #[inline]
    pub fn load(&mut self) -> &mut T {
        // SAFETY: element `index` is visited by one iteration of one loop only, and the trial
        // states are as many as the committed ones whenever a law with friction asks for them.
        let st = unsafe { &mut *self.trial.at(self.index) };
        *st = self.committed[self.index];
        st
    }
}

/// A kind of force element as the assembly evaluates it.
pub(crate) trait Contribution: Sync {
    /// Per-element internal-friction state.
    type State: Copy + Send + Sync;
    /// Stiffness block type.
    type Block: Send;
    /// Stiffness blocks per element.
    const BLOCKS: usize;
    /// Right-hand-side terms per element.
    const TERMS: usize;
    /// Writes the element's right-hand-side terms `g` (`TERMS` of them) and, in matrix mode,
    /// its stiffness blocks `bl` (`BLOCKS`); returns its elastic energy.
    fn contribute(
        &self,
        p: &Pass<'_>,
        state: FrictionSlot<'_, Self::State>,
        g: &mut [Vec3],
        bl: &mut [Self::Block],
    ) -> f64;
}

/// Evaluates every element of `els` in parallel chunks into `blocks`, `g` and the per-chunk
/// energies `ep`, with friction states `committed` / `trial`; returns the energy, summed in
/// element order within a chunk and in chunk order across them. The loop is compiled twice
/// and runs its AVX2 form where the CPU has it (bit-identical: see [`super::simd`]).
pub(crate) fn contribute_all<E: Contribution>(
    els: &[E],
    p: &Pass<'_>,
    blocks: &mut [E::Block],
    g: &mut [Vec3],
    ep: &mut [f64],
    committed: &[E::State],
    trial: SyncPtr<E::State>,
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    match super::simd::level() {
        // SAFETY: the CPU has the features (checked at run time).
        Level::Avx512 => {
            return unsafe { contribute_all_avx512(els, p, blocks, g, ep, committed, trial) }
        }
        // SAFETY: as above.
        Level::Avx2 => {
            return unsafe { contribute_all_avx2(els, p, blocks, g, ep, committed, trial) }
        }
        Level::Generic => {}
    }
    contribute_loop!(els, p, blocks, g, ep, committed, trial)
}

/// [`contribute_all`] compiled for AVX2 and FMA (the closure handed to rayon inherits them).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn contribute_all_avx2<E: Contribution>(
    els: &[E],
    p: &Pass<'_>,
    blocks: &mut [E::Block],
    g: &mut [Vec3],
    ep: &mut [f64],
    committed: &[E::State],
    trial: SyncPtr<E::State>,
) -> f64 {
    contribute_loop!(els, p, blocks, g, ep, committed, trial)
}

/// [`contribute_all`] compiled for AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl,avx512bw,avx512dq,avx512cd")]
fn contribute_all_avx512<E: Contribution>(
    els: &[E],
    p: &Pass<'_>,
    blocks: &mut [E::Block],
    g: &mut [Vec3],
    ep: &mut [f64],
    committed: &[E::State],
    trial: SyncPtr<E::State>,
) -> f64 {
    contribute_loop!(els, p, blocks, g, ep, committed, trial)
}

/// The body of [`contribute_all`], written once for both of its forms.
macro_rules! contribute_loop {
    ($els:expr, $p:expr, $blocks:expr, $g:expr, $ep:expr, $committed:expr, $trial:expr) => {{
        let (els, p, ep, committed, trial) = ($els, $p, $ep, $committed, $trial);
        els.par_chunks(CHUNK)
            .zip($blocks.par_chunks_mut(E::BLOCKS * CHUNK))
            .zip($g.par_chunks_mut(E::TERMS * CHUNK))
            .zip(ep.par_iter_mut())
            .enumerate()
            .for_each(|(c, (((els, bl), g), ep))| {
                let mut e = 0.0;
                for k in 0..els.len() {
                    let state = FrictionSlot {
                        committed,
                        trial,
                        index: c * CHUNK + k,
                    };
                    let (t, b) = (E::TERMS * k, E::BLOCKS * k);
                    e += els[k].contribute(
                        p,
                        state,
                        &mut g[t..t + E::TERMS],
                        &mut bl[b..b + E::BLOCKS],
                    );
                }
                *ep = e;
            });
        ordered_sum(&ep[..chunks(els.len(), CHUNK)])
    }};
}
use contribute_loop;

impl Contribution for Spring {
    type State = [f64; 2];
    type Block = Sym3;
    const BLOCKS: usize = 1;
    const TERMS: usize = 1;

    #[inline(always)]
    fn contribute(
        &self,
        p: &Pass<'_>,
        mut state: FrictionSlot<'_, [f64; 2]>,
        g: &mut [Vec3],
        bl: &mut [Sym3],
    ) -> f64 {
        let (s, x, v) = (self, p.x, p.v);
        let mut ev = s.eval(p.law, &x[s.a], &x[s.b]);
        let energy = ev.energy;
        let fr = match s.kind {
            SpringKind::Stretch { warp_weight } if warp_weight >= 0.5 => p.fr_warp,
            SpringKind::Stretch { .. } => p.fr_weft,
            SpringKind::Shear => p.fr_shear,
            SpringKind::Seam { .. } | SpringKind::Flexion { .. } => None,
        };
        let axial_el = ev.axial;
        if let Some(f) = fr {
            s.add_friction(&f, state.load(), &x[s.a], &x[s.b], &mut ev);
        }
        let rel = v[s.b] - v[s.a];
        let damp = p.beta_s * axial_el * ev.dir.dot(&rel);
        let mut ga = ev.dir * ((ev.tension + damp) * p.hf);
        if p.matrix {
            let kmat = ev.stiffness();
            ga += kmat * rel * p.hk;
            let c = ev.dir * ev.dir.transpose() * (p.beta_s * axial_el);
            bl[0] = Sym3::from_upper(&(kmat * p.hk + c * p.dt));
        }
        g[0] = ga;
        energy
    }
}

/// A shear cell: two spring-like diagonals.
impl Contribution for ShearQuad {
    type State = [f64; 2];
    type Block = Sym3;
    const BLOCKS: usize = 2;
    const TERMS: usize = 2;

    #[inline(always)]
    fn contribute(
        &self,
        p: &Pass<'_>,
        mut state: FrictionSlot<'_, [f64; 2]>,
        g: &mut [Vec3],
        bl: &mut [Sym3],
    ) -> f64 {
        let (q, v) = (self, p.v);
        let sm = q.measure(p.x);
        let gamma = sm.gamma;
        let (mut hs, mut dhs, w) = p.law.shear(gamma);
        let dhs_el = dhs;
        if let Some(f) = p.fr_shear {
            let st = state.load();
            if st[0].is_nan() {
                *st = [gamma, 0.0];
            }
            let (z, dz) = f.update(st[0], st[1], gamma, hs, dhs);
            *st = [gamma, z];
            hs += z;
            dhs += dz;
        }
        let energy = q.area * w;
        for m in 0..2 {
            let (a, b) = (q.nodes[2 * m], q.nodes[2 * m + 1]);
            let d = sm.d[m];
            // γ depends on |d|² with slope dg: ∂γ/∂x_b = 2 dg d
            let gk = 2.0 * sm.dg[m];
            let rel = v[b] - v[a];
            let ddt = d * d.transpose();
            let axial = ddt * (2.0 * q.area * gk * gk);
            let cdamp = axial * (p.beta_s * dhs_el);
            // force on the diagonal's first node (the second gets the opposite)
            let mut ga = d * (q.area * hs * gk * p.hf) + cdamp * rel * p.hf;
            if p.matrix {
                let kmat = axial * dhs.max(0.0) + Mat3::identity() * (q.area * hs * gk).max(0.0);
                ga += kmat * rel * p.hk;
                bl[m] = Sym3::from_upper(&(kmat * p.hk + cdamp * p.dt));
            }
            g[m] = ga;
        }
        energy
    }
}

impl Contribution for BendLine {
    type State = [Vec3; 2];
    type Block = Sym3;
    const BLOCKS: usize = 1;
    const TERMS: usize = 3;

    #[inline(always)]
    fn contribute(
        &self,
        p: &Pass<'_>,
        mut state: FrictionSlot<'_, [Vec3; 2]>,
        g: &mut [Vec3],
        bl: &mut [Sym3],
    ) -> f64 {
        let (el, v) = (self, p.v);
        let geo = el.geometry(p.x);
        let kappa = geo.qn.norm();
        let (m_el, dm, en) = p.law.bending(el.dir, kappa);
        let (mut mv, mut s) = BendLine::elastic(&geo, m_el, dm);
        let f2 = el.area * geo.scale * geo.scale;
        let s_el = s * f2;
        let fr = match el.dir {
            Direction::Warp => p.fr_bend_u,
            Direction::Weft => p.fr_bend_v,
        };
        if let Some(f) = fr {
            let st = state.load();
            // scalar friction on the signed curvature, its sign kept continuous through the
            // reference direction st[1] (rotation does not slide it)
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
                s += qq * dz.max(0.0) + (Mat3::identity() - qq) * (sgn * z / kappa).max(0.0);
                st[1] = qh * sgn;
            } else {
                mv += r_old * z;
                s += Mat3::identity() * dz.max(0.0);
            }
            st[0] = Vec3::new(ks, z, 0.0);
        }
        let s = s * f2;
        let energy = el.area * en;
        let forces = el.forces(&geo, &mv);
        let [a, b, cc] = el.nodes;
        let w = v[a] * el.coef[0] + v[b] * el.coef[1] + v[cc] * el.coef[2];
        let sw = s * w;
        let dw = s_el * w * p.beta_b;
        // f_m − β c_m S_el w (damping), and the K v term c_m S w
        for m in 0..3 {
            let cm = el.coef[m];
            g[m] = (forces[m] - dw * cm) * p.hf - sw * (cm * p.hk);
        }
        if p.matrix {
            bl[0] = Sym3::from_upper(&(s * p.hk + s_el * (p.dt * p.beta_b)));
        }
        energy
    }
}

/// Zeroes the force terms and the 4 × 4 stiffness blocks of a four-node element (a hinge or
/// an arc that contributes nothing this step).
fn clear_four_node_element(g: &mut [Vec3], blocks: &mut [Mat3]) {
    g.fill(Vec3::zeros());
    blocks.fill(Mat3::zeros());
}

impl Contribution for Hinge {
    type State = [f64; 2];
    type Block = Mat3;
    const BLOCKS: usize = 16;
    const TERMS: usize = 4;

    #[inline(always)]
    fn contribute(
        &self,
        p: &Pass<'_>,
        mut state: FrictionSlot<'_, [f64; 2]>,
        g: &mut [Vec3],
        bl: &mut [Mat3],
    ) -> f64 {
        let (el, v) = (self, p.v);
        let angle = if el.weight > 0.0 {
            el.angle_and_gradient(p.x)
        } else {
            None
        };
        let Some((theta, grad)) = angle else {
            clear_four_node_element(g, bl);
            return 0.0;
        };
        let kappa = theta.abs() * el.edge / el.area;
        let (mo, dm, w) = el.law(p.law, kappa);
        let (mo, dm, w) = (mo * el.weight, dm * el.weight, w * el.weight);
        let energy = el.area * w;
        // signed moment per width and its tangent in signed curvature
        let (mut ms, mut dms) = (mo * theta.signum(), dm);
        let fr = if el.warp_weight >= 0.5 {
            p.fr_bend_u
        } else {
            p.fr_bend_v
        };
        if let Some(f) = fr {
            let st = state.load();
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
            g[m] =
                -grad[m] * (dedtheta * p.hf + stiff_el * gv * p.beta_b * p.hf + stiff * gv * p.hk);
            if p.matrix {
                for q in 0..4 {
                    bl[4 * m + q] =
                        grad[m] * grad[q].transpose() * (stiff * p.hk + stiff_el * p.dt * p.beta_b);
                }
            }
        }
        energy
    }
}

/// Choi–Ko's arc connection: the stable part axial · ∇l ∇lᵀ, stretch damping.
impl Contribution for ArcConnection {
    type State = ();
    type Block = Mat3;
    const BLOCKS: usize = 16;
    const TERMS: usize = 4;

    #[inline(always)]
    fn contribute(
        &self,
        p: &Pass<'_>,
        _state: FrictionSlot<'_, ()>,
        g: &mut [Vec3],
        bl: &mut [Mat3],
    ) -> f64 {
        let (el, v) = (self, p.v);
        let Some(ev) = el.eval(p.law, p.x) else {
            clear_four_node_element(g, bl);
            return 0.0;
        };
        let energy = ev.energy;
        let grad = ev.grad;
        // the matrix's part of the gradient: along the chord, on the ends
        let gc = [-ev.chord, ev.chord, Vec3::zeros(), Vec3::zeros()];
        let rate: f64 = (0..4).map(|m| grad[m].dot(&v[el.nodes[m]])).sum();
        let rate_c = ev.chord.dot(&(v[el.nodes[1]] - v[el.nodes[0]]));
        let force = (ev.tension + p.beta_s * ev.axial * rate) * p.hf;
        let kv = ev.axial * rate_c * p.hk;
        let kc = ev.axial * (p.hk + p.beta_s * p.dt);
        // the arc's bending stiffness acts on the middle's offset from the ends' midpoint,
        // m − (a + c)/2: weights −½, −½, ½, ½
        const W: [f64; 4] = [-0.5, -0.5, 0.5, 0.5];
        let vr = (v[el.nodes[2]] + v[el.nodes[3]] - v[el.nodes[0]] - v[el.nodes[1]]) * 0.5;
        let mv = ev.middle * vr * p.hk;
        for m in 0..4 {
            g[m] = -grad[m] * force - gc[m] * kv - mv * W[m];
            if p.matrix {
                for q in 0..4 {
                    bl[4 * m + q] =
                        gc[m] * gc[q].transpose() * kc + ev.middle * (W[m] * W[q] * p.hk);
                }
            }
        }
        energy
    }
}
