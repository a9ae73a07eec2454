//! Independent, exact edge–triangle intersection counter for tests.
//!
//! Nothing here calls `emilion`: the orientation predicates are evaluated exactly with
//! floating-point expansion arithmetic (Shewchuk 1997: error-free `two_sum`/`two_product`
//! and expansion growth), behind a floating-point filter with Shewchuk's static error bound,
//! so every sign decision is the sign of the exact determinant of the given `f64`
//! coordinates. Exactness assumes no overflow or underflow in the products, i.e. coordinates
//! (and their differences) of magnitude between about 1e-90 and 1e90, or zero.
//!
//! Intersection semantics are closed: touching (a segment end on the triangle, a segment
//! through an edge or a vertex) counts, and so does any overlap of a segment lying in the
//! triangle's plane. Zero-area triangles are treated as the union of their edges.
#![allow(dead_code)]

type P3 = [f64; 3];

/// Machine epsilon of Shewchuk's papers: half an ulp of 1, `2⁻⁵³`.
const EPS: f64 = f64::EPSILON * 0.5;
/// Static error-bound coefficient of the 2D orientation filter.
const CCW_ERRBOUND_A: f64 = (3.0 + 16.0 * EPS) * EPS;
/// Static error-bound coefficient of the 3D orientation filter.
const O3D_ERRBOUND_A: f64 = (7.0 + 56.0 * EPS) * EPS;
/// Dekker's splitter, `2²⁷ + 1`.
const SPLITTER: f64 = 134_217_729.0;

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

#[inline]
fn two_diff(a: f64, b: f64) -> (f64, f64) {
    let x = a - b;
    let bv = a - x;
    let av = x + bv;
    (x, (a - av) + (bv - b))
}

#[inline]
fn split(a: f64) -> (f64, f64) {
    let c = SPLITTER * a;
    let big = c - a;
    let hi = c - big;
    (hi, a - hi)
}

#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    let (ahi, alo) = split(a);
    let (bhi, blo) = split(b);
    let err = x - ahi * bhi - alo * bhi - ahi * blo;
    (x, alo * blo - err)
}

/// A nonoverlapping floating-point expansion (components in increasing magnitude, zeros
/// removed) whose exact sum is the represented value. Fixed capacity, no allocation.
struct Expansion {
    c: [f64; 128],
    n: usize,
}

impl Expansion {
    fn new() -> Self {
        Expansion {
            c: [0.0; 128],
            n: 0,
        }
    }

    /// Adds one double exactly (Shewchuk's Grow-Expansion with zero elimination).
    fn add(&mut self, b: f64) {
        if b == 0.0 {
            return;
        }
        let mut q = b;
        let mut k = 0;
        for i in 0..self.n {
            let (s, h) = two_sum(q, self.c[i]);
            q = s;
            if h != 0.0 {
                self.c[k] = h;
                k += 1;
            }
        }
        if q != 0.0 {
            self.c[k] = q;
            k += 1;
        }
        self.n = k;
    }

    /// Adds `s · x · y` exactly.
    fn add_product(&mut self, s: f64, x: f64, y: f64) {
        let (h, l) = two_product(x, y);
        self.add(s * h);
        self.add(s * l);
    }

    /// Adds `s · x · y · z` exactly.
    fn add_triple(&mut self, s: f64, x: f64, y: f64, z: f64) {
        let (h, l) = two_product(x, y);
        let (h1, l1) = two_product(h, z);
        let (h2, l2) = two_product(l, z);
        self.add(s * l2);
        self.add(s * h2);
        self.add(s * l1);
        self.add(s * h1);
    }

    /// Sign of the exact value: that of the largest component.
    fn sign(&self) -> i32 {
        if self.n == 0 {
            0
        } else if self.c[self.n - 1] > 0.0 {
            1
        } else {
            -1
        }
    }
}

#[inline]
fn sign_of(x: f64) -> i32 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// Exact sign of `det[a − c, b − c]` for 2D points: +1 when `a, b, c` turn counter-clockwise.
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i32 {
    let detleft = (a[0] - c[0]) * (b[1] - c[1]);
    let detright = (a[1] - c[1]) * (b[0] - c[0]);
    let det = detleft - detright;
    let detsum = if detleft > 0.0 {
        if detright <= 0.0 {
            return sign_of(det);
        }
        detleft + detright
    } else if detleft < 0.0 {
        if detright >= 0.0 {
            return sign_of(det);
        }
        -detleft - detright
    } else {
        return sign_of(det);
    };
    let errbound = CCW_ERRBOUND_A * detsum;
    if det >= errbound || -det >= errbound {
        return sign_of(det);
    }
    orient2d_exact(a, b, c)
}

/// Exact 2D orientation without the filter (always the expansion path).
pub fn orient2d_exact(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> i32 {
    let mut e = Expansion::new();
    let (acx, acx_t) = two_diff(a[0], c[0]);
    let (acy, acy_t) = two_diff(a[1], c[1]);
    let (bcx, bcx_t) = two_diff(b[0], c[0]);
    let (bcy, bcy_t) = two_diff(b[1], c[1]);
    if acx_t == 0.0 && acy_t == 0.0 && bcx_t == 0.0 && bcy_t == 0.0 {
        e.add_product(1.0, acx, bcy);
        e.add_product(-1.0, acy, bcx);
    } else {
        // ax by − ax cy − cx by − ay bx + ay cx + cy bx
        e.add_product(1.0, a[0], b[1]);
        e.add_product(-1.0, a[0], c[1]);
        e.add_product(-1.0, c[0], b[1]);
        e.add_product(-1.0, a[1], b[0]);
        e.add_product(1.0, a[1], c[0]);
        e.add_product(1.0, c[1], b[0]);
    }
    e.sign()
}

/// Exact sign of `det[a − d, b − d, c − d]`: +1 when `d` lies below the plane through
/// `a, b, c` (counter-clockwise seen from above), 0 when the four points are coplanar.
pub fn orient3d(a: P3, b: P3, c: P3, d: P3) -> i32 {
    let adx = a[0] - d[0];
    let bdx = b[0] - d[0];
    let cdx = c[0] - d[0];
    let ady = a[1] - d[1];
    let bdy = b[1] - d[1];
    let cdy = c[1] - d[1];
    let adz = a[2] - d[2];
    let bdz = b[2] - d[2];
    let cdz = c[2] - d[2];
    let bdxcdy = bdx * cdy;
    let cdxbdy = cdx * bdy;
    let cdxady = cdx * ady;
    let adxcdy = adx * cdy;
    let adxbdy = adx * bdy;
    let bdxady = bdx * ady;
    let det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * adz.abs()
        + (cdxady.abs() + adxcdy.abs()) * bdz.abs()
        + (adxbdy.abs() + bdxady.abs()) * cdz.abs();
    if permanent == 0.0 {
        // every product vanishes (barring underflow): the determinant is exactly zero
        return 0;
    }
    let errbound = O3D_ERRBOUND_A * permanent;
    if det > errbound || -det > errbound {
        return sign_of(det);
    }
    orient3d_exact(a, b, c, d)
}

/// Exact 3D orientation without the filter (always the expansion path).
pub fn orient3d_exact(a: P3, b: P3, c: P3, d: P3) -> i32 {
    let mut e = Expansion::new();
    let mut diff = [[0.0; 3]; 3];
    let mut exact_diffs = true;
    for (row, p) in diff.iter_mut().zip([a, b, c]) {
        for k in 0..3 {
            let (x, tail) = two_diff(p[k], d[k]);
            row[k] = x;
            exact_diffs &= tail == 0.0;
        }
    }
    if exact_diffs {
        add_det3(&mut e, 1.0, diff[0], diff[1], diff[2]);
    } else {
        // det(a − d, b − d, c − d) = det(a,b,c) − det(d,b,c) − det(a,d,c) − det(a,b,d)
        add_det3(&mut e, 1.0, a, b, c);
        add_det3(&mut e, -1.0, d, b, c);
        add_det3(&mut e, -1.0, a, d, c);
        add_det3(&mut e, -1.0, a, b, d);
    }
    e.sign()
}

/// Adds `s · det[u, v, w]` (rows) exactly.
fn add_det3(e: &mut Expansion, s: f64, u: P3, v: P3, w: P3) {
    e.add_triple(s, u[0], v[1], w[2]);
    e.add_triple(-s, u[0], v[2], w[1]);
    e.add_triple(-s, u[1], v[0], w[2]);
    e.add_triple(s, u[1], v[2], w[0]);
    e.add_triple(s, u[2], v[0], w[1]);
    e.add_triple(-s, u[2], v[1], w[0]);
}

/// Coordinate planes `(i, j)`: projections dropping x, y and z.
const PROJ: [(usize, usize); 3] = [(1, 2), (2, 0), (0, 1)];

#[inline]
fn pr(p: &P3, (i, j): (usize, usize)) -> [f64; 2] {
    [p[i], p[j]]
}

#[inline]
fn in_box(u: [f64; 2], v: [f64; 2], x: [f64; 2]) -> bool {
    x[0] >= u[0].min(v[0])
        && x[0] <= u[0].max(v[0])
        && x[1] >= u[1].min(v[1])
        && x[1] <= u[1].max(v[1])
}

/// Closed 2D segment–segment intersection, exact.
pub fn segments_intersect_2d(p: [f64; 2], q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> bool {
    let d1 = orient2d(a, b, p);
    let d2 = orient2d(a, b, q);
    let d3 = orient2d(p, q, a);
    let d4 = orient2d(p, q, b);
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    (d1 == 0 && in_box(a, b, p))
        || (d2 == 0 && in_box(a, b, q))
        || (d3 == 0 && in_box(p, q, a))
        || (d4 == 0 && in_box(p, q, b))
}

/// Closed 2D segment–triangle intersection, exact (a degenerate triangle is its edges).
fn segment_triangle_2d(p: [f64; 2], q: [f64; 2], a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
    if segments_intersect_2d(p, q, a, b)
        || segments_intersect_2d(p, q, b, c)
        || segments_intersect_2d(p, q, c, a)
    {
        return true;
    }
    let o = orient2d(a, b, c);
    if o == 0 {
        return false;
    }
    orient2d(a, b, p) * o >= 0 && orient2d(b, c, p) * o >= 0 && orient2d(c, a, p) * o >= 0
}

/// Closed 3D segment–segment intersection, exact: coplanar and meeting in every
/// coordinate projection (one of which is one-to-one on a common plane).
pub fn segments_intersect_3d(p: P3, q: P3, a: P3, b: P3) -> bool {
    orient3d(p, q, a, b) == 0
        && PROJ
            .iter()
            .all(|&k| segments_intersect_2d(pr(&p, k), pr(&q, k), pr(&a, k), pr(&b, k)))
}

/// Whether `a, b, c` are exactly collinear (all three projected areas vanish).
fn collinear(a: &P3, b: &P3, c: &P3) -> bool {
    PROJ.iter()
        .all(|&k| orient2d(pr(a, k), pr(b, k), pr(c, k)) == 0)
}

/// Exact closed segment–triangle intersection test.
pub fn segment_triangle_intersect_exact(p: P3, q: P3, a: P3, b: P3, c: P3) -> bool {
    let op = orient3d(a, b, c, p);
    let oq = orient3d(a, b, c, q);
    if op * oq > 0 {
        return false;
    }
    if op != 0 || oq != 0 {
        // the segment meets the plane in one point, and the triangle is not degenerate
        // (otherwise every orientation against it would vanish)
        let s1 = orient3d(p, q, a, b);
        let s2 = orient3d(p, q, b, c);
        let s3 = orient3d(p, q, c, a);
        let any_pos = s1 > 0 || s2 > 0 || s3 > 0;
        let any_neg = s1 < 0 || s2 < 0 || s3 < 0;
        return !(any_pos && any_neg);
    }
    if collinear(&a, &b, &c) {
        return segments_intersect_3d(p, q, a, b)
            || segments_intersect_3d(p, q, b, c)
            || segments_intersect_3d(p, q, c, a);
    }
    // coplanar with a proper triangle: meeting in every projection ⇔ meeting in 3D
    PROJ.iter()
        .all(|&k| segment_triangle_2d(pr(&p, k), pr(&q, k), pr(&a, k), pr(&b, k), pr(&c, k)))
}

/// Unique undirected edges `(i, j)`, `i < j`, of the triangles, sorted.
pub fn unique_edges(triangles: &[[usize; 3]]) -> Vec<(usize, usize)> {
    let mut edges: Vec<(usize, usize)> = triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .filter(|(i, j)| i != j)
        .map(|(i, j)| (i.min(j), i.max(j)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

#[inline]
fn shares_vertex(e: (usize, usize), t: &[usize; 3]) -> bool {
    t.contains(&e.0) || t.contains(&e.1)
}

/// Number of pairs (mesh edge, triangle) that intersect (closed sets, exact predicates),
/// excluding pairs that share a vertex. Edges are the unique undirected triangle edges.
/// Uses a uniform grid over triangle bounding boxes.
pub fn count_edge_triangle_intersections(
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
) -> usize {
    if triangles.is_empty() {
        return 0;
    }
    let edges = unique_edges(triangles);

    // triangle bounding boxes and the grid's extent
    let mut boxes = Vec::with_capacity(triangles.len());
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut size_sum = 0.0;
    for t in triangles {
        let mut bl = [f64::INFINITY; 3];
        let mut bh = [f64::NEG_INFINITY; 3];
        for &v in t {
            for k in 0..3 {
                bl[k] = bl[k].min(positions[v][k]);
                bh[k] = bh[k].max(positions[v][k]);
            }
        }
        for k in 0..3 {
            lo[k] = lo[k].min(bl[k]);
            hi[k] = hi[k].max(bh[k]);
        }
        size_sum += (0..3).map(|k| bh[k] - bl[k]).fold(0.0, f64::max);
        boxes.push((bl, bh));
    }
    let mut h = size_sum / triangles.len() as f64;
    let max_extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    if h.is_nan() || h <= 0.0 || h.is_infinite() {
        h = if max_extent > 0.0 { max_extent } else { 1.0 };
    }
    let max_cells = 4 * triangles.len() + 1024;
    let dims = |h: f64| -> [usize; 3] {
        let mut n = [1usize; 3];
        for k in 0..3 {
            n[k] = (((hi[k] - lo[k]) / h).floor() as usize).saturating_add(1);
        }
        n
    };
    let mut n = dims(h);
    while n[0].saturating_mul(n[1]).saturating_mul(n[2]) > max_cells {
        h *= 1.5;
        n = dims(h);
    }
    let inv_h = 1.0 / h;
    // monotone cell coordinate: overlapping boxes always share a cell
    let cell = |x: f64, k: usize| -> usize { (((x - lo[k]) * inv_h) as usize).min(n[k] - 1) };
    let range = |bl: &[f64; 3], bh: &[f64; 3]| -> ([usize; 3], [usize; 3]) {
        (
            [cell(bl[0], 0), cell(bl[1], 1), cell(bl[2], 2)],
            [cell(bh[0], 0), cell(bh[1], 1), cell(bh[2], 2)],
        )
    };
    let index = |i: usize, j: usize, k: usize| (k * n[1] + j) * n[0] + i;

    // compressed cell → triangle lists
    let ncells = n[0] * n[1] * n[2];
    let mut start = vec![0u32; ncells + 1];
    for (bl, bh) in &boxes {
        let (c0, c1) = range(bl, bh);
        for k in c0[2]..=c1[2] {
            for j in c0[1]..=c1[1] {
                for i in c0[0]..=c1[0] {
                    start[index(i, j, k) + 1] += 1;
                }
            }
        }
    }
    for c in 0..ncells {
        start[c + 1] += start[c];
    }
    let mut fill = start.clone();
    let mut items = vec![0u32; start[ncells] as usize];
    for (ti, (bl, bh)) in boxes.iter().enumerate() {
        let (c0, c1) = range(bl, bh);
        for k in c0[2]..=c1[2] {
            for j in c0[1]..=c1[1] {
                for i in c0[0]..=c1[0] {
                    let c = index(i, j, k);
                    items[fill[c] as usize] = ti as u32;
                    fill[c] += 1;
                }
            }
        }
    }

    let mut stamp = vec![u32::MAX; triangles.len()];
    let mut count = 0;
    for (ei, &(u, v)) in edges.iter().enumerate() {
        let (p, q) = (positions[u], positions[v]);
        let el = [p[0].min(q[0]), p[1].min(q[1]), p[2].min(q[2])];
        let eh = [p[0].max(q[0]), p[1].max(q[1]), p[2].max(q[2])];
        let (c0, c1) = range(&el, &eh);
        for k in c0[2]..=c1[2] {
            for j in c0[1]..=c1[1] {
                for i in c0[0]..=c1[0] {
                    let c = index(i, j, k);
                    for &ti in &items[start[c] as usize..start[c + 1] as usize] {
                        let ti = ti as usize;
                        if stamp[ti] == ei as u32 {
                            continue;
                        }
                        stamp[ti] = ei as u32;
                        let (bl, bh) = &boxes[ti];
                        if (0..3).any(|d| el[d] > bh[d] || eh[d] < bl[d]) {
                            continue;
                        }
                        let t = &triangles[ti];
                        if shares_vertex((u, v), t) {
                            continue;
                        }
                        let [a, b, cc] = [positions[t[0]], positions[t[1]], positions[t[2]]];
                        if segment_triangle_intersect_exact(p, q, a, b, cc) {
                            count += 1;
                        }
                    }
                }
            }
        }
    }
    count
}

/// Brute-force reference for [`count_edge_triangle_intersections`]: every edge against every
/// triangle, no acceleration structure (for cross-checking on small meshes).
pub fn count_edge_triangle_intersections_brute(
    positions: &[[f64; 3]],
    triangles: &[[usize; 3]],
) -> usize {
    let edges = unique_edges(triangles);
    let mut count = 0;
    for &(u, v) in &edges {
        for t in triangles {
            if shares_vertex((u, v), t) {
                continue;
            }
            if segment_triangle_intersect_exact(
                positions[u],
                positions[v],
                positions[t[0]],
                positions[t[1]],
                positions[t[2]],
            ) {
                count += 1;
            }
        }
    }
    count
}
