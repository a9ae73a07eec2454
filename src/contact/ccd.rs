//! Continuous collision detection (CCD) for linearly moving primitives over one step.
//!
//! Each of the four points moves from `x[i]` at `t = 0` to `x[i] + d[i]` at `t = 1`. A
//! vertex–face or edge–edge collision can only happen when the four points are coplanar,
//! so (after Provot 1997, Bridson, Fedkiw & Anderson 2002) the coplanarity condition
//!
//! ```text
//! f(t) = ((x1 − x0 + t(d1 − d0)) × (x2 − x0 + t(d2 − d0))) · (x3 − x0 + t(d3 − d0)) = 0
//! ```
//!
//! a cubic in `t`, is solved for all its roots in `[0, 1]`, and at each root, in increasing
//! order, the primitives are tested for proximity (distance within the thickness) with the
//! closest-point functions of [`super::primitives`]. The first root that passes is the hit.
//!
//! The root finder does not use the closed-form cubic: it splits `[0, 1]` at the roots of
//! `f′` (a quadratic, solved stably; a vanishing leading coefficient degrades to the
//! linear case), so that `f` is monotone on each piece, and brackets each sign change with
//! a safeguarded Newton–bisection iteration. Breakpoints where `|f|` is within round-off of
//! zero (grazing double roots, an interval end on the plane) are candidates too.
//!
//! The detection is *pure*: only coplanarity events are reported. Primitives that are already
//! within the thickness at `t = 0` but not coplanar during the step are **not** reported —
//! callers that want a proximity (repulsion) test must do it separately. When the motion is
//! coplanar throughout (the cubic vanishes identically to round-off), every time is a
//! coplanarity event; the candidates are then `t = 0`, `t = 1` and the times at which a
//! vertex becomes collinear with an edge of the other primitive (the in-plane events), so
//! the hit time is the first of those at which the primitives are within the thickness.
//!
//! The thickness is a tolerance on the distance at the event and is floored at
//! [`MIN_THICKNESS`] so that a root computed to round-off still passes an exact touch.

use super::primitives::{closest_point_triangle, closest_points_segments};
use nalgebra::Vector3;

type Vec3 = Vector3<f64>;

/// Smallest distance tolerance used by the CCD tests (metres): a smaller or negative
/// `thickness` argument is raised to this.
pub const MIN_THICKNESS: f64 = 1e-6;

/// A collision found by [`vertex_face_ccd`] or [`edge_edge_ccd`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CcdHit {
    /// Time of impact as a fraction of the step, in `[0, 1]`.
    pub t: f64,
    /// Weights of the four points such that `Σ wᵢ xᵢ(t)` is the vector between the two contact
    /// points (Bridson 2002 signs): vertex–face `(1, −wa, −wb, −wc)` with the barycentric
    /// weights of the closest point on the face; edge–edge `(1 − s, s, −(1 − u), −u)` with the
    /// parameters `s`, `u` of the closest points on the first and second edge.
    pub weights: [f64; 4],
    /// Unit normal at the time of impact, pointing from the face (second edge) toward the
    /// vertex (first edge), i.e. toward the side the vertex (first edge) came from.
    pub normal: Vec3,
}

/// Coefficients `[c0, c1, c2, c3]` of `((a + t da) × (b + t db)) · (c + t dc)`.
#[inline]
fn triple_coeffs(a: Vec3, da: Vec3, b: Vec3, db: Vec3, c: Vec3, dc: Vec3) -> [f64; 4] {
    let n0 = a.cross(&b);
    let n1 = a.cross(&db) + da.cross(&b);
    let n2 = da.cross(&db);
    [
        n0.dot(&c),
        n0.dot(&dc) + n1.dot(&c),
        n1.dot(&dc) + n2.dot(&c),
        n2.dot(&dc),
    ]
}

/// A bound on `|f(t)|` over `[0, 1]` for the product above, used to scale tolerances.
#[inline]
fn triple_bound(a: Vec3, da: Vec3, b: Vec3, db: Vec3, c: Vec3, dc: Vec3) -> f64 {
    (a.norm() + da.norm()) * (b.norm() + db.norm()) * (c.norm() + dc.norm())
}

#[inline]
fn eval(c: &[f64; 4], t: f64) -> f64 {
    ((c[3] * t + c[2]) * t + c[1]) * t + c[0]
}

#[inline]
fn deriv(c: &[f64; 4], t: f64) -> f64 {
    (3.0 * c[3] * t + 2.0 * c[2]) * t + c[1]
}

/// Safeguarded Newton–bisection for a root of the cubic in `(lo, hi)`, where `f(lo)` and
/// `f(hi)` have strictly opposite signs.
fn refine_root(c: &[f64; 4], mut lo: f64, mut hi: f64, flo: f64) -> f64 {
    let lo_neg = flo < 0.0;
    let mut t = 0.5 * (lo + hi);
    let mut dx_old = hi - lo;
    let mut dx = dx_old;
    let mut f = eval(c, t);
    let mut df = deriv(c, t);
    for _ in 0..100 {
        if f == 0.0 {
            return t;
        }
        if (f < 0.0) == lo_neg {
            lo = t;
        } else {
            hi = t;
        }
        let newton_out = ((t - hi) * df - f) * ((t - lo) * df - f) > 0.0;
        if newton_out || (2.0 * f).abs() > (dx_old * df).abs() || df == 0.0 {
            dx_old = dx;
            dx = 0.5 * (hi - lo);
            let prev = t;
            t = lo + dx;
            if t == prev || t == lo {
                return t;
            }
        } else {
            dx_old = dx;
            dx = f / df;
            let prev = t;
            t -= dx;
            if t == prev {
                return t;
            }
        }
        if dx.abs() < 1e-16 || hi - lo < 1e-16 {
            return t;
        }
        f = eval(c, t);
        df = deriv(c, t);
    }
    t
}

/// Writes the roots in `(0, 1)` of `a2 t² + a1 t + a0` (for a negative discriminant, the
/// vertex, where `|f′|` is smallest) into `out` from index `n`; returns the new count.
#[inline]
fn quadratic_breakpoints(a2: f64, a1: f64, a0: f64, out: &mut [f64; 4], mut n: usize) -> usize {
    let mut push = |r: f64| {
        if r > 0.0 && r < 1.0 {
            out[n] = r;
            n += 1;
        }
    };
    if a2 == 0.0 {
        if a1 != 0.0 {
            push(-a0 / a1);
        }
    } else {
        let disc = a1 * a1 - 4.0 * a2 * a0;
        if disc < 0.0 {
            push(-a1 / (2.0 * a2));
        } else {
            let q = -0.5 * (a1 + disc.sqrt().copysign(a1));
            push(q / a2);
            if q != 0.0 {
                push(a0 / q);
            }
        }
    }
    n
}

/// All roots of the cubic `c` in `[0, 1]`, ascending, into `out`; returns their count.
/// Values with `|f| ≤ ftol` at a breakpoint (0, 1, or an extremum) count as roots there.
fn roots_in_unit(c: &[f64; 4], ftol: f64, out: &mut [f64; 8]) -> usize {
    let mut bp = [0.0; 4];
    let mut nb = quadratic_breakpoints(3.0 * c[3], 2.0 * c[2], c[1], &mut bp, 1);
    if nb == 3 && bp[1] > bp[2] {
        bp.swap(1, 2);
    }
    bp[nb] = 1.0;
    nb += 1;

    let mut n = 0;
    let mut push = |r: f64, n: &mut usize| {
        if *n == 0 || r > out[*n - 1] {
            out[*n] = r;
            *n += 1;
        }
    };
    let mut f_prev = eval(c, bp[0]);
    for i in 0..nb {
        let fi = if i == 0 { f_prev } else { eval(c, bp[i]) };
        if i > 0 && ((f_prev < 0.0 && fi > 0.0) || (f_prev > 0.0 && fi < 0.0)) {
            let r = refine_root(c, bp[i - 1], bp[i], f_prev);
            push(r, &mut n);
        }
        if fi.abs() <= ftol {
            push(bp[i], &mut n);
        }
        f_prev = fi;
    }
    n
}

/// Sign (+1, −1 or 0) of the coplanarity function just before the root `r`, `prev` being the
/// previous root (or 0).
#[inline]
fn side_before(c: &[f64; 4], prev: f64, r: f64, ftol: f64) -> f64 {
    if r > prev {
        let fm = eval(c, 0.5 * (prev + r));
        if fm.abs() > ftol {
            return fm.signum();
        }
    }
    let dr = deriv(c, r);
    if dr != 0.0 {
        -dr.signum()
    } else {
        0.0
    }
}

/// Unit normal from `n_raw` oriented by `side`; when `n_raw` is degenerate or `side` is 0,
/// falls back to the separation `sep` (from face/second edge to vertex/first edge) and then
/// to the opposite of the relative velocity `vrel` of the contact points.
#[inline]
fn oriented_normal(n_raw: Vec3, side: f64, sep: Vec3, vrel: Vec3) -> Vec3 {
    let nn = n_raw.norm();
    if nn > 0.0 && nn.is_finite() {
        let n = n_raw / nn;
        let s = if side != 0.0 {
            side
        } else if n.dot(&sep) != 0.0 {
            n.dot(&sep).signum()
        } else if n.dot(&vrel) != 0.0 {
            -n.dot(&vrel).signum()
        } else {
            1.0
        };
        return n * s;
    }
    let ns = sep.norm();
    if ns > 0.0 && ns.is_finite() {
        return sep / ns;
    }
    let nv = vrel.norm();
    if nv > 0.0 && nv.is_finite() {
        return -vrel / nv;
    }
    Vec3::z()
}

#[inline]
fn at(x: &[Vec3; 4], d: &[Vec3; 4], t: f64) -> [Vec3; 4] {
    [
        x[0] + d[0] * t,
        x[1] + d[1] * t,
        x[2] + d[2] * t,
        x[3] + d[3] * t,
    ]
}

/// Insertion-sorts `v[..n]` ascending.
#[inline]
fn sort_small(v: &mut [f64], n: usize) {
    for i in 1..n {
        let mut j = i;
        while j > 0 && v[j - 1] > v[j] {
            v.swap(j - 1, j);
            j -= 1;
        }
    }
}

/// Candidate times for motion that is coplanar throughout: 0, 1 and the roots of the
/// collinearity functions `N · ((e0 − v) × (e1 − v))` for the `(vertex, edge)` index triples
/// in `pairs`, `N` being the largest of the cross products of the point differences sampled
/// at `t = 0, ½, 1`. Returns the count written into `out` (sorted).
fn coplanar_candidates(
    x: &[Vec3; 4],
    d: &[Vec3; 4],
    pairs: &[[usize; 3]],
    out: &mut [f64; 32],
) -> usize {
    let mut reference = Vec3::zeros();
    for t in [0.0, 0.5, 1.0] {
        let y = at(x, d, t);
        for (i, j) in [(1, 2), (1, 3), (2, 3)] {
            let n = (y[i] - y[0]).cross(&(y[j] - y[0]));
            if n.norm_squared() > reference.norm_squared() {
                reference = n;
            }
        }
    }
    out[0] = 0.0;
    out[1] = 1.0;
    let mut n = 2;
    if reference.norm_squared() > 0.0 {
        let nref = reference.normalize();
        for &[v, e0, e1] in pairs {
            let (u, du) = (x[e0] - x[v], d[e0] - d[v]);
            let (w, dw) = (x[e1] - x[v], d[e1] - d[v]);
            let c = triple_coeffs(u, du, w, dw, nref, Vec3::zeros());
            let ftol = 64.0 * f64::EPSILON * triple_bound(u, du, w, dw, nref, Vec3::zeros());
            if c.iter().all(|ci| ci.abs() <= ftol) {
                continue; // collinear throughout: no distinct event
            }
            let mut roots = [0.0; 8];
            let k = roots_in_unit(&c, ftol, &mut roots);
            for &r in &roots[..k] {
                if n < out.len() {
                    out[n] = r;
                    n += 1;
                }
            }
        }
    } else {
        out[2] = 0.5;
        n = 3;
    }
    sort_small(out, n);
    n
}

/// Vertex–face continuous collision test.
///
/// `x = [p, a, b, c]` are the vertex and the triangle's corners at `t = 0`, `d` their
/// displacements over the step. Returns the earliest coplanarity time at which the vertex is
/// within `thickness` (at least [`MIN_THICKNESS`]) of the triangle, with weights
/// `(1, −wa, −wb, −wc)` and the face normal oriented toward the side the vertex came from.
pub fn vertex_face_ccd(x: [Vec3; 4], d: [Vec3; 4], thickness: f64) -> Option<CcdHit> {
    let tol = thickness.max(MIN_THICKNESS);
    let [p, a, b, c] = x;
    let [dp, da, db, dc] = d;
    let (ab, dab) = (b - a, db - da);
    let (ac, dac) = (c - a, dc - da);
    let (ap, dap) = (p - a, dp - da);
    let coeffs = triple_coeffs(ab, dab, ac, dac, ap, dap);
    let ftol = 64.0 * f64::EPSILON * triple_bound(ab, dab, ac, dac, ap, dap);
    if !coeffs.iter().all(|ci| ci.is_finite()) {
        return None;
    }

    let test = |t: f64, side: f64| -> Option<CcdHit> {
        let [pt, at_, bt, ct] = at(&x, &d, t);
        let (q, w) = closest_point_triangle(pt, at_, bt, ct);
        let sep = pt - q;
        if sep.norm() > tol {
            return None;
        }
        let vrel = dp - (da * w[0] + db * w[1] + dc * w[2]);
        let n_raw = (bt - at_).cross(&(ct - at_));
        Some(CcdHit {
            t,
            weights: [1.0, -w[0], -w[1], -w[2]],
            normal: oriented_normal(n_raw, side, sep, vrel),
        })
    };

    let pairs = [[0, 1, 2], [0, 2, 3], [0, 3, 1]];
    earliest_hit(&x, &d, &coeffs, ftol, &pairs, test)
}

/// Edge–edge continuous collision test.
///
/// `x = [p0, p1, q0, q1]` are the endpoints of the first and second edge at `t = 0`, `d` their
/// displacements over the step. Returns the earliest coplanarity time at which the edges are
/// within `thickness` (at least [`MIN_THICKNESS`]), with weights `(1 − s, s, −(1 − u), −u)`
/// of the closest points and the normal `±(p1 − p0) × (q1 − q0)` oriented from the second
/// edge toward the side the first edge came from (for parallel edges, the separation or the
/// opposite of the relative velocity).
pub fn edge_edge_ccd(x: [Vec3; 4], d: [Vec3; 4], thickness: f64) -> Option<CcdHit> {
    let tol = thickness.max(MIN_THICKNESS);
    let [p0, p1, q0, q1] = x;
    let [dp0, dp1, dq0, dq1] = d;
    let (a, da) = (p1 - p0, dp1 - dp0);
    let (b, db) = (q0 - p0, dq0 - dp0);
    let (c, dc) = (q1 - p0, dq1 - dp0);
    // f = det(p1 − p0, q0 − p0, q1 − p0) = ((p1 − p0) × (q1 − q0)) · (p0 − q0)
    let coeffs = triple_coeffs(a, da, b, db, c, dc);
    let ftol = 64.0 * f64::EPSILON * triple_bound(a, da, b, db, c, dc);
    if !coeffs.iter().all(|ci| ci.is_finite()) {
        return None;
    }

    let test = |t: f64, side: f64| -> Option<CcdHit> {
        let [p0t, p1t, q0t, q1t] = at(&x, &d, t);
        let (s, u, c1, c2) = closest_points_segments(p0t, p1t, q0t, q1t);
        let sep = c1 - c2;
        if sep.norm() > tol {
            return None;
        }
        let vrel = (dp0 * (1.0 - s) + dp1 * s) - (dq0 * (1.0 - u) + dq1 * u);
        let n_raw = (p1t - p0t).cross(&(q1t - q0t));
        Some(CcdHit {
            t,
            weights: [1.0 - s, s, -(1.0 - u), -u],
            normal: oriented_normal(n_raw, side, sep, vrel),
        })
    };

    let pairs = [[0, 2, 3], [1, 2, 3], [2, 0, 1], [3, 0, 1]];
    earliest_hit(&x, &d, &coeffs, ftol, &pairs, test)
}

/// The first hit `test(t, side)` finds at the coplanarity times of four moving points: the
/// roots in `[0, 1]` of their cubic `coeffs` (tolerance `ftol`), each with the side the points
/// came from, or, when the cubic vanishes (coplanar throughout), the candidate times of the
/// point–segment `pairs` (side 0).
fn earliest_hit(
    x: &[Vec3; 4],
    d: &[Vec3; 4],
    coeffs: &[f64; 4],
    ftol: f64,
    pairs: &[[usize; 3]],
    test: impl Fn(f64, f64) -> Option<CcdHit>,
) -> Option<CcdHit> {
    if coeffs.iter().all(|ci| ci.abs() <= ftol) {
        let mut cand = [0.0; 32];
        let n = coplanar_candidates(x, d, pairs, &mut cand);
        return cand[..n].iter().find_map(|&t| test(t, 0.0));
    }

    let mut roots = [0.0; 8];
    let n = roots_in_unit(coeffs, ftol, &mut roots);
    let mut prev = 0.0;
    for &r in &roots[..n] {
        let side = side_before(coeffs, prev, r, ftol);
        if let Some(hit) = test(r, side) {
            return Some(hit);
        }
        prev = r;
    }
    None
}

/// Coplanarity cubic of four linearly moving points, `[c0, c1, c2, c3]` with
/// `f(t) = Σ cₖ tᵏ = ((x1 − x0 + t(d1 − d0)) × (x2 − x0 + t(d2 − d0))) · (x3 − x0 + t(d3 − d0))`.
/// Exposed for tests and diagnostics.
#[inline]
pub fn coplanarity_cubic(x: [Vec3; 4], d: [Vec3; 4]) -> [f64; 4] {
    triple_coeffs(
        x[1] - x[0],
        d[1] - d[0],
        x[2] - x[0],
        d[2] - d[0],
        x[3] - x[0],
        d[3] - d[0],
    )
}

/// Roots in `[0, 1]` of the cubic `Σ cₖ tᵏ`, ascending, written into `out`; returns their
/// count (at most 8, duplicates removed). A value within `ftol` of zero at `0`, `1` or an
/// extremum counts as a root there. Exposed for tests and diagnostics.
#[inline]
pub fn cubic_roots_in_unit_interval(c: [f64; 4], ftol: f64, out: &mut [f64; 8]) -> usize {
    roots_in_unit(&c, ftol, out)
}
