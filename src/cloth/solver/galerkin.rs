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

/// Half-width of the coarse stencil.
const R: i64 = 2;
/// Blocks of a full coarse row.
const W: usize = (2 * R as usize + 1) * (2 * R as usize + 1);

/// The bilinear transfer between a fine and a coarse grid, both in row numbering, as the
/// Galerkin product reads it.
#[derive(Debug, Clone)]
pub struct GalerkinTransfer {
    /// Coarse grid width.
    cx: usize,
    /// For each fine particle, its coarse taps (coarse particle, weight; weight 0: unused).
    taps: Vec<[(u32, f64); 4]>,
    /// For each coarse particle, the fine particles whose taps reference it, with the weight.
    rev_ptr: Vec<usize>,
    rev: Vec<(u32, f64)>,
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
        GalerkinTransfer {
            cx: coarse.0,
            taps,
            rev_ptr,
            rev,
        }
    }
}

/// The symmetric pattern of the 5 × 5 stencil on an `nx` × `ny` grid.
pub fn coarse_pattern(nx: usize, ny: usize) -> Bcsr3 {
    let mut pairs = Vec::with_capacity(nx * ny * W / 2);
    for i in 0..ny as i64 {
        for j in 0..nx as i64 {
            for di in 0..=R {
                for dj in -R..=R {
                    if di == 0 && dj <= 0 {
                        continue;
                    }
                    let (i2, j2) = (i + di, j + dj);
                    if i2 < ny as i64 && (0..nx as i64).contains(&j2) {
                        let a = (i * nx as i64 + j) as usize;
                        pairs.push((a, (i2 * nx as i64 + j2) as usize));
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
    let cx = t.cx as i64;
    let fixed = |i: usize| !cons.fixed.is_empty() && cons.fixed[i];
    let vals = SyncPtr(coarse.values32.as_mut_ptr());
    let perm = coarse
        .permuted
        .as_mut()
        .map(|p| (SyncPtr(p.values.as_mut_ptr()), &p.row_start[..]));
    let (row_ptr, cols) = (&coarse.row_ptr, &coarse.cols);
    for_each_index(nc, nc >= PAR_MIN, |c| {
        let (ci, cj) = ((c as i64) / cx, (c as i64) % cx);
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
                for &(c2, w2) in &t.taps[j] {
                    if w2 == 0.0 {
                        continue;
                    }
                    let c2 = c2 as i64;
                    let (di, dj) = (c2 / cx - ci, c2 % cx - cj);
                    let slot = ((di + R) * (2 * R + 1) + dj + R) as usize;
                    acc[slot].add_scaled_sym(&blk, w * w2);
                }
            }
        }
        for k in row_ptr[c]..row_ptr[c + 1] {
            let c2 = cols[k] as i64;
            let (di, dj) = (c2 / cx - ci, c2 % cx - cj);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The Galerkin product of the identity under the bilinear transfer of a 3-point line onto
    /// 2 points is Pᵀ P, checked against the product written out by hand.
    #[test]
    fn galerkin_of_identity_is_p_transpose_p() {
        // fine 3×1 grid → coarse 2×1: taps 1, (½, ½), 1
        let taps = vec![
            [(0, 1.0), (1, 0.0), (0, 0.0), (1, 0.0)],
            [(0, 0.5), (1, 0.5), (0, 0.0), (1, 0.0)],
            [(0, 0.0), (1, 1.0), (0, 0.0), (1, 0.0)],
        ];
        let t = GalerkinTransfer::new(taps, (2, 1));
        let mut fine = Bcsr3::with_pattern(3, &[]);
        fine.enable_mirror32();
        for i in 0..3 {
            let k = fine.diag[i];
            fine.values32[k] = Sym3f([1.0, 0.0, 0.0, 1.0, 0.0, 1.0]);
        }
        let mut coarse = coarse_pattern(2, 1);
        coarse.enable_mirror32();
        let none = FineConstraints {
            pen: &[],
            fixed: &[],
        };
        fill(&fine, none, &t, &mut coarse);
        // PᵀP = [[1.25, 0.25], [0.25, 1.25]] times I
        let d = coarse.values32[coarse.diag[0]].0[0];
        let o = coarse.values32[coarse.slot(0, 1).unwrap()].0[0];
        assert!((d - 1.25).abs() < 1e-7 && (o - 0.25).abs() < 1e-7, "{d} {o}");
    }
}
