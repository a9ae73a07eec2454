//! The grid multigrid's transfers between a level and the next coarser one: bilinear
//! interpolation in the rest plane (prolongation), its adjoint (restriction), both optionally
//! projecting out constrained directions, and the sampling of a coarse level's state from the
//! finer one.

use super::parallel::{for_each_mut, PAR_MIN};
use crate::geometry::Vec3;

/// Bilinear interpolation from a coarse grid to a fine one: four (coarse particle, weight)
/// pairs per fine particle.
#[derive(Debug, Clone)]
pub(super) struct Transfer {
    pub(super) taps: Vec<[(u32, f64); 4]>,
    /// For each coarse particle, the fine taps that reference it: (fine particle, weight).
    rev_ptr: Vec<usize>,
    rev: Vec<(u32, f64)>,
}

impl Transfer {
    pub(super) fn new(fine: (usize, usize), coarse: (usize, usize)) -> Self {
        let axis = |nf: usize, nc: usize| -> Vec<(usize, f64)> {
            (0..nf)
                .map(|k| {
                    let s = k as f64 / (nf - 1) as f64 * (nc - 1) as f64;
                    let c = (s.floor() as usize).min(nc - 2);
                    (c, s - c as f64)
                })
                .collect()
        };
        let (ax, ay) = (axis(fine.0, coarse.0), axis(fine.1, coarse.1));
        let ncx = coarse.0;
        let mut taps = Vec::with_capacity(fine.0 * fine.1);
        for &(cy, ty) in &ay {
            for &(cx, tx) in &ax {
                let id = |i: usize, j: usize| (i * ncx + j) as u32;
                taps.push([
                    (id(cy, cx), (1.0 - tx) * (1.0 - ty)),
                    (id(cy, cx + 1), tx * (1.0 - ty)),
                    (id(cy + 1, cx), (1.0 - tx) * ty),
                    (id(cy + 1, cx + 1), tx * ty),
                ]);
            }
        }
        let nc = coarse.0 * coarse.1;
        let mut lists: Vec<Vec<(u32, f64)>> = vec![Vec::new(); nc];
        for (f, t) in taps.iter().enumerate() {
            for &(c, w) in t {
                if w != 0.0 {
                    lists[c as usize].push((f as u32, w));
                }
            }
        }
        let mut rev_ptr = vec![0];
        let mut rev = Vec::new();
        for l in lists {
            rev.extend(l);
            rev_ptr.push(rev.len());
        }
        Transfer { taps, rev_ptr, rev }
    }

    /// The same transfer with the fine particles renumbered: fine position `p` is particle
    /// `order[p]`.
    pub(super) fn permuted_fine(&self, order: &[u32]) -> Self {
        let mut inv = vec![0u32; order.len()];
        for (p, &i) in order.iter().enumerate() {
            inv[i as usize] = p as u32;
        }
        Transfer {
            taps: order.iter().map(|&i| self.taps[i as usize]).collect(),
            rev_ptr: self.rev_ptr.clone(),
            rev: self
                .rev
                .iter()
                .map(|&(f, w)| (inv[f as usize], w))
                .collect(),
        }
    }

    /// fine += S P coarse: with constrained directions `dirs` (a unit normal or zero per fine
    /// particle), the correction's component along each is projected out (S = I − n nᵀ), so
    /// that the coarse correction never pushes against a contact.
    pub(super) fn prolong_add(
        &self,
        coarse: &[Vec3],
        fine: &mut [Vec3],
        fixed: &[bool],
        dirs: Option<&[Vec3]>,
    ) {
        let par = fine.len() >= PAR_MIN;
        match dirs {
            None => for_each_mut(fine, par, |i, f| {
                if !fixed[i] {
                    *f += bilinear(&self.taps[i], coarse);
                }
            }),
            Some(dirs) => for_each_mut(fine, par, |i, f| {
                if !fixed[i] {
                    *f += project_out(bilinear(&self.taps[i], coarse), &dirs[i]);
                }
            }),
        }
    }

    /// coarse = Pᵀ S fine (fixed coarse particles get zero; `dirs` as in
    /// [`Transfer::prolong_add`], whose adjoint this is).
    pub(super) fn restrict(
        &self,
        fine: &[Vec3],
        coarse: &mut [Vec3],
        coarse_fixed: &[bool],
        dirs: Option<&[Vec3]>,
    ) {
        let par = coarse.len() >= PAR_MIN;
        for_each_mut(coarse, par, |i, out| {
            *out = Vec3::zeros();
            if !coarse_fixed[i] {
                let taps = &self.rev[self.rev_ptr[i]..self.rev_ptr[i + 1]];
                match dirs {
                    None => {
                        for &(f, w) in taps {
                            *out += fine[f as usize] * w;
                        }
                    }
                    Some(dirs) => {
                        for &(f, w) in taps {
                            let f = f as usize;
                            *out += project_out(fine[f], &dirs[f]) * w;
                        }
                    }
                }
            }
        });
    }
}

/// The bilinear combination of `field` at four taps.
#[inline]
fn bilinear(t: &[(u32, f64); 4], field: &[Vec3]) -> Vec3 {
    field[t[0].0 as usize] * t[0].1
        + field[t[1].0 as usize] * t[1].1
        + field[t[2].0 as usize] * t[2].1
        + field[t[3].0 as usize] * t[3].1
}

/// `v` without its component along `n` (a unit vector, or zero: `v` unchanged).
#[inline]
fn project_out(v: Vec3, n: &Vec3) -> Vec3 {
    v - n * n.dot(&v)
}

/// A coarse level's state sampled from the finer level's field at the coarse rest positions.
pub(super) fn sample(fine: &[Vec3], coarse: &mut [Vec3], taps: &[[(u32, f64); 4]]) {
    let par = coarse.len() >= PAR_MIN;
    for_each_mut(coarse, par, |i, out| *out = bilinear(&taps[i], fine));
}

/// The fine-grid bilinear taps at each coarse node's rest position.
pub(super) fn sampling(fine: (usize, usize), coarse: (usize, usize)) -> Vec<[(u32, f64); 4]> {
    Transfer::new(coarse, fine).taps
}
