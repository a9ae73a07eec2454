//! Block line Gauss–Seidel along the warp and weft lines of a grid cloth: the smoother of the
//! multigrid preconditioner. Stretch springs couple particles strongly along their own line
//! only, and bending couples particles two apart, so point smoothers stall or diverge on them.
//! Each line's block-pentadiagonal system (3×3 blocks, neighbours one and two apart) is
//! factorised exactly once per step; lines are swept in three colours (lines three apart never
//! share an element), so lines of one colour are solved in parallel, one task per line. Weft
//! lines work in the weft numbering (particles column by column): they read the matrix's
//! permuted mirror and copies of the residual, correction, fixed flags and penalties permuted
//! the same way (blocked transposes; a V-cycle level transposes in once before its
//! pre-smoothing weft sweep and out once after its post-smoothing one, forming its residual and
//! taking the coarse correction in the weft numbering between them), so in either direction a
//! line is a run of consecutive particles and every array streams through memory. No
//! allocation per step.

use super::bcsr::{Bcsr3, Mat3f, Rows32, Sym3f};
use super::parallel::{for_each_index, for_each_mut, SyncPtr, PAR_MIN};
use super::simd::multiversion;
use crate::geometry::{Mat3, Vec3};

/// Which family of grid lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineDir {
    /// Rows: particles i*nx + j for j = 0..nx (the warp).
    Warp,
    /// Columns: particles i*nx + j for i = 0..ny (the weft).
    Weft,
}

/// Banded block LU factors of every line of one direction, stored line by line: position
/// `p = line · len + t` is the line's `t`-th particle (in that direction's numbering).
#[derive(Debug, Clone)]
struct Factors {
    /// Slots, in this direction's rows, of blocks (p, p − 1) and (p, p − 2) on the line, or
    /// `NONE`.
    prev1: Vec<usize>,
    prev2: Vec<usize>,
    /// Each particle's factor blocks, together: the sweeps stream one array, not three.
    blk: Vec<LineFactor>,
}

/// One particle's blocks of a line factorisation (single precision: a preconditioner,
/// bounded by memory traffic).
#[derive(Debug, Clone, Copy)]
struct LineFactor {
    /// Inverse pivot.
    g: Sym3f,
    /// Upper blocks to the next particle and the one after.
    u1: Mat3f,
    u2: Mat3f,
}

/// Factorised line systems of one grid for both directions, plus scratch.
#[derive(Debug, Clone)]
pub struct LineSolver {
    nx: usize,
    ny: usize,
    warp: Factors,
    weft: Factors,
    /// Forward-elimination scratch, stored line by line like the factors.
    y: Vec<Vec3>,
    /// Weft-numbered copies: residual, correction, fixed flags, penalty blocks.
    r_weft: Vec<Vec3>,
    e_weft: Vec<Vec3>,
    fixed_weft: Vec<bool>,
    pen_weft: Vec<Sym3f>,
}

const NONE: usize = usize::MAX;

/// Stored row `p` of the weft-ordered mirror is particle `order[p]`: weft lines one after the
/// other.
pub(crate) fn weft_order(nx: usize, ny: usize) -> Vec<u32> {
    (0..nx * ny)
        .map(|p| ((p % ny) * nx + p / ny) as u32)
        .collect()
}

impl LineSolver {
    /// Prepares the solver for an `nx` × `ny` grid whose matrix pattern is `a`, enabling the
    /// single-precision mirrors of `a` it reads (row order for warp lines, weft order for
    /// weft lines).
    pub fn new(a: &mut Bcsr3, nx: usize, ny: usize) -> Self {
        let n = nx * ny;
        a.enable_permuted_mirror(&weft_order(nx, ny));
        let factors = |dir: LineDir| {
            let rows = Self::rows(a, dir);
            let (nl, len) = match dir {
                LineDir::Warp => (ny, nx),
                LineDir::Weft => (nx, ny),
            };
            let (mut prev1, mut prev2) = (vec![NONE; n], vec![NONE; n]);
            for line in 0..nl {
                for t in 0..len {
                    let p = line * len + t;
                    if t >= 1 {
                        prev1[p] = rows.slot(p, p - 1).unwrap_or(NONE);
                    }
                    if t >= 2 {
                        prev2[p] = rows.slot(p, p - 2).unwrap_or(NONE);
                    }
                }
            }
            Factors {
                prev1,
                prev2,
                blk: vec![
                    LineFactor {
                        g: Sym3f::default(),
                        u1: Mat3f::zeros(),
                        u2: Mat3f::zeros(),
                    };
                    n
                ],
            }
        };
        let warp = factors(LineDir::Warp);
        let weft = factors(LineDir::Weft);
        LineSolver {
            nx,
            ny,
            warp,
            weft,
            y: vec![Vec3::zeros(); n],
            r_weft: vec![Vec3::zeros(); n],
            e_weft: vec![Vec3::zeros(); n],
            fixed_weft: vec![false; n],
            pen_weft: vec![Sym3f::default(); n],
        }
    }

    /// The rows that lines of `dir` read, in that direction's numbering: stored row
    /// `line · len + t` is the line's `t`-th particle.
    fn rows(a: &Bcsr3, dir: LineDir) -> Rows32<'_> {
        match dir {
            LineDir::Warp => a.rows32(),
            LineDir::Weft => a
                .permuted
                .as_ref()
                .expect("the line solver enabled the weft-ordered mirror")
                .rows(),
        }
    }

    /// Number of lines and their length.
    fn lines(&self, dir: LineDir) -> (usize, usize) {
        match dir {
            LineDir::Warp => (self.ny, self.nx),
            LineDir::Weft => (self.nx, self.ny),
        }
    }

    /// Factorises the line systems of `a` (plus the diagonal penalty blocks `pen`, if any);
    /// `fixed` particles get identity rows (no correction).
    pub fn factor(&mut self, a: &Bcsr3, fixed: &[bool], pen: Option<&[Sym3f]>) {
        let (nx, ny) = (self.nx, self.ny);
        transpose(fixed, &mut self.fixed_weft, nx, ny);
        if let Some(pn) = pen {
            transpose(pn, &mut self.pen_weft, nx, ny);
        }
        for dir in [LineDir::Warp, LineDir::Weft] {
            let (nl, len) = self.lines(dir);
            let (f, fixed, pen) = match dir {
                LineDir::Warp => (&mut self.warp, fixed, pen),
                LineDir::Weft => (
                    &mut self.weft,
                    &self.fixed_weft[..],
                    pen.map(|_| &self.pen_weft[..]),
                ),
            };
            factor_lines(
                f,
                Self::rows(a, dir),
                fixed,
                pen,
                nl,
                len,
                nx * ny >= PAR_MIN,
            );
        }
    }

    /// One block Gauss–Seidel sweep over all lines of `dir`: for each of three colours in
    /// `order`, the residual `r − (A + pen) e` of that colour's lines is solved exactly on each
    /// line and added to `e`. Fixed particles keep a zero correction. `from_zero` says `e` is
    /// zero on entry, which spares the first colour's matrix product. `pen` must be the
    /// penalty last given to [`LineSolver::factor`].
    #[allow(clippy::too_many_arguments)]
    pub fn sweep(
        &mut self,
        a: &Bcsr3,
        dir: LineDir,
        r: &[Vec3],
        e: &mut [Vec3],
        fixed: &[bool],
        pen: Option<&[Sym3f]>,
        order: [usize; 3],
        from_zero: bool,
    ) {
        let (nx, ny) = (self.nx, self.ny);
        let (nl, len) = self.lines(dir);
        let rows = Self::rows(a, dir);
        match dir {
            LineDir::Warp => {
                let f = &self.warp;
                sweep_lines(
                    f,
                    rows,
                    nl,
                    len,
                    &mut self.y,
                    r,
                    e,
                    fixed,
                    pen,
                    order,
                    from_zero,
                );
            }
            LineDir::Weft => {
                if from_zero {
                    transpose(r, &mut self.r_weft, nx, ny);
                    self.e_weft.fill(Vec3::zeros());
                } else {
                    self.enter_weft(r, e);
                }
                self.sweep_weft(a, pen.is_some(), order, from_zero);
                self.leave_weft(e);
            }
        }
    }
}

/// The weft-numbered copies of the residual and the correction that a V-cycle level keeps
/// between its pre- and post-smoothing weft sweeps, so that each is transposed once per
/// visit instead of around every sweep.
impl LineSolver {
    /// Copies `r` and `e` into the weft numbering.
    pub fn enter_weft(&mut self, r: &[Vec3], e: &[Vec3]) {
        let (nx, ny) = (self.nx, self.ny);
        transpose(r, &mut self.r_weft, nx, ny);
        transpose(e, &mut self.e_weft, nx, ny);
    }

    /// Copies the per-particle field `src` (row numbering) into `dst` in the weft numbering.
    pub fn to_weft<T: Copy + Send + Sync>(&self, src: &[T], dst: &mut [T]) {
        transpose(src, dst, self.nx, self.ny);
    }

    /// Copies the weft-numbered correction back into `e` (row numbering).
    pub fn leave_weft(&self, e: &mut [Vec3]) {
        transpose(&self.e_weft, e, self.ny, self.nx);
    }

    /// One weft sweep, as [`LineSolver::sweep`], on the weft-numbered copies made by
    /// [`LineSolver::enter_weft`]; `penalized` says whether the penalty last given to
    /// [`LineSolver::factor`] applies, `from_zero` that the correction is zero.
    pub fn sweep_weft(&mut self, a: &Bcsr3, penalized: bool, order: [usize; 3], from_zero: bool) {
        let (nl, len) = self.lines(LineDir::Weft);
        sweep_lines(
            &self.weft,
            Self::rows(a, LineDir::Weft),
            nl,
            len,
            &mut self.y,
            &self.r_weft,
            &mut self.e_weft,
            &self.fixed_weft,
            penalized.then_some(&self.pen_weft[..]),
            order,
            from_zero,
        );
    }

    /// `d = r − (A + pen) e` in the weft numbering (zero at fixed particles), from the
    /// weft-numbered copies, right after a weft sweep whose last colour was `last`: the lines of
    /// that colour were just solved exactly given all the others, so their residual is zero up
    /// to the factors' rounding and is set to zero without reading their rows (a third of the
    /// matrix). The same CG iteration counts, 3 % less V-cycle time at 256².
    pub fn residual_weft(&self, a: &Bcsr3, penalized: bool, last: usize, d: &mut [Vec3]) {
        let rows = Self::rows(a, LineDir::Weft);
        let (r, e, fixed, pen) = (&self.r_weft, &self.e_weft, &self.fixed_weft, &self.pen_weft);
        let len = self.ny;
        let par = d.len() >= PAR_MIN;
        for_each_mut(d, par, |p, out| {
            *out = if fixed[p] || (p / len) % 3 == last {
                Vec3::zeros()
            } else {
                // SAFETY: `e` holds one vector per stored row and nobody writes it meanwhile.
                let mut dp = r[p] - unsafe { rows.row_times_ptr(p, e.as_ptr()) };
                if penalized {
                    dp -= pen[p].mul(&e[p]);
                }
                dp
            };
        });
    }

    /// The weft-numbered correction and fixed flags, for a prolongation in that numbering.
    pub fn weft_correction(&mut self) -> (&mut [Vec3], &[bool]) {
        (&mut self.e_weft, &self.fixed_weft)
    }
}

multiversion! {
    /// The factorisation of [`LineSolver::factor`] for the `nl` lines of `len` particles of one
    /// direction, whose rows (in that direction's numbering) are `rows`; in parallel when
    /// `par`.
    fn factor_lines(
        f: &mut Factors,
        rows: Rows32<'_>,
        fixed: &[bool],
        pen: Option<&[Sym3f]>,
        nl: usize,
        len: usize,
        par: bool,
    ) {
        let fp = SyncPtr(f.blk.as_mut_ptr());
        let (prev1, prev2) = (&f.prev1, &f.prev2);
        // block (p, p − back) of the line system, zero when either particle is fixed
        let blk = |p: usize, back: usize, slot: usize| {
            if slot == NONE || fixed[p] || fixed[p - back] {
                Mat3::zeros()
            } else {
                rows.values[slot].to_mat3()
            }
        };
        for_each_index(nl, par, |line| {
            let p0 = line * len;
            // factors of the two previous particles, kept in double precision
            let z = Mat3::zeros();
            let (mut g_1, mut u1_1, mut u2_1) = (z, z, z);
            let (mut g_2, mut u1_2, mut u2_2) = (z, z, z);
            for t in 0..len {
                let p = p0 + t;
                let a2 = if t >= 2 {
                    blk(p, 2, prev2[p])
                } else {
                    Mat3::zeros()
                };
                let mut a1 = if t >= 1 {
                    blk(p, 1, prev1[p])
                } else {
                    Mat3::zeros()
                };
                let mut d = if fixed[p] {
                    Mat3::identity()
                } else {
                    match pen {
                        Some(pn) => rows.values[rows.diag[p]].to_mat3() + pn[p].to_mat3(),
                        None => rows.values[rows.diag[p]].to_mat3(),
                    }
                };
                // eliminate column p − 2, then column p − 1
                let l2 = if t >= 2 { a2 * g_2 } else { Mat3::zeros() };
                if t >= 2 {
                    a1 -= l2 * u1_2;
                    d -= l2 * u2_2;
                }
                let l1 = if t >= 1 { a1 * g_1 } else { Mat3::zeros() };
                if t >= 1 {
                    d -= l1 * u1_1;
                }
                let g = d.try_inverse().unwrap_or_else(Mat3::identity);
                // upper blocks (p, p + 1), (p, p + 2): transposes of later rows' lower blocks
                // (A is symmetric), minus the fill from column p − 1
                let mut u1 = if t + 1 < len {
                    blk(p + 1, 1, prev1[p + 1]).transpose()
                } else {
                    Mat3::zeros()
                };
                let u2 = if t + 2 < len {
                    blk(p + 2, 2, prev2[p + 2]).transpose()
                } else {
                    Mat3::zeros()
                };
                if t >= 1 && t + 1 < len {
                    u1 -= l1 * u2_1;
                }
                // SAFETY: each particle belongs to exactly one line of this direction.
                unsafe {
                    // W is a Schur complement of a symmetric matrix: G is symmetric
                    *fp.at(p) = LineFactor {
                        g: Sym3f::from_upper(&g),
                        u1: u1.cast::<f32>(),
                        u2: u2.cast::<f32>(),
                    };
                }
                (g_2, u1_2, u2_2) = (g_1, u1_1, u2_1);
                (g_1, u1_1, u2_1) = (g, u1, u2);
            }
        });
    }
}

multiversion! {
    /// The sweep of [`LineSolver::sweep`] in one direction's numbering: `nl` lines of `len`
    /// consecutive particles.
    #[allow(clippy::too_many_arguments)]
    fn sweep_lines(
        f: &Factors,
        rows: Rows32<'_>,
        nl: usize,
        len: usize,
        y: &mut [Vec3],
        r: &[Vec3],
        e: &mut [Vec3],
        fixed: &[bool],
        pen: Option<&[Sym3f]>,
        order: [usize; 3],
        from_zero: bool,
    ) {
        let yp = SyncPtr(y.as_mut_ptr());
        let ep = SyncPtr(e.as_mut_ptr());
        for (pass, color) in order.into_iter().enumerate() {
            // with e = 0 on entry, the first colour's residual is r itself
            let skip_product = from_zero && pass == 0;
            let count = (nl + 2 - color) / 3;
            for_each_index(count, nl * len >= PAR_MIN, |m| {
                let p0 = (color + 3 * m) * len;
                // SAFETY: lines of one colour are three apart, so no element couples two of
                // them: each task writes its own line's e and y and reads e of other colours only.
                unsafe {
                    // residuals of the line, then forward elimination in place
                    for p in p0..p0 + len {
                        let mut d = if fixed[p] {
                            Vec3::zeros()
                        } else if skip_product {
                            r[p]
                        } else {
                            let mut d = r[p] - rows.row_times_ptr(p, ep.0);
                            if let Some(pn) = pen {
                                d -= pn[p].mul(&*ep.at(p));
                            }
                            d
                        };
                        // symmetric elimination: L(p, p−1) = U(p−1, p)ᵀ G(p−1); the scratch
                        // holds w = G y, so the multiplier is never stored
                        if p > p0 {
                            d -= f.blk[p - 1].u1.cast::<f64>().tr_mul(&*yp.at(p - 1));
                        }
                        if p >= p0 + 2 {
                            d -= f.blk[p - 2].u2.cast::<f64>().tr_mul(&*yp.at(p - 2));
                        }
                        *yp.at(p) = f.blk[p].g.mul(&d);
                    }
                    let (mut x1, mut x2) = (Vec3::zeros(), Vec3::zeros());
                    for p in (p0..p0 + len).rev() {
                        let b = &f.blk[p];
                        let xp = *yp.at(p)
                            - b.g
                                .mul(&(b.u1.cast::<f64>() * x1 + b.u2.cast::<f64>() * x2));
                        *ep.at(p) += xp;
                        x2 = x1;
                        x1 = xp;
                    }
                }
            });
        }
    }
}

/// `dst = srcᵀ` for a field stored as `rows` × `cols` (row-major) into `cols` × `rows`:
/// particles row by row to column by column. Blocked, so both sides stay in cache; parallel
/// over blocks of destination rows.
fn transpose<T: Copy + Send + Sync>(src: &[T], dst: &mut [T], cols: usize, rows: usize) {
    const B: usize = 16;
    debug_assert_eq!(src.len(), rows * cols);
    let dp = SyncPtr(dst.as_mut_ptr());
    let bands = cols.div_ceil(B);
    for_each_index(bands, rows * cols >= PAR_MIN, |band| {
        let (c0, c1) = (band * B, ((band + 1) * B).min(cols));
        for r0 in (0..rows).step_by(B) {
            let r1 = (r0 + B).min(rows);
            for c in c0..c1 {
                for r in r0..r1 {
                    // SAFETY: destination rows c0..c1 belong to this band alone.
                    unsafe { *dp.at(c * rows + r) = src[r * cols + c] };
                }
            }
        }
    });
}
