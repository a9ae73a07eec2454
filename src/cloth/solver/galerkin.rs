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
//! particles up to two apart, bilinear taps one apart): it stays 5 × 5 level after level. Each
//! coarse row is summed by one task in a fixed order: bit-identical whatever the thread count.

use super::bcsr::{Bcsr3, Sym3, Sym3f};
use super::parallel::{for_each_index, SyncPtr, PAR_MIN};

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

/// Fills `coarse` (pattern of [`coarse_pattern`], single-precision mirrors enabled) with
/// `Pᵀ Â P`, `Â` the single-precision mirror of `fine` with `cons` applied: a fixed particle's
/// row and column are dropped and its diagonal becomes `d I`, `d` the largest diagonal entry of
/// its block. Writes the row-order mirror and the permuted one, if any.
pub fn fill(fine: &Bcsr3, cons: FineConstraints<'_>, t: &GalerkinTransfer, coarse: &mut Bcsr3) {
    let rows = fine.rows32();
    let nc = coarse.rows();
    let cx = t.cx;
    let fixed = |i: usize| !cons.fixed.is_empty() && cons.fixed[i];
    let vals = SyncPtr(coarse.values32.as_mut_ptr());
    let perm = coarse
        .permuted
        .as_mut()
        .map(|p| (SyncPtr(p.values.as_mut_ptr()), &p.row_start[..]));
    let (row_ptr, cols) = (&coarse.row_ptr, &coarse.cols);
    for_each_index(nc, nc >= PAR_MIN, |c| {
        let (ci, cj) = ((c / cx) as i32, (c % cx) as i32);
        let mut acc = [Sym3::default(); W];
        for &(f, w) in &t.rev[t.rev_ptr[c]..t.rev_ptr[c + 1]] {
            let f = f as usize;
            let (s, e) = (rows.start[f], rows.start[f + 1]);
            let f_fixed = fixed(f);
            for k in s..e {
                let j = rows.cols[k] as usize;
                let blk = if j == f {
                    let mut b = Sym3(rows.values[k].0.map(f64::from));
                    if f_fixed {
                        let d = b.0[0].max(b.0[3]).max(b.0[5]);
                        b = Sym3([d, 0.0, 0.0, d, 0.0, d]);
                    } else if !cons.pen.is_empty() {
                        b.add_scaled_sym(&Sym3(cons.pen[f].0.map(f64::from)), 1.0);
                    }
                    b
                } else if f_fixed || fixed(j) {
                    continue;
                } else {
                    Sym3(rows.values[k].0.map(f64::from))
                };
                for tap in &t.taps[j] {
                    if tap.w == 0.0 {
                        break;
                    }
                    let slot = ((tap.i - ci + R) * (2 * R + 1) + tap.j - cj + R) as usize;
                    acc[slot].add_scaled_sym(&blk, w * tap.w);
                }
            }
        }
        for k in row_ptr[c]..row_ptr[c + 1] {
            let c2 = cols[k] as usize;
            let (di, dj) = ((c2 / cx) as i32 - ci, (c2 % cx) as i32 - cj);
            let b = acc[((di + R) * (2 * R + 1) + dj + R) as usize].to_f32();
            // SAFETY: row c's blocks belong to this task alone, in both mirrors.
            unsafe {
                *vals.at(k) = b;
                if let Some((pv, row_start)) = &perm {
                    *pv.at(row_start[c] + k - row_ptr[c]) = b;
                }
            }
        }
    });
}
