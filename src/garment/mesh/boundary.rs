//! Boundary sampling for meshing ([`crate::garment::mesh`]): the outline of every piece cut into boundary
//! vertices at the target edge length, with the two edges of each seam sampled at the same
//! arc-length fractions (corner to corner where both edges have corners at nearly the same
//! place) so that their vertices pair one to one.
//!
//! Owns its own Bézier evaluation and arc-length parameterisation (dense chord tables), the
//! planning of seam fractions, and the check that a sampled outline is a simple polygon.

use crate::garment::error::PatternError;
use crate::garment::pattern::{Pattern, Piece, Segment, P2};

/// Chords per cubic in the arc-length table.
const TABLE: usize = 512;
/// A fraction this close (relative to the edge length) to a corner is that corner.
const SAME: f64 = 1e-9;

/// One outline segment with an arc-length parameterisation.
pub(super) struct Curve {
    p: [P2; 4],
    line: bool,
    /// Arc length at t = i / TABLE (cubics only).
    cum: Vec<f64>,
    pub length: f64,
}

fn lerp(a: P2, b: P2, t: f64) -> P2 {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The cubic Bézier with control points `p` at parameter `t`.
pub(super) fn bezier(p: &[P2; 4], t: f64) -> P2 {
    let s = 1.0 - t;
    let (a, b, c, d) = (s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t);
    [
        a * p[0][0] + b * p[1][0] + c * p[2][0] + d * p[3][0],
        a * p[0][1] + b * p[1][1] + c * p[2][1] + d * p[3][1],
    ]
}

impl Curve {
    /// The segment leaving `from` with shape `seg` and ending at `to`.
    pub fn new(from: P2, seg: &Segment, to: P2) -> Self {
        match *seg {
            Segment::Line => Curve {
                p: [from, from, to, to],
                line: true,
                cum: Vec::new(),
                length: dist(from, to),
            },
            Segment::Cubic { c1, c2 } => {
                let p = [from, c1, c2, to];
                let mut cum = Vec::with_capacity(TABLE + 1);
                cum.push(0.0);
                let mut prev = from;
                for i in 1..=TABLE {
                    let q = bezier(&p, i as f64 / TABLE as f64);
                    cum.push(cum[i - 1] + dist(prev, q));
                    prev = q;
                }
                let length = cum[TABLE];
                Curve {
                    p,
                    line: false,
                    cum,
                    length,
                }
            }
        }
    }

    /// The point at arc length `s` from the start (0 ≤ s ≤ length).
    pub fn point_at(&self, s: f64) -> P2 {
        if self.line {
            return lerp(self.p[0], self.p[3], s / self.length);
        }
        let i = self.cum.partition_point(|&c| c <= s).clamp(1, TABLE) - 1;
        let span = self.cum[i + 1] - self.cum[i];
        let f = if span > 0.0 {
            ((s - self.cum[i]) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        bezier(&self.p, (i as f64 + f) / TABLE as f64)
    }
}

/// A piece's outline sampled into a closed loop of boundary points, counter-clockwise.
pub(super) struct PieceBoundary {
    /// The boundary points (drawing coordinates, m), starting at corner 0.
    pub points: Vec<P2>,
    /// Loop index of each corner, in outline order.
    pub corners: Vec<usize>,
}

/// The boundary sampling of a whole pattern.
pub(super) struct Plan {
    /// Per piece.
    pub boundaries: Vec<PieceBoundary>,
    /// Per seam.
    pub seams: Vec<SeamPlan>,
}

/// The boundary vertices of one seam.
pub(super) struct SeamPlan {
    /// The pieces of edges a and b.
    pub pieces: (usize, usize),
    /// Pairs of loop indices (on a's piece, on b's piece), from a.from to a.to.
    pub pairs: Vec<(usize, usize)>,
}

/// The name the errors give the pattern.
pub(super) fn source_name(pattern: &Pattern) -> String {
    if pattern.source.is_empty() {
        pattern.name.clone()
    } else {
        pattern.source.clone()
    }
}

/// A seam edge resolved to outline segments.
struct EdgePath {
    piece: usize,
    from: usize,
    /// The segments it runs along, in order.
    segs: Vec<usize>,
    /// Arc length at the start of each segment, and the total at the end.
    cum: Vec<f64>,
}

/// Where a fraction of an edge falls: on a corner, or inside a segment at an arc length.
enum Loc {
    Corner(usize),
    On(usize, f64),
}

impl EdgePath {
    fn length(&self) -> f64 {
        *self.cum.last().unwrap()
    }

    fn locate(&self, f: f64, n_corners: usize) -> Loc {
        let len = self.length();
        let s = f * len;
        for (k, &c) in self.cum.iter().enumerate() {
            if (s - c).abs() <= 2.0 * SAME * len {
                return Loc::Corner((self.from + k) % n_corners);
            }
        }
        let i = self.cum.partition_point(|&c| c < s) - 1;
        Loc::On(self.segs[i], s - self.cum[i])
    }

    /// The fractions of the corners strictly inside the edge.
    fn corner_fractions(&self) -> impl Iterator<Item = f64> + '_ {
        let len = self.length();
        self.cum[1..self.cum.len() - 1].iter().map(move |c| c / len)
    }
}

fn corner_index(piece: &Piece, name: &str) -> Option<usize> {
    piece.outline.corners.iter().position(|c| c.name == name)
}

/// Samples every piece's outline at edge length `h`, seams first (see [`seam_fractions`]),
/// the remaining segments uniformly; checks each loop is a simple CCW polygon.
pub(super) fn plan(pattern: &Pattern, curves: &[Vec<Curve>], h: f64) -> Result<Plan, PatternError> {
    let src = source_name(pattern);
    let seam_err = |seam: &str, message: String| PatternError::Seam {
        source_name: src.clone(),
        seam: seam.to_string(),
        message,
    };
    // per piece, per segment: the arc lengths of the points inside it, and which seam owns it
    let mut inner: Vec<Vec<Vec<f64>>> = curves.iter().map(|c| vec![Vec::new(); c.len()]).collect();
    let mut owner: Vec<Vec<Option<usize>>> = curves.iter().map(|c| vec![None; c.len()]).collect();
    let mut seam_plans = Vec::with_capacity(pattern.seams.len());
    for (si, seam) in pattern.seams.iter().enumerate() {
        let mut paths = Vec::with_capacity(2);
        for e in [&seam.a, &seam.b] {
            let Some(p) = pattern.pieces.iter().position(|q| q.name == e.piece) else {
                return Err(seam_err(&seam.name, format!("no piece '{}'", e.piece)));
            };
            let piece = &pattern.pieces[p];
            let corner = |name: &str| {
                corner_index(piece, name).ok_or_else(|| {
                    seam_err(
                        &seam.name,
                        format!("piece '{}' has no corner '{name}'", piece.name),
                    )
                })
            };
            let (from, to) = (corner(&e.from)?, corner(&e.to)?);
            if from == to {
                return Err(seam_err(
                    &seam.name,
                    format!("edge of piece '{}' from '{}' to itself", piece.name, e.from),
                ));
            }
            let n = curves[p].len();
            let mut path = EdgePath {
                piece: p,
                from,
                segs: Vec::new(),
                cum: vec![0.0],
            };
            let mut j = from;
            while j != to {
                if let Some(other) = owner[p][j] {
                    return Err(seam_err(
                        &seam.name,
                        format!(
                            "edge {}→{} of piece '{}' overlaps seam '{}'",
                            e.from, e.to, piece.name, pattern.seams[other].name
                        ),
                    ));
                }
                owner[p][j] = Some(si);
                path.segs.push(j);
                path.cum
                    .push(path.cum.last().unwrap() + curves[p][j].length);
                j = (j + 1) % n;
            }
            paths.push(path);
        }
        let (b, a) = (paths.pop().unwrap(), paths.pop().unwrap());
        // b's fraction g meets a's fraction f = g (aligned) or 1 - g
        let to_a = |g: f64| if seam.aligned { g } else { 1.0 - g };
        let fractions = seam_fractions(
            a.corner_fractions().collect(),
            b.corner_fractions().map(to_a).collect(),
            a.length(),
            b.length(),
            h,
        );
        for &(f, g) in &fractions {
            for (path, x) in [(&a, f), (&b, to_a(g))] {
                if let Loc::On(j, s) = path.locate(x, curves[path.piece].len()) {
                    inner[path.piece][j].push(s);
                }
            }
        }
        seam_plans.push((a, b, fractions, seam.aligned));
    }
    // the segments no seam covers, uniformly
    for (p, segs) in curves.iter().enumerate() {
        for (j, c) in segs.iter().enumerate() {
            if owner[p][j].is_none() {
                let k = (c.length / h).round().max(1.0) as usize;
                inner[p][j].extend((1..k).map(|i| c.length * i as f64 / k as f64));
            }
        }
    }
    // the loops
    let mut boundaries = Vec::with_capacity(curves.len());
    let mut first = Vec::with_capacity(curves.len()); // per piece, per segment: loop index of its first inner point
    for (p, segs) in curves.iter().enumerate() {
        let mut points = Vec::new();
        let mut corners = Vec::with_capacity(segs.len());
        let mut starts = Vec::with_capacity(segs.len());
        for (j, c) in segs.iter().enumerate() {
            corners.push(points.len());
            points.push(pattern.pieces[p].outline.corners[j].at);
            let list = &mut inner[p][j];
            list.sort_by(f64::total_cmp);
            starts.push(points.len());
            points.extend(list.iter().map(|&s| c.point_at(s)));
        }
        check_simple(&points, &corners, &pattern.pieces[p], &src)?;
        boundaries.push(PieceBoundary { points, corners });
        first.push(starts);
    }
    let index = |path: &EdgePath, g: f64| -> usize {
        let p = path.piece;
        match path.locate(g, curves[p].len()) {
            Loc::Corner(k) => boundaries[p].corners[k],
            Loc::On(j, s) => first[p][j] + inner[p][j].partition_point(|&x| x < s),
        }
    };
    let seams = seam_plans
        .iter()
        .map(|(a, b, fractions, aligned)| SeamPlan {
            pieces: (a.piece, b.piece),
            pairs: fractions
                .iter()
                .map(|&(f, g)| (index(a, f), index(b, if *aligned { g } else { 1.0 - g })))
                .collect(),
        })
        .collect();
    Ok(Plan { boundaries, seams })
}

/// The vertices of a seam as pairs of fractions (on edge a, on edge b measured in a's
/// direction), from (0, 0) to (1, 1), given the fractions of the corners inside each edge.
///
/// Every corner is a vertex on its own edge; it meets the point at the same fraction on the
/// other edge, unless a corner of the other edge lies within half an edge length (arc length)
/// of it: then the two corners meet each other, so that matching corners drawn at slightly
/// different fractions do not leave a sliver. Between these fixed pairs, both edges are cut
/// into the same number of pieces (from the longer side and `h`), at equal fractions of the
/// span; with no corners inside, this is equal arc-length fractions over the whole seam.
fn seam_fractions(ca: Vec<f64>, cb: Vec<f64>, la: f64, lb: f64, h: f64) -> Vec<(f64, f64)> {
    let mut marks: Vec<(f64, bool)> = ca.into_iter().map(|f| (f, true)).collect();
    marks.extend(cb.into_iter().map(|g| (g, false)));
    marks.sort_by(|x, y| x.0.total_cmp(&y.0).then(y.1.cmp(&x.1)));
    let tol = 0.5 * h / la.max(lb);
    let mut fixed = vec![(0.0, 0.0)];
    let mut i = 0;
    while i < marks.len() {
        let (x, on_a) = marks[i];
        match marks.get(i + 1) {
            Some(&(y, next_on_a)) if next_on_a != on_a && y - x < tol => {
                fixed.push(if on_a { (x, y) } else { (y, x) });
                i += 2;
            }
            _ => {
                fixed.push((x, x));
                i += 1;
            }
        }
    }
    fixed.push((1.0, 1.0));
    let mut out = vec![(0.0, 0.0)];
    for w in fixed.windows(2) {
        let ((f0, g0), (f1, g1)) = (w[0], w[1]);
        let span = ((f1 - f0) * la).max((g1 - g0) * lb);
        let mut k = (span / h).round().max(1.0) as usize;
        if fixed.len() == 2 {
            k = k.max(2);
        }
        out.extend((1..k).map(|i| {
            let t = i as f64 / k as f64;
            (f0 + (f1 - f0) * t, g0 + (g1 - g0) * t)
        }));
        out.push((f1, g1));
    }
    out
}

/// Twice the signed area of a closed polygon (shoelace).
pub(super) fn signed_area2(points: &[P2]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

fn orient(a: P2, b: P2, c: P2) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Whether closed segments `ab` and `cd` share a point.
fn segments_meet(a: P2, b: P2, c: P2, d: P2) -> bool {
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return true;
    }
    let on = |p: P2, q: P2, r: P2, o: f64| {
        o == 0.0
            && r[0] >= p[0].min(q[0])
            && r[0] <= p[0].max(q[0])
            && r[1] >= p[1].min(q[1])
            && r[1] <= p[1].max(q[1])
    };
    on(c, d, a, d1) || on(c, d, b, d2) || on(a, b, c, d3) || on(a, b, d, d4)
}

/// Checks a sampled outline: at least three points, counter-clockwise, no two non-adjacent
/// sides meeting and no adjacent sides folding back on each other.
fn check_simple(
    points: &[P2],
    corners: &[usize],
    piece: &Piece,
    src: &str,
) -> Result<(), PatternError> {
    let err = |message: String| PatternError::Piece {
        source_name: src.to_string(),
        piece: piece.name.clone(),
        message,
    };
    let n = points.len();
    if n < 3 {
        return Err(err(format!("outline has only {n} boundary points")));
    }
    if points.iter().flatten().any(|c| !c.is_finite()) {
        return Err(err("outline has a non-finite coordinate".into()));
    }
    if signed_area2(points) <= 0.0 {
        return Err(err(
            "outline is not counter-clockwise (or has no area)".into()
        ));
    }
    // sweep over the sides sorted by their lowest x
    let side = |i: usize| (points[i], points[(i + 1) % n]);
    let mut order: Vec<usize> = (0..n).collect();
    let xmin = |i: usize| side(i).0[0].min(side(i).1[0]);
    order.sort_by(|&i, &j| xmin(i).total_cmp(&xmin(j)).then(i.cmp(&j)));
    for (k, &i) in order.iter().enumerate() {
        let (a, b) = side(i);
        let xmax = a[0].max(b[0]);
        for &j in &order[k + 1..] {
            if xmin(j) > xmax {
                break;
            }
            let (c, d) = side(j);
            let adjacent = (i + 1) % n == j || (j + 1) % n == i;
            let meet = if adjacent {
                // adjacent sides share one end; they must not overlap beyond it
                let (p, q, r) = if (i + 1) % n == j {
                    (a, b, d)
                } else {
                    (c, d, b)
                };
                orient(p, q, r) == 0.0
                    && (r[0] - q[0]) * (p[0] - q[0]) + (r[1] - q[1]) * (p[1] - q[1]) > 0.0
            } else {
                segments_meet(a, b, c, d)
            };
            if meet {
                // name the corners whose segments the two sides belong to
                let name = |s: usize| {
                    let k = corners.partition_point(|&c| c <= s) - 1;
                    &piece.outline.corners[k].name
                };
                return Err(err(format!(
                    "outline intersects itself: the segment after corner '{}' meets the \
                     segment after corner '{}' (near ({:.4}, {:.4}))",
                    name(i.min(j)),
                    name(i.max(j)),
                    c[0],
                    c[1]
                )));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_length_of_a_straight_cubic_is_its_chord() {
        let c = Curve::new(
            [0.0, 0.0],
            &Segment::Cubic {
                c1: [0.1, 0.0],
                c2: [0.2, 0.0],
            },
            [0.3, 0.0],
        );
        assert!((c.length - 0.3).abs() < 1e-12);
        let p = c.point_at(0.1);
        assert!((p[0] - 0.1).abs() < 1e-9 && p[1] == 0.0);
    }

    #[test]
    fn seam_fractions_are_uniform_without_corners_and_merge_near_corners() {
        let f = seam_fractions(vec![], vec![], 1.0, 0.8, 0.1);
        assert_eq!(f.len(), 11);
        assert!(f.iter().all(|&(a, b)| a == b));
        // a corner at 0.5 on a, one at 0.52 on b (a's direction): they meet
        let f = seam_fractions(vec![0.5], vec![0.52], 1.0, 1.0, 0.1);
        assert!(f.contains(&(0.5, 0.52)));
        // far apart: each meets a plain point of the other edge
        let f = seam_fractions(vec![0.3], vec![0.6], 1.0, 1.0, 0.1);
        assert!(f.contains(&(0.3, 0.3)) && f.contains(&(0.6, 0.6)));
        assert!(f.windows(2).all(|w| w[1].0 > w[0].0 && w[1].1 > w[0].1));
    }
}
