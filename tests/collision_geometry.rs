//! Collision geometry against analytic answers: closest points (triangle Voronoi regions,
//! skew/parallel/degenerate segments), continuous collision detection (vertex–face and
//! edge–edge times, weights and normals, degenerate cubics), and the independent exact
//! edge–triangle intersection counter of `tests/support`.

mod support;

use std::time::Instant;

use emilion::contact::ccd::{
    coplanarity_cubic, cubic_roots_in_unit_interval, edge_edge_ccd, vertex_face_ccd, CcdHit,
    MIN_THICKNESS,
};
use emilion::contact::primitives::{
    closest_point_segment, closest_point_triangle, closest_points_segments,
    segment_triangle_intersect,
};
use nalgebra::Vector3;
use support::intersections::{
    count_edge_triangle_intersections, count_edge_triangle_intersections_brute, orient2d,
    orient2d_exact, orient3d, orient3d_exact, segment_triangle_intersect_exact,
    segments_intersect_3d,
};

type Vec3 = Vector3<f64>;

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn arr(p: Vec3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// xorshift64* — deterministic test randomness without a dependency.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn vec(&mut self, s: f64) -> Vec3 {
        v(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
    fn int(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next_u64() % ((hi - lo + 1) as u64)) as i64
    }
}

fn assert_close(a: Vec3, b: Vec3, tol: f64) {
    assert!((a - b).norm() <= tol, "{a:?} vs {b:?}");
}

fn assert_weights(w: &[f64], expected: &[f64], tol: f64) {
    for (x, y) in w.iter().zip(expected) {
        assert!((x - y).abs() <= tol, "weights {w:?} vs {expected:?}");
    }
}

fn assert_valid_barycentric(w: [f64; 3]) {
    assert!(
        w.iter().all(|x| x.is_finite() && *x >= 0.0 && *x <= 1.0),
        "{w:?}"
    );
    assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{w:?}");
}

// ---------------------------------------------------------------------------------------
// closest point on a triangle
// ---------------------------------------------------------------------------------------

#[test]
fn closest_point_triangle_each_voronoi_region() {
    let (a, b, c) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0));
    let cases: [(Vec3, Vec3, [f64; 3]); 7] = [
        // vertex regions
        (v(-1.0, -1.0, 0.5), a, [1.0, 0.0, 0.0]),
        (v(2.0, -0.5, 0.3), b, [0.0, 1.0, 0.0]),
        (v(-0.5, 2.0, -0.3), c, [0.0, 0.0, 1.0]),
        // edge regions
        (v(0.3, -1.0, 0.7), v(0.3, 0.0, 0.0), [0.7, 0.3, 0.0]),
        (v(-1.0, 0.4, 0.2), v(0.0, 0.4, 0.0), [0.6, 0.0, 0.4]),
        (v(1.0, 1.0, -0.5), v(0.5, 0.5, 0.0), [0.0, 0.5, 0.5]),
        // face region
        (v(0.2, 0.3, 0.9), v(0.2, 0.3, 0.0), [0.5, 0.2, 0.3]),
    ];
    for (p, q, w) in cases {
        let (got, gw) = closest_point_triangle(p, a, b, c);
        assert_close(got, q, 1e-14);
        assert_weights(&gw, &w, 1e-14);
        assert_valid_barycentric(gw);
        assert_close(a * gw[0] + b * gw[1] + c * gw[2], got, 1e-14);
    }
}

#[test]
fn closest_point_triangle_is_optimal_on_random_triangles() {
    // For the closest point q of a convex set, (p − q)·(x − q) ≤ 0 for every x in the set;
    // by linearity checking the three corners suffices.
    let mut rng = Rng(0x1234_5678);
    for _ in 0..20_000 {
        let (a, b, c) = (rng.vec(1.0), rng.vec(1.0), rng.vec(1.0));
        let p = rng.vec(2.0);
        let (q, w) = closest_point_triangle(p, a, b, c);
        assert_valid_barycentric(w);
        assert_close(a * w[0] + b * w[1] + c * w[2], q, 1e-12);
        let scale = 1.0 + (p - q).norm();
        for x in [a, b, c] {
            assert!(
                (p - q).dot(&(x - q)) <= 1e-12 * scale,
                "not optimal: p={p:?}"
            );
        }
    }
}

#[test]
fn closest_point_triangle_degenerate_triangles_have_no_nan() {
    // collinear: c between a and b → closest point on the longest edge a–b
    let (a, b, c) = (v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(1.0, 0.0, 0.0));
    let (q, w) = closest_point_triangle(v(0.5, 1.0, 1.0), a, b, c);
    assert_close(q, v(0.5, 0.0, 0.0), 1e-15);
    assert_valid_barycentric(w);
    assert_weights(&w, &[0.75, 0.25, 0.0], 1e-15);
    // longest edge is b–c
    let (q, w) = closest_point_triangle(
        v(3.0, -1.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.0, 0.0, 0.0),
        v(4.0, 0.0, 0.0),
    );
    assert_close(q, v(3.0, 0.0, 0.0), 1e-15);
    assert_weights(&w, &[0.0, 0.25, 0.75], 1e-15);
    // longest edge is c–a
    let (q, w) = closest_point_triangle(
        v(-1.0, 0.0, 5.0),
        v(1.0, 0.0, 0.0),
        v(0.0, 0.0, 0.0),
        v(-4.0, 0.0, 0.0),
    );
    assert_close(q, v(-1.0, 0.0, 0.0), 1e-15);
    assert_weights(&w, &[0.6, 0.0, 0.4], 1e-15);
    // two coincident corners
    let (q, w) = closest_point_triangle(v(0.5, 3.0, 0.0), a, a, b);
    assert_close(q, v(0.5, 0.0, 0.0), 1e-15);
    assert_valid_barycentric(w);
    // all corners coincident
    let (q, w) = closest_point_triangle(v(1.0, 2.0, 3.0), b, b, b);
    assert_close(q, b, 0.0);
    assert_valid_barycentric(w);
    // sliver: area far below round-off of the edge lengths, far-away query point
    let s = v(1.0, 1e-17, 0.0);
    let (q, w) = closest_point_triangle(v(1e3, -2e3, 7.0), a, b, s);
    assert!(q.iter().all(|x| x.is_finite()));
    assert_valid_barycentric(w);
    assert_close(q, b, 1e-12);
}

#[test]
fn closest_point_on_segment() {
    let (q, s) = closest_point_segment(v(0.25, 1.0, 0.0), v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0));
    assert_close(q, v(0.25, 0.0, 0.0), 1e-15);
    assert!((s - 0.25).abs() < 1e-15);
    let (q, s) = closest_point_segment(v(3.0, 1.0, 0.0), v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0));
    assert_close(q, v(1.0, 0.0, 0.0), 0.0);
    assert_eq!(s, 1.0);
    let (q, s) = closest_point_segment(v(3.0, 1.0, 0.0), v(1.0, 1.0, 1.0), v(1.0, 1.0, 1.0));
    assert_close(q, v(1.0, 1.0, 1.0), 0.0);
    assert_eq!(s, 0.0);
}

// ---------------------------------------------------------------------------------------
// closest points of two segments
// ---------------------------------------------------------------------------------------

#[test]
fn segments_skew_interior() {
    let (s, t, c1, c2) = closest_points_segments(
        v(-1.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.5, -1.0, 1.0),
        v(0.5, 1.0, 1.0),
    );
    assert!(
        (s - 0.75).abs() < 1e-15 && (t - 0.5).abs() < 1e-15,
        "{s} {t}"
    );
    assert_close(c1, v(0.5, 0.0, 0.0), 1e-15);
    assert_close(c2, v(0.5, 0.0, 1.0), 1e-15);
}

#[test]
fn segments_skew_clamped_to_ends() {
    // lines cross beyond the end of the second segment
    let (s, t, c1, c2) = closest_points_segments(
        v(-1.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.5, 1.0, 1.0),
        v(0.5, 3.0, 1.0),
    );
    assert!((s - 0.75).abs() < 1e-15 && t == 0.0, "{s} {t}");
    assert_close(c1, v(0.5, 0.0, 0.0), 1e-15);
    assert_close(c2, v(0.5, 1.0, 1.0), 1e-15);
    // both clamped: ends nearest each other
    let (s, t, _, _) = closest_points_segments(
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(2.0, 1.0, 0.0),
        v(2.0, 3.0, 0.0),
    );
    assert_eq!((s, t), (1.0, 0.0));
}

#[test]
fn segments_parallel_overlapping_and_disjoint() {
    // overlapping parallel segments one unit apart: the middle of the overlap
    let (s, t, c1, c2) = closest_points_segments(
        v(0.0, 0.0, 0.0),
        v(2.0, 0.0, 0.0),
        v(1.0, 1.0, 0.0),
        v(3.0, 1.0, 0.0),
    );
    assert!(((c1 - c2).norm() - 1.0).abs() < 1e-15);
    assert!(
        (s - 0.75).abs() < 1e-15 && (t - 0.25).abs() < 1e-15,
        "{s} {t}"
    );
    // anti-parallel
    let (s, t, c1, c2) = closest_points_segments(
        v(0.0, 0.0, 0.0),
        v(2.0, 0.0, 0.0),
        v(3.0, 0.0, 1.0),
        v(1.0, 0.0, 1.0),
    );
    assert!(((c1 - c2).norm() - 1.0).abs() < 1e-15);
    assert!((0.5..=1.0).contains(&s) && (0.0..=1.0).contains(&t));
    // collinear with a gap: facing ends
    let (s, t, c1, c2) = closest_points_segments(
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(3.0, 0.0, 0.0),
        v(2.0, 0.0, 0.0),
    );
    assert_eq!((s, t), (1.0, 1.0));
    assert_close(c1, v(1.0, 0.0, 0.0), 0.0);
    assert_close(c2, v(2.0, 0.0, 0.0), 0.0);
    // nearly parallel (angle 1e-9): still a distance within round-off of the true one (1)
    let (_, _, c1, c2) = closest_points_segments(
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.0, 1.0, 0.0),
        v(1.0, 1.0 + 1e-9, 0.0),
    );
    assert!(((c1 - c2).norm() - 1.0).abs() < 1e-12);
}

#[test]
fn segments_degenerate() {
    let a = v(0.0, 0.0, 0.0);
    let b = v(2.0, 0.0, 0.0);
    let p = v(0.5, 1.0, 0.0);
    // point vs segment, both orders
    let (s, t, c1, c2) = closest_points_segments(p, p, a, b);
    assert_eq!(s, 0.0);
    assert!((t - 0.25).abs() < 1e-15);
    assert_close(c1, p, 0.0);
    assert_close(c2, v(0.5, 0.0, 0.0), 1e-15);
    let (s, t, _, c2) = closest_points_segments(a, b, p, p);
    assert!((s - 0.25).abs() < 1e-15 && t == 0.0);
    assert_close(c2, p, 0.0);
    // point vs point
    let (s, t, c1, c2) = closest_points_segments(a, a, b, b);
    assert_eq!((s, t), (0.0, 0.0));
    assert_close(c1, a, 0.0);
    assert_close(c2, b, 0.0);
    // identical segments
    let (s, t, c1, c2) = closest_points_segments(a, b, a, b);
    assert!(s.is_finite() && t.is_finite());
    assert!((c1 - c2).norm() < 1e-15);
    // tiny segment (1e-300 long): finite and correct distance
    let (s, t, c1, c2) = closest_points_segments(p, p + v(1e-300, 0.0, 0.0), a, b);
    assert!(s.is_finite() && t.is_finite());
    assert!(((c1 - c2).norm() - 1.0).abs() < 1e-15);
}

#[test]
fn segments_random_are_optimal() {
    // Compare with a fine two-parameter search (coarse grid + local refinement).
    let mut rng = Rng(99);
    for _ in 0..2_000 {
        let (p0, p1, q0, q1) = (rng.vec(1.0), rng.vec(1.0), rng.vec(1.0), rng.vec(1.0));
        let (s, t, c1, c2) = closest_points_segments(p0, p1, q0, q1);
        assert!((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t));
        assert_close(c1, p0 + (p1 - p0) * s, 1e-14);
        assert_close(c2, q0 + (q1 - q0) * t, 1e-14);
        let dist = (c1 - c2).norm();
        let n = 60;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=n {
                let (u, w) = (i as f64 / n as f64, j as f64 / n as f64);
                let d = (p0 + (p1 - p0) * u - q0 - (q1 - q0) * w).norm();
                best = best.min(d);
            }
        }
        assert!(dist <= best + 1e-12, "{dist} > sampled {best}");
        // first-order optimality: each point is the closest on its segment to the other
        let (_, s2) = closest_point_segment(c2, p0, p1);
        let (_, t2) = closest_point_segment(c1, q0, q1);
        let d_s = (p0 + (p1 - p0) * s2 - c2).norm();
        let d_t = (q0 + (q1 - q0) * t2 - c1).norm();
        assert!(dist <= d_s + 1e-12 && dist <= d_t + 1e-12);
    }
}

// ---------------------------------------------------------------------------------------
// fast segment–triangle test
// ---------------------------------------------------------------------------------------

#[test]
fn fast_segment_triangle_basic_cases() {
    let (a, b, c) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0));
    let up = v(0.0, 0.0, 1.0);
    let inside = v(0.2, 0.3, 0.0);
    let outside = v(0.8, 0.8, 0.0);
    assert!(segment_triangle_intersect(
        inside - up,
        inside + up,
        a,
        b,
        c
    ));
    assert!(!segment_triangle_intersect(
        outside - up,
        outside + up,
        a,
        b,
        c
    ));
    assert!(!segment_triangle_intersect(
        inside + up,
        inside + up * 2.0,
        a,
        b,
        c
    ));
    // touching: endpoint on the face, through an edge, through a vertex
    assert!(segment_triangle_intersect(inside, inside + up, a, b, c));
    assert!(segment_triangle_intersect(
        v(0.5, 0.0, -1.0),
        v(0.5, 0.0, 1.0),
        a,
        b,
        c
    ));
    assert!(segment_triangle_intersect(
        v(1.0, 0.0, -1.0),
        v(1.0, 0.0, 1.0),
        a,
        b,
        c
    ));
    // coplanar: overlapping, inside, disjoint
    assert!(segment_triangle_intersect(
        v(-1.0, 0.2, 0.0),
        v(2.0, 0.2, 0.0),
        a,
        b,
        c
    ));
    assert!(segment_triangle_intersect(
        v(0.1, 0.1, 0.0),
        v(0.2, 0.2, 0.0),
        a,
        b,
        c
    ));
    assert!(!segment_triangle_intersect(
        v(1.0, 1.0, 0.0),
        v(2.0, 2.0, 0.0),
        a,
        b,
        c
    ));
}

#[test]
fn fast_segment_triangle_agrees_with_exact_on_generic_input() {
    let mut rng = Rng(7);
    let mut hits = 0;
    for _ in 0..50_000 {
        let (a, b, c) = (rng.vec(1.0), rng.vec(1.0), rng.vec(1.0));
        let (p, q) = (rng.vec(1.0), rng.vec(1.0));
        let fast = segment_triangle_intersect(p, q, a, b, c);
        let exact = segment_triangle_intersect_exact(arr(p), arr(q), arr(a), arr(b), arr(c));
        assert_eq!(fast, exact, "p={p:?} q={q:?} a={a:?} b={b:?} c={c:?}");
        hits += exact as usize;
    }
    assert!(hits > 1_000, "{hits}");
}

// ---------------------------------------------------------------------------------------
// cubic roots
// ---------------------------------------------------------------------------------------

fn roots(c: [f64; 4], ftol: f64) -> Vec<f64> {
    let mut out = [0.0; 8];
    let n = cubic_roots_in_unit_interval(c, ftol, &mut out);
    out[..n].to_vec()
}

fn poly_from_roots(k: f64, r: [f64; 3]) -> [f64; 4] {
    // k (t − r0)(t − r1)(t − r2)
    let [a, b, c] = r;
    [
        -k * a * b * c,
        k * (a * b + b * c + a * c),
        -k * (a + b + c),
        k,
    ]
}

#[test]
fn cubic_roots_three_simple_roots() {
    let r = roots(poly_from_roots(1.0, [0.2, 0.5, 0.9]), 1e-15);
    assert_eq!(r.len(), 3, "{r:?}");
    for (x, y) in r.iter().zip([0.2, 0.5, 0.9]) {
        assert!((x - y).abs() < 1e-14, "{r:?}");
    }
    // scale does not matter
    let r = roots(poly_from_roots(-1e-12, [0.2, 0.5, 0.9]), 1e-30);
    assert_eq!(r.len(), 3, "{r:?}");
    // roots outside [0, 1] are ignored
    let r = roots(poly_from_roots(3.0, [-0.5, 0.25, 1.5]), 1e-15);
    assert_eq!(r.len(), 1);
    assert!((r[0] - 0.25).abs() < 1e-14);
    // closely spaced roots
    let r = roots(poly_from_roots(1.0, [0.3, 0.3 + 1e-6, 0.7]), 1e-18);
    assert_eq!(r.len(), 3, "{r:?}");
}

#[test]
fn cubic_roots_degenerate_leading_coefficients() {
    // quadratic: (t − 0.25)(t − 0.75)
    let r = roots([0.1875, -1.0, 1.0, 0.0], 1e-15);
    assert_eq!(r.len(), 2);
    assert!((r[0] - 0.25).abs() < 1e-14 && (r[1] - 0.75).abs() < 1e-14);
    // linear
    let r = roots([-1.0, 2.0, 0.0, 0.0], 1e-15);
    assert_eq!(r, vec![0.5]);
    // constant, non-zero: no root
    assert!(roots([1.0, 0.0, 0.0, 0.0], 1e-15).is_empty());
    // tiny leading coefficient on a quadratic
    let r = roots([0.1875, -1.0, 1.0, 1e-17], 1e-15);
    assert_eq!(r.len(), 2);
    assert!((r[0] - 0.25).abs() < 1e-12 && (r[1] - 0.75).abs() < 1e-12);
}

#[test]
fn cubic_roots_double_root_and_interval_ends() {
    // (t − 0.5)² (t + 3): a double root (grazing), no sign change
    let r = roots(poly_from_roots(1.0, [0.5, 0.5, -3.0]), 1e-14);
    assert_eq!(r.len(), 1, "{r:?}");
    assert!((r[0] - 0.5).abs() < 1e-7, "{r:?}");
    // roots exactly at 0 and 1: t (t − 1) (t + 2)
    let r = roots(poly_from_roots(1.0, [0.0, 1.0, -2.0]), 1e-15);
    assert_eq!(r, vec![0.0, 1.0]);
    // triple root
    let r = roots(poly_from_roots(1.0, [0.4, 0.4, 0.4]), 1e-15);
    assert!(
        !r.is_empty() && r.iter().all(|x| (x - 0.4).abs() < 1e-5),
        "{r:?}"
    );
}

#[test]
fn coplanarity_cubic_matches_direct_determinant() {
    let mut rng = Rng(5);
    for _ in 0..1000 {
        let x = [rng.vec(1.0), rng.vec(1.0), rng.vec(1.0), rng.vec(1.0)];
        let d = [rng.vec(1.0), rng.vec(1.0), rng.vec(1.0), rng.vec(1.0)];
        let c = coplanarity_cubic(x, d);
        for t in [0.0, 0.3, 0.7, 1.0] {
            let y: Vec<Vec3> = (0..4).map(|i| x[i] + d[i] * t).collect();
            let f = (y[1] - y[0]).cross(&(y[2] - y[0])).dot(&(y[3] - y[0]));
            let g = c[0] + t * (c[1] + t * (c[2] + t * c[3]));
            assert!((f - g).abs() < 1e-12, "{f} {g}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// vertex–face CCD
// ---------------------------------------------------------------------------------------

const Z: Vec3 = Vec3::new(0.0, 0.0, 0.0);

fn tri() -> [Vec3; 3] {
    [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)]
}

#[test]
fn vertex_face_point_through_static_triangle() {
    let [a, b, c] = tri();
    let p = v(0.25, 0.25, 1.0);
    let hit = vertex_face_ccd([p, a, b, c], [v(0.0, 0.0, -2.0), Z, Z, Z], 1e-6).expect("hit");
    assert!((hit.t - 0.5).abs() < 1e-9, "{}", hit.t);
    assert_weights(&hit.weights, &[1.0, -0.5, -0.25, -0.25], 1e-9);
    assert_close(hit.normal, v(0.0, 0.0, 1.0), 1e-12);
    // from below, and with the triangle's winding reversed: the normal still points toward
    // the side the vertex came from
    let p = v(0.25, 0.25, -1.0);
    let hit = vertex_face_ccd([p, a, c, b], [v(0.0, 0.0, 2.0), Z, Z, Z], 1e-6).expect("hit");
    assert!((hit.t - 0.5).abs() < 1e-9);
    assert_close(hit.normal, v(0.0, 0.0, -1.0), 1e-12);
    assert_weights(&hit.weights, &[1.0, -0.5, -0.25, -0.25], 1e-9);
    // asymmetric time: from z = 0.3 to z = −0.7 → t = 0.3
    let hit = vertex_face_ccd(
        [v(0.1, 0.6, 0.3), a, b, c],
        [v(0.0, 0.0, -1.0), Z, Z, Z],
        0.0,
    )
    .expect("hit");
    assert!((hit.t - 0.3).abs() < 1e-12, "{}", hit.t);
    // the weights reproduce the contact-point difference (≈ 0 at impact)
    let y = [v(0.1, 0.6, 0.0), a, b, c];
    let diff: Vec3 = (0..4).map(|i| y[i] * hit.weights[i]).sum();
    assert!(diff.norm() < 1e-12);
}

#[test]
fn vertex_face_misses_outside_and_parallel() {
    let [a, b, c] = tri();
    // crosses the plane outside the triangle
    let p = v(0.8, 0.8, 1.0);
    assert!(vertex_face_ccd([p, a, b, c], [v(0.0, 0.0, -2.0), Z, Z, Z], 1e-3).is_none());
    // stops short of the plane
    let p = v(0.25, 0.25, 1.0);
    assert!(vertex_face_ccd([p, a, b, c], [v(0.0, 0.0, -0.9), Z, Z, Z], 1e-3).is_none());
    // moves parallel to the plane above it
    assert!(vertex_face_ccd([p, a, b, c], [v(0.5, 0.1, 0.0), Z, Z, Z], 1e-3).is_none());
    // passes 1e-3 outside an edge: a miss with thickness 1e-4, a hit with 2e-3
    let p = v(0.5, -1e-3, 1.0);
    let d = [v(0.0, 0.0, -2.0), Z, Z, Z];
    assert!(vertex_face_ccd([p, a, b, c], d, 1e-4).is_none());
    let hit = vertex_face_ccd([p, a, b, c], d, 2e-3).expect("within thickness");
    assert!((hit.t - 0.5).abs() < 1e-9);
    assert_weights(&hit.weights, &[1.0, -0.5, -0.5, 0.0], 1e-9);
    // the MIN_THICKNESS floor: 1e-7 outside the edge with zero thickness is a hit
    let p = v(0.5, -1e-7, 1.0);
    const { assert!(MIN_THICKNESS > 1e-7) };
    assert!(vertex_face_ccd([p, a, b, c], d, 0.0).is_some());
}

#[test]
fn vertex_face_moving_triangle() {
    let [a, b, c] = tri();
    // the triangle rises from z = 0 to z = 2 into a static vertex at z = 0.5 → t = 0.25
    let up = v(0.0, 0.0, 2.0);
    let p = v(0.3, 0.3, 0.5);
    let hit = vertex_face_ccd([p, a, b, c], [Z, up, up, up], 1e-6).expect("hit");
    assert!((hit.t - 0.25).abs() < 1e-12, "{}", hit.t);
    assert_close(hit.normal, v(0.0, 0.0, 1.0), 1e-12);
    assert_weights(&hit.weights, &[1.0, -0.4, -0.3, -0.3], 1e-12);
    // a common velocity added to all four points changes nothing
    let w = v(0.3, -0.7, 0.2);
    let hit2 = vertex_face_ccd([p, a, b, c], [w, up + w, up + w, up + w], 1e-6).expect("hit");
    assert!((hit2.t - 0.25).abs() < 1e-12);
}

#[test]
fn vertex_face_hinged_rotating_triangle() {
    // a, b on the y axis stay fixed; c swings from (1, 0, 1) to (1, 0, −1): the plane is
    // z = x (1 − 2t) and holds the static vertex (0.5, 0, 0.2) at t = 0.3.
    let (a, b) = (v(0.0, -1.0, 0.0), v(0.0, 1.0, 0.0));
    let c = v(1.0, 0.0, 1.0);
    let p = v(0.5, 0.0, 0.2);
    let hit = vertex_face_ccd([p, a, b, c], [Z, Z, Z, v(0.0, 0.0, -2.0)], 1e-6).expect("hit");
    assert!((hit.t - 0.3).abs() < 1e-12, "{}", hit.t);
    // at t = 0.3, c = (1, 0, 0.4): p = 0.25 a + 0.25 b + 0.5 c
    assert_weights(&hit.weights, &[1.0, -0.25, -0.25, -0.5], 1e-12);
    // normal ⟂ (1, 0, 0.4)-plane containing the y axis, on the vertex's initial side (below
    // the plane z = x at t = 0, i.e. toward +x −z)
    let n = v(0.4, 0.0, -1.0).normalize();
    assert_close(hit.normal, n, 1e-12);
}

/// Coplanarity determinant from positions (independent of the CCD's coefficients).
fn coplanarity(y: &[Vec3; 4]) -> f64 {
    (y[1] - y[0]).cross(&(y[2] - y[0])).dot(&(y[3] - y[0]))
}

fn at(x: &[Vec3; 4], d: &[Vec3; 4], t: f64) -> [Vec3; 4] {
    [
        x[0] + d[0] * t,
        x[1] + d[1] * t,
        x[2] + d[2] * t,
        x[3] + d[3] * t,
    ]
}

/// Roots of the coplanarity determinant found by dense sampling and bisection, each with the
/// distance between the primitives there.
fn sampled_events(
    x: &[Vec3; 4],
    d: &[Vec3; 4],
    order: [usize; 4],
    dist: impl Fn(&[Vec3; 4]) -> f64,
) -> Vec<(f64, f64)> {
    let f = |t: f64| {
        let y = at(x, d, t);
        coplanarity(&[y[order[0]], y[order[1]], y[order[2]], y[order[3]]])
    };
    let n = 4000;
    let mut out = Vec::new();
    let mut t0 = 0.0;
    let mut f0 = f(0.0);
    for i in 1..=n {
        let t1 = i as f64 / n as f64;
        let f1 = f(t1);
        if f0 == 0.0 || f0 * f1 < 0.0 {
            let (mut lo, mut hi, flo) = (t0, t1, f0);
            if f0 != 0.0 {
                for _ in 0..200 {
                    let m = 0.5 * (lo + hi);
                    if (f(m) < 0.0) == (flo < 0.0) {
                        lo = m;
                    } else {
                        hi = m;
                    }
                }
            }
            out.push((lo, dist(&at(x, d, lo))));
        }
        t0 = t1;
        f0 = f1;
    }
    out
}

/// Random motions of size `scale` around `offset`, checked against `sampled_events`.
fn check_random_ccd(
    seed: u64,
    scale: f64,
    offset: Vec3,
    ccd: impl Fn([Vec3; 4], [Vec3; 4], f64) -> Option<CcdHit>,
    order: [usize; 4],
    dist: impl Fn(&[Vec3; 4]) -> f64,
) -> (usize, usize) {
    let mut rng = Rng(seed);
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..3000 {
        let mut x = [Z; 4];
        let mut d = [Z; 4];
        for i in 0..4 {
            x[i] = offset + rng.vec(scale);
            d[i] = rng.vec(scale);
        }
        let thickness = 0.05 * scale;
        let events = sampled_events(&x, &d, order, &dist);
        let clear_hit = |&(_, dd): &(f64, f64)| dd < thickness * 0.999;
        match ccd(x, d, thickness) {
            Some(hit) => {
                hits += 1;
                assert!((0.0..=1.0).contains(&hit.t));
                assert!((hit.normal.norm() - 1.0).abs() < 1e-12);
                let y = at(&x, &d, hit.t);
                let yo = [y[order[0]], y[order[1]], y[order[2]], y[order[3]]];
                assert!(
                    coplanarity(&yo).abs() < 1e-10 * scale.powi(3),
                    "not coplanar at hit"
                );
                assert!(dist(&y) <= thickness * (1.0 + 1e-9));
                // the weights give the contact-point difference, whose length is the distance
                let diff: Vec3 = (0..4).map(|i| y[i] * hit.weights[i]).sum();
                assert!((diff.norm() - dist(&y)).abs() < 1e-9 * scale);
                // no clearly earlier event
                for e in events.iter().filter(|e| clear_hit(e)) {
                    assert!(
                        e.0 >= hit.t - 1e-9,
                        "missed earlier event {e:?}, hit at {}",
                        hit.t
                    );
                }
            }
            None => {
                misses += 1;
                assert!(!events.iter().any(clear_hit), "missed event {events:?}");
            }
        }
    }
    (hits, misses)
}

#[test]
fn vertex_face_random_against_sampling() {
    let dist = |y: &[Vec3; 4]| (y[0] - closest_point_triangle(y[0], y[1], y[2], y[3]).0).norm();
    // cubic's base ordering (a, b, c, p) is only a permutation: same roots
    for (seed, scale, offset) in [(11, 1.0, Z), (12, 0.01, v(3.0, -7.0, 10.0))] {
        let (hits, misses) =
            check_random_ccd(seed, scale, offset, vertex_face_ccd, [1, 2, 3, 0], dist);
        assert!(hits > 100 && misses > 100, "{hits} {misses}");
    }
}

#[test]
fn vertex_face_general_cubic_motion() {
    // every point moves; the triangle tilts (its normal is quadratic in t) and the vertex
    // moves too: a genuinely cubic coplanarity function. Reference root by bisection on
    // the determinant of the positions.
    let x = [
        v(0.3, 0.25, 0.8),
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.0, 1.0, 0.0),
    ];
    let d = [
        v(0.1, 0.05, -1.5),
        v(0.0, 0.0, 0.1),
        v(0.0, 0.6, 0.4),
        v(-0.5, 0.0, 0.3),
    ];
    let c = coplanarity_cubic([x[1], x[2], x[3], x[0]], [d[1], d[2], d[3], d[0]]);
    assert!(c[3].abs() > 1e-3 && c[2].abs() > 1e-3, "{c:?}");
    let f = |t: f64| {
        let y = at(&x, &d, t);
        coplanarity(&[y[1], y[2], y[3], y[0]])
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    assert!(f(lo) > 0.0 && f(hi) < 0.0);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if f(m) > 0.0 {
            lo = m;
        } else {
            hi = m;
        }
    }
    let hit = vertex_face_ccd(x, d, 1e-6).expect("hit");
    assert!((hit.t - lo).abs() < 1e-12, "{} vs {lo}", hit.t);
    let y = at(&x, &d, hit.t);
    let n = (y[2] - y[1]).cross(&(y[3] - y[1])).normalize();
    assert_close(hit.normal, n, 1e-9); // came from above (+n side)
}

#[test]
fn vertex_face_coplanar_motion_is_not_a_spurious_hit() {
    let [a, b, c] = tri();
    // everything in z = 0 for the whole step: the cubic vanishes identically
    let p = v(2.0, 2.0, 0.0);
    let d = [v(0.5, 0.0, 0.0), v(0.1, 0.1, 0.0), Z, v(-0.1, 0.0, 0.0)];
    assert_eq!(coplanarity_cubic([a, b, c, p], d), [0.0; 4]);
    assert!(vertex_face_ccd([p, a, b, c], d, 1e-3).is_none());
    // in-plane motion entering the triangle through the edge x = 0 at t = 0.5
    let p = v(-1.0, 0.25, 0.0);
    let hit = vertex_face_ccd([p, a, b, c], [v(2.0, 0.0, 0.0), Z, Z, Z], 0.0).expect("hit");
    assert!((hit.t - 0.5).abs() < 1e-12, "{}", hit.t);
    assert_weights(&hit.weights, &[1.0, -0.75, 0.0, -0.25], 1e-12);
    assert!((hit.normal.norm() - 1.0).abs() < 1e-12);
    // starting within the thickness, in the plane: hit at t = 0
    let p = v(-1e-4, 0.25, 0.0);
    let hit = vertex_face_ccd([p, a, b, c], [v(-1.0, 0.0, 0.0), Z, Z, Z], 1e-3).expect("hit");
    assert_eq!(hit.t, 0.0);
    // the same plane tilted (coefficients vanish only to round-off)
    let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
    let p = v(2.0, 2.0, 0.0);
    let d = [v(0.5, 0.0, 0.0), v(0.1, 0.1, 0.0), Z, v(-0.1, 0.0, 0.0)];
    let x = [rot * p, rot * a, rot * b, rot * c];
    let dr = [rot * d[0], rot * d[1], rot * d[2], rot * d[3]];
    assert!(vertex_face_ccd(x, dr, 1e-3).is_none());
}

#[test]
fn vertex_face_no_nan_on_degenerate_input() {
    let p = v(0.0, 0.0, 1.0);
    // triangle collapsed to a point, moving through the vertex's path
    let q = v(0.0, 0.0, 0.0);
    let r = vertex_face_ccd([p, q, q, q], [v(0.0, 0.0, -2.0), Z, Z, Z], 1e-6);
    if let Some(h) = r {
        assert!(h.t.is_finite() && h.normal.iter().all(|x| x.is_finite()));
        assert!((h.normal.norm() - 1.0).abs() < 1e-12);
    }
    // nothing moves
    assert!(vertex_face_ccd([p, q, v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)], [Z; 4], 1e-6).is_none());
}

// ---------------------------------------------------------------------------------------
// edge–edge CCD
// ---------------------------------------------------------------------------------------

#[test]
fn edge_edge_crossing_edges() {
    // first edge along x at z = 1 drops to z = −1; second along y in z = 0: t = 0.5
    let x = [
        v(-1.0, 0.0, 1.0),
        v(1.0, 0.0, 1.0),
        v(0.0, -1.0, 0.0),
        v(0.0, 1.0, 0.0),
    ];
    let down = v(0.0, 0.0, -2.0);
    let hit = edge_edge_ccd(x, [down, down, Z, Z], 1e-6).expect("hit");
    assert!((hit.t - 0.5).abs() < 1e-9, "{}", hit.t);
    assert_weights(&hit.weights, &[0.5, 0.5, -0.5, -0.5], 1e-9);
    assert_close(hit.normal, v(0.0, 0.0, 1.0), 1e-12);
    // asymmetric: second edge offset, first edge faster: s = 0.75, u = 0.25, t = 0.25
    let x = [
        v(-1.0, 0.0, 1.0),
        v(1.0, 0.0, 1.0),
        v(0.5, -0.5, 0.0),
        v(0.5, 1.5, 0.0),
    ];
    let fall = v(0.0, 0.0, -4.0);
    let hit = edge_edge_ccd(x, [fall, fall, Z, Z], 1e-6).expect("hit");
    assert!((hit.t - 0.25).abs() < 1e-12, "{}", hit.t);
    assert_weights(&hit.weights, &[0.25, 0.75, -0.75, -0.25], 1e-12);
    assert_close(hit.normal, v(0.0, 0.0, 1.0), 1e-12);
    // the first edge lies below the second, which comes down onto it: the normal from the
    // second edge toward the first points down (−z)
    let x = [
        v(-1.0, 0.0, -1.0),
        v(1.0, 0.0, -1.0),
        v(0.0, -1.0, 0.0),
        v(0.0, 1.0, 0.0),
    ];
    let hit = edge_edge_ccd(x, [Z, Z, down, down], 1e-6).expect("hit");
    assert!((hit.t - 0.5).abs() < 1e-12);
    assert_close(hit.normal, v(0.0, 0.0, -1.0), 1e-12);
}

#[test]
fn edge_edge_misses() {
    let down = v(0.0, 0.0, -2.0);
    // the lines cross beyond the end of the second edge
    let x = [
        v(-1.0, 0.0, 1.0),
        v(1.0, 0.0, 1.0),
        v(0.0, 0.5, 0.0),
        v(0.0, 2.0, 0.0),
    ];
    assert!(edge_edge_ccd(x, [down, down, Z, Z], 1e-3).is_none());
    // stops short
    let x = [
        v(-1.0, 0.0, 1.0),
        v(1.0, 0.0, 1.0),
        v(0.0, -1.0, 0.0),
        v(0.0, 1.0, 0.0),
    ];
    assert!(edge_edge_ccd(x, [down * 0.4, down * 0.4, Z, Z], 1e-3).is_none());
    // passes the end of the second edge at 1e-3: miss for 1e-4, hit for 2e-3
    let x = [
        v(-1.0, 0.0, 1.0),
        v(1.0, 0.0, 1.0),
        v(0.0, 1e-3, 0.0),
        v(0.0, 1.0, 0.0),
    ];
    assert!(edge_edge_ccd(x, [down, down, Z, Z], 1e-4).is_none());
    let hit = edge_edge_ccd(x, [down, down, Z, Z], 2e-3).expect("within thickness");
    assert!((hit.t - 0.5).abs() < 1e-9);
    assert_weights(&hit.weights, &[0.5, 0.5, -1.0, 0.0], 1e-9);
}

#[test]
fn edge_edge_random_against_sampling() {
    let dist = |y: &[Vec3; 4]| {
        let (_, _, c1, c2) = closest_points_segments(y[0], y[1], y[2], y[3]);
        (c1 - c2).norm()
    };
    for (seed, scale, offset) in [(23, 1.0, Z), (24, 0.01, v(3.0, -7.0, 10.0))] {
        let (hits, misses) =
            check_random_ccd(seed, scale, offset, edge_edge_ccd, [0, 1, 2, 3], dist);
        assert!(hits > 100 && misses > 100, "{hits} {misses}");
    }
}

#[test]
fn edge_edge_coplanar_motion() {
    // two edges in z = 0 throughout: the cubic vanishes identically
    let x = [
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.5, 1.0, 0.0),
        v(0.5, 2.0, 0.0),
    ];
    let d = [v(0.0, 0.2, 0.0), v(0.0, 0.2, 0.0), Z, Z];
    assert_eq!(coplanarity_cubic(x, d), [0.0; 4]);
    assert!(edge_edge_ccd(x, d, 1e-3).is_none());
    // the second edge slides down until its end q0 touches the first edge at t = 0.5
    let d = [Z, Z, v(0.0, -2.0, 0.0), v(0.0, -2.0, 0.0)];
    let hit = edge_edge_ccd(x, d, 0.0).expect("hit");
    assert!((hit.t - 0.5).abs() < 1e-12, "{}", hit.t);
    assert_weights(&hit.weights, &[0.5, 0.5, -1.0, 0.0], 1e-12);
    assert!((hit.normal.norm() - 1.0).abs() < 1e-12);
    // parallel edges, coplanar, overlapping, approaching each other: hit when they touch
    let x = [
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.5, 1.0, 0.0),
        v(1.5, 1.0, 0.0),
    ];
    let d = [Z, Z, v(0.0, -1.25, 0.0), v(0.0, -1.25, 0.0)];
    let hit = edge_edge_ccd(x, d, 0.0).expect("hit");
    assert!((hit.t - 0.8).abs() < 1e-12, "{}", hit.t);
}

#[test]
fn edge_edge_parallel_edges_normal_is_finite() {
    // parallel edges one above the other, the upper falling onto the lower: e1 × e2 = 0 at
    // impact, so the normal comes from the separation / relative velocity
    let x = [
        v(0.0, 0.0, 1.0),
        v(1.0, 0.0, 1.0),
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
    ];
    let down = v(0.0, 0.0, -2.0);
    let hit = edge_edge_ccd(x, [down, down, Z, Z], 1e-6).expect("hit");
    assert!((hit.t - 0.5).abs() < 1e-9, "{}", hit.t);
    assert_close(hit.normal, v(0.0, 0.0, 1.0), 1e-12);
}

// ---------------------------------------------------------------------------------------
// exact predicates of the independent checker
// ---------------------------------------------------------------------------------------

fn det3_i128(a: [i128; 3], b: [i128; 3], c: [i128; 3], d: [i128; 3]) -> i32 {
    let u = [a[0] - d[0], a[1] - d[1], a[2] - d[2]];
    let v = [b[0] - d[0], b[1] - d[1], b[2] - d[2]];
    let w = [c[0] - d[0], c[1] - d[1], c[2] - d[2]];
    let det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]);
    det.signum() as i32
}

#[test]
fn orient3d_is_exact_on_near_coplanar_lattice_points() {
    // integer lattice scaled by 2^-20, magnitudes up to 2^39 units: every coordinate is an
    // exact f64 and the i128 determinant cannot overflow
    let scale = 1.0 / (1u64 << 20) as f64;
    let mut rng = Rng(2024);
    let mut counts = [0usize; 3];
    let mut naive_wrong = 0;
    for _ in 0..20_000 {
        let big = 1i64 << 38;
        let base = [rng.int(-big, big), rng.int(-big, big), rng.int(-big, big)];
        let pt = |rng: &mut Rng| -> [i64; 3] {
            let s = 1i64 << rng.int(0, 20);
            [
                base[0] + rng.int(-s, s),
                base[1] + rng.int(-s, s),
                base[2] + rng.int(-s, s),
            ]
        };
        let (a, b, c) = (pt(&mut rng), pt(&mut rng), pt(&mut rng));
        // d = a + u (b − a) + w (c − a) exactly, then nudged by −1, 0 or +1 in one coordinate
        let (u, w) = (rng.int(-3, 3), rng.int(-3, 3));
        let mut d = [0i64; 3];
        for k in 0..3 {
            d[k] = a[k] + u * (b[k] - a[k]) + w * (c[k] - a[k]);
        }
        d[rng.int(0, 2) as usize] += rng.int(-1, 1);
        if d.iter().any(|x| x.abs() >= 1 << 39) {
            continue;
        }
        let f = |p: [i64; 3]| {
            [
                p[0] as f64 * scale,
                p[1] as f64 * scale,
                p[2] as f64 * scale,
            ]
        };
        let i = |p: [i64; 3]| [p[0] as i128, p[1] as i128, p[2] as i128];
        let expected = det3_i128(i(a), i(b), i(c), i(d));
        let (fa, fb, fc, fd) = (f(a), f(b), f(c), f(d));
        assert_eq!(orient3d(fa, fb, fc, fd), expected);
        assert_eq!(orient3d_exact(fa, fb, fc, fd), expected);
        // permutations flip the sign as they should
        assert_eq!(orient3d(fb, fc, fa, fd), expected);
        assert_eq!(orient3d(fb, fa, fc, fd), -expected);
        counts[(expected + 1) as usize] += 1;
        let naive = {
            let (u, v, w) = (
                Vec3::from(fa) - Vec3::from(fd),
                Vec3::from(fb) - Vec3::from(fd),
                Vec3::from(fc) - Vec3::from(fd),
            );
            u.dot(&v.cross(&w))
        };
        naive_wrong +=
            (naive.signum() as i32 != expected && !(naive == 0.0 && expected == 0)) as usize;
    }
    assert!(counts.iter().all(|&c| c > 1000), "{counts:?}");
    assert!(
        naive_wrong > 0,
        "the cases are not hard enough to need exact arithmetic"
    );
}

#[test]
fn orient3d_exact_with_inexact_differences() {
    // x coordinates mix ~2^36 and ~2^-10 magnitudes, so differences such as a.x − d.x are
    // not representable and the exact path must expand the raw coordinates. Units of 2^-20
    // keep the i128 reference in range (|x| < 2^57 units, |y|, |z| < 2^25 units).
    let unit = 1.0 / (1u64 << 20) as f64;
    let mut rng = Rng(9001);
    let mut counts = [0usize; 3];
    let mut tries = 0;
    while counts.iter().sum::<usize>() < 6000 {
        tries += 1;
        assert!(tries < 1_000_000);
        let small = |rng: &mut Rng| rng.int(-(1 << 24), 1 << 24);
        let bigx = |rng: &mut Rng| rng.int(1 << 55, 1 << 56) & !0xff; // multiples of 2^-12
        let a = [small(&mut rng), small(&mut rng), small(&mut rng)];
        let b = [bigx(&mut rng), small(&mut rng), small(&mut rng)];
        let c = [bigx(&mut rng), small(&mut rng), small(&mut rng)];
        let (u, w) = (rng.int(-2, 3), rng.int(-2, 3));
        let mut d = [0i64; 3];
        for k in 0..3 {
            d[k] = a[k] + u * (b[k] - a[k]) + w * (c[k] - a[k]);
        }
        d[1 + rng.int(0, 1) as usize] += rng.int(-1, 1);
        let representable = |x: i64| (x as f64) as i64 == x && x.abs() < 1 << 58;
        if !d.iter().all(|&x| representable(x)) || d[1].abs() >= 1 << 27 || d[2].abs() >= 1 << 27 {
            continue;
        }
        let f = |p: [i64; 3]| [p[0] as f64 * unit, p[1] as f64 * unit, p[2] as f64 * unit];
        let i = |p: [i64; 3]| [p[0] as i128, p[1] as i128, p[2] as i128];
        let expected = det3_i128(i(a), i(b), i(c), i(d));
        let (fa, fb, fc, fd) = (f(a), f(b), f(c), f(d));
        assert_eq!(
            orient3d(fa, fb, fc, fd),
            expected,
            "{a:?} {b:?} {c:?} {d:?}"
        );
        assert_eq!(orient3d_exact(fa, fb, fc, fd), expected);
        assert_eq!(orient3d_exact(fd, fb, fc, fa), -expected);
        assert_eq!(orient3d_exact(fa, fb, fd, fc), -expected);
        counts[(expected + 1) as usize] += 1;
    }
    assert!(counts.iter().all(|&c| c > 500), "{counts:?}");
}

#[test]
fn orient2d_is_exact() {
    let mut rng = Rng(77);
    let scale = 1.0 / (1u64 << 30) as f64;
    for _ in 0..20_000 {
        let big = 1i64 << 50;
        let a = [rng.int(-big, big), rng.int(-big, big)];
        let b = [rng.int(-big, big), rng.int(-big, big)];
        let u = rng.int(-5, 5);
        let mut c = [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])];
        c[rng.int(0, 1) as usize] += rng.int(-1, 1);
        if c.iter().any(|x| x.abs() >= 1 << 52) {
            continue;
        }
        let det = (a[0] as i128 - c[0] as i128) * (b[1] as i128 - c[1] as i128)
            - (a[1] as i128 - c[1] as i128) * (b[0] as i128 - c[0] as i128);
        let f = |p: [i64; 2]| [p[0] as f64 * scale, p[1] as f64 * scale];
        assert_eq!(orient2d(f(a), f(b), f(c)), det.signum() as i32);
        assert_eq!(orient2d_exact(f(a), f(b), f(c)), det.signum() as i32);
    }
}

// ---------------------------------------------------------------------------------------
// exact segment–triangle and the intersection counter
// ---------------------------------------------------------------------------------------

#[test]
fn exact_segment_triangle_cases() {
    let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let st = |p: [f64; 3], q: [f64; 3]| segment_triangle_intersect_exact(p, q, a, b, c);
    assert!(st([0.2, 0.3, -1.0], [0.2, 0.3, 1.0])); // proper crossing
    assert!(!st([0.8, 0.8, -1.0], [0.8, 0.8, 1.0])); // outside
    assert!(!st([0.2, 0.3, 1e-300], [0.2, 0.3, 1.0])); // just above
    assert!(st([0.2, 0.3, 0.0], [0.2, 0.3, 1.0])); // endpoint on the face
    assert!(st([0.5, 0.0, -1.0], [0.5, 0.0, 1.0])); // through an edge
    assert!(st([0.0, 1.0, -1.0], [0.0, 1.0, 1.0])); // through a vertex
    assert!(st([0.5, 0.5, -1.0], [0.5, 0.5, 1.0])); // through the hypotenuse (exact 0.5+0.5=1)
    assert!(!st([0.5, 0.5 + 1e-16, -1.0], [0.5, 0.5 + 1e-16, 1.0]));
    // coplanar: overlap, inside, touching a vertex, disjoint
    assert!(st([-1.0, 0.2, 0.0], [2.0, 0.2, 0.0]));
    assert!(st([0.1, 0.1, 0.0], [0.2, 0.2, 0.0]));
    assert!(st([1.0, 0.0, 0.0], [2.0, 0.0, 0.0]));
    assert!(!st([1.0 + 1e-15, 0.0, 0.0], [2.0, 0.0, 0.0]));
    assert!(!st([1.0, 1.0, 0.0], [2.0, 2.0, 0.0]));
    // degenerate segment (a point) on and off the triangle
    assert!(st([0.2, 0.2, 0.0], [0.2, 0.2, 0.0]));
    assert!(!st([0.2, 0.2, 1e-20], [0.2, 0.2, 1e-20]));
    // degenerate triangle: a segment from (0,0,0) to (2,0,0)
    let (d0, d1, d2) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
    assert!(segment_triangle_intersect_exact(
        [1.5, -1.0, 0.0],
        [1.5, 1.0, 0.0],
        d0,
        d1,
        d2
    ));
    assert!(segment_triangle_intersect_exact(
        [1.5, 0.0, -1.0],
        [1.5, 0.0, 1.0],
        d0,
        d1,
        d2
    ));
    assert!(!segment_triangle_intersect_exact(
        [2.5, -1.0, 0.0],
        [2.5, 1.0, 0.0],
        d0,
        d1,
        d2
    ));
    assert!(!segment_triangle_intersect_exact(
        [1.5, 1.0, -1.0],
        [1.5, 1.0, 1.0],
        d0,
        d1,
        d2
    ));
    // 3D segment–segment
    assert!(segments_intersect_3d(
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 1.0]
    ));
    assert!(!segments_intersect_3d(
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 1.1]
    ));
    // parallel, offset in one coordinate only (overlap in two projections, not in 3D)
    assert!(!segments_intersect_3d(
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0]
    ));
}

#[test]
fn single_triangle_pierced_by_one_edge() {
    // T1 = (0,1,2) in z = 0; T2 = (0,3,4) shares corner 0 and its edge 3–4 pierces T1 at
    // (0.25, 0.25, 0). Edges 0–3, 0–4 (vs T1) and 0–1, 2–0 (vs T2) share vertex 0; edge 1–2
    // meets the plane x = y of T2 at (0.5, 0.5, 0), outside T2. Exactly one pair.
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.25, 0.25, -1.0],
        [0.25, 0.25, 1.0],
    ];
    let triangles = [[0, 1, 2], [0, 3, 4]];
    assert_eq!(count_edge_triangle_intersections(&positions, &triangles), 1);
    assert_eq!(
        count_edge_triangle_intersections_brute(&positions, &triangles),
        1
    );
    // two separate triangles crossing each other: the intersection segment has two ends,
    // one on an edge of each triangle here → two pairs
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.25, 0.25, -1.0],
        [0.25, 0.25, 1.0],
        [5.0, 5.0, 0.0],
    ];
    let triangles = [[0, 1, 2], [3, 4, 5]];
    assert_eq!(count_edge_triangle_intersections(&positions, &triangles), 2);
}

#[test]
fn touching_at_a_shared_vertex_is_excluded() {
    // T2 meets T1 only at the origin
    let mut positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, -1.0, 1.0],
        [-1.0, -2.0, 1.0],
    ];
    assert_eq!(
        count_edge_triangle_intersections(&positions, &[[0, 1, 2], [0, 3, 4]]),
        0
    );
    // the same geometry with the shared corner duplicated: edges 5–3, 4–5 touch T1 at its
    // corner and edges 0–1, 2–0 touch T2 at its corner → 4 pairs
    positions.push([0.0, 0.0, 0.0]);
    assert_eq!(
        count_edge_triangle_intersections(&positions, &[[0, 1, 2], [5, 3, 4]]),
        4
    );
    // two triangles sharing an edge, folded at any angle: nothing
    let positions = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.3, 0.2, 1e-30],
    ];
    assert_eq!(
        count_edge_triangle_intersections(&positions, &[[0, 1, 2], [0, 1, 3]]),
        0
    );
}

/// `x` as an exact integer multiple of 2⁻⁸⁰ (valid for |x| < 2⁴⁰ with ulp ≥ 2⁻⁸⁰).
fn fixed80(x: f64) -> i128 {
    let s = x * (2f64).powi(80);
    assert_eq!(s.fract(), 0.0);
    s as i128
}

#[test]
fn near_degenerate_points_are_decided_exactly() {
    // Triangle on the plane x + y + z = 1; segment ends p near it (residuals of order
    // 1e-17, below the f64 resolution of the coordinates) going away along (1,1,1).
    // Reference: the exact residual x + y + z − 1 in 2⁻⁸⁰ fixed point.
    let t = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut rng = Rng(31);
    let (mut below, mut above, mut on) = (0, 0, 0);
    for k in 0..400 {
        let x = if k == 0 { 0.1 } else { rng.range(0.05, 0.45) };
        let y = if k == 0 { 0.2 } else { rng.range(0.05, 0.45) };
        let mut z = 1.0 - x - y;
        for _ in 0..3 {
            z = f64::from_bits(z.to_bits() - 1);
        }
        for _ in 0..7 {
            let p = [x, y, z];
            let residual = fixed80(x) + fixed80(y) + fixed80(z) - fixed80(1.0);
            let q = [x + 0.5, y + 0.5, z + 0.5];
            let r = [x + 0.5, y + 0.49, z + 0.5];
            let expected = residual <= 0;
            assert_eq!(
                segment_triangle_intersect_exact(p, q, t[0], t[1], t[2]),
                expected,
                "p = {p:?}, residual = {residual}"
            );
            let positions = [t[0], t[1], t[2], p, q, r];
            let count = count_edge_triangle_intersections(&positions, &[[0, 1, 2], [3, 4, 5]]);
            assert_eq!(count, 2 * expected as usize);
            match residual.signum() {
                -1 => below += 1,
                0 => on += 1,
                _ => above += 1,
            }
            z = f64::from_bits(z.to_bits() + 1);
        }
    }
    assert!(below > 100 && above > 100 && on > 0, "{below} {on} {above}");
    // a residual far below the coordinates' ulp
    let p = [0.1, 0.2, 0.7];
    let residual = fixed80(0.1) + fixed80(0.2) + fixed80(0.7) - fixed80(1.0);
    assert!(residual != 0 && (residual.abs() as f64) < 2f64.powi(80) * 1e-16);
    assert_eq!(
        segment_triangle_intersect_exact(p, [0.6, 0.7, 1.2], t[0], t[1], t[2]),
        residual <= 0
    );
}

fn grid(n: usize, map: impl Fn(f64, f64) -> [f64; 3]) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut positions = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            positions.push(map(i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64));
        }
    }
    let mut triangles = Vec::with_capacity(2 * (n - 1) * (n - 1));
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (
                j * n + i,
                j * n + i + 1,
                (j + 1) * n + i,
                (j + 1) * n + i + 1,
            );
            if (i + j) % 2 == 0 {
                triangles.push([a, b, d]);
                triangles.push([a, d, c]);
            } else {
                triangles.push([a, b, c]);
                triangles.push([b, d, c]);
            }
        }
    }
    (positions, triangles)
}

/// Half of the sheet (u > ½) folded back over the other half, with a wave across v that
/// makes it pass through the flat half.
fn folded(u: f64, v: f64) -> [f64; 3] {
    if u <= 0.5 {
        [u, v, 0.0]
    } else {
        [
            1.0 - u,
            v,
            0.1 * (u - 0.5) * (6.0 * std::f64::consts::PI * v).sin(),
        ]
    }
}

#[test]
fn flat_grids_have_no_intersections() {
    let (p, t) = grid(128, |u, v| [u, v, 0.0]);
    let start = Instant::now();
    assert_eq!(count_edge_triangle_intersections(&p, &t), 0);
    let flat = start.elapsed();
    // a tilted plane: nearly every candidate pair is coplanar only to round-off
    let (p, t) = grid(128, |u, v| [u, v, 0.3 * u + 0.7 * v]);
    let start = Instant::now();
    assert_eq!(count_edge_triangle_intersections(&p, &t), 0);
    let tilted = start.elapsed();
    eprintln!("128×128 flat: {flat:?}, tilted: {tilted:?}");
    assert!(flat.as_secs_f64() < 1.0 && tilted.as_secs_f64() < 1.0);
}

#[test]
fn folded_grid_passes_through_itself() {
    let (p, t) = grid(128, folded);
    let start = Instant::now();
    let n = count_edge_triangle_intersections(&p, &t);
    let took = start.elapsed();
    eprintln!("128×128 folded: {n} intersections in {took:?}");
    assert!(n > 0);
    assert!(took.as_secs_f64() < 1.0);
    // the grid acceleration agrees with brute force on a smaller fold
    let (p, t) = grid(25, folded);
    let n = count_edge_triangle_intersections(&p, &t);
    assert!(n > 0);
    assert_eq!(n, count_edge_triangle_intersections_brute(&p, &t));
}

#[test]
fn crumpled_grid_matches_brute_force() {
    let mut rng = Rng(4242);
    for (n, amp) in [(8, 0.3), (12, 0.2), (16, 0.05)] {
        let (mut p, t) = grid(n, |u, v| [u, v, 0.0]);
        for x in &mut p {
            for c in x.iter_mut() {
                *c += rng.range(-amp, amp);
            }
        }
        let fast = count_edge_triangle_intersections(&p, &t);
        let brute = count_edge_triangle_intersections_brute(&p, &t);
        assert_eq!(fast, brute);
        assert!(fast > 0, "n = {n}");
    }
}
