//! Plane geometry behind the DXF-AAMA reader and writer: chaining polyline pieces into closed
//! loops, turning a closed polyline into corners and segments (straight lines and cubic Béziers
//! fitted by least squares), projections onto polylines and the seam-allowance measure.
//!
//! Everything works on plain `[f64; 2]` points; tolerances are in the unit of the points.

use crate::garment::pattern::{Segment, P2};

pub(crate) fn sub(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}
pub(crate) fn add(a: P2, b: P2) -> P2 {
    [a[0] + b[0], a[1] + b[1]]
}
pub(crate) fn mul(a: P2, s: f64) -> P2 {
    [a[0] * s, a[1] * s]
}
pub(crate) fn dot(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
pub(crate) fn cross(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
pub(crate) fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Signed area of a closed polygon (positive when counter-clockwise).
pub(crate) fn signed_area(pts: &[P2]) -> f64 {
    let n = pts.len();
    (0..n).map(|i| cross(pts[i], pts[(i + 1) % n])).sum::<f64>() / 2.0
}

/// The point of segment `a`–`b` closest to `p`, and its parameter in [0, 1].
pub(crate) fn closest_on_segment(a: P2, b: P2, p: P2) -> (P2, f64) {
    let d = sub(b, a);
    let l2 = dot(d, d);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (add(a, mul(d, t)), t)
}

/// The point of closed polygon `pts` closest to `p`: (point, distance, edge index, parameter).
pub(crate) fn closest_on_loop(pts: &[P2], p: P2) -> (P2, f64, usize, f64) {
    let n = pts.len();
    let mut best = (pts[0], f64::INFINITY, 0, 0.0);
    for i in 0..n {
        let (q, t) = closest_on_segment(pts[i], pts[(i + 1) % n], p);
        let d = dist(p, q);
        if d < best.1 {
            best = (q, d, i, t);
        }
    }
    best
}

/// Distance from `p` to the infinite line through `a` and `b` (to `a` if they coincide).
pub(crate) fn dist_to_line(a: P2, b: P2, p: P2) -> f64 {
    let d = sub(b, a);
    let l = d[0].hypot(d[1]);
    if l > 0.0 {
        cross(d, sub(p, a)).abs() / l
    } else {
        dist(a, p)
    }
}

/// Where segments `a0`–`a1` and `b0`–`b1` cross, if they do.
pub(crate) fn segment_intersection(a0: P2, a1: P2, b0: P2, b1: P2) -> Option<P2> {
    let r = sub(a1, a0);
    let s = sub(b1, b0);
    let den = cross(r, s);
    if den.abs() < 1e-300 {
        return None;
    }
    let q = sub(b0, a0);
    let t = cross(q, s) / den;
    let u = cross(q, r) / den;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then(|| add(a0, mul(r, t)))
}

/// An open or closed polyline read from one entity; `at` says where it came from.
#[derive(Debug, Clone)]
pub(crate) struct Path {
    pub pts: Vec<P2>,
    pub closed: bool,
    pub at: String,
}

/// A chain that does not close: its loose end, the nearest point it could join and the gap.
#[derive(Debug)]
pub(crate) struct OpenChain {
    pub end: P2,
    pub nearest: P2,
    pub gap: f64,
    pub at: String,
}

/// Drops consecutive points closer than `tol`, and a last point equal to the first.
fn dedup(pts: &mut Vec<P2>, tol: f64) {
    pts.dedup_by(|b, a| dist(*a, *b) <= tol);
    while pts.len() > 1 && dist(pts[0], pts[pts.len() - 1]) <= tol {
        pts.pop();
    }
}

/// Joins paths end to end (either way round, within `tol`) into closed loops.
/// Fails on the first chain that cannot be closed.
pub(crate) fn chain(paths: Vec<Path>, tol: f64) -> Result<Vec<Vec<P2>>, OpenChain> {
    let mut loops = Vec::new();
    let mut pool: Vec<Path> = Vec::new();
    for p in paths {
        if p.pts.is_empty() {
            continue;
        }
        let ends_meet = p.pts.len() > 2 && dist(p.pts[0], p.pts[p.pts.len() - 1]) <= tol;
        if p.closed || ends_meet {
            let mut pts = p.pts;
            dedup(&mut pts, tol);
            loops.push(pts);
        } else {
            pool.push(p);
        }
    }
    while !pool.is_empty() {
        let first = pool.remove(0);
        let at = first.at.clone();
        let mut pts = first.pts;
        loop {
            let start = pts[0];
            let end = pts[pts.len() - 1];
            if pts.len() > 2 && dist(start, end) <= tol {
                break;
            }
            // The nearest free end among the unused paths.
            let mut best: Option<(usize, bool, f64)> = None;
            for (k, p) in pool.iter().enumerate() {
                for (rev, q) in [(false, p.pts[0]), (true, p.pts[p.pts.len() - 1])] {
                    let d = dist(end, q);
                    if best.is_none_or(|b| d < b.2) {
                        best = Some((k, rev, d));
                    }
                }
            }
            match best {
                Some((k, rev, d)) if d <= tol => {
                    let mut next = pool.remove(k).pts;
                    if rev {
                        next.reverse();
                    }
                    pts.extend(next);
                }
                _ => {
                    let (nearest, gap) = match best {
                        Some((k, rev, d)) if d < dist(end, start) || pts.len() <= 2 => {
                            let p = &pool[k].pts;
                            (if rev { p[p.len() - 1] } else { p[0] }, d)
                        }
                        _ => (start, dist(end, start)),
                    };
                    return Err(OpenChain {
                        end,
                        nearest,
                        gap,
                        at,
                    });
                }
            }
        }
        dedup(&mut pts, tol);
        loops.push(pts);
    }
    loops.retain(|l| l.len() >= 2);
    Ok(loops)
}

/// Points of the arc from `a` to `b` with bulge `bulge` (tan of a quarter of the included
/// angle, positive counter-clockwise), `b` excluded, with chords within `tol` of the arc.
pub(crate) fn bulge_points(a: P2, b: P2, bulge: f64, tol: f64) -> Vec<P2> {
    let chord = dist(a, b);
    if bulge.abs() < 1e-9 || chord <= 0.0 || !bulge.is_finite() {
        return vec![a];
    }
    let theta = 4.0 * bulge.atan();
    let r = chord / (2.0 * (theta / 2.0).sin().abs());
    let mid = mul(add(a, b), 0.5);
    let dir = mul(sub(b, a), 1.0 / chord);
    let normal = [-dir[1], dir[0]];
    // Centre: left of the chord for a counter-clockwise arc of less than half a turn.
    let h = r * (theta / 2.0).cos().abs();
    let side = if (bulge > 0.0) == (bulge.abs() < 1.0) {
        1.0
    } else {
        -1.0
    };
    let c = add(mid, mul(normal, h * side));
    let a0 = (a[1] - c[1]).atan2(a[0] - c[0]);
    arc_points(c, r, a0, theta, tol)
}

/// Points of an arc of centre `c`, radius `r` from angle `a0` sweeping `sweep` (rad),
/// end excluded, with chords within `tol` of the arc.
pub(crate) fn arc_points(c: P2, r: f64, a0: f64, sweep: f64, tol: f64) -> Vec<P2> {
    let step = if r > tol {
        2.0 * (1.0 - tol / r).acos()
    } else {
        std::f64::consts::PI / 2.0
    };
    let n = ((sweep.abs() / step.max(1e-6)).ceil() as usize).clamp(1, 4096);
    (0..n)
        .map(|i| {
            let a = a0 + sweep * i as f64 / n as f64;
            [c[0] + r * a.cos(), c[1] + r * a.sin()]
        })
        .collect()
}

/// Cubic Bézier point at `t`.
pub(crate) fn bezier(p: [P2; 4], t: f64) -> P2 {
    let s = 1.0 - t;
    let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
    [
        w[0] * p[0][0] + w[1] * p[1][0] + w[2] * p[2][0] + w[3] * p[3][0],
        w[0] * p[0][1] + w[1] * p[1][1] + w[2] * p[2][1] + w[3] * p[3][1],
    ]
}

fn bezier_d1(p: [P2; 4], t: f64) -> P2 {
    let s = 1.0 - t;
    let a = mul(sub(p[1], p[0]), 3.0 * s * s);
    let b = mul(sub(p[2], p[1]), 6.0 * s * t);
    let c = mul(sub(p[3], p[2]), 3.0 * t * t);
    add(add(a, b), c)
}

fn bezier_d2(p: [P2; 4], t: f64) -> P2 {
    let a = add(sub(p[2], mul(p[1], 2.0)), p[0]);
    let b = add(sub(p[3], mul(p[2], 2.0)), p[1]);
    add(mul(a, 6.0 * (1.0 - t)), mul(b, 6.0 * t))
}

/// Least-squares cubic through `q` (ends fixed, inner control points free), with Newton
/// reparameterisation from chord-length parameters, and again from evenly spaced ones (how
/// writers sample a curve, ours included); the better of the two. Returns the control points
/// and the largest point error.
fn fit_cubic(q: &[P2]) -> Option<([P2; 4], f64)> {
    let m = q.len() - 1;
    let mut u = vec![0.0; q.len()];
    for i in 1..=m {
        u[i] = u[i - 1] + dist(q[i], q[i - 1]);
    }
    let total = u[m];
    if total <= 0.0 {
        return None;
    }
    u.iter_mut().for_each(|x| *x /= total);
    let even: Vec<f64> = (0..=m).map(|i| i as f64 / m as f64).collect();
    match (fit_cubic_from(q, u, total), fit_cubic_from(q, even, total)) {
        (Some(a), Some(b)) => Some(if b.1 < a.1 { b } else { a }),
        (a, b) => a.or(b),
    }
}

/// [`fit_cubic`] from the starting parameters `u` (0 to 1); `total` is the polyline's length.
fn fit_cubic_from(q: &[P2], mut u: Vec<f64>, total: f64) -> Option<([P2; 4], f64)> {
    let m = q.len() - 1;
    let (p0, p3) = (q[0], q[m]);
    let mut ctrl = [p0, p0, p3, p3];
    for _ in 0..400 {
        let (mut a11, mut a12, mut a22) = (0.0, 0.0, 0.0);
        let (mut r1, mut r2) = ([0.0; 2], [0.0; 2]);
        for (i, &t) in u.iter().enumerate() {
            let s = 1.0 - t;
            let (b0, b1, b2, b3) = (s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t);
            let rest = sub(q[i], add(mul(p0, b0), mul(p3, b3)));
            a11 += b1 * b1;
            a12 += b1 * b2;
            a22 += b2 * b2;
            r1 = add(r1, mul(rest, b1));
            r2 = add(r2, mul(rest, b2));
        }
        let det = a11 * a22 - a12 * a12;
        if det.is_nan() || det <= 1e-12 * (a11 + a22).powi(2) {
            return None;
        }
        let c1 = mul(sub(mul(r1, a22), mul(r2, a12)), 1.0 / det);
        let c2 = mul(sub(mul(r2, a11), mul(r1, a12)), 1.0 / det);
        ctrl = [p0, c1, c2, p3];
        let mut moved: f64 = 0.0;
        for (i, t) in u.iter_mut().enumerate().take(m).skip(1) {
            let d = sub(bezier(ctrl, *t), q[i]);
            let d1 = bezier_d1(ctrl, *t);
            let den = dot(d1, d1) + dot(d, bezier_d2(ctrl, *t));
            if den.abs() > 1e-300 {
                let new = (*t - dot(d, d1) / den).clamp(0.0, 1.0);
                moved = moved.max((new - *t).abs());
                *t = new;
            }
        }
        if moved < 1e-12 {
            break;
        }
    }
    let err = (1..m)
        .map(|i| dist(bezier(ctrl, u[i]), q[i]))
        .fold(0.0, f64::max);
    // Reject wild control polygons (loops, cusps) even if they pass through the points.
    let polygon = dist(ctrl[0], ctrl[1]) + dist(ctrl[1], ctrl[2]) + dist(ctrl[2], ctrl[3]);
    (err.is_finite() && polygon <= 2.0 * total).then_some((ctrl, err))
}

/// The segment for one run of points between two corners, or where to split it.
fn fit_run(q: &[P2], tol: f64) -> Result<Segment, usize> {
    let m = q.len() - 1;
    if m == 1 {
        return Ok(Segment::Line);
    }
    let (a, b) = (q[0], q[m]);
    let far = (1..m)
        .map(|i| (i, dist(closest_on_segment(a, b, q[i]).0, q[i])))
        .fold((1, -1.0), |x, y| if y.1 > x.1 { y } else { x });
    if far.1 <= tol * 0.2 {
        return Ok(Segment::Line);
    }
    if m == 2 {
        // The quadratic through the middle point, at its chord-length parameter.
        let (d1, d2) = (dist(q[0], q[1]), dist(q[1], q[2]));
        let t = d1 / (d1 + d2);
        let s = 1.0 - t;
        let c = mul(
            sub(q[1], add(mul(a, s * s), mul(b, t * t))),
            1.0 / (2.0 * s * t),
        );
        if dist(a, c) + dist(c, b) <= 1.5 * (d1 + d2) {
            let c1 = add(a, mul(sub(c, a), 2.0 / 3.0));
            let c2 = add(b, mul(sub(c, b), 2.0 / 3.0));
            return Ok(Segment::Cubic { c1, c2 });
        }
        return Err(1);
    }
    match fit_cubic(q) {
        Some((c, err)) if err <= tol => Ok(Segment::Cubic { c1: c[1], c2: c[2] }),
        _ => Err(far.0),
    }
}

/// Turns the closed polygon `pts` into corners and segments. Vertices flagged in `corner`
/// are kept as corners; the runs between them become a line (when straight within `tol/5`)
/// or a cubic (when one follows every vertex within `tol`), else the run is split at a vertex
/// (one flagged in `prefer` when there is one, else the worst one) which becomes a corner.
/// At least three corners are kept. Returns the corners' vertex indices and segments, in
/// polygon order.
pub(crate) fn fit_loop(
    pts: &[P2],
    corner: &[bool],
    prefer: &[bool],
    tol: f64,
) -> Vec<(usize, Segment)> {
    let n = pts.len();
    let mut is_corner = corner.to_vec();
    if !is_corner.iter().any(|&c| c) {
        is_corner[lowest_leftmost(pts)] = true;
    }
    // Arc length along the polygon, to add corners as far as possible from existing ones.
    let mut s = vec![0.0; n + 1];
    for i in 0..n {
        s[i + 1] = s[i] + dist(pts[i], pts[(i + 1) % n]);
    }
    while is_corner.iter().filter(|&&c| c).count() < 3.min(n) {
        let cs: Vec<usize> = (0..n).filter(|&i| is_corner[i]).collect();
        let away = |i: usize| {
            cs.iter()
                .map(|&c| {
                    let d = (s[i] - s[c]).abs();
                    d.min(s[n] - d)
                })
                .fold(f64::INFINITY, f64::min)
        };
        let far = (0..n)
            .filter(|&i| !is_corner[i])
            .max_by(|&a, &b| away(a).total_cmp(&away(b)));
        match far {
            Some(i) => is_corner[i] = true,
            None => break,
        }
    }
    let cs: Vec<usize> = (0..n).filter(|&i| is_corner[i]).collect();
    let mut out = Vec::new();
    for (k, &c0) in cs.iter().enumerate() {
        let c1 = cs[(k + 1) % cs.len()];
        let len = (c1 + n - c0 - 1) % n + 1;
        let idx: Vec<usize> = (0..=len).map(|j| (c0 + j) % n).collect();
        // Work list of (from, to) positions in `idx`, handled in order.
        let mut todo = vec![(0, len)];
        while let Some((a, b)) = todo.pop() {
            let q: Vec<P2> = idx[a..=b].iter().map(|&i| pts[i]).collect();
            match fit_run(&q, tol) {
                Ok(seg) => out.push((idx[a], seg)),
                Err(worst) => {
                    let pick = (1..b - a)
                        .filter(|&j| prefer[idx[a + j]])
                        .min_by_key(|&j| j.abs_diff(worst))
                        .unwrap_or(worst);
                    todo.push((a + pick, b));
                    todo.push((a, a + pick));
                }
            }
        }
    }
    out
}

/// Index of the lowest point, leftmost among equally low ones (within 1e-9 of the scale).
pub(crate) fn lowest_leftmost(pts: &[P2]) -> usize {
    let scale = pts
        .iter()
        .map(|p| p[0].abs().max(p[1].abs()))
        .fold(0.0, f64::max);
    let eps = 1e-9 * scale.max(1e-300);
    let mut best = 0;
    for (i, p) in pts.iter().enumerate() {
        let b = pts[best];
        if p[1] < b[1] - eps || ((p[1] - b[1]).abs() <= eps && p[0] < b[0]) {
            best = i;
        }
    }
    best
}

/// Mean distance from the closed polygon `inner` to `outer`, measured along the outward normal
/// of `inner` at evenly spaced samples (about `samples` of them). Samples where the two
/// coincide (closer than `skip`: folds, edges without allowance) and rays that miss are left
/// out; `None` when nothing is left.
pub(crate) fn mean_offset(inner: &[P2], outer: &[P2], samples: usize, skip: f64) -> Option<f64> {
    let n = inner.len();
    let perimeter: f64 = (0..n).map(|i| dist(inner[i], inner[(i + 1) % n])).sum();
    if n < 3 || outer.len() < 3 || perimeter <= 0.0 {
        return None;
    }
    let step = perimeter / samples.max(1) as f64;
    let orientation = signed_area(inner).signum();
    let reach = 2.0 * perimeter;
    let (mut sum, mut weight) = (0.0, 0.0);
    for i in 0..n {
        let (a, b) = (inner[i], inner[(i + 1) % n]);
        let len = dist(a, b);
        if len <= 0.0 {
            continue;
        }
        let d = mul(sub(b, a), 1.0 / len);
        let normal = mul([d[1], -d[0]], orientation);
        let k = (len / step).round().max(1.0) as usize;
        let w = len / k as f64;
        for j in 0..k {
            let p = add(a, mul(d, len * (j as f64 + 0.5) / k as f64));
            if closest_on_loop(outer, p).1 <= skip {
                continue;
            }
            let far = add(p, mul(normal, reach));
            let hit = (0..outer.len())
                .filter_map(|e| {
                    segment_intersection(p, far, outer[e], outer[(e + 1) % outer.len()])
                })
                .map(|q| dist(p, q))
                .fold(f64::INFINITY, f64::min);
            if hit.is_finite() {
                sum += hit * w;
                weight += w;
            }
        }
    }
    (weight > 0.0).then(|| sum / weight)
}
