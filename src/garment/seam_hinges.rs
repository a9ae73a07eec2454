//! Bending hinges across seams. Two pieces sewn along a seam share no triangle, so nothing
//! resists their folding about the seam line: the strip along one side can fold over the
//! other and through it (self-collision treats sewn vertices as one and does not see it).
//! A stitched seam bends like the fabric, so each seam edge — two consecutive seam pairs
//! whose vertices are a boundary edge of both pieces — gets a hinge joining the triangle on
//! one side to the triangle on the other, flat at rest, as a fabric edge has.

use std::collections::HashMap;

use super::mesh::GarmentMesh;
use crate::cloth::elements::Hinge;

/// The hinges across every seam edge of `garment`, switched off (`weight` 0): the sewing
/// schedule switches them on when the seams are stitched.
pub fn seam_hinges(garment: &GarmentMesh) -> Vec<Hinge> {
    let rest = &garment.mesh.rest;
    // each boundary edge's one triangle, by its third vertex (interior edges are dropped)
    let mut wing: HashMap<(usize, usize), Option<usize>> = HashMap::new();
    for t in &garment.mesh.triangles {
        for k in 0..3 {
            let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            wing.entry((p.min(q), p.max(q)))
                .and_modify(|w| *w = None)
                .or_insert(Some(r));
        }
    }
    let third = |p: usize, q: usize| wing.get(&(p.min(q), p.max(q))).copied().flatten();
    let area = |a: usize, b: usize, c: usize| {
        let (u, v) = (
            [rest[b][0] - rest[a][0], rest[b][1] - rest[a][1]],
            [rest[c][0] - rest[a][0], rest[c][1] - rest[a][1]],
        );
        0.5 * (u[0] * v[1] - u[1] * v[0]).abs()
    };
    let mut hinges = Vec::new();
    for seam in &garment.seams {
        for w in seam.pairs.windows(2) {
            let ((a0, b0), (a1, b1)) = (w[0], w[1]);
            if a0 == a1 || b0 == b1 || a0 == b0 || a1 == b1 {
                continue;
            }
            let (Some(c), Some(d)) = (third(a0, a1), third(b0, b1)) else {
                continue;
            };
            let (du, dv) = (rest[a1][0] - rest[a0][0], rest[a1][1] - rest[a0][1]);
            let l2 = du * du + dv * dv;
            let sum = area(a0, a1, c) + area(b0, b1, d);
            if l2 <= 0.0 || sum <= 0.0 {
                continue;
            }
            hinges.push(Hinge {
                nodes: [a0, a1, c, d],
                edge: l2.sqrt(),
                area: sum,
                warp_weight: dv * dv / l2,
                weight: 0.0,
                seam: true,
            });
        }
    }
    hinges
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::garment::mesh::{PieceMesh, SeamMesh};
    use crate::geometry::{TriMesh, Vec3};

    /// Two unit right triangles side by side, sewn along their facing edges.
    fn two_pieces() -> GarmentMesh {
        // piece A: 0 (0,0), 1 (0,1), 2 (-1,0); piece B: 3 (0,0), 4 (0,1), 5 (1,0)
        let rest = vec![
            [0.0, 0.0],
            [0.0, 1.0],
            [-1.0, 0.0],
            [0.0, 0.0],
            [0.0, 1.0],
            [1.0, 0.0],
        ];
        let positions: Vec<Vec3> = rest.iter().map(|p| Vec3::new(p[0], p[1], 0.0)).collect();
        let mesh = TriMesh {
            positions,
            rest: rest.clone(),
            triangles: vec![[0, 2, 1], [3, 4, 5]],
        };
        let piece = |name: &str, v: std::ops::Range<usize>, t: std::ops::Range<usize>| PieceMesh {
            name: name.into(),
            boundary: v.clone().collect(),
            corners: Vec::new(),
            vertices: v,
            triangles: t,
        };
        GarmentMesh {
            mesh,
            flat: rest,
            pieces: vec![piece("a", 0..3, 0..1), piece("b", 3..6, 1..2)],
            seams: vec![SeamMesh {
                name: "s".into(),
                pairs: vec![(0, 3), (1, 4)],
            }],
        }
    }

    #[test]
    fn a_seam_edge_gets_one_hinge_from_one_piece_to_the_other_off_until_stitched() {
        let h = seam_hinges(&two_pieces());
        assert_eq!(h.len(), 1);
        assert_eq!(h[0].nodes, [0, 1, 2, 5]);
        assert_eq!(h[0].edge, 1.0);
        assert_eq!(h[0].area, 1.0);
        // the seam runs along v: curvature across it bends the warp (u)
        assert_eq!(h[0].warp_weight, 1.0);
        assert_eq!(h[0].weight, 0.0);
        assert!(h[0].seam);
        // sewn flat, the hinge reads no angle
        let x: Vec<Vec3> = two_pieces().mesh.positions;
        let (theta, _) = h[0].angle_and_gradient(&x).unwrap();
        assert!(theta.abs() < 1e-12);
    }
}
