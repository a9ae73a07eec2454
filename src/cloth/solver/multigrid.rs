//! Geometric multigrid preconditioner for grid cloths: a hierarchy of coarser grid cloths of the
//! same fabric (rediscretised: each level assembles its own implicit matrix at positions and
//! velocities sampled from the finer level), bilinear transfer in the rest plane, and
//! alternating warp/weft block-line smoothing. One symmetric V-cycle per application keeps the
//! CG iteration count nearly independent of resolution. Built once per topology; no allocation
//! per step.

use super::assembly::{Assembly, AssemblyInputs};
use super::bcsr::{Bcsr3, Sym3f};
pub use super::galerkin::ContactCoarsening;
use super::galerkin::{self, Changes, FineConstraints, GalerkinTransfer, HalfProduct};
use super::grid_transfer::{sample, sampling, Transfer};
use super::line_solver::{weft_order, LineDir, LineSolver};
use super::vcycle::{self, Hierarchy};
use crate::cloth::constraints::{Filter, ParticleFilter};
use crate::cloth::model::ClothModel;
use crate::cloth::ClothError;
use crate::geometry::Vec3;

/// Coarsest grid size (particles per side) at which the V-cycle stops coarsening.
const COARSEST: usize = 6;
/// Smoothing sweeps on the coarsest level.
const COARSE_SWEEPS: usize = 3;

/// One coarse level: its own cloth model and assembly, and scratch vectors.
#[derive(Debug)]
struct Level {
    /// `None` on the finest level (which uses the simulation's own matrix).
    model: Option<ClothModel>,
    asm: Option<Assembly>,
    lines: LineSolver,
    fixed: Vec<bool>,
    /// Constrained directions of each particle (contact normals; zero when free) and the
    /// penalty blocks κ n nᵀ that stand for them in this level's operator.
    pen_dir: Vec<Vec3>,
    pen: Vec<Sym3f>,
    penalized: bool,
    /// `pen_dir` in the weft numbering, where the transfers work.
    dir_weft: Vec<Vec3>,
    /// Transfer from the next coarser level to this one, this level's particles in the weft
    /// numbering (where its residual is formed and its correction lives between the two
    /// weft sweeps).
    to_fine: Option<Transfer>,
    /// Sampling of this level's state from the next finer level (coarse levels only).
    sample: Vec<[(u32, f64); 4]>,
    /// Grid size (particles per side).
    dims: (usize, usize),
    /// The Galerkin operator used while contacts constrain the cloth (coarse levels only;
    /// built on the first such step).
    gal: Option<GalerkinOp>,
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    r: Vec<Vec3>,
    e: Vec<Vec3>,
    d: Vec<Vec3>,
}

/// A coarse level's Galerkin operator, its line factors and the transfer from the finer level
/// in row numbering.
#[derive(Debug)]
struct GalerkinOp {
    a: Bcsr3,
    lines: LineSolver,
    from_fine: GalerkinTransfer,
    half: HalfProduct,
}

/// The multigrid hierarchy of one grid cloth.
#[derive(Debug)]
pub struct Multigrid {
    levels: Vec<Level>,
    /// How contacts reach the coarse levels.
    pub contact: ContactCoarsening,
    /// Whether this step's coarse levels are Galerkin operators.
    galerkin_now: bool,
    /// Accumulated wall time in `setup` and `apply` (s), and the number of applications.
    pub timing: (f64, f64, u64),
    /// Scratch of a setup after a change of filter only.
    refit: Changes,
}

impl Multigrid {
    /// Builds the hierarchy for `model`, which must be a grid cloth with matrix pattern `a`
    /// (whose single-precision mirrors the smoother reads: they are enabled here).
    pub fn new(model: &ClothModel, a: &mut Bcsr3) -> Result<Self, ClothError> {
        let Some((nx, ny)) = model.grid else {
            return Err(ClothError::Parameter(
                "the multigrid preconditioner needs a grid cloth".into(),
            ));
        };
        let (w, h) = grid_extent(model, nx, ny);
        let n = nx * ny;
        let lines = LineSolver::new(a, nx, ny);
        // a grid's blocks are symmetric: the conjugate gradient's products then stream two
        // thirds of the bytes (rows too long for that keep general blocks)
        a.store_symmetric();
        let mut levels = vec![Level {
            model: None,
            asm: None,
            lines,
            fixed: vec![false; n],
            pen_dir: vec![Vec3::zeros(); n],
            pen: vec![Sym3f::default(); n],
            penalized: false,
            dir_weft: vec![Vec3::zeros(); n],
            to_fine: None,
            sample: Vec::new(),
            dims: (nx, ny),
            gal: None,
            x: Vec::new(),
            v: Vec::new(),
            r: vec![Vec3::zeros(); n],
            e: vec![Vec3::zeros(); n],
            d: vec![Vec3::zeros(); n],
        }];
        let (mut fx, mut fy) = (nx, ny);
        while fx.max(fy) > COARSEST && fx.min(fy) >= 4 {
            let (cx, cy) = (fx.div_ceil(2).max(2), fy.div_ceil(2).max(2));
            let cm = ClothModel::grid(w, h, cx, cy, model.fabric)?;
            let mut cm = cm;
            cm.set_law(model.law.clone());
            if model.choi_ko {
                cm.enable_choi_ko();
            }
            let mut asm = Assembly::new(&cm);
            asm.jacobi = false;
            let nc = cx * cy;
            let lines = LineSolver::new(&mut asm.a, cx, cy);
            // only the smoother reads a coarse level's matrix, in single precision
            asm.a.store_single_only();
            let to_fine = Transfer::new((fx, fy), (cx, cy)).permuted_fine(&weft_order(fx, fy));
            levels.last_mut().expect("level").to_fine = Some(to_fine);
            levels.push(Level {
                model: Some(cm),
                asm: Some(asm),
                lines,
                fixed: vec![false; nc],
                pen_dir: vec![Vec3::zeros(); nc],
                pen: vec![Sym3f::default(); nc],
                penalized: false,
                dir_weft: vec![Vec3::zeros(); nc],
                to_fine: None,
                sample: sampling((fx, fy), (cx, cy)),
                dims: (cx, cy),
                gal: None,
                x: vec![Vec3::zeros(); nc],
                v: vec![Vec3::zeros(); nc],
                r: vec![Vec3::zeros(); nc],
                e: vec![Vec3::zeros(); nc],
                d: vec![Vec3::zeros(); nc],
            });
            (fx, fy) = (cx, cy);
        }
        // the Galerkin products need a finest pattern coupling particles at most two apart
        // (every grid cloth's); another keeps the rediscretised levels in contact too
        let mut contact = ContactCoarsening::from_env();
        if let Some(c) = levels.get(1) {
            let t = GalerkinTransfer::new(Transfer::new(levels[0].dims, c.dims).taps, c.dims);
            if contact == ContactCoarsening::Galerkin && !galerkin::windows_fit(a, &t) {
                contact = ContactCoarsening::Injected;
            }
        }
        Ok(Multigrid {
            levels,
            contact,
            galerkin_now: false,
            timing: (0.0, 0.0, 0),
            refit: Changes::default(),
        })
    }

    /// Number of levels including the finest.
    pub fn depth(&self) -> usize {
        self.levels.len()
    }

    /// Writes what carries from one step to the next: the coarse levels' friction states.
    pub fn save_state(&self, e: &mut crate::geometry::checkpoint::Encoder) {
        for asm in self.levels.iter().filter_map(|l| l.asm.as_ref()) {
            asm.save_friction(e);
        }
    }

    /// Reads what [`Multigrid::save_state`] wrote.
    pub fn load_state(
        &mut self,
        d: &mut crate::geometry::checkpoint::Decoder,
    ) -> Result<(), crate::geometry::GeometryError> {
        for asm in self.levels.iter_mut().filter_map(|l| l.asm.as_mut()) {
            asm.load_friction(d)?;
        }
        Ok(())
    }

    /// Rebuilds every level's operator for the current step: coarse states sampled from the
    /// fine one, coarse matrices assembled, fixed particles mapped, lines factorised. The
    /// filter's fixed particles are fixed on every level; its velocity-constrained directions
    /// (contacts) enter each level's operator as stiff penalty springs κ n nᵀ, so that the
    /// V-cycle approximates the inverse of the constrained system rather than the free one.
    /// While any particle is in contact the coarse levels are instead Galerkin products of
    /// the level above (with [`ContactCoarsening::Galerkin`], the default), which carry every
    /// constraint down exactly.
    ///
    /// `refilter` says that only the filter changed since the last call (the same matrix `a`,
    /// the same state: a step solved again after a stage loosened constraints); the Galerkin
    /// coarse rows are then rebuilt only where a changed particle reaches them, with the same
    /// result as a full rebuild.
    pub fn setup(
        &mut self,
        a: &Bcsr3,
        x: &[Vec3],
        v: &[Vec3],
        filter: &Filter,
        inp: AssemblyInputs,
        refilter: bool,
    ) {
        let t0 = std::time::Instant::now();
        let was_galerkin = self.galerkin_now;
        {
            let l0 = &mut self.levels[0];
            let changed = &mut self.refit.changed;
            changed.clear();
            l0.penalized = false;
            for (i, k) in filter.kind.iter().enumerate() {
                let fixed = matches!(k, ParticleFilter::Fixed { .. });
                let dir = match k {
                    ParticleFilter::Normal { normal, .. } => {
                        l0.penalized = true;
                        *normal
                    }
                    _ => Vec3::zeros(),
                };
                if refilter && (fixed != l0.fixed[i] || dir != l0.pen_dir[i]) {
                    changed.push(i as u32);
                }
                l0.fixed[i] = fixed;
                l0.pen_dir[i] = dir;
            }
            if l0.penalized {
                fill_penalty(a, &l0.pen_dir, &mut l0.pen);
                if self.contact == ContactCoarsening::Projected {
                    l0.lines.to_weft(&l0.pen_dir, &mut l0.dir_weft);
                }
            }
            let pen = l0.penalized.then_some(&l0.pen[..]);
            l0.lines.factor(a, &l0.fixed, pen);
        }
        self.galerkin_now = self.levels[0].penalized && self.contact == ContactCoarsening::Galerkin;
        if self.galerkin_now {
            let only_changed = refilter && was_galerkin;
            self.setup_galerkin(a, only_changed);
            self.timing.0 += t0.elapsed().as_secs_f64();
            return;
        }
        for l in 1..self.levels.len() {
            let (fine, coarse) = self.levels.split_at_mut(l);
            let f = &fine[l - 1];
            let c = &mut coarse[0];
            let (fxs, fvs): (&[Vec3], &[Vec3]) = if l == 1 { (x, v) } else { (&f.x, &f.v) };
            sample(fxs, &mut c.x, &c.sample);
            sample(fvs, &mut c.v, &c.sample);
            // a coarse particle is fixed when the fine particle at its rest position is
            for (i, s) in c.sample.iter().enumerate() {
                c.fixed[i] = s.iter().any(|&(k, w)| w > 0.999_999 && f.fixed[k as usize]);
            }
            c.penalized = f.penalized;
            if f.penalized {
                // a coarse particle keeps the constraint of the fine particle at its rest position
                for (i, s) in c.sample.iter().enumerate() {
                    c.pen_dir[i] = s
                        .iter()
                        .find(|&&(_, w)| w > 0.999_999)
                        .map_or(Vec3::zeros(), |&(k, _)| f.pen_dir[k as usize]);
                }
            }
            let model = c.model.as_ref().expect("coarse model");
            let asm = c.asm.as_mut().expect("coarse assembly");
            asm.assemble(model, &c.x, &c.v, inp);
            if c.penalized {
                fill_penalty(&asm.a, &c.pen_dir, &mut c.pen);
                if self.contact == ContactCoarsening::Projected {
                    c.lines.to_weft(&c.pen_dir, &mut c.dir_weft);
                }
            }
            let pen = c.penalized.then_some(&c.pen[..]);
            c.lines.factor(&asm.a, &c.fixed, pen);
        }
        self.timing.0 += t0.elapsed().as_secs_f64();
    }

    /// The coarse levels as Galerkin products `Pᵀ Â P` of the level above (see
    /// [`galerkin`]): the finest level's operator with its penalties and fixed particles, each
    /// coarser one from the last. Coarse levels then have no fixed particles or penalties of
    /// their own. Built on the first call (allocation once per topology). With `only_changed`,
    /// each level rebuilds only the rows that the particles in `self.refit.changed` (finest
    /// level) reach, and passes those rows on as the next level's changed particles.
    fn setup_galerkin(&mut self, a: &Bcsr3, only_changed: bool) {
        let work = &mut self.refit;
        for l in 1..self.levels.len() {
            let (fine, coarse) = self.levels.split_at_mut(l);
            let f = &fine[l - 1];
            let c = &mut coarse[0];
            let gal = c.gal.get_or_insert_with(|| {
                let (cx, cy) = c.dims;
                let mut ga = galerkin::coarse_pattern(cx, cy);
                let lines = LineSolver::new(&mut ga, cx, cy);
                ga.store_single_only();
                let taps = Transfer::new(f.dims, c.dims).taps;
                GalerkinOp {
                    a: ga,
                    lines,
                    from_fine: GalerkinTransfer::new(taps, c.dims),
                    half: HalfProduct::default(),
                }
            });
            let (fa, cons) = if l == 1 {
                let pen: &[Sym3f] = if f.penalized { &f.pen } else { &[] };
                (
                    a,
                    FineConstraints {
                        pen,
                        fixed: &f.fixed,
                    },
                )
            } else {
                let fa = &f.gal.as_ref().expect("finer Galerkin level").a;
                (
                    fa,
                    FineConstraints {
                        pen: &[],
                        fixed: &[],
                    },
                )
            };
            if only_changed {
                work.reach(fa, &gal.from_fine);
            }
            let changes = only_changed.then_some(&*work);
            galerkin::fill(fa, cons, &gal.from_fine, &mut gal.half, &mut gal.a, changes);
            if only_changed {
                work.descend();
            }
            c.fixed.fill(false);
            c.penalized = false;
            gal.lines.factor(&gal.a, &c.fixed, None);
        }
    }

    /// Applies one V-cycle to residual `r` (finest level, matrix `a`), writing `s ≈ A⁻¹ r`.
    pub fn apply(&mut self, a: &Bcsr3, r: &[Vec3], s: &mut [Vec3]) {
        vcycle::apply(self, a, r, s);
    }
}

impl Hierarchy for Multigrid {
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

    /// The coarsest level of a V-cycle: symmetric alternating line sweeps only.
    fn solve_coarsest(&mut self, l: usize, a0: &Bcsr3) {
        let gal = self.galerkin_now && l > 0;
        let lv = &mut self.levels[l];
        let (a, lines) = operator_lines(&lv.asm, &mut lv.gal, &mut lv.lines, gal, a0);
        let pen = lv.penalized.then_some(&lv.pen[..]);
        lv.e.fill(Vec3::zeros());
        for p in 0..COARSE_SWEEPS {
            let (r, e) = (&lv.r, &mut lv.e);
            lines.sweep(a, LineDir::Warp, r, e, &lv.fixed, pen, FORWARD, p == 0);
            lines.sweep(a, LineDir::Weft, r, e, &lv.fixed, pen, FORWARD, false);
        }
        for _ in 0..COARSE_SWEEPS {
            let (r, e) = (&lv.r, &mut lv.e);
            lines.sweep(a, LineDir::Weft, r, e, &lv.fixed, pen, BACKWARD, false);
            lines.sweep(a, LineDir::Warp, r, e, &lv.fixed, pen, BACKWARD, false);
        }
    }

    /// Warp lines, then weft lines, colours forward; the weft sweep, the residual and the
    /// transfers work in the weft numbering.
    fn pre_smooth(&mut self, l: usize, a0: &Bcsr3) {
        let gal = self.galerkin_now && l > 0;
        let lv = &mut self.levels[l];
        let (a, lines) = operator_lines(&lv.asm, &mut lv.gal, &mut lv.lines, gal, a0);
        let pen = lv.penalized.then_some(&lv.pen[..]);
        lv.e.fill(Vec3::zeros());
        lines.sweep(
            a,
            LineDir::Warp,
            &lv.r,
            &mut lv.e,
            &lv.fixed,
            pen,
            FORWARD,
            true,
        );
        lines.enter_weft(&lv.r, &lv.e);
        lines.sweep_weft(a, lv.penalized, FORWARD, false);
        lines.residual_weft(a, lv.penalized, FORWARD[2], &mut lv.d);
    }

    fn restrict(&mut self, l: usize) {
        let projected = self.contact == ContactCoarsening::Projected;
        let (fine, coarse) = self.levels.split_at_mut(l + 1);
        let (f, c) = (&fine[l], &mut coarse[0]);
        let dirs = (projected && f.penalized).then_some(&f.dir_weft[..]);
        f.to_fine
            .as_ref()
            .expect("transfer")
            .restrict(&f.d, &mut c.r, &c.fixed, dirs);
    }

    fn prolong(&mut self, l: usize) {
        let gal = self.galerkin_now && l > 0;
        let projected = self.contact == ContactCoarsening::Projected;
        let (fine, coarse) = self.levels.split_at_mut(l + 1);
        let (lv, c) = (&mut fine[l], &coarse[0]);
        let dirs = (projected && lv.penalized).then_some(&lv.dir_weft[..]);
        let lines = match (gal, lv.gal.as_mut()) {
            (true, Some(g)) => &mut g.lines,
            _ => &mut lv.lines,
        };
        let (e_weft, fixed_weft) = lines.weft_correction();
        lv.to_fine
            .as_ref()
            .expect("transfer")
            .prolong_add(&c.e, e_weft, fixed_weft, dirs);
    }

    /// Weft then warp, colours backward.
    fn post_smooth(&mut self, l: usize, a0: &Bcsr3) {
        let gal = self.galerkin_now && l > 0;
        let lv = &mut self.levels[l];
        let (a, lines) = operator_lines(&lv.asm, &mut lv.gal, &mut lv.lines, gal, a0);
        lines.sweep_weft(a, lv.penalized, BACKWARD, false);
        lines.leave_weft(&mut lv.e);
        let pen = lv.penalized.then_some(&lv.pen[..]);
        lines.sweep(
            a,
            LineDir::Warp,
            &lv.r,
            &mut lv.e,
            &lv.fixed,
            pen,
            BACKWARD,
            false,
        );
    }
}

/// A level's matrix and line factors: its Galerkin operator's when `gal`, otherwise its own
/// assembly's matrix, or the finest level's `a0`, with its own line factors.
fn operator_lines<'a>(
    asm: &'a Option<Assembly>,
    gal_op: &'a mut Option<GalerkinOp>,
    lines: &'a mut LineSolver,
    gal: bool,
    a0: &'a Bcsr3,
) -> (&'a Bcsr3, &'a mut LineSolver) {
    match (gal, gal_op.as_mut()) {
        (true, Some(g)) => (&g.a, &mut g.lines),
        _ => (asm.as_ref().map_or(a0, |asm| &asm.a), lines),
    }
}

const FORWARD: [usize; 3] = [0, 1, 2];
const BACKWARD: [usize; 3] = [2, 1, 0];

/// Penalty stiffness of a constrained direction relative to the particle's own diagonal.
const PENALTY: f64 = 1e3;

/// Penalty blocks κ n nᵀ for the constrained directions `dirs` (zero vectors: none), κ a
/// multiple of the largest entry of the particle's diagonal block of `a`.
fn fill_penalty(a: &Bcsr3, dirs: &[Vec3], pen: &mut [Sym3f]) {
    for (i, n) in dirs.iter().enumerate() {
        pen[i] = if *n == Vec3::zeros() {
            Sym3f::default()
        } else {
            let d = a.values32[a.diag[i]].to_mat3();
            let kappa = PENALTY * d.diagonal().max();
            Sym3f::from_upper(&(n * n.transpose() * kappa))
        };
    }
}

/// Width and height of a grid model from its rest coordinates.
fn grid_extent(model: &ClothModel, nx: usize, ny: usize) -> (f64, f64) {
    let r = &model.mesh.rest;
    (r[nx - 1][0] - r[0][0], r[(ny - 1) * nx][1] - r[0][1])
}
