//! Shapes of the SVG importer: SVG basic shapes as sub-paths, sub-paths as pattern outlines
//! (merged corners, straight cubics as lines), and the markings read off a piece: fold edge,
//! grain orientation, default grain, seam allowance.

use super::path::{PathSeg, SubPath};
use super::xml::Element;
use crate::garment::pattern::{Corner, Outline, Segment, P2};

pub(super) fn num_attr(el: &Element, name: &str) -> f64 {
    el.attr(name).and_then(length_number).unwrap_or(0.0)
}

pub(super) fn length_number(v: &str) -> Option<f64> {
    v.trim()
        .trim_end_matches("px")
        .trim()
        .parse()
        .ok()
        .filter(|x: &f64| x.is_finite())
}

pub(super) fn polygon(el: &Element, closed: bool) -> Result<Vec<SubPath>, String> {
    let v: Vec<f64> = el
        .attr("points")
        .unwrap_or("")
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .map_err(|_| format!("bad number '{s}' in points"))
        })
        .collect::<Result<_, _>>()?;
    if v.len() < 4 {
        return Ok(Vec::new());
    }
    let pts: Vec<P2> = v.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
    let mut segs: Vec<PathSeg> = pts[1..].iter().map(|&p| PathSeg::Line(p)).collect();
    if closed {
        segs.push(PathSeg::Line(pts[0]));
    }
    Ok(vec![SubPath {
        start: pts[0],
        segs,
        closed,
    }])
}

pub(super) fn rect(el: &Element) -> Vec<SubPath> {
    let (x, y, w, h) = (
        num_attr(el, "x"),
        num_attr(el, "y"),
        num_attr(el, "width"),
        num_attr(el, "height"),
    );
    if w <= 0.0 || h <= 0.0 {
        return Vec::new();
    }
    let segs = [[x + w, y], [x + w, y + h], [x, y + h], [x, y]]
        .map(PathSeg::Line)
        .to_vec();
    vec![SubPath {
        start: [x, y],
        segs,
        closed: true,
    }]
}

pub(super) fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

pub(super) fn extent(s: &SubPath) -> f64 {
    s.segs
        .iter()
        .map(|g| dist(s.start, g.end()))
        .fold(0.0, f64::max)
}

/// Distance from `p` to the line through `a` and `b` and the parameter of its foot.
pub(super) fn line_distance(p: P2, a: P2, b: P2) -> (f64, f64) {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    if l2 == 0.0 {
        return (dist(p, a), 0.0);
    }
    let t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2;
    (dist(p, [a[0] + t * d[0], a[1] + t * d[1]]), t)
}

/// The outline of a closed sub-path: one corner per segment start, short segments merged,
/// straight cubics turned into lines (corner names are filled in later).
pub(super) fn outline_of(s: &SubPath, merge: f64) -> Outline {
    let mut corners: Vec<Corner> = Vec::new();
    let mut at = s.start;
    let mut segs = s.segs.clone();
    // A path closed without Z repeats its start point: that last segment is the closing one.
    if !s.closed && dist(s.end(), s.start) <= merge {
        if let Some(last) = segs.last_mut() {
            *last = match *last {
                PathSeg::Line(_) => PathSeg::Line(s.start),
                PathSeg::Cubic(a, b, _) => PathSeg::Cubic(a, b, s.start),
            };
        }
    }
    for seg in &segs {
        let end = seg.end();
        if dist(at, end) <= merge {
            continue; // a degenerate segment: the corners merge
        }
        let segment = match *seg {
            PathSeg::Line(_) => Segment::Line,
            PathSeg::Cubic(c1, c2, _) => {
                let straight = [c1, c2].iter().all(|&c| {
                    let (d, t) = line_distance(c, at, end);
                    d <= merge && (-1e-9..=1.0 + 1e-9).contains(&t)
                });
                if straight {
                    Segment::Line
                } else {
                    Segment::Cubic { c1, c2 }
                }
            }
        };
        corners.push(Corner {
            name: String::new(),
            at,
            segment,
        });
        at = end;
    }
    Outline { corners }
}

/// The corner whose straight segment lies on the line through `a` and `b` (the longest one
/// if several do), within 0.5 mm.
pub(super) fn fold_corner(outline: &Outline, a: P2, b: P2) -> Option<String> {
    let n = outline.corners.len();
    (0..n)
        .filter(|&i| outline.corners[i].segment == Segment::Line)
        .filter(|&i| {
            let (p, q) = (outline.corners[i].at, outline.corners[(i + 1) % n].at);
            line_distance(p, a, b).0 < 5e-4 && line_distance(q, a, b).0 < 5e-4
        })
        .max_by(|&i, &j| {
            outline
                .segment_length(i)
                .total_cmp(&outline.segment_length(j))
        })
        .map(|i| outline.corners[i].name.clone())
}

pub(super) fn orient_up((a, b): (P2, P2)) -> (P2, P2) {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    if dy < 0.0 || (dy.abs() <= 1e-9 * dx.abs().max(1e-12) && dx < 0.0) {
        (b, a)
    } else {
        (a, b)
    }
}

pub(super) fn default_grain(outline: &Outline) -> (P2, P2) {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for c in &outline.corners {
        for k in 0..2 {
            lo[k] = lo[k].min(c.at[k]);
            hi[k] = hi[k].max(c.at[k]);
        }
    }
    let (cx, cy, h) = (
        (lo[0] + hi[0]) / 2.0,
        (lo[1] + hi[1]) / 2.0,
        (hi[1] - lo[1]).max(1e-3),
    );
    ([cx, cy - h / 4.0], [cx, cy + h / 4.0])
}

/// Median distance (0.1 mm steps) from the outline of the seam-allowance points that are off
/// the outline; `None` without such points.
pub(super) fn infer_allowance(outline: &Outline, points: &[P2]) -> Option<f64> {
    let flat = outline.flatten(1e-5);
    let n = flat.points.len();
    let mut d: Vec<f64> = points
        .iter()
        .map(|&p| {
            (0..n)
                .map(|i| segment_distance(p, flat.points[i].at, flat.points[(i + 1) % n].at))
                .fold(f64::MAX, f64::min)
        })
        .filter(|&d| d > 5e-4)
        .collect();
    if d.is_empty() {
        return None;
    }
    d.sort_by(f64::total_cmp);
    Some((d[(d.len() - 1) / 2] * 1e4).round() / 1e4)
}

pub(super) fn segment_distance(p: P2, a: P2, b: P2) -> f64 {
    let (_, t) = line_distance(p, a, b);
    let t = t.clamp(0.0, 1.0);
    dist(p, [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])])
}
