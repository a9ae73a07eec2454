//! Block line Gauss–Seidel along the warp and weft lines of a grid cloth: the smoother of the
//! multigrid preconditioner. Stretch springs couple particles strongly along their own line
//! only, and bending couples particles two apart, so point smoothers stall or diverge on them.
//! Each line's block-pentadiagonal system (3×3 blocks, neighbours one and two apart) is
//! factorised exactly once per step; lines are swept in three colours (lines three apart never
//! share an element), so lines of one colour are solved in parallel. No allocation per step.

use super::bcsr::{Bcsr3, Mat3f, Sym3f};
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

/// Banded block LU factors of every line of one direction.
#[derive(Debug, Clone)]
struct Factors {
    /// Slots of blocks (k, previous) and (k, previous of previous) on the line, or usize::MAX.
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
    y: Vec<Vec3>,
}

const NONE: usize = usize::MAX;

impl LineSolver {
    /// Prepares the solver for an `nx` × `ny` grid whose matrix pattern is `a`.
    pub fn new(a: &Bcsr3, nx: usize, ny: usize) -> Self {
        let n = nx * ny;
        let slot = |k: usize, back: usize, ok: bool| {
            if ok {
                a.slot(k, k - back).unwrap_or(NONE)
            } else {
                NONE
            }
        };
        let factors = |stride: usize, pos: &dyn Fn(usize) -> usize| {
            let z = vec![Mat3f::zeros(); n];
            Factors {
                prev1: (0..n).map(|k| slot(k, stride, pos(k) >= 1)).collect(),
                prev2: (0..n).map(|k| slot(k, 2 * stride, pos(k) >= 2)).collect(),
                g: vec![Sym3f::default(); n],
                u1: z.clone(),
                u2: z,
            }
        };
        let warp = factors(1, &|k| k % nx);
        let weft = factors(nx, &|k| k / nx);
        LineSolver {
            nx,
            ny,
            warp,
            weft,
            y: vec![Vec3::zeros(); n],
        }
    }

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
            let f = match dir {
                LineDir::Warp => &mut self.warp,
                LineDir::Weft => &mut self.weft,
            };
            let nl = match dir {
                LineDir::Warp => ny,
                LineDir::Weft => nx,
            };
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
                    a.values32[slot].to_mat3()
                }
            };
            // lines in lockstep groups, so that weft lines walk memory row by row
            let group = group_size(dir, nl);
            for_each_index(nl.div_ceil(group), nx * ny >= PAR_MIN, |gi| {
                let lines = gi * group..((gi + 1) * group).min(nl);
                let (_, s, len) = Self::line(nx, ny, dir, 0);
                // factors of the two previous rows of each line, kept in double precision
                let z = [Mat3::zeros(); GROUP];
                let (mut g_1, mut u1_1, mut u2_1) = (z, z, z);
                let (mut g_2, mut u1_2, mut u2_2) = (z, z, z);
                for t in 0..len {
                    for line in lines.clone() {
                        let q = line - lines.start;
                        let first = Self::line(nx, ny, dir, line).0;
                        let k = first + t * s;
                        let a2 = if t >= 2 {
                            blk(k, 2 * s, prev2[k])
                        } else {
                            Mat3::zeros()
                        };
                        let mut a1 = if t >= 1 {
                            blk(k, s, prev1[k])
                        } else {
                            Mat3::zeros()
                        };
                        let mut d = if fixed[k] {
                            Mat3::identity()
                        } else {
                            match pen {
                                Some(p) => a.values32[a.diag[k]].to_mat3() + p[k].to_mat3(),
                                None => a.values32[a.diag[k]].to_mat3(),
                            }
                        };
                        // eliminate column k − 2s, then column k − s
                        let l2 = if t >= 2 { a2 * g_2[q] } else { Mat3::zeros() };
                        if t >= 2 {
                            a1 -= l2 * u1_2[q];
                            d -= l2 * u2_2[q];
                        }
                        let l1 = if t >= 1 { a1 * g_1[q] } else { Mat3::zeros() };
                        if t >= 1 {
                            d -= l1 * u1_1[q];
                        }
                        let g = d.try_inverse().unwrap_or_else(Mat3::identity);
                        // upper blocks (k, k + s), (k, k + 2s): transposes of later rows' lower blocks
                        // (A is symmetric), minus the fill from column k − s
                        let mut u1 = if t + 1 < len {
                            blk(k + s, s, prev1[k + s]).transpose()
                        } else {
                            Mat3::zeros()
                        };
                        let u2 = if t + 2 < len {
                            blk(k + 2 * s, 2 * s, prev2[k + 2 * s]).transpose()
                        } else {
                            Mat3::zeros()
                        };
                        if t >= 1 && t + 1 < len {
                            u1 -= l1 * u2_1[q];
                        }
                        // SAFETY: each particle belongs to exactly one line of this direction.
                        unsafe {
                            // W is a Schur complement of a symmetric matrix: G is symmetric
                            *gp.at(k) = Sym3f::from_upper(&g);
                            *u1p.at(k) = u1.cast::<f32>();
                            *u2p.at(k) = u2.cast::<f32>();
                        }
                        (g_2[q], u1_2[q], u2_2[q]) = (g_1[q], u1_1[q], u2_1[q]);
                        (g_1[q], u1_1[q], u2_1[q]) = (g, u1, u2);
                    }
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
        let yp = SyncPtr(self.y.as_mut_ptr());
        let ep = SyncPtr(e.as_mut_ptr());
        for (pass, color) in order.into_iter().enumerate() {
            // with e = 0 on entry, the first colour's residual is r itself
            let skip_product = from_zero && pass == 0;
            let count = (nl + 2 - color) / 3;
            let group = group_size(dir, count);
            for_each_index(count.div_ceil(group), nx * ny >= PAR_MIN, |gi| {
                let members = gi * group..((gi + 1) * group).min(count);
                let (_, s, len) = Self::line(nx, ny, dir, 0);
                // SAFETY: lines of one colour are three apart, so no element couples two of
                // them: each task writes its own lines' e and y and reads e of other colours only.
                unsafe {
                    // residuals of the lines, then forward elimination in place, row by row
                    for t in 0..len {
                        for m in members.clone() {
                            let k = Self::line(nx, ny, dir, color + 3 * m).0 + t * s;
                            let mut d = if fixed[k] {
                                Vec3::zeros()
                            } else {
                                if skip_product {
                                    r[k]
                                } else {
                                    let mut d = r[k] - a.row_times32_ptr(k, ep.0);
                                    if let Some(p) = pen {
                                        d -= p[k].mul(&*ep.at(k));
                                    }
                                    d
                                }
                            };
                            // symmetric elimination: L(k, k−s) = U(k−s, k)ᵀ G(k−s); the
                            // scratch holds w = G y, so the multiplier is never stored
                            if t >= 1 {
                                d -= f.u1[k - s].cast::<f64>().tr_mul(&*yp.at(k - s));
                            }
                            if t >= 2 {
                                d -= f.u2[k - 2 * s].cast::<f64>().tr_mul(&*yp.at(k - 2 * s));
                            }
                            *yp.at(k) = f.g[k].mul(&d);
                        }
                    }
                    let mut x1 = [Vec3::zeros(); GROUP];
                    let mut x2 = [Vec3::zeros(); GROUP];
                    for t in (0..len).rev() {
                        for m in members.clone() {
                            let q = m - members.start;
                            let k = Self::line(nx, ny, dir, color + 3 * m).0 + t * s;
                            let xk = *yp.at(k)
                                - f.g[k].mul(
                                    &(f.u1[k].cast::<f64>() * x1[q]
                                        + f.u2[k].cast::<f64>() * x2[q]),
                                );
                            *ep.at(k) += xk;
                            x2[q] = x1[q];
                            x1[q] = xk;
                        }
                    }
                }
            });
        }
    }
}

/// Most lines processed in lockstep by one task.
const GROUP: usize = 128;

/// Lines per task when `count` lines are to be processed: weft lines are strided in memory, so
/// as many as possible advance together row by row (one group per thread, which turns the
/// accesses into sequential streams); warp lines are contiguous and go one by one. Grouping
/// changes no arithmetic, so results do not depend on the thread count.
fn group_size(dir: LineDir, count: usize) -> usize {
    match dir {
        LineDir::Warp => 1,
        LineDir::Weft => count.div_ceil(rayon::current_num_threads()).clamp(1, GROUP),
    }
}
