//! Inside a closed triangle mesh by the parity of a ray's crossings (exact segment–triangle
//! tests; the ray's direction is irrational-looking so that it misses edges and vertices).
#![allow(dead_code)]

use super::intersections::segment_triangle_intersect_exact;

/// How many of `points` lie inside the closed mesh (`vertices`, `triangles`).
pub fn count_inside(points: &[[f64; 3]], vertices: &[[f64; 3]], triangles: &[[usize; 3]]) -> usize {
    points
        .iter()
        .filter(|q| {
            let far = [q[0] + 31.7, q[1] + 17.3, q[2] + 23.9];
            triangles
                .iter()
                .filter(|t| {
                    segment_triangle_intersect_exact(
                        **q,
                        far,
                        vertices[t[0]],
                        vertices[t[1]],
                        vertices[t[2]],
                    )
                })
                .count()
                % 2
                == 1
        })
        .count()
}
