//! Garments that go over the top of the body (straps over the shoulders), for
//! pre-positioning: the body's top per silhouette column, how a figurine point above it is
//! laid over the top towards the other side (the seed's 3D silhouette), and how far pieces
//! must rise for their shoulder seams to meet there.

use super::figurine::{s_of, Figurine};
use super::silhouette::{Landmarks, Silhouettes};
use crate::garment::mesh::GarmentMesh;
use crate::garment::{Side, P2};

/// How far each piece must rise so that the seams joining a front piece to a back piece over
/// the top of the body (shoulder seams) meet when both are laid over the top
/// ([`over_the_top`]): for each such seam, half of what its two edges lack to cover the body's
/// depth there; a piece takes the largest of its seams. Seams elsewhere (side seams, which the
/// shells already close) ask for nothing.
#[allow(clippy::too_many_arguments)]
pub(super) fn over_the_top_lifts(
    garment: &GarmentMesh,
    figs: &[Figurine],
    fig_pos: &[P2],
    piece_of: &[usize],
    sil: &Silhouettes,
    marks: &Landmarks,
    tops: &[Option<usize>],
    dz: f64,
) -> Vec<f64> {
    let mut lift = vec![0.0f64; figs.len()];
    let fin = 0.5 * dz;
    for seam in &garment.seams {
        let (mut need, mut count) = (0.0, 0usize);
        let mut pieces = None;
        for &(a, b) in &seam.pairs {
            let (pa, pb) = (piece_of[a], piece_of[b]);
            if figs[pa].side == figs[pb].side {
                continue;
            }
            let (f, bk) = if figs[pa].side == Side::Front {
                (a, b)
            } else {
                (b, a)
            };
            let s = s_of(Side::Front, fig_pos[f][0]);
            let j = sil.col(s);
            let Some(i) = tops[j] else { continue };
            let top = sil.h_of(i).min(marks.neck) + dz;
            let (yf, yb) = (fig_pos[f][1], fig_pos[bk][1]);
            // only seams that end near the top of the body, not side seams
            if yf < top - 0.04 || yb < top - 0.04 {
                continue;
            }
            let Some((df, db)) = sil.depths(i, j) else {
                continue;
            };
            need += 0.5 * ((df - db) + 2.0 * dz - 2.0 * fin - (yf - top) - (yb - top));
            count += 1;
            pieces = Some((piece_of[f], piece_of[bk]));
        }
        if let (Some((pf, pb)), true) = (pieces, count > 0) {
            let l = (need / count as f64).max(0.0);
            lift[pf] = lift[pf].max(l);
            lift[pb] = lift[pb].max(l);
        }
    }
    lift
}

/// Per silhouette column, the highest covered row no higher than the neck (the top of the
/// shoulder under a strap), or `None` for an empty column.
pub(super) fn column_tops(sil: &Silhouettes, marks: &Landmarks) -> Vec<Option<usize>> {
    let cap = sil.row(marks.neck);
    (0..sil.ns)
        .map(|j| (0..=cap).rev().find(|&i| sil.covered(i, j)))
        .collect()
}

/// A vertex of the figurine that rises above the body's top at its column (a strap above the
/// shoulder) is laid over the top instead, front pieces towards the back and back pieces
/// towards the front, up to a fin just off the body's mid-depth where the two meet (the seed's
/// 3D silhouette): returns its height and depth.
#[allow(clippy::too_many_arguments)]
pub(super) fn over_the_top(
    sil: &Silhouettes,
    marks: &Landmarks,
    tops: &[Option<usize>],
    side: Side,
    s: f64,
    y: f64,
    d: f64,
    dz: f64,
) -> (f64, f64) {
    let j = sil.col(s);
    let Some(i) = tops[j] else {
        return (y, d);
    };
    let top = sil.h_of(i).min(marks.neck) + dz;
    if y <= top {
        return (y, d);
    }
    let Some((f, b)) = sil.depths(i, j) else {
        return (y, d);
    };
    let e = y - top;
    let fin = 0.5 * dz;
    let mid = 0.5 * (f + b);
    match side {
        Side::Front => {
            let room = (d - mid - fin).max(0.0);
            (top + (e - room).max(0.0), d - e.min(room))
        }
        Side::Back => {
            let room = (mid - fin - d).max(0.0);
            (top + (e - room).max(0.0), d + e.min(room))
        }
    }
}
