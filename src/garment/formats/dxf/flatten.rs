//! The DXF-AAMA writer's plane geometry: an outline flattened into a polyline that keeps its
//! corners, the middles of its curves and its notches on straight edges as exact vertices
//! ([`flatten`]), and the
//! polygon offset that draws the cut line around the sewing line ([`offset`]).

use super::geom::{add, closest_on_segment, cross, dist, mul, signed_area, sub};
use crate::garment::pattern::{Piece, Segment, P2};

/// Largest distance from a flattened curve to its chords (m): 1 µm, so that a notch on a
/// curve, read back on the chords, stays within 0.01 mm.
const FLATTEN_TOL: f64 = 1e-6;
/// Samples per curve of the coarse search for the point nearest a notch.
const COARSE: usize = 256;

/// The outline flattened: points, which are corners, which are the middles of curves, which
/// edges (from point i to i + 1) lie on the fold, and where each notch is (its projection onto
/// the outline; a vertex of `pts` on a straight edge).
pub(crate) struct Flat {
    pub pts: Vec<P2>,
    pub corners: Vec<usize>,
    pub middles: Vec<usize>,
    pub fold: Vec<bool>,
    pub notches: Vec<P2>,
}

/// The point of the outline nearest `p`: (corner index of its segment, parameter on it).
fn project(piece: &Piece, p: P2) -> (usize, f64) {
    let cs = &piece.outline.corners;
    let mut best = (0, 0.0, f64::INFINITY);
    for (i, c) in cs.iter().enumerate() {
        let (p0, p3) = (c.at, cs[(i + 1) % cs.len()].at);
        let (t, d) = match c.segment {
            Segment::Line => {
                let (q, t) = closest_on_segment(p0, p3, p);
                (t, dist(q, p))
            }
            Segment::Cubic { .. } => {
                let at = |t: f64| dist(c.segment.point(p0, p3, t), p);
                let k = (0..=COARSE)
                    .min_by(|&a, &b| {
                        at(a as f64 / COARSE as f64).total_cmp(&at(b as f64 / COARSE as f64))
                    })
                    .unwrap_or(0);
                // Golden-section search around the best sample.
                let h = 1.0 / COARSE as f64;
                let (mut lo, mut hi) = (
                    ((k as f64 - 1.0) * h).max(0.0),
                    ((k as f64 + 1.0) * h).min(1.0),
                );
                let g = 0.5 * (5f64.sqrt() - 1.0);
                for _ in 0..80 {
                    let (a, b) = (hi - g * (hi - lo), lo + g * (hi - lo));
                    if at(a) < at(b) {
                        hi = b;
                    } else {
                        lo = a;
                    }
                }
                let t = 0.5 * (lo + hi);
                (t, at(t))
            }
        };
        if d < best.2 {
            best = (i, t, d);
        }
    }
    (best.0, best.1)
}

/// Flattens the outline of `piece` within 1 µm, its notches projected onto it.
pub(crate) fn flatten(piece: &Piece) -> Flat {
    let cs = &piece.outline.corners;
    let n_c = cs.len();
    // Notches as (corner, parameter), moved to the corner when at a segment's end.
    let on: Vec<(usize, f64)> = piece
        .notches
        .iter()
        .map(|&p| match project(piece, p) {
            (i, t) if t >= 1.0 - 1e-12 => ((i + 1) % n_c, 0.0),
            (i, t) if t <= 1e-12 => (i, 0.0),
            x => x,
        })
        .collect();
    let mut f = Flat {
        pts: Vec::new(),
        corners: Vec::new(),
        middles: Vec::new(),
        fold: Vec::new(),
        notches: on
            .iter()
            .map(|&(i, t)| cs[i].segment.point(cs[i].at, cs[(i + 1) % n_c].at, t))
            .collect(),
    };
    for (i, c) in cs.iter().enumerate() {
        let (p0, p3) = (c.at, cs[(i + 1) % n_c].at);
        let on_fold = piece.fold.as_deref() == Some(c.name.as_str());
        let mut ts: Vec<f64> = match c.segment {
            Segment::Line => vec![0.0],
            Segment::Cubic { c1, c2 } => {
                // Chord error of n even steps ≤ max|B''| / (8 n²), |B''| ≤ 6 max(|Δ²P|).
                let d2 = dist(add(p0, c2), mul(c1, 2.0)).max(dist(add(c1, p3), mul(c2, 2.0)));
                let n = ((6.0 * d2 / (8.0 * FLATTEN_TOL)).sqrt().ceil() as usize).clamp(2, 2000);
                let n = n + n % 2;
                (0..n).map(|k| k as f64 / n as f64).collect()
            }
        };
        ts.extend(
            on.iter()
                .filter(|&&(j, t)| j == i && t > 0.0)
                .map(|&(_, t)| t),
        );
        ts.sort_by(f64::total_cmp);
        ts.dedup_by(|b, a| (*b - *a).abs() < 1e-12);
        f.corners.push(f.pts.len());
        for t in ts {
            if t == 0.5 && c.segment != Segment::Line {
                f.middles.push(f.pts.len());
            }
            f.pts.push(if t == 0.0 {
                p0
            } else {
                c.segment.point(p0, p3, t)
            });
            f.fold.push(on_fold);
        }
    }
    f
}

/// The polygon `pts` with each edge moved outwards by its own distance `d[i]` (mitred, the
/// mitre limited to four times the largest distance). Vertex i of the result goes with
/// vertex i of `pts`.
pub(crate) fn offset(pts: &[P2], d: &[f64]) -> Vec<P2> {
    let n = pts.len();
    let sign = signed_area(pts).signum();
    let normal = |i: usize| {
        let e = sub(pts[(i + 1) % n], pts[i]);
        let l = e[0].hypot(e[1]).max(1e-300);
        mul([e[1], -e[0]], sign / l)
    };
    let limit = 4.0 * d.iter().cloned().fold(0.0, f64::max);
    (0..n)
        .map(|i| {
            let j = (i + n - 1) % n;
            let (n0, n1) = (normal(j), normal(i));
            let det = cross(n0, n1);
            let p = if det.abs() < 1e-9 {
                add(pts[i], mul(n1, d[i]))
            } else {
                // The offset q = p − v with n0·q = d0 and n1·q = d1.
                let (r0, r1) = (d[j], d[i]);
                let q = [
                    (r0 * n1[1] - r1 * n0[1]) / det,
                    (n0[0] * r1 - n1[0] * r0) / det,
                ];
                add(pts[i], q)
            };
            let off = sub(p, pts[i]);
            let l = off[0].hypot(off[1]);
            if l > limit && l > 0.0 {
                add(pts[i], mul(off, limit / l))
            } else {
                p
            }
        })
        .collect()
}
