//! Where the cloth passes through itself: intersecting edge–triangle pairs, for reports and
//! for the stop checks of the cloth–cloth response.

use rayon::prelude::*;

use super::super::primitives::segment_triangle_intersect;
use super::super::spatial_hash::Aabb;
use super::SelfCollision;
use crate::geometry::Vec3;

impl SelfCollision {
    /// Number of (edge, triangle) pairs of the cloth at `x` that intersect, pairs sharing a
    /// vertex excluded (fast floating-point test).
    pub fn count_intersections(&mut self, x: &[Vec3]) -> usize {
        self.intersections(x).len()
    }

    /// The (edge, triangle) pairs of the cloth at `x` that intersect, pairs sharing a vertex
    /// excluded (fast floating-point test), in a deterministic order.
    pub fn intersections(&mut self, x: &[Vec3]) -> Vec<([u32; 2], [u32; 3])> {
        let tight = |ids: &[u32]| {
            let mut b = Aabb::empty();
            for &i in ids {
                b.grow(&x[i as usize]);
            }
            b
        };
        self.tri_boxes.clear();
        self.tri_boxes
            .extend(self.triangles.iter().map(|t| tight(t)));
        self.tri_hash.build(&self.tri_boxes, self.cell);
        let (tris, edges, hash) = (&self.triangles, &self.edges, &self.tri_hash);
        let rep = &self.welds.rep;
        let r = |i: u32| if rep.is_empty() { i } else { rep[i as usize] };
        let ne = edges.len();
        let chunk = 1024;
        (0..ne.div_ceil(chunk))
            .into_par_iter()
            .map(|c| {
                let mut buf = Vec::new();
                let mut found = Vec::new();
                for e in c * chunk..((c + 1) * chunk).min(ne) {
                    let [a, b] = edges[e];
                    hash.query(&tight(&[a, b]), &mut buf);
                    for &t in &buf {
                        let t = tris[t as usize];
                        if t.iter().any(|&k| r(k) == r(a) || r(k) == r(b)) {
                            continue;
                        }
                        let p = t.map(|i| x[i as usize]);
                        if segment_triangle_intersect(
                            x[a as usize],
                            x[b as usize],
                            p[0],
                            p[1],
                            p[2],
                        ) {
                            found.push(([a, b], t));
                        }
                    }
                }
                found
            })
            .flatten()
            .collect()
    }
}
