//! Block line Gauss–Seidel along the warp and weft lines of a grid cloth: the smoother of the
//! multigrid preconditioner. Stretch springs couple particles strongly along their own line
//! only, and bending couples particles two apart, so point smoothers stall or diverge on them.
//! Each line's block-pentadiagonal system (3×3 blocks, neighbours one and two apart) is
//! factorised exactly once per step; lines are swept in three colours (lines three apart never
//! share an element), so lines of one colour are solved in parallel, one task per line. Weft
//! lines read the matrix's permuted mirror, whose rows lie line by line, and their factors are
//! stored the same way, so both directions stream through memory. No allocation per step.

use super::bcsr::{Bcsr3, Mat3f, Rows32, Sym3f};
use super::parallel::{for_each_index, SyncPtr, PAR_MIN};
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
/// `p = line · len + t` is the line's `t`-th particle.
#[derive(Debug, Clone)]
struct Factors {
    /// Slots, in this direction's rows, of blocks (k, previous) and (k, previous of previous)
    /// on the line, or `NONE`.
    prev1: Vec<usize>,
    prev2: Vec<usize>,
    /// Inverse pivots (single precision: a preconditioner, bounded by memory traffic).
    g: Vec<Sym3f>,
    /// Upper blocks to the next and the one after.
    u1: Vec<Mat3f>,
    u2: Vec<Mat3f>,
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
}

const NONE: usize = usize::MAX;

/// Stored row `p` of the weft-ordered mirror is particle `order[p]`: weft lines one after the
/// other.
fn weft_order(nx: usize, ny: usize) -> Vec<u32> {
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
                let (first, s, _) = Self::line(nx, ny, dir, line);
                for t in 0..len {
                    let (k, p) = (first + t * s, line * len + t);
                    if t >= 1 {
                        prev1[p] = rows.slot(p, k - s).unwrap_or(NONE);
                    }
                    if t >= 2 {
                        prev2[p] = rows.slot(p, k - 2 * s).unwrap_or(NONE);
                    }
                }
            }
            let z = vec![Mat3f::zeros(); n];
            Factors {
                prev1,
                prev2,
                g: vec![Sym3f::default(); n],
                u1: z.clone(),
                u2: z,
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
        }
    }

    /// The rows that lines of `dir` read: stored row `line · len + t` is the line's `t`-th
    /// particle.
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

    /// First particle, stride and length of a line.
    #[inline]
    fn line(nx: usize, ny: usize, dir: LineDir, line: usize) -> (usize, usize, usize) {
        match dir {
            LineDir::Warp => (line * nx, 1, nx),
            LineDir::Weft => (line, nx, ny),
        }
    }

    fn line_count(&self, dir: LineDir) -> usize {
        match dir {
            LineDir::Warp => self.ny,
            LineDir::Weft => self.nx,
        }
    }

    /// Factorises the line systems of `a` (plus the diagonal penalty blocks `pen`, if any);
    /// `fixed` particles get identity rows (no correction).
    pub fn factor(&mut self, a: &Bcsr3, fixed: &[bool], pen: Option<&[Sym3f]>) {
        let (nx, ny) = (self.nx, self.ny);
        for dir in [LineDir::Warp, LineDir::Weft] {
            let nl = self.line_count(dir);
            let f = match dir {
                LineDir::Warp => &mut self.warp,
                LineDir::Weft => &mut self.weft,
            };
            let rows = Self::rows(a, dir);
            let (gp, u1p, u2p) = (
                SyncPtr(f.g.as_mut_ptr()),
                SyncPtr(f.u1.as_mut_ptr()),
                SyncPtr(f.u2.as_mut_ptr()),
            );
            let (prev1, prev2) = (&f.prev1, &f.prev2);
            // block (k, k − back) of the line system, zero when either particle is fixed
            let blk = |k: usize, back: usize, slot: usize| {
                if slot == NONE || fixed[k] || fixed[k - back] {
                    Mat3::zeros()
                } else {
                    rows.values[slot].to_mat3()
                }
            };
            for_each_index(nl, nx * ny >= PAR_MIN, |line| {
                let (first, s, len) = Self::line(nx, ny, dir, line);
                let p0 = line * len;
                // factors of the two previous particles, kept in double precision
                let z = Mat3::zeros();
                let (mut g_1, mut u1_1, mut u2_1) = (z, z, z);
                let (mut g_2, mut u1_2, mut u2_2) = (z, z, z);
                for t in 0..len {
                    let (k, p) = (first + t * s, p0 + t);
                    let a2 = if t >= 2 {
                        blk(k, 2 * s, prev2[p])
                    } else {
                        Mat3::zeros()
                    };
                    let mut a1 = if t >= 1 {
                        blk(k, s, prev1[p])
                    } else {
                        Mat3::zeros()
                    };
                    let mut d = if fixed[k] {
                        Mat3::identity()
                    } else {
                        match pen {
                            Some(pn) => rows.values[rows.diag[p]].to_mat3() + pn[k].to_mat3(),
                            None => rows.values[rows.diag[p]].to_mat3(),
                        }
                    };
                    // eliminate column k − 2s, then column k − s
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
                    // upper blocks (k, k + s), (k, k + 2s): transposes of later rows' lower blocks
                    // (A is symmetric), minus the fill from column k − s
                    let mut u1 = if t + 1 < len {
                        blk(k + s, s, prev1[p + 1]).transpose()
                    } else {
                        Mat3::zeros()
                    };
                    let u2 = if t + 2 < len {
                        blk(k + 2 * s, 2 * s, prev2[p + 2]).transpose()
                    } else {
                        Mat3::zeros()
                    };
                    if t >= 1 && t + 1 < len {
                        u1 -= l1 * u2_1;
                    }
                    // SAFETY: each particle belongs to exactly one line of this direction.
                    unsafe {
                        // W is a Schur complement of a symmetric matrix: G is symmetric
                        *gp.at(p) = Sym3f::from_upper(&g);
                        *u1p.at(p) = u1.cast::<f32>();
                        *u2p.at(p) = u2.cast::<f32>();
                    }
                    (g_2, u1_2, u2_2) = (g_1, u1_1, u2_1);
                    (g_1, u1_1, u2_1) = (g, u1, u2);
                }
            });
        }
    }

    /// One block Gauss–Seidel sweep over all lines of `dir`: for each of three colours in
    /// `order`, the residual `r − (A + pen) e` of that colour's lines is solved exactly on each
    /// line and added to `e`. Fixed particles keep a zero correction. `from_zero` says `e` is
    /// zero on entry, which spares the first colour's matrix product.
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
        let nl = self.line_count(dir);
        let f = match dir {
            LineDir::Warp => &self.warp,
            LineDir::Weft => &self.weft,
        };
        let rows = Self::rows(a, dir);
        let yp = SyncPtr(self.y.as_mut_ptr());
        let ep = SyncPtr(e.as_mut_ptr());
        for (pass, color) in order.into_iter().enumerate() {
            // with e = 0 on entry, the first colour's residual is r itself
            let skip_product = from_zero && pass == 0;
            let count = (nl + 2 - color) / 3;
            for_each_index(count, nx * ny >= PAR_MIN, |m| {
                let line = color + 3 * m;
                let (first, s, len) = Self::line(nx, ny, dir, line);
                let p0 = line * len;
                // SAFETY: lines of one colour are three apart, so no element couples two of
                // them: each task writes its own line's e and y and reads e of other colours only.
                unsafe {
                    // residuals of the line, then forward elimination in place
                    for t in 0..len {
                        let (k, p) = (first + t * s, p0 + t);
                        let mut d = if fixed[k] {
                            Vec3::zeros()
                        } else if skip_product {
                            r[k]
                        } else {
                            let mut d = r[k] - rows.row_times_ptr(p, ep.0);
                            if let Some(pn) = pen {
                                d -= pn[k].mul(&*ep.at(k));
                            }
                            d
                        };
                        // symmetric elimination: L(k, k−s) = U(k−s, k)ᵀ G(k−s); the scratch
                        // holds w = G y, so the multiplier is never stored
                        if t >= 1 {
                            d -= f.u1[p - 1].cast::<f64>().tr_mul(&*yp.at(p - 1));
                        }
                        if t >= 2 {
                            d -= f.u2[p - 2].cast::<f64>().tr_mul(&*yp.at(p - 2));
                        }
                        *yp.at(p) = f.g[p].mul(&d);
                    }
                    let (mut x1, mut x2) = (Vec3::zeros(), Vec3::zeros());
                    for t in (0..len).rev() {
                        let (k, p) = (first + t * s, p0 + t);
                        let xk = *yp.at(p)
                            - f.g[p]
                                .mul(&(f.u1[p].cast::<f64>() * x1 + f.u2[p].cast::<f64>() * x2));
                        *ep.at(k) += xk;
                        x2 = x1;
                        x1 = xk;
                    }
                }
            });
        }
    }
}
