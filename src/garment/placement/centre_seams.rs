//! Centre seams in pre-positioning: a seam joining two pieces of the same figurine that starts
//! on the centre line (a skirt's centre back, the crotch seams of trousers) lies in the body's
//! plane of symmetry. Row by row mapping keeps heights, so a trouser front's crotch extension
//! would lie flat over the other leg; here both edges of such a seam are laid along the body's
//! centre profile at their arc length from their top end (down the front, under the crotch and
//! up the back, grown by the clearance), and the rest of the two pieces follows with a
//! displacement that fades with the distance along the piece from the seam.

use super::shell::convex_hull;
use crate::garment::mesh::graph::Adjacency;
use crate::garment::mesh::GarmentMesh;
use crate::garment::{Side, P2};
use crate::geometry::Vec3;

/// The centre profile: the body's outline in its plane of symmetry (height, depth), grown by
/// the clearance and made convex, from the garment's top at the front, down, under the body
/// and up to the top at the back.
pub(super) struct CentreProfile {
    /// (h, d) points from the top front to the top back, with their arc lengths.
    pts: Vec<[f64; 2]>,
    cum: Vec<f64>,
    /// Arc length of the lowest point (where the front part ends).
    bottom: f64,
}

impl CentreProfile {
    /// The profile around `rows` = (h, front depth, back depth) of the body's centre line,
    /// from the top down: their convex hull grown by `dz`, cut at the top row, its part below
    /// the lowest row lowered by `extra`.
    pub(super) fn new(rows: &[(f64, f64, f64)], dz: f64, extra: f64) -> Option<CentreProfile> {
        let h_top = rows.first()?.0;
        let h_low = rows.last()?.0;
        let points: Vec<[f64; 2]> = rows.iter().flat_map(|r| [[r.0, r.1], [r.0, r.2]]).collect();
        let k = 24;
        let radius = dz / (std::f64::consts::PI / k as f64).cos();
        let grown: Vec<[f64; 2]> = convex_hull(points)
            .into_iter()
            .flat_map(|q| {
                (0..k).map(move |i| {
                    let a = std::f64::consts::TAU * i as f64 / k as f64;
                    [q[0] + radius * a.cos(), q[1] + radius * a.sin()]
                })
            })
            .collect();
        let hull = convex_hull(grown);
        let n = hull.len();
        if n < 3 {
            return None;
        }
        // the run of hull points below the top, and where the hull crosses the top
        let below = |i: usize| hull[i % n][0] <= h_top;
        let first = (0..n).find(|&i| below(i) && !below(i + n - 1))?;
        let mut pts = Vec::with_capacity(n + 2);
        let cross = |a: [f64; 2], b: [f64; 2]| {
            let t = (h_top - a[0]) / (b[0] - a[0]);
            [h_top, a[1] + t * (b[1] - a[1])]
        };
        pts.push(cross(hull[(first + n - 1) % n], hull[first]));
        let mut i = first;
        while below(i) && pts.len() <= n {
            pts.push(hull[i % n]);
            i += 1;
        }
        pts.push(cross(hull[(i + n - 1) % n], hull[i % n]));
        if pts[0][1] < pts[pts.len() - 1][1] {
            pts.reverse();
        }
        for p in &mut pts {
            if p[0] < h_low {
                p[0] -= extra;
            }
        }
        let mut cum = vec![0.0];
        for w in pts.windows(2) {
            let l = (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]);
            cum.push(cum.last().copied().unwrap_or(0.0) + l);
        }
        let low = (0..pts.len())
            .min_by(|&a, &b| pts[a][0].total_cmp(&pts[b][0]))
            .unwrap_or(0);
        Some(CentreProfile {
            bottom: cum[low],
            pts,
            cum,
        })
    }

    fn total(&self) -> f64 {
        self.cum.last().copied().unwrap_or(0.0)
    }

    /// (h, d) at arc length `sigma` (clamped to the profile).
    fn at(&self, sigma: f64) -> [f64; 2] {
        let s = sigma.clamp(0.0, self.total());
        let i = match self.cum.binary_search_by(|c| c.total_cmp(&s)) {
            Ok(i) => i.min(self.pts.len() - 2),
            Err(i) => (i - 1).min(self.pts.len() - 2),
        };
        let (a, b) = (self.pts[i], self.pts[i + 1]);
        let l = self.cum[i + 1] - self.cum[i];
        let t = if l > 0.0 { (s - self.cum[i]) / l } else { 0.0 };
        [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
    }

    /// Arc length of the point at height `h` on the front part or on the back part.
    fn arc_at_height(&self, h: f64, side: Side) -> f64 {
        let mut best = match side {
            Side::Front => 0.0,
            Side::Back => self.total(),
        };
        for i in 0..self.pts.len() - 1 {
            let (a, b) = (self.pts[i], self.pts[i + 1]);
            let on_side = match side {
                Side::Front => self.cum[i + 1] <= self.bottom,
                Side::Back => self.cum[i] >= self.bottom,
            };
            if !on_side || (a[0] - h) * (b[0] - h) > 0.0 || a[0] == b[0] {
                continue;
            }
            let t = (h - a[0]) / (b[0] - a[0]);
            best = self.cum[i] + t * (self.cum[i + 1] - self.cum[i]);
            if side == Side::Front {
                break;
            }
        }
        best
    }
}

/// One edge of a centre seam: its vertices from the top end down, and the piece's side.
pub(super) struct CentreEdge {
    pub(super) vertices: Vec<usize>,
    pub(super) side: Side,
    pub(super) piece: usize,
}

/// Lays the `edges` of centre seams along the centre profile through `rows` (see
/// [`CentreProfile::new`]) and moves the rest of their pieces with a displacement fading to 0
/// at `falloff` (m along the piece). `x` are the mapped positions, `to_world(h, d)` the world
/// point of the centre line at height h and depth d. The crossing under the body lies `dz`
/// below it, or lower where the front and back seams are together longer than the profile
/// (the crotch of trousers hangs below the body): front and back ends then meet.
#[allow(clippy::too_many_arguments)]
pub(super) fn lay_centre_seams(
    garment: &GarmentMesh,
    edges: &[CentreEdge],
    rows: &[(f64, f64, f64)],
    dz: f64,
    height_of: impl Fn(&Vec3) -> f64,
    to_world: impl Fn(f64, f64) -> Vec3,
    falloff: f64,
    x: &mut [Vec3],
) {
    let flat: &[P2] = &garment.flat;
    let Some(level) = CentreProfile::new(rows, dz, 0.0) else {
        return;
    };
    // how far along the profile each side's longest edge reaches from the profile's ends
    let mut reach = [None::<f64>; 2];
    for e in edges {
        let Some(&top) = e.vertices.first() else {
            continue;
        };
        let length: f64 = e
            .vertices
            .windows(2)
            .map(|w| (flat[w[1]][0] - flat[w[0]][0]).hypot(flat[w[1]][1] - flat[w[0]][1]))
            .sum();
        let arc = level.arc_at_height(height_of(&x[top]), e.side);
        let (k, from_end) = match e.side {
            Side::Front => (0, arc),
            Side::Back => (1, level.total() - arc),
        };
        let r = from_end + length;
        reach[k] = Some(reach[k].map_or(r, |q: f64| q.max(r)));
    }
    let extra = match reach {
        [Some(f), Some(b)] => (0.5 * (f + b - level.total())).max(0.0),
        _ => 0.0,
    };
    let Some(profile) = CentreProfile::new(rows, dz, extra) else {
        return;
    };
    let adjacency = Adjacency::new(&garment.mesh.triangles, x.len());
    for piece in 0..garment.pieces.len() {
        let mine: Vec<&CentreEdge> = edges.iter().filter(|e| e.piece == piece).collect();
        if mine.is_empty() {
            continue;
        }
        let mut sources = Vec::new();
        let mut delta = vec![Vec3::zeros(); x.len()];
        for e in mine {
            let Some(&top) = e.vertices.first() else {
                continue;
            };
            let mut sigma = profile.arc_at_height(height_of(&x[top]), e.side);
            let mut prev = top;
            for &v in &e.vertices {
                let step = (flat[v][0] - flat[prev][0]).hypot(flat[v][1] - flat[prev][1]);
                sigma += match e.side {
                    Side::Front => step,
                    Side::Back => -step,
                };
                prev = v;
                let [h, d] = profile.at(sigma);
                delta[v] = to_world(h, d) - x[v];
                sources.push(v);
            }
        }
        let (dist, nearest) = adjacency.nearest(&sources, flat, falloff);
        for v in garment.pieces[piece].vertices.clone() {
            if dist[v] < falloff {
                x[v] += delta[nearest[v]] * (1.0 - dist[v] / falloff);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box-shaped body 0.2 m deep and 0.2 m tall: the grown profile runs 0.2 m down the
    /// front, round a quarter circle of radius dz, 0.2 m under, and up the back.
    #[test]
    fn profile_of_a_box_goes_down_under_and_up() {
        let dz = 0.01;
        let rows: Vec<(f64, f64, f64)> = (0..=20).map(|i| (-0.01 * i as f64, 0.1, -0.1)).collect();
        let p = CentreProfile::new(&rows, dz, 0.0).unwrap();
        let expected = 0.2 + 0.2 + 0.2 + std::f64::consts::PI * dz;
        assert!(
            (p.total() - expected).abs() < 0.01 * expected,
            "{} vs {expected}",
            p.total()
        );
        // starts at the top front, grown by dz, and reaches the bottom at the crossing
        let [h, d] = p.at(0.0);
        assert!(h.abs() < 1e-12 && (d - 0.11).abs() < 1e-3, "{h} {d}");
        let front = p.arc_at_height(-0.1, Side::Front);
        assert!((front - 0.1).abs() < 1e-3, "{front}");
        let back = p.arc_at_height(-0.1, Side::Back);
        assert!((p.total() - back - 0.1).abs() < 1e-3, "{back}");
        let [h, _] = p.at(0.5 * p.total());
        assert!((h + 0.21).abs() < 1e-3, "middle of the crossing at {h}");
        // a crotch hanging lower lengthens the profile by twice the drop
        let low = CentreProfile::new(&rows, dz, 0.03).unwrap();
        assert!((low.total() - p.total() - 0.06).abs() < 1e-3);
    }
}
