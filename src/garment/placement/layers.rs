//! Layering of overlapping pieces in pre-positioning. Pieces laid on the same figurine may
//! overlap where the garment has two layers (the vent extensions of a skirt's two back
//! halves, a shirt's button stands): mapped onto the same shell they would coincide and
//! intersect. Where a later piece overlaps an earlier one on the same side, the later piece is
//! lifted away from the body by a layer gap, ramped down with the distance (along the piece)
//! from the overlap so the piece is not sheared.

use crate::garment::mesh::graph::Adjacency;
use crate::garment::mesh::GarmentMesh;
use crate::garment::{Side, P2};

/// Lift (m, outwards) of every garment vertex so that overlapping pieces form layers.
///
/// `fig_pos` are the vertices' figurine positions and `sides` each piece's figurine side. A
/// vertex of piece B counts as overlapping piece A (A before B, same side) when it lies inside
/// A's outline deeper than `margin`: pieces that only meet along a seam do not overlap. Each
/// overlapping pair adds `gap` at the overlap, falling linearly to 0 at distance `ramp` from it.
pub(super) fn layer_lifts(
    garment: &GarmentMesh,
    fig_pos: &[P2],
    sides: &[Side],
    gap: f64,
    ramp: f64,
    margin: f64,
) -> Vec<f64> {
    let n = fig_pos.len();
    let mut lift = vec![0.0; n];
    if gap <= 0.0 {
        return lift;
    }
    let adjacency = Adjacency::new(&garment.mesh.triangles, n);
    let boxes: Vec<[f64; 4]> = garment
        .pieces
        .iter()
        .map(|pm| {
            pm.boundary
                .iter()
                .fold([f64::MAX, f64::MAX, f64::MIN, f64::MIN], |b, &v| {
                    let p = fig_pos[v];
                    [
                        b[0].min(p[0]),
                        b[1].min(p[1]),
                        b[2].max(p[0]),
                        b[3].max(p[1]),
                    ]
                })
        })
        .collect();
    for b in 1..garment.pieces.len() {
        for a in 0..b {
            if sides[a] != sides[b] || !boxes_overlap(&boxes[a], &boxes[b], margin) {
                continue;
            }
            let outline: Vec<P2> = garment.pieces[a]
                .boundary
                .iter()
                .map(|&v| fig_pos[v])
                .collect();
            let range = garment.pieces[b].vertices.clone();
            let sources: Vec<usize> = range
                .clone()
                .filter(|&v| depth_inside(&outline, fig_pos[v]) > margin)
                .collect();
            if sources.is_empty() {
                continue;
            }
            let (dist, _) = adjacency.nearest(&sources, fig_pos, ramp);
            for v in range {
                if dist[v] < ramp {
                    lift[v] += gap * (1.0 - dist[v] / ramp);
                }
            }
        }
    }
    lift
}

/// Mean rest length of the garment's triangle edges (interior edges counted twice).
pub(super) fn mean_edge_length(garment: &GarmentMesh) -> f64 {
    let m = &garment.mesh;
    let (mut sum, mut count) = (0.0, 0usize);
    for t in &m.triangles {
        for k in 0..3 {
            let (a, b) = (m.rest[t[k]], m.rest[t[(k + 1) % 3]]);
            sum += (a[0] - b[0]).hypot(a[1] - b[1]);
            count += 1;
        }
    }
    sum / count.max(1) as f64
}

fn boxes_overlap(a: &[f64; 4], b: &[f64; 4], margin: f64) -> bool {
    a[0] + margin < b[2] && b[0] + margin < a[2] && a[1] + margin < b[3] && b[1] + margin < a[3]
}

/// Signed distance from `p` to the closed polygon `outline` (positive inside).
fn depth_inside(outline: &[P2], p: P2) -> f64 {
    let mut inside = false;
    let mut d2 = f64::MAX;
    for i in 0..outline.len() {
        let (a, b) = (outline[i], outline[(i + 1) % outline.len()]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x > p[0] {
                inside = !inside;
            }
        }
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let len2 = ex * ex + ey * ey;
        let t = if len2 > 0.0 {
            (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (dx, dy) = (p[0] - a[0] - t * ex, p[1] - a[1] - t * ey);
        d2 = d2.min(dx * dx + dy * dy);
    }
    if inside {
        d2.sqrt()
    } else {
        -d2.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_of_a_unit_square() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert!((depth_inside(&sq, [0.5, 0.25]) - 0.25).abs() < 1e-12);
        assert!((depth_inside(&sq, [1.5, 0.5]) + 0.5).abs() < 1e-12);
    }
}
