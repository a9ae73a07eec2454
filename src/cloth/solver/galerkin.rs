//! Galerkin coarse operators for the geometric multigrid when contacts constrain the cloth:
//! `A_c = Pᵀ Â P` with `P` the bilinear transfer and `Â` the operator the finer level's
//! smoother works on: the finer matrix plus the contact penalties κ n nᵀ, with the rows and
//! columns of fixed particles (pins, particles stuck by static friction) replaced by a
//! mass-like diagonal. A rediscretised coarse cloth sees a constraint only where a coarse
//! particle sits on a constrained fine one, so across the rim of a contact its operator and the
//! fine one disagree and the V-cycle stops being a good preconditioner; the Galerkin product
//! carries every fine constraint down exactly. Every block of `Â` is symmetric (springs, n nᵀ,
//! a multiple of I), so every block of `A_c` is too and the line smoother's single-precision
//! symmetric storage holds it. The coarse pattern is the 5 × 5 stencil (a fine row couples
//! particles up to two apart, bilinear taps one apart): it stays 5 × 5 level after level. The
//! product is formed in two halves, `Â P` by fine rows (each a 4 × 4 window of coarse
//! columns), then `Pᵀ (Â P)` by coarse rows; after a change of constraints at a few particles
//! only the rows they reach are formed again. Each row is summed by one task in a fixed
//! order: bit-identical whatever the thread count.

use super::bcsr::{Bcsr3, Rows32, Sym3, Sym3f};
use super::parallel::{for_each_index, SyncPtr, PAR_MIN};
use super::simd::multiversion;

/// How the coarse levels see the contact constraints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactCoarsening {
    /// Galerkin coarse operators of the penalised, fixed-filtered fine operator (the default
    /// since a static hold that pulls is let go within its own step, issue 53).
    Galerkin,
    /// Rediscretised coarse cloths with the constraint of the fine particle under each coarse
    /// one, the transfers projecting out the constrained directions.
    Projected,
    /// Rediscretised coarse cloths with the constraint of the fine particle under each coarse
    /// one (the default before issue 53).
    Injected,
}

impl ContactCoarsening {
    /// The choice of `EMILION_MG_CONTACT` (`galerkin`, `projected`, `injected`), or the
    /// default (`galerkin`).
    pub(crate) fn from_env() -> Self {
        match std::env::var("EMILION_MG_CONTACT").as_deref() {
            Ok("galerkin") => ContactCoarsening::Galerkin,
            Ok("projected") => ContactCoarsening::Projected,
            Ok("injected") => ContactCoarsening::Injected,
            _ => ContactCoarsening::Galerkin,
        }
    }
}

/// Half-width of the coarse stencil.
const R: i32 = 2;
/// Blocks of a full coarse row.
const W: usize = (2 * R as usize + 1) * (2 * R as usize + 1);

/// The bilinear transfer between a fine and a coarse grid, both in row numbering, as the
/// Galerkin product reads it.
#[derive(Debug, Clone)]
pub struct GalerkinTransfer {
    /// Coarse grid width.
    cx: usize,
    /// For each fine particle, its coarse taps: the coarse particle's grid row and column and
    /// the weight (taps of weight 0 left out; unused entries have weight 0).
    taps: Vec<[Tap; 4]>,
    /// For each coarse particle, the fine particles whose taps reference it, with the weight.
    rev_ptr: Vec<usize>,
    rev: Vec<(u32, f64)>,
    /// For each fine particle, the first coarse grid row and column of its window in the half
    /// product: one before its coarse cell.
    anchor: Vec<(i32, i32)>,
}

/// One coarse tap of a fine particle: grid row, grid column, weight.
#[derive(Debug, Clone, Copy, Default)]
struct Tap {
    i: i32,
    j: i32,
    w: f64,
}

impl GalerkinTransfer {
    /// The transfer from `taps` (fine particle → four coarse taps) onto a coarse grid of
    /// `coarse.0` × `coarse.1` particles.
    pub fn new(taps: Vec<[(u32, f64); 4]>, coarse: (usize, usize)) -> Self {
        let nc = coarse.0 * coarse.1;
        let mut count = vec![0usize; nc + 1];
        for t in &taps {
            for &(c, w) in t {
                if w != 0.0 {
                    count[c as usize + 1] += 1;
                }
            }
        }
        for i in 0..nc {
            count[i + 1] += count[i];
        }
        let rev_ptr = count.clone();
        let mut rev = vec![(0u32, 0.0); rev_ptr[nc]];
        let mut at = count;
        for (f, t) in taps.iter().enumerate() {
            for &(c, w) in t {
                if w != 0.0 {
                    rev[at[c as usize]] = (f as u32, w);
                    at[c as usize] += 1;
                }
            }
        }
        let cx = coarse.0;
        // the first tap is the cell's corner, kept even where its weight is zero
        let anchor = taps
            .iter()
            .map(|t| {
                let c = t[0].0 as usize;
                ((c / cx) as i32 - 1, (c % cx) as i32 - 1)
            })
            .collect();
        let taps = taps
            .iter()
            .map(|t| {
                let mut out = [Tap::default(); 4];
                let kept = t.iter().filter(|&&(_, w)| w != 0.0);
                for (o, &(c, w)) in out.iter_mut().zip(kept) {
                    let c = c as usize;
                    *o = Tap {
                        i: (c / cx) as i32,
                        j: (c % cx) as i32,
                        w,
                    };
                }
                out
            })
            .collect();
        GalerkinTransfer {
            cx,
            taps,
            rev_ptr,
            rev,
            anchor,
        }
    }
}

/// The symmetric pattern of the 5 × 5 stencil on an `nx` × `ny` grid.
pub fn coarse_pattern(nx: usize, ny: usize) -> Bcsr3 {
    let mut pairs = Vec::with_capacity(nx * ny * W / 2);
    for i in 0..ny as i32 {
        for j in 0..nx as i32 {
            for di in 0..=R {
                for dj in -R..=R {
                    if di == 0 && dj <= 0 {
                        continue;
                    }
                    let (i2, j2) = (i + di, j + dj);
                    if i2 < ny as i32 && (0..nx as i32).contains(&j2) {
                        let a = i as usize * nx + j as usize;
                        pairs.push((a, i2 as usize * nx + j2 as usize));
                    }
                }
            }
        }
    }
    Bcsr3::with_pattern(nx * ny, &pairs)
}

/// What the fine level adds to its matrix: the penalty blocks of its constrained directions
/// and its fixed particles (both empty on a level that has none).
#[derive(Debug, Clone, Copy)]
pub struct FineConstraints<'a> {
    /// Penalty block of each particle (empty: none).
    pub pen: &'a [Sym3f],
    /// Fixed particles (empty: none).
    pub fixed: &'a [bool],
}

/// Side of the window of coarse columns one fine row of `Â P` spans: a fine row couples
/// particles up to two apart, whose bilinear taps lie in the 4 × 4 coarse particles from one
/// before the fine particle's coarse cell.
const HW: usize = 4;

/// One fine row of the half product `Â P`: its coarse columns in the window from the row's
/// anchor, in single precision.
type HalfRow = [Sym3f; HW * HW];

/// The half product `Â P` of a Galerkin level, one window per fine row.
#[derive(Debug, Default)]
pub struct HalfProduct {
    rows: Vec<HalfRow>,
}

/// Scratch of a rebuild after the constraints changed at a few fine particles: the changed
/// particles, the fine rows of `Â P` and the coarse rows they reach, a flag per fine and per
/// coarse particle (left all false).
#[derive(Debug, Default)]
pub struct Changes {
    /// The changed particles of the fine level.
    pub changed: Vec<u32>,
    fine_rows: Vec<u32>,
    /// The coarse rows rebuilt (after [`Changes::reach`]).
    pub coarse_rows: Vec<u32>,
    fine_mark: Vec<bool>,
    coarse_mark: Vec<bool>,
}

impl Changes {
    /// Finds what the changed particles reach: their fine rows and columns change, so every
    /// fine row of `Â P` that has a changed neighbour, and every coarse row one of those taps.
    /// Both lists in increasing order.
    pub fn reach(&mut self, fine: &Bcsr3, t: &GalerkinTransfer) {
        let rows = fine.rows32();
        self.fine_mark.resize(fine.rows(), false);
        self.coarse_mark.resize(t.rev_ptr.len() - 1, false);
        self.fine_rows.clear();
        self.coarse_rows.clear();
        for &k in &self.changed {
            let k = k as usize;
            for &j in &rows.cols[rows.start[k]..rows.start[k + 1]] {
                if std::mem::replace(&mut self.fine_mark[j as usize], true) {
                    continue;
                }
                self.fine_rows.push(j);
                for tap in &t.taps[j as usize] {
                    if tap.w == 0.0 {
                        break;
                    }
                    let c = tap.i as usize * t.cx + tap.j as usize;
                    if !std::mem::replace(&mut self.coarse_mark[c], true) {
                        self.coarse_rows.push(c as u32);
                    }
                }
            }
        }
        self.fine_rows.sort_unstable();
        self.coarse_rows.sort_unstable();
        for &j in &self.fine_rows {
            self.fine_mark[j as usize] = false;
        }
        for &c in &self.coarse_rows {
            self.coarse_mark[c as usize] = false;
        }
    }

    /// The coarse rows become the next coarser level's changed particles.
    pub fn descend(&mut self) {
        std::mem::swap(&mut self.changed, &mut self.coarse_rows);
    }
}

/// Fills `coarse` (pattern of [`coarse_pattern`], single-precision mirrors enabled) with
/// `Pᵀ Â P`, `Â` the single-precision mirror of `fine` with `cons` applied: a fixed particle's
/// row and column are dropped and its diagonal becomes `d I`, `d` the largest diagonal entry of
/// its block. Writes the row-order mirror and the permuted one, if any: every row, or, with
/// `changes` (after [`Changes::reach`]), only the rows the changed particles reach (the others
/// are left as they are, and `half` must hold the last fill's half product). The fine
/// pattern must [fit the windows](windows_fit). The product is formed in two halves, `Â P` by fine rows into `half`, then `Pᵀ (Â P)` by coarse rows: each
/// fine row is multiplied once rather than once per coarse particle it taps.
pub fn fill(
    fine: &Bcsr3,
    cons: FineConstraints<'_>,
    t: &GalerkinTransfer,
    half: &mut HalfProduct,
    coarse: &mut Bcsr3,
    changes: Option<&Changes>,
) {
    debug_assert!(
        windows_fit(fine, t),
        "a fine pattern wider than the windows"
    );
    let coarse_only = changes.map(|c| &c.coarse_rows[..]);
    half.rows.resize(fine.rows(), [Sym3f::default(); HW * HW]);
    half_rows(
        fine,
        cons,
        t,
        &mut half.rows,
        changes.map(|c| &c.fine_rows[..]),
    );
    coarse_rows(t, &half.rows, coarse, coarse_only);
}

/// Whether every fine row's coarse columns in `Â P` lie in its window, as [`fill`] needs
/// (true of a fine pattern coupling particles at most two apart along each grid axis).
pub fn windows_fit(fine: &Bcsr3, t: &GalerkinTransfer) -> bool {
    let rows = fine.rows32();
    (0..fine.rows()).all(|f| {
        let (ai, aj) = t.anchor[f];
        rows.cols[rows.start[f]..rows.start[f + 1]]
            .iter()
            .all(|&j| {
                t.taps[j as usize].iter().all(|tap| {
                    tap.w == 0.0
                        || ((0..HW as i32).contains(&(tap.i - ai))
                            && (0..HW as i32).contains(&(tap.j - aj)))
                })
            })
    })
}

/// Block `k` (column `j`) of fine row `f` of `Â`: `None` where a fixed particle drops it.
#[inline(always)]
fn constrained_block(
    rows: &Rows32<'_>,
    cons: &FineConstraints<'_>,
    f: usize,
    j: usize,
    k: usize,
) -> Option<Sym3> {
    let fixed = |i: usize| !cons.fixed.is_empty() && cons.fixed[i];
    let mut b = Sym3(rows.values[k].0.map(f64::from));
    if j == f {
        if fixed(f) {
            let d = b.0[0].max(b.0[3]).max(b.0[5]);
            b = Sym3([d, 0.0, 0.0, d, 0.0, d]);
        } else if !cons.pen.is_empty() {
            b.add_scaled_sym(&Sym3(cons.pen[f].0.map(f64::from)), 1.0);
        }
        Some(b)
    } else if fixed(f) || fixed(j) {
        None
    } else {
        Some(b)
    }
}

/// Writes coarse row `c` from its 5 × 5 stencil sums `acc` into both mirrors.
///
/// # Safety
/// No other thread may write row `c` meanwhile.
#[inline(always)]
unsafe fn write_row(
    coarse: &CoarseOut<'_>,
    c: usize,
    (ci, cj): (i32, i32),
    cx: usize,
    acc: &[Sym3; W],
) {
    for k in coarse.row_ptr[c]..coarse.row_ptr[c + 1] {
        let c2 = coarse.cols[k] as usize;
        let (di, dj) = ((c2 / cx) as i32 - ci, (c2 % cx) as i32 - cj);
        let b = acc[((di + R) * (2 * R + 1) + dj + R) as usize].to_f32();
        // SAFETY: row c's blocks belong to this task alone, in both mirrors.
        unsafe {
            *coarse.vals.at(k) = b;
            if let Some((pv, row_start)) = &coarse.perm {
                *pv.at(row_start[c] + k - coarse.row_ptr[c]) = b;
            }
        }
    }
}

/// Where the coarse rows are written: the row-order mirror and the permuted one, if any.
struct CoarseOut<'a> {
    vals: SyncPtr<Sym3f>,
    perm: Option<(SyncPtr<Sym3f>, &'a [usize])>,
    row_ptr: &'a [usize],
    cols: &'a [u32],
}

impl<'a> CoarseOut<'a> {
    fn new(coarse: &'a mut Bcsr3) -> Self {
        CoarseOut {
            vals: SyncPtr(coarse.values32.as_mut_ptr()),
            perm: coarse
                .permuted
                .as_mut()
                .map(|p| (SyncPtr(p.values.as_mut_ptr()), &p.row_start[..])),
            row_ptr: &coarse.row_ptr,
            cols: &coarse.cols,
        }
    }
}

multiversion! {
    /// The rows of `Â P` into `half`: every fine row, or those `only` lists.
    fn half_rows(
        fine: &Bcsr3,
        cons: FineConstraints<'_>,
        t: &GalerkinTransfer,
        half: &mut [HalfRow],
        only: Option<&[u32]>,
    ) {
        let rows = fine.rows32();
        let n = only.map_or(half.len(), |o| o.len());
        let out = SyncPtr(half.as_mut_ptr());
        for_each_index(n, n >= PAR_MIN, |idx| {
            let f = only.map_or(idx, |o| o[idx] as usize);
            let (ai, aj) = t.anchor[f];
            let mut acc = [Sym3::default(); HW * HW];
            for k in rows.start[f]..rows.start[f + 1] {
                let j = rows.cols[k] as usize;
                let Some(blk) = constrained_block(&rows, &cons, f, j, k) else {
                    continue;
                };
                for tap in &t.taps[j] {
                    if tap.w == 0.0 {
                        break;
                    }
                    let slot = (tap.i - ai) as usize * HW + (tap.j - aj) as usize;
                    acc[slot].add_scaled_sym(&blk, tap.w);
                }
            }
            // SAFETY: row f belongs to this task alone.
            unsafe {
                *out.at(f) = acc.map(|b| b.to_f32());
            }
        });
    }
}

multiversion! {
    /// The coarse rows `Pᵀ (Â P)` from the half product: every row, or those `only` lists.
    fn coarse_rows(t: &GalerkinTransfer, half: &[HalfRow], coarse: &mut Bcsr3, only: Option<&[u32]>) {
        let nc = only.map_or(coarse.rows(), |o| o.len());
        let cx = t.cx;
        let out = CoarseOut::new(coarse);
        for_each_index(nc, nc >= PAR_MIN, |idx| {
            let c = only.map_or(idx, |o| o[idx] as usize);
            let (ci, cj) = ((c / cx) as i32, (c % cx) as i32);
            let mut acc = [Sym3::default(); W];
            for &(f, w) in &t.rev[t.rev_ptr[c]..t.rev_ptr[c + 1]] {
                let (ai, aj) = t.anchor[f as usize];
                // the window's first row and column in the 5 × 5 stencil (0 or 1)
                let (oi, oj) = ((ai - ci + R) as usize, (aj - cj + R) as usize);
                let row = &half[f as usize];
                for u in 0..HW {
                    for v in 0..HW {
                        let b = Sym3(row[u * HW + v].0.map(f64::from));
                        acc[(oi + u) * (2 * R as usize + 1) + oj + v].add_scaled_sym(&b, w);
                    }
                }
            }
            // SAFETY: row c belongs to this task alone.
            unsafe { write_row(&out, c, (ci, cj), cx, &acc) };
        });
    }
}
