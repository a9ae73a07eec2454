//! Geometric primitives for cloth collision: closest points between a point and a triangle
//! and between two segments, and a fast segment–triangle intersection test.
//!
//! Everything here works in `f64` on [`nalgebra::Vector3<f64>`] (the crate's `Vec3`), does
//! not allocate, and never produces NaN for finite input: degenerate triangles (zero area)
//! and degenerate or parallel segments fall back to well-defined answers.
//!
//! References: C. Ericson, *Real-Time Collision Detection* (2005), §5.1.5 (closest point on
//! a triangle, Voronoi-region method) and §5.1.9 (closest points of two segments).

use nalgebra::Vector3;

type Vec3 = Vector3<f64>;

/// Below this ratio of squared area to squared squared longest edge, `|ab × ac|² ≤ (64 ε)² ·
/// lmax⁴`, a triangle is treated as degenerate (its normal carries no correct digit).
const DEGENERATE_SIN2: f64 = (64.0 * f64::EPSILON) * (64.0 * f64::EPSILON);

/// Relative threshold on `a e − b²` below which two segments are treated as parallel.
const PARALLEL_SIN2: f64 = 1e-14;

/// Relative threshold on `a e − b²` below which end-point candidates are also compared.
const NEAR_PARALLEL_SIN2: f64 = 1e-4;

#[inline]
fn clamp01(x: f64) -> f64 {
    // unlike `f64::clamp`, a NaN maps to 0 here
    if x > 0.0 {
        if x < 1.0 {
            x
        } else {
            1.0
        }
    } else {
        0.0
    }
}

/// Closest point to `p` on the segment `a`–`b`: returns `(point, s)` with `point = a + s (b − a)`,
/// `s ∈ [0, 1]`. A zero-length segment gives `(a, 0)`.
#[inline]
pub fn closest_point_segment(p: Vec3, a: Vec3, b: Vec3) -> (Vec3, f64) {
    let ab = b - a;
    let len2 = ab.norm_squared();
    if len2 <= 0.0 {
        return (a, 0.0);
    }
    let s = clamp01((p - a).dot(&ab) / len2);
    (a + ab * s, s)
}

/// Closest point on the triangle `abc` to `p`.
///
/// Returns the point and its barycentric weights `[wa, wb, wc]` (each in `[0, 1]`, summing to
/// 1, point `= wa a + wb b + wc c`). Uses Ericson's Voronoi-region classification. A triangle
/// whose area is negligible against its longest edge (collinear or coincident vertices) is
/// handled as its longest edge, so the result is finite for any finite input.
pub fn closest_point_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, [f64; 3]) {
    let ab = b - a;
    let ac = c - a;
    let bc = c - b;
    let lmax2 = ab
        .norm_squared()
        .max(ac.norm_squared())
        .max(bc.norm_squared());
    let n2 = ab.cross(&ac).norm_squared();
    if n2.is_nan() || n2 <= DEGENERATE_SIN2 * lmax2 * lmax2 {
        return closest_point_longest_edge(p, a, b, c);
    }

    // vertex region A
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    // vertex region B
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    // edge region AB
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let den = d1 - d3;
        let v = if den > 0.0 { clamp01(d1 / den) } else { 0.0 };
        return (a + ab * v, [1.0 - v, v, 0.0]);
    }
    // vertex region C
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    // edge region AC
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let den = d2 - d6;
        let w = if den > 0.0 { clamp01(d2 / den) } else { 0.0 };
        return (a + ac * w, [1.0 - w, 0.0, w]);
    }
    // edge region BC
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let num = d4 - d3;
        let den = num + (d5 - d6);
        let w = if den > 0.0 { clamp01(num / den) } else { 0.0 };
        return (b + bc * w, [0.0, 1.0 - w, w]);
    }
    // face region: clamp the (mathematically positive) weights against round-off
    let (u, v, w) = (va.max(0.0), vb.max(0.0), vc.max(0.0));
    let sum = u + v + w;
    if !(sum > 0.0 && sum.is_finite()) {
        return closest_point_longest_edge(p, a, b, c);
    }
    let (u, v, w) = (u / sum, v / sum, w / sum);
    (a * u + b * v + c * w, [u, v, w])
}

/// Degenerate-triangle fallback: closest point on the longest edge, weights mapped back to
/// the three vertices.
#[inline]
fn closest_point_longest_edge(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, [f64; 3]) {
    let lab = (b - a).norm_squared();
    let lbc = (c - b).norm_squared();
    let lca = (a - c).norm_squared();
    if lab >= lbc && lab >= lca {
        let (q, s) = closest_point_segment(p, a, b);
        (q, [1.0 - s, s, 0.0])
    } else if lbc >= lca {
        let (q, s) = closest_point_segment(p, b, c);
        (q, [0.0, 1.0 - s, s])
    } else {
        let (q, s) = closest_point_segment(p, c, a);
        (q, [s, 0.0, 1.0 - s])
    }
}

/// Closest points between the segments `p0`–`p1` and `q0`–`q1`.
///
/// Returns `(s, t, c1, c2)` with `c1 = p0 + s (p1 − p0)`, `c2 = q0 + t (q1 − q0)` and
/// `s, t ∈ [0, 1]` minimising `|c1 − c2|` (Ericson's method). Zero-length segments reduce
/// to point–segment queries; parallel segments pick the middle of the overlap of their
/// projections (or the nearest ends when they do not overlap); nearly parallel ones also
/// compare the four end-point–segment candidates, so the distance stays accurate to
/// round-off and the answer is deterministic and finite.
pub fn closest_points_segments(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> (f64, f64, Vec3, Vec3) {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);

    let (s, t);
    if a <= 0.0 && e <= 0.0 {
        s = 0.0;
        t = 0.0;
    } else if a <= 0.0 {
        s = 0.0;
        t = clamp01(f / e);
    } else {
        let c = d1.dot(&r);
        if e <= 0.0 {
            t = 0.0;
            s = clamp01(-c / a);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let s0 = if denom > PARALLEL_SIN2 * a * e {
                clamp01((b * f - c * e) / denom)
            } else {
                // parallel: parameters on the first segment of q0 and q1
                let u0 = -c / a;
                let u1 = (b - c) / a;
                let lo = u0.min(u1).max(0.0);
                let hi = u0.max(u1).min(1.0);
                if lo <= hi {
                    0.5 * (lo + hi)
                } else if hi < 0.0 {
                    0.0
                } else {
                    1.0
                }
            };
            let tt = (b * s0 + f) / e;
            let (mut bs, mut bt) = if tt < 0.0 {
                (clamp01(-c / a), 0.0)
            } else if tt > 1.0 {
                (clamp01((b - c) / a), 1.0)
            } else if tt.is_finite() {
                (s0, tt)
            } else {
                (clamp01(-c / a), 0.0)
            };
            if denom <= NEAR_PARALLEL_SIN2 * a * e {
                // Nearly parallel: the formula above loses accuracy (and the parallel choice
                // ignores a small angle), while the minimum then usually lies on the boundary
                // of the parameter square. Keep the current pair unless an end-point
                // candidate is closer by more than round-off.
                let dist2 = |s: f64, t: f64| (r + d1 * s - d2 * t).norm_squared();
                let mut best = dist2(bs, bt);
                let slack = 16.0 * f64::EPSILON * (best + a + e);
                let mut cut = best - slack;
                for (cs, ct) in [
                    (0.0, clamp01(f / e)),
                    (1.0, clamp01((b + f) / e)),
                    (clamp01(-c / a), 0.0),
                    (clamp01((b - c) / a), 1.0),
                ] {
                    let d2c = dist2(cs, ct);
                    if d2c < cut {
                        best = d2c;
                        cut = best;
                        bs = cs;
                        bt = ct;
                    }
                }
            }
            s = bs;
            t = bt;
        }
    }
    (s, t, p0 + d1 * s, q0 + d2 * t)
}

/// Sign of the f64 orientation determinant `det[a − d, b − d, c − d]`: positive when `d`
/// lies below the plane of `a, b, c` seen counter-clockwise from above.
#[inline]
fn orient3d_f64(a: &Vec3, b: &Vec3, c: &Vec3, d: &Vec3) -> f64 {
    (a - d).dot(&(b - d).cross(&(c - d)))
}

/// f64 2D orientation of projected points (coordinates `i`, `j`).
#[inline]
fn orient2d_f64(a: &Vec3, b: &Vec3, c: &Vec3, i: usize, j: usize) -> f64 {
    (a[i] - c[i]) * (b[j] - c[j]) - (a[j] - c[j]) * (b[i] - c[i])
}

/// Closed 2D segment–segment test in the coordinate plane `(i, j)`.
fn segments_meet_2d(p: &Vec3, q: &Vec3, a: &Vec3, b: &Vec3, i: usize, j: usize) -> bool {
    let d1 = orient2d_f64(a, b, p, i, j);
    let d2 = orient2d_f64(a, b, q, i, j);
    let d3 = orient2d_f64(p, q, a, i, j);
    let d4 = orient2d_f64(p, q, b, i, j);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let within = |u: &Vec3, v: &Vec3, x: &Vec3| {
        x[i] >= u[i].min(v[i])
            && x[i] <= u[i].max(v[i])
            && x[j] >= u[j].min(v[j])
            && x[j] <= u[j].max(v[j])
    };
    (d1 == 0.0 && within(a, b, p))
        || (d2 == 0.0 && within(a, b, q))
        || (d3 == 0.0 && within(p, q, a))
        || (d4 == 0.0 && within(p, q, b))
}

/// Closed 2D segment–triangle test in the coordinate plane `(i, j)`.
fn segment_meets_triangle_2d(
    p: &Vec3,
    q: &Vec3,
    a: &Vec3,
    b: &Vec3,
    c: &Vec3,
    i: usize,
    j: usize,
) -> bool {
    if segments_meet_2d(p, q, a, b, i, j)
        || segments_meet_2d(p, q, b, c, i, j)
        || segments_meet_2d(p, q, c, a, i, j)
    {
        return true;
    }
    let o = orient2d_f64(a, b, c, i, j);
    if o == 0.0 {
        return false;
    }
    let s1 = orient2d_f64(a, b, p, i, j) * o;
    let s2 = orient2d_f64(b, c, p, i, j) * o;
    let s3 = orient2d_f64(c, a, p, i, j) * o;
    s1 >= 0.0 && s2 >= 0.0 && s3 >= 0.0
}

const PROJECTIONS: [(usize, usize); 3] = [(1, 2), (2, 0), (0, 1)];

/// Whether the closed segment `p0`–`p1` meets the closed triangle `abc`.
///
/// Decided from the signs of f64 orientation determinants (no exact arithmetic: results
/// for configurations within round-off of a degenerate one may go either way; meant for
/// statistics, not for decisions that must be consistent). Touching counts as meeting;
/// a segment lying in the triangle's plane is tested in 2D along the dominant normal axis;
/// a zero-area triangle is treated as the union of its edges.
pub fn segment_triangle_intersect(p0: Vec3, p1: Vec3, a: Vec3, b: Vec3, c: Vec3) -> bool {
    // orientations within round-off of zero count as zero: a segment lying in the triangle's
    // plane must take the 2D test, not the line test, whose signs are then noise
    let scale = [b - a, c - a, p0 - a, p1 - a]
        .iter()
        .map(|v| v.amax())
        .fold(0.0, f64::max);
    let tol = 1e-12 * scale * scale * scale;
    let snap = |o: f64| if o.abs() <= tol { 0.0 } else { o };
    let op = snap(orient3d_f64(&a, &b, &c, &p0));
    let oq = snap(orient3d_f64(&a, &b, &c, &p1));
    if (op > 0.0 && oq > 0.0) || (op < 0.0 && oq < 0.0) {
        return false;
    }
    if op != 0.0 || oq != 0.0 {
        let s1 = snap(orient3d_f64(&p0, &p1, &a, &b));
        let s2 = snap(orient3d_f64(&p0, &p1, &b, &c));
        let s3 = snap(orient3d_f64(&p0, &p1, &c, &a));
        let any_pos = s1 > 0.0 || s2 > 0.0 || s3 > 0.0;
        let any_neg = s1 < 0.0 || s2 < 0.0 || s3 < 0.0;
        return !(any_pos && any_neg);
    }
    let n = (b - a).cross(&(c - a));
    if n == Vec3::zeros() {
        // degenerate triangle: union of its edges
        let seg_seg = |u: &Vec3, v: &Vec3| {
            orient3d_f64(&p0, &p1, u, v) == 0.0
                && PROJECTIONS
                    .iter()
                    .all(|&(i, j)| segments_meet_2d(&p0, &p1, u, v, i, j))
        };
        return seg_seg(&a, &b) || seg_seg(&b, &c) || seg_seg(&c, &a);
    }
    // coplanar: project along the dominant normal axis
    let k = if n.x.abs() >= n.y.abs() && n.x.abs() >= n.z.abs() {
        0
    } else if n.y.abs() >= n.z.abs() {
        1
    } else {
        2
    };
    let (i, j) = PROJECTIONS[k];
    segment_meets_triangle_2d(&p0, &p1, &a, &b, &c, i, j)
}
