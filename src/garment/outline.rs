//! Outline geometry: segment evaluation, signed area, arc lengths, orientation, and adaptive
//! flattening of an [`Outline`] into a closed polyline whose points remember the corner and
//! curve parameter they come from ([`FlatOutline`]), so that a mesher can resample any edge
//! between two corners by arc length.

use super::pattern::{Corner, Outline, Segment, P2};

/// Gauss–Legendre nodes and weights on [0, 1] (5 points: exact for polynomials of degree 9).
const GAUSS5: [(f64, f64); 5] = [
    (0.046_910_077_030_668, 0.118_463_442_528_095),
    (0.230_765_344_947_158, 0.239_314_335_249_683),
    (0.5, 0.284_444_444_444_444),
    (0.769_234_655_052_842, 0.239_314_335_249_683),
    (0.953_089_922_969_332, 0.118_463_442_528_095),
];

fn lerp(a: P2, b: P2, t: f64) -> P2 {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

impl Segment {
    /// The point at parameter `t` ∈ [0, 1] of this segment from `p0` to `p3`.
    pub fn point(&self, p0: P2, p3: P2, t: f64) -> P2 {
        match *self {
            Segment::Line => lerp(p0, p3, t),
            Segment::Cubic { c1, c2 } => {
                let u = 1.0 - t;
                let (b0, b1, b2, b3) = (u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t);
                [
                    b0 * p0[0] + b1 * c1[0] + b2 * c2[0] + b3 * p3[0],
                    b0 * p0[1] + b1 * c1[1] + b2 * c2[1] + b3 * p3[1],
                ]
            }
        }
    }

    /// The derivative d/dt at parameter `t` of this segment from `p0` to `p3`.
    pub fn derivative(&self, p0: P2, p3: P2, t: f64) -> P2 {
        match *self {
            Segment::Line => [p3[0] - p0[0], p3[1] - p0[1]],
            Segment::Cubic { c1, c2 } => {
                let u = 1.0 - t;
                let (a, b, c) = (3.0 * u * u, 6.0 * u * t, 3.0 * t * t);
                [
                    a * (c1[0] - p0[0]) + b * (c2[0] - c1[0]) + c * (p3[0] - c2[0]),
                    a * (c1[1] - p0[1]) + b * (c2[1] - c1[1]) + c * (p3[1] - c2[1]),
                ]
            }
        }
    }

    /// The same curve run backwards (from `p3` to `p0`).
    pub fn reversed(&self) -> Segment {
        match *self {
            Segment::Line => Segment::Line,
            Segment::Cubic { c1, c2 } => Segment::Cubic { c1: c2, c2: c1 },
        }
    }

    /// The segment with its control points mapped by `f` (an affine map keeps the curve exact).
    pub fn mapped(&self, f: impl Fn(P2) -> P2) -> Segment {
        match *self {
            Segment::Line => Segment::Line,
            Segment::Cubic { c1, c2 } => Segment::Cubic {
                c1: f(c1),
                c2: f(c2),
            },
        }
    }

    /// Arc length of this segment from `p0` to `p3` (m), to about 1e-9 relative.
    pub fn length(&self, p0: P2, p3: P2) -> f64 {
        match self {
            Segment::Line => dist(p0, p3),
            Segment::Cubic { .. } => {
                const PIECES: usize = 16;
                let mut total = 0.0;
                for k in 0..PIECES {
                    let (a, b) = (k as f64 / PIECES as f64, (k + 1) as f64 / PIECES as f64);
                    for (x, w) in GAUSS5 {
                        let d = self.derivative(p0, p3, a + (b - a) * x);
                        total += w * (b - a) * d[0].hypot(d[1]);
                    }
                }
                total
            }
        }
    }

    /// Twice the signed area swept from the origin by this segment: ∫ x dy − y dx.
    fn area2(&self, p0: P2, p3: P2) -> f64 {
        match self {
            Segment::Line => p0[0] * p3[1] - p3[0] * p0[1],
            // The integrand is a polynomial of degree 5: Gauss–Legendre is exact.
            Segment::Cubic { .. } => GAUSS5
                .iter()
                .map(|&(t, w)| {
                    let p = self.point(p0, p3, t);
                    let d = self.derivative(p0, p3, t);
                    w * (p[0] * d[1] - p[1] * d[0])
                })
                .sum(),
        }
    }
}

/// A point of a flattened outline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatPoint {
    /// Where the point is (m).
    pub at: P2,
    /// The corner whose segment the point lies on (the point is that corner when `t == 0`).
    pub corner: usize,
    /// Curve parameter on that segment, in [0, 1).
    pub t: f64,
    /// Arc length along the polyline from corner 0 (m).
    pub s: f64,
}

/// An outline flattened into a closed polyline (the last point joins the first).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FlatOutline {
    /// The polyline's points, counter-clockwise, starting at corner 0.
    pub points: Vec<FlatPoint>,
    /// For each corner, the index of its point in `points`.
    pub corner_points: Vec<usize>,
    /// Length of the closed polyline (m).
    pub perimeter: f64,
}

impl FlatOutline {
    /// Indices into `points` of the edge that runs forward from corner `from` to corner `to`,
    /// both ends included (`from == to`: the whole loop, back to `from`).
    pub fn edge_indices(&self, from: usize, to: usize) -> Vec<usize> {
        let n = self.points.len();
        let (a, b) = (self.corner_points[from], self.corner_points[to]);
        let count = if a == b { n } else { (b + n - a) % n };
        (0..=count).map(|k| (a + k) % n).collect()
    }

    /// The polyline of the edge from corner `from` to corner `to` (see [`Self::edge_indices`]).
    pub fn edge(&self, from: usize, to: usize) -> Vec<P2> {
        self.edge_indices(from, to)
            .into_iter()
            .map(|i| self.points[i].at)
            .collect()
    }

    /// Length of the polyline of an edge (m).
    pub fn edge_length(&self, from: usize, to: usize) -> f64 {
        let p = self.edge(from, to);
        p.windows(2).map(|w| dist(w[0], w[1])).sum()
    }

    /// `n + 1` points evenly spaced by arc length along the polyline of an edge, both corners
    /// included (`n ≥ 1`).
    pub fn resample_edge(&self, from: usize, to: usize, n: usize) -> Vec<P2> {
        let p = self.edge(from, to);
        let n = n.max(1);
        let mut cum = vec![0.0];
        for w in p.windows(2) {
            cum.push(cum.last().copied().unwrap_or(0.0) + dist(w[0], w[1]));
        }
        let total = cum.last().copied().unwrap_or(0.0);
        let mut out = Vec::with_capacity(n + 1);
        let mut k = 0;
        for i in 0..=n {
            if i == n {
                out.push(p[p.len() - 1]);
                break;
            }
            let s = total * i as f64 / n as f64;
            while k + 2 < cum.len() && cum[k + 1] < s {
                k += 1;
            }
            let len = cum[k + 1] - cum[k];
            let t = if len > 0.0 {
                ((s - cum[k]) / len).clamp(0.0, 1.0)
            } else {
                0.0
            };
            out.push(lerp(p[k], p[k + 1], t));
        }
        out
    }
}

impl Outline {
    /// The index of the corner called `name`.
    pub fn corner_index(&self, name: &str) -> Option<usize> {
        self.corners.iter().position(|c| c.name == name)
    }

    /// The point where corner `i`'s segment ends (the next corner).
    pub fn segment_end(&self, i: usize) -> P2 {
        self.corners[(i + 1) % self.corners.len()].at
    }

    /// Signed area (m²): positive when the outline runs counter-clockwise (y up).
    pub fn area(&self) -> f64 {
        let a2: f64 = (0..self.corners.len())
            .map(|i| {
                self.corners[i]
                    .segment
                    .area2(self.corners[i].at, self.segment_end(i))
            })
            .sum();
        0.5 * a2
    }

    /// Arc length of corner `i`'s segment (m).
    pub fn segment_length(&self, i: usize) -> f64 {
        self.corners[i]
            .segment
            .length(self.corners[i].at, self.segment_end(i))
    }

    /// Arc length of the edge running forward (counter-clockwise) from corner index `from` to
    /// corner index `to` (m); `from == to` gives the whole perimeter.
    pub fn edge_length(&self, from: usize, to: usize) -> f64 {
        let n = self.corners.len();
        if n == 0 {
            return 0.0;
        }
        let count = if from == to { n } else { (to + n - from) % n };
        (0..count)
            .map(|k| self.segment_length((from + k) % n))
            .sum()
    }

    /// The outline run the other way round, corner 0 kept first; each corner keeps its name.
    pub fn reversed(&self) -> Outline {
        let n = self.corners.len();
        let corners = (0..n)
            .map(|k| {
                let i = (n - k) % n; // 0, n-1, n-2, …, 1
                let prev = (i + n - 1) % n; // the segment arriving at i, run backwards
                Corner {
                    name: self.corners[i].name.clone(),
                    at: self.corners[i].at,
                    segment: self.corners[prev].segment.reversed(),
                }
            })
            .collect();
        Outline { corners }
    }

    /// Makes the outline counter-clockwise (reversing it if its area is negative); returns
    /// whether it was reversed.
    pub fn make_ccw(&mut self) -> bool {
        if self.area() < 0.0 {
            *self = self.reversed();
            true
        } else {
            false
        }
    }

    /// Flattens the outline into a closed polyline whose chords stay within `tol` (m) of the
    /// curves (adaptive subdivision of the Béziers; straight segments give their two ends).
    pub fn flatten(&self, tol: f64) -> FlatOutline {
        let tol = if tol.is_finite() && tol > 0.0 {
            tol
        } else {
            1e-4
        };
        let mut flat = FlatOutline::default();
        let mut s = 0.0;
        let mut last: Option<P2> = None;
        for (i, c) in self.corners.iter().enumerate() {
            let end = self.segment_end(i);
            let mut ts = vec![0.0];
            if let Segment::Cubic { c1, c2 } = c.segment {
                subdivide([c.at, c1, c2, end], 0.0, 1.0, tol, 0, &mut ts);
            }
            flat.corner_points.push(flat.points.len());
            for t in ts {
                let at = if t == 0.0 {
                    c.at
                } else {
                    c.segment.point(c.at, end, t)
                };
                if let Some(p) = last {
                    s += dist(p, at);
                }
                flat.points.push(FlatPoint {
                    at,
                    corner: i,
                    t,
                    s,
                });
                last = Some(at);
            }
        }
        if let (Some(p), Some(first)) = (last, flat.points.first()) {
            s += dist(p, first.at);
        }
        flat.perimeter = s;
        flat
    }
}

/// Appends to `ts` the interior parameters (in (t0, t1], excluding 1) of an adaptive
/// flattening of the cubic `b` restricted to [t0, t1].
fn subdivide(b: [P2; 4], t0: f64, t1: f64, tol: f64, depth: u32, ts: &mut Vec<f64>) {
    let flat = {
        let (p0, p3) = (b[0], b[3]);
        let d = [p3[0] - p0[0], p3[1] - p0[1]];
        let len = d[0].hypot(d[1]);
        let off = |p: P2| {
            if len > 1e-15 {
                ((p[0] - p0[0]) * d[1] - (p[1] - p0[1]) * d[0]).abs() / len
            } else {
                dist(p, p0)
            }
        };
        off(b[1]).max(off(b[2]))
    };
    // Control points within tol of the chord bound the curve within 3/4 tol of it.
    if flat <= tol || depth >= 18 {
        if t1 < 1.0 {
            ts.push(t1);
        }
        return;
    }
    let m01 = lerp(b[0], b[1], 0.5);
    let m12 = lerp(b[1], b[2], 0.5);
    let m23 = lerp(b[2], b[3], 0.5);
    let m012 = lerp(m01, m12, 0.5);
    let m123 = lerp(m12, m23, 0.5);
    let mid = lerp(m012, m123, 0.5);
    let tm = 0.5 * (t0 + t1);
    subdivide([b[0], m01, m012, mid], t0, tm, tol, depth + 1, ts);
    subdivide([mid, m123, m23, b[3]], tm, t1, tol, depth + 1, ts);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_with_arc() -> Outline {
        // Unit square whose top edge bulges upwards (a cubic).
        let k = 0.552_284_749_8;
        let c = |name: &str, at: P2, segment: Segment| Corner {
            name: name.into(),
            at,
            segment,
        };
        Outline {
            corners: vec![
                c("a", [0.0, 0.0], Segment::Line),
                c("b", [1.0, 0.0], Segment::Line),
                c(
                    "c",
                    [1.0, 1.0],
                    Segment::Cubic {
                        c1: [1.0, 1.0 + k * 0.5],
                        c2: [0.5 + k * 0.5, 1.5],
                    },
                ),
                c(
                    "d",
                    [0.5, 1.5],
                    Segment::Cubic {
                        c1: [0.5 - k * 0.5, 1.5],
                        c2: [0.0, 1.0 + k * 0.5],
                    },
                ),
                c("e", [0.0, 1.0], Segment::Line),
            ],
        }
    }

    #[test]
    fn area_length_and_flattening_agree_with_the_half_disc() {
        let o = square_with_arc();
        let half_disc = std::f64::consts::PI * 0.25 / 2.0;
        assert!((o.area() - (1.0 + half_disc)).abs() < 1e-3, "{}", o.area());
        let arc = o.edge_length(2, 4);
        assert!((arc - std::f64::consts::PI * 0.5).abs() < 1e-3, "{arc}");
        let f = o.flatten(1e-5);
        assert!((f.edge_length(2, 4) - arc).abs() < 1e-4);
        assert_eq!(f.points[f.corner_points[3]].at, [0.5, 1.5]);
        let r = f.resample_edge(2, 4, 10);
        assert_eq!(r.len(), 11);
        assert_eq!(r[0], [1.0, 1.0]);
        assert_eq!(r[10], [0.0, 1.0]);
        let rev = o.reversed();
        assert!((rev.area() + o.area()).abs() < 1e-12);
        assert_eq!(rev.corners[1].name, "e");
        assert!((rev.edge_length(1, 3) - arc).abs() < 1e-9);
    }
}
