//! Checks of a [`Pattern`]: pieces that can be meshed and seams that can be sewn.
//!
//! A piece needs at least three corners with unique names, finite coordinates within
//! ±[`MAX_COORDINATE`] m, an outline (control points included) that fits a [`MAX_PIECE_SIZE`]
//! square, a seam allowance of at most [`MAX_SEAM_ALLOWANCE`], a grain line
//! of non-zero length, a counter-clockwise outline of positive area (importers turn clockwise
//! outlines round, so a clockwise one here is a bug of whoever built the pattern) that does
//! not cross itself (tested on the outline flattened to [`CROSSING_TOLERANCE`]), edges of
//! non-zero length, a fold corner (if any) whose segment is straight, and a placement (if
//! any) whose anchor exists and whose level is a known landmark.
//!
//! Seams are checked against the [expanded](Pattern::expanded) pattern: their pieces and
//! corners exist, the two edges have the same arc length within
//! max([`SEAM_LENGTH_TOLERANCE`], [`SEAM_LENGTH_RELATIVE`] × the longer one), and no two seams
//! sew overlapping parts of the same piece edge.

use std::collections::BTreeMap;

use super::error::PatternError;
use super::pattern::{Corner, EdgeRef, Outline, Pattern, Piece, Segment, P2};

/// Flattening tolerance for the self-intersection test (m).
pub const CROSSING_TOLERANCE: f64 = 1e-4;
/// Absolute tolerance on the difference of the two edge lengths of a seam (m).
pub const SEAM_LENGTH_TOLERANCE: f64 = 2e-3;
/// Relative tolerance on the difference of the two edge lengths of a seam.
pub const SEAM_LENGTH_RELATIVE: f64 = 0.01;
/// The body landmarks a [`Placement`](super::pattern::Placement) may name.
pub const LEVELS: [&str; 8] = [
    "neck", "shoulder", "chest", "waist", "hip", "crotch", "knee", "ankle",
];

/// Largest piece (m): its outline, control points included, fits a 10 m × 10 m square. No
/// garment piece comes near it (a floor-length circle skirt is under 3 m across); a bigger one
/// is a unit mistake (a pattern in mm read as m) or a broken file.
pub const MAX_PIECE_SIZE: f64 = 10.0;
/// Largest coordinate magnitude (m) of any point of a pattern (corners, control points, grain
/// line, notches): pieces laid out on a sheet stay well within ±1 km.
pub const MAX_COORDINATE: f64 = 1000.0;
/// Largest seam allowance (m).
pub const MAX_SEAM_ALLOWANCE: f64 = 1.0;
/// Most corners on one piece's outline: far above any drafted or digitised piece (a few
/// hundred), low enough that the crossing test stays within a second on any outline.
pub const MAX_CORNERS: usize = 20_000;

/// Smallest accepted outline area (m²) and edge or grain length (m).
const MIN_AREA: f64 = 1e-6;
const MIN_LENGTH: f64 = 1e-6;

impl Pattern {
    /// Checks the pieces, then the seams against the expanded pattern (see the module doc).
    pub fn validate(&self) -> Result<(), PatternError> {
        let source = self.source_name();
        check_pieces(&self.pieces, &source)?;
        let needs_expansion = self
            .pieces
            .iter()
            .any(|p| p.fold.is_some() || p.copies == super::pattern::Copies::Pair);
        if needs_expansion {
            let expanded = self.expanded()?;
            check_pieces(&expanded.pieces, &source)?;
            check_seams(&expanded, &source)
        } else {
            check_seams(self, &source)
        }
    }

    /// The pattern's origin for error messages (`source`, else `name`, else `<pattern>`).
    pub fn source_name(&self) -> String {
        if !self.source.is_empty() {
            self.source.clone()
        } else if !self.name.is_empty() {
            self.name.clone()
        } else {
            "<pattern>".into()
        }
    }
}

impl Piece {
    /// Checks this piece alone (see the module doc); `source` names the file in errors.
    pub fn validate(&self, source: &str) -> Result<(), PatternError> {
        let err = |message: String| PatternError::Piece {
            source_name: source.to_string(),
            piece: self.name.clone(),
            message,
        };
        if self.name.is_empty() {
            return Err(err("the piece has no name".into()));
        }
        let corners = &self.outline.corners;
        if corners.len() < 3 {
            return Err(err(format!(
                "the outline has {} corners; at least 3 are needed",
                corners.len()
            )));
        }
        if corners.len() > MAX_CORNERS {
            return Err(err(format!(
                "the outline has {} corners, over the limit of {MAX_CORNERS} per piece",
                corners.len()
            )));
        }
        let finite = |p: &P2| p.iter().all(|c| c.is_finite() && c.abs() <= MAX_COORDINATE);
        let mut names = BTreeMap::new();
        for (i, c) in corners.iter().enumerate() {
            if c.name.is_empty() {
                return Err(err(format!("corner {i} has no name")));
            }
            if let Some(j) = names.insert(c.name.as_str(), i) {
                return Err(err(format!(
                    "corners {j} and {i} are both called '{}'",
                    c.name
                )));
            }
            let controls_finite = match &c.segment {
                Segment::Line => true,
                Segment::Cubic { c1, c2 } => finite(c1) && finite(c2),
            };
            if !finite(&c.at) || !controls_finite {
                return Err(err(format!(
                    "corner '{}' (at {:?}) has a coordinate that is not a finite number within ±{MAX_COORDINATE} m",
                    c.name, c.at
                )));
            }
        }
        let (w, h) = extent(corners);
        if w > MAX_PIECE_SIZE || h > MAX_PIECE_SIZE {
            return Err(err(format!(
                "the piece spans {w:.3} m × {h:.3} m, over the largest accepted piece size of {MAX_PIECE_SIZE} m (a pattern in mm read as metres?)"
            )));
        }
        if !self.grain.iter().all(finite) || dist(self.grain[0], self.grain[1]) < MIN_LENGTH {
            return Err(err(format!(
                "the grain line {:?} → {:?} is degenerate (zero length, or not finite within ±{MAX_COORDINATE} m)",
                self.grain[0], self.grain[1]
            )));
        }
        if !(self.seam_allowance.is_finite()
            && (0.0..=MAX_SEAM_ALLOWANCE).contains(&self.seam_allowance))
        {
            return Err(err(format!(
                "seam allowance {} m is not a number in [0, {MAX_SEAM_ALLOWANCE}] m",
                self.seam_allowance
            )));
        }
        if let Some(bad) = self.notches.iter().find(|p| !finite(p)) {
            return Err(err(format!(
                "notch {bad:?} is not finite within ±{MAX_COORDINATE} m"
            )));
        }
        for i in 0..corners.len() {
            if self.outline.segment_length(i) < MIN_LENGTH {
                return Err(err(format!(
                    "edge {} has zero length",
                    edge_name(&self.outline, i)
                )));
            }
        }
        let area = self.outline.area();
        if area.is_nan() || area < MIN_AREA {
            let why = if area < 0.0 {
                "runs clockwise"
            } else {
                "encloses no area"
            };
            return Err(err(format!("the outline {why} (signed area {area:.3e} m²); it must run counter-clockwise, y up")));
        }
        if let Some((a, b)) = self_crossing(&self.outline, CROSSING_TOLERANCE) {
            return Err(err(format!(
                "the outline crosses itself: edge {} crosses edge {}",
                edge_name(&self.outline, a),
                edge_name(&self.outline, b)
            )));
        }
        if let Some(fold) = &self.fold {
            let i = self
                .outline
                .corner_index(fold)
                .ok_or_else(|| err(format!("fold corner '{fold}' does not exist")))?;
            if corners[i].segment != Segment::Line {
                return Err(err(format!(
                    "fold edge {} is not a straight line",
                    edge_name(&self.outline, i)
                )));
            }
        }
        if let Some(pl) = &self.placement {
            if self.outline.corner_index(&pl.anchor).is_none() {
                return Err(err(format!(
                    "placement anchor corner '{}' does not exist",
                    pl.anchor
                )));
            }
            if !LEVELS.contains(&pl.level.as_str()) {
                return Err(err(format!(
                    "placement level '{}' is not one of {}",
                    pl.level,
                    LEVELS.join(", ")
                )));
            }
            if !pl.x.is_finite() || !pl.dz.is_finite() {
                return Err(err("placement x or dz is not a finite number".into()));
            }
        }
        Ok(())
    }
}

/// The name `from→to` of the edge that leaves corner `i`.
pub(crate) fn edge_name(outline: &Outline, i: usize) -> String {
    let n = outline.corners.len();
    format!(
        "{}→{}",
        outline.corners[i].name,
        outline.corners[(i + 1) % n].name
    )
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Width and height (m) of the box around the corners and control points.
fn extent(corners: &[Corner]) -> (f64, f64) {
    let points = corners.iter().flat_map(|c| {
        let controls = match &c.segment {
            Segment::Line => [c.at, c.at],
            Segment::Cubic { c1, c2 } => [*c1, *c2],
        };
        std::iter::once(c.at).chain(controls)
    });
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (hi[0] - lo[0], hi[1] - lo[1])
}

fn check_pieces(pieces: &[Piece], source: &str) -> Result<(), PatternError> {
    let mut names = BTreeMap::new();
    for p in pieces {
        if names.insert(p.name.as_str(), ()).is_some() {
            return Err(PatternError::Piece {
                source_name: source.to_string(),
                piece: p.name.clone(),
                message: "two pieces have this name".into(),
            });
        }
        p.validate(source)?;
    }
    Ok(())
}

/// A seam edge resolved to indices: piece index, from, to.
type Resolved = (usize, usize, usize);

fn check_seams(pattern: &Pattern, source: &str) -> Result<(), PatternError> {
    let mut seam_names = BTreeMap::new();
    // For each piece, which seam sews each of its segments.
    let mut used: Vec<Vec<Option<&str>>> = pattern
        .pieces
        .iter()
        .map(|p| vec![None; p.outline.corners.len()])
        .collect();
    for seam in &pattern.seams {
        let err = |message: String| PatternError::Seam {
            source_name: source.to_string(),
            seam: seam.name.clone(),
            message,
        };
        if seam.name.is_empty() {
            return Err(err("a seam has no name".into()));
        }
        if seam_names.insert(seam.name.as_str(), ()).is_some() {
            return Err(err("two seams have this name".into()));
        }
        let resolve = |e: &EdgeRef| -> Result<Resolved, PatternError> {
            let pi = pattern
                .pieces
                .iter()
                .position(|p| p.name == e.piece)
                .ok_or_else(|| {
                    let known: Vec<&str> = pattern.pieces.iter().map(|p| p.name.as_str()).collect();
                    err(format!(
                        "edge {}.{}→{}: piece '{}' does not exist (pieces after expansion: {})",
                        e.piece,
                        e.from,
                        e.to,
                        e.piece,
                        known.join(", ")
                    ))
                })?;
            let o = &pattern.pieces[pi].outline;
            let corner = |name: &str| {
                o.corner_index(name).ok_or_else(|| {
                    err(format!(
                        "edge {}.{}→{}: piece '{}' has no corner '{name}'",
                        e.piece, e.from, e.to, e.piece
                    ))
                })
            };
            let (f, t) = (corner(&e.from)?, corner(&e.to)?);
            if f == t {
                return Err(err(format!(
                    "edge {}.{}→{} starts and ends at the same corner",
                    e.piece, e.from, e.to
                )));
            }
            Ok((pi, f, t))
        };
        let (ra, rb) = (resolve(&seam.a)?, resolve(&seam.b)?);
        let la = pattern.pieces[ra.0].outline.edge_length(ra.1, ra.2);
        let lb = pattern.pieces[rb.0].outline.edge_length(rb.1, rb.2);
        let tolerance = SEAM_LENGTH_TOLERANCE.max(SEAM_LENGTH_RELATIVE * la.max(lb));
        if (la - lb).abs() > tolerance {
            return Err(err(format!(
                "edge {}.{}→{} ({:.1} mm) and edge {}.{}→{} ({:.1} mm) differ by {:.1} mm (tolerance {:.1} mm)",
                seam.a.piece,
                seam.a.from,
                seam.a.to,
                la * 1e3,
                seam.b.piece,
                seam.b.from,
                seam.b.to,
                lb * 1e3,
                (la - lb).abs() * 1e3,
                tolerance * 1e3
            )));
        }
        for (r, e) in [(ra, &seam.a), (rb, &seam.b)] {
            let n = used[r.0].len();
            let mut k = r.1;
            while k != r.2 {
                if let Some(other) = used[r.0][k] {
                    return Err(err(format!(
                        "edge {}.{}→{} overlaps seam '{other}' on edge {}",
                        e.piece,
                        e.from,
                        e.to,
                        edge_name(&pattern.pieces[r.0].outline, k)
                    )));
                }
                used[r.0][k] = Some(seam.name.as_str());
                k = (k + 1) % n;
            }
        }
    }
    Ok(())
}

fn orient(a: P2, b: P2, c: P2) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn on_segment(a: P2, b: P2, p: P2) -> bool {
    p[0] >= a[0].min(b[0])
        && p[0] <= a[0].max(b[0])
        && p[1] >= a[1].min(b[1])
        && p[1] <= a[1].max(b[1])
}

/// Whether segments `p1p2` and `q1q2` cross or touch.
fn segments_meet(p1: P2, p2: P2, q1: P2, q2: P2) -> bool {
    let (d1, d2) = (orient(q1, q2, p1), orient(q1, q2, p2));
    let (d3, d4) = (orient(p1, p2, q1), orient(p1, p2, q2));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return true;
    }
    (d1 == 0.0 && on_segment(q1, q2, p1))
        || (d2 == 0.0 && on_segment(q1, q2, p2))
        || (d3 == 0.0 && on_segment(p1, p2, q1))
        || (d4 == 0.0 && on_segment(p1, p2, q2))
}

/// The first pair of corners (in a deterministic order) whose edges cross, on the outline
/// flattened to `tol`; `None` for a simple outline.
pub fn self_crossing(outline: &Outline, tol: f64) -> Option<(usize, usize)> {
    let flat = outline.flatten(tol);
    let pts: Vec<P2> = flat.points.iter().map(|p| p.at).collect();
    let n = pts.len();
    if n < 3 {
        return None;
    }
    let seg = |i: usize| (pts[i], pts[(i + 1) % n]);
    let corner = |i: usize| flat.points[i].corner;
    // Adjacent segments meet at their shared point; they are wrong only if they fold back.
    for i in 0..n {
        let (a, b) = seg(i);
        let (_, c) = seg((i + 1) % n);
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
        let (lu, lv) = (u[0].hypot(u[1]), v[0].hypot(v[1]));
        let cross = u[0] * v[1] - u[1] * v[0];
        let dot = u[0] * v[0] + u[1] * v[1];
        if lu > 0.0 && lv > 0.0 && cross.abs() <= 1e-9 * lu * lv && dot < 0.0 {
            return Some((corner(i), corner((i + 1) % n)));
        }
    }
    // Sweep along x over the segments' bounding boxes.
    let mut order: Vec<usize> = (0..n).collect();
    let min_x = |i: usize| seg(i).0[0].min(seg(i).1[0]);
    let max_x = |i: usize| seg(i).0[0].max(seg(i).1[0]);
    order.sort_by(|&a, &b| min_x(a).total_cmp(&min_x(b)).then(a.cmp(&b)));
    for (k, &i) in order.iter().enumerate() {
        let (p1, p2) = seg(i);
        let (ylo, yhi) = (p1[1].min(p2[1]), p1[1].max(p2[1]));
        for &j in &order[k + 1..] {
            if min_x(j) > max_x(i) {
                break;
            }
            if (i + 1) % n == j || (j + 1) % n == i {
                continue;
            }
            let (q1, q2) = seg(j);
            if q1[1].max(q2[1]) < ylo || q1[1].min(q2[1]) > yhi {
                continue;
            }
            if segments_meet(p1, p2, q1, q2) {
                // the first crossing of the sweep: stopping here keeps the test near
                // O(n log n) on outlines that cross early (a scan for the smallest pair was
                // O(n²) on a 20 000-point fuzzed path: 6 s)
                return Some((corner(i.min(j)), corner(i.max(j))));
            }
        }
    }
    None
}
