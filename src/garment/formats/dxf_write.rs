//! DXF-AAMA export of a [`Pattern`], for CAD systems and for round trips through
//! [`super::dxf::read_pattern_dxf`].
//!
//! The file is ASCII DXF R12 (`AC1009`) in millimetres (`Units: METRIC` style text and
//! `$INSUNITS` = 4), as pattern CAD systems write it: one BLOCK per piece, placed by an INSERT
//! at the origin, holding
//! - layer 1: the boundary (cut line) as a closed POLYLINE: the sewing line offset by the seam
//!   allowance (mitred corners; no allowance along a fold), and the piece system text
//!   (`Piece Name:`, `Quantity:` 2 for a pair, else 1);
//! - layer 14: the sewing line (the outline), when the piece has a seam allowance;
//! - layer 2 turn points at the corners and layer 3 curve points at the middle of each curve,
//!   for both lines; curves are flattened to chords within 0.05 mm;
//! - layer 4 notches: a slit LINE from the cut line to the notch on the sewing line (a POINT
//!   when there is no allowance there); layer 7 the grain line; layer 6 the mirror line of a
//!   piece cut on the fold.
//!
//! Seams and placements have no AAMA form and are not written.

use std::fmt::Write as _;
use std::path::Path;

use super::dxf::geom::{add, bezier, closest_on_loop, cross, dist, mul, signed_area, sub};
use crate::garment::error::PatternError;
use crate::garment::pattern::{Copies, Pattern, Piece, Segment, P2};

/// Largest distance from a flattened curve to its chords (m).
const FLATTEN_TOL: f64 = 5e-5;

/// Writes `pattern` as a DXF-AAMA file.
pub fn write_pattern_dxf(pattern: &Pattern, path: &Path) -> Result<(), PatternError> {
    let text = pattern_to_dxf(pattern)?;
    std::fs::write(path, text).map_err(|source| PatternError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The text of the DXF-AAMA file for `pattern`.
pub fn pattern_to_dxf(pattern: &Pattern) -> Result<String, PatternError> {
    let mut blocks = Out::default();
    let mut names: Vec<String> = Vec::new();
    for piece in &pattern.pieces {
        let base: String = piece
            .name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let base = if base.is_empty() {
            "PIECE".into()
        } else {
            base
        };
        let mut name = base.clone();
        let mut k = 2;
        while names.iter().any(|n| n.eq_ignore_ascii_case(&name)) {
            name = format!("{base}_{k}");
            k += 1;
        }
        write_block(&mut blocks, piece, &name).map_err(|message| PatternError::Piece {
            source_name: pattern.source.clone(),
            piece: piece.name.clone(),
            message,
        })?;
        names.push(name);
    }

    let mut o = Out::default();
    o.section("HEADER");
    o.pair(9, "$ACADVER");
    o.pair(1, "AC1009");
    o.pair(9, "$INSUNITS");
    o.pair(70, 4);
    o.pair(9, "$MEASUREMENT");
    o.pair(70, 1);
    o.pair(0, "ENDSEC");
    o.section("TABLES");
    o.table("LTYPE", 1);
    o.pair(0, "LTYPE");
    o.pair(2, "CONTINUOUS");
    o.pair(70, 0);
    o.pair(3, "Solid line");
    o.pair(72, 65);
    o.pair(73, 0);
    o.pair(40, "0.0");
    o.pair(0, "ENDTAB");
    let layers = ["1", "2", "3", "4", "6", "7", "14"];
    o.table("LAYER", layers.len());
    for l in layers {
        o.pair(0, "LAYER");
        o.pair(2, l);
        o.pair(70, 0);
        o.pair(62, 7);
        o.pair(6, "CONTINUOUS");
    }
    o.pair(0, "ENDTAB");
    o.pair(0, "ENDSEC");
    o.section("BLOCKS");
    o.0.push_str(&blocks.0);
    o.pair(0, "ENDSEC");
    o.section("ENTITIES");
    let style = one_line(&pattern.name);
    for (i, t) in [format!("Style Name: {style}"), "Units: METRIC".into()]
        .iter()
        .enumerate()
    {
        o.text(t, [0.0, -0.01 * (i as f64 + 1.0)], 5.0);
    }
    for n in &names {
        o.pair(0, "INSERT");
        o.pair(8, "1");
        o.pair(2, n);
        o.point(10, [0.0, 0.0]);
    }
    o.pair(0, "ENDSEC");
    o.pair(0, "EOF");
    Ok(o.0)
}

fn one_line(s: &str) -> String {
    s.replace(['\r', '\n'], " ")
}

/// Group codes and values, one per line, coordinates in mm.
#[derive(Default)]
struct Out(String);

impl Out {
    fn pair(&mut self, code: i32, value: impl std::fmt::Display) {
        let _ = writeln!(self.0, "{code:>3}\n{value}");
    }
    fn num(&mut self, code: i32, v: f64) {
        let v = if v.abs() < 5e-7 { 0.0 } else { v };
        self.pair(code, format!("{v:.6}"));
    }
    /// A point given in metres, written in mm under `code`, `code + 10`, `code + 20`.
    fn point(&mut self, code: i32, p: P2) {
        self.num(code, p[0] * 1000.0);
        self.num(code + 10, p[1] * 1000.0);
        self.num(code + 20, 0.0);
    }
    fn section(&mut self, name: &str) {
        self.pair(0, "SECTION");
        self.pair(2, name);
    }
    fn table(&mut self, name: &str, count: usize) {
        self.pair(0, "TABLE");
        self.pair(2, name);
        self.pair(70, count);
    }
    fn polyline(&mut self, layer: &str, pts: &[P2]) {
        self.pair(0, "POLYLINE");
        self.pair(8, layer);
        self.pair(66, 1);
        self.point(10, [0.0, 0.0]);
        self.pair(70, 1);
        for &p in pts {
            self.pair(0, "VERTEX");
            self.pair(8, layer);
            self.point(10, p);
        }
        self.pair(0, "SEQEND");
        self.pair(8, layer);
    }
    fn point_entity(&mut self, layer: &str, p: P2) {
        self.pair(0, "POINT");
        self.pair(8, layer);
        self.point(10, p);
    }
    fn line(&mut self, layer: &str, a: P2, b: P2) {
        self.pair(0, "LINE");
        self.pair(8, layer);
        self.point(10, a);
        self.point(11, b);
    }
    /// A TEXT on layer 1 at `at` (m), `height` mm high.
    fn text(&mut self, value: &str, at: P2, height: f64) {
        self.pair(0, "TEXT");
        self.pair(8, "1");
        self.point(10, at);
        self.num(40, height);
        self.pair(1, one_line(value));
    }
}

/// The outline flattened: points, which are corners, which are the middles of curves, and
/// which edges (from point i to i + 1) lie on the fold.
struct Flat {
    pts: Vec<P2>,
    corners: Vec<usize>,
    middles: Vec<usize>,
    fold: Vec<bool>,
}

fn flatten(piece: &Piece) -> Flat {
    let cs = &piece.outline.corners;
    let mut f = Flat {
        pts: Vec::new(),
        corners: Vec::new(),
        middles: Vec::new(),
        fold: Vec::new(),
    };
    for (i, c) in cs.iter().enumerate() {
        let (p0, p3) = (c.at, cs[(i + 1) % cs.len()].at);
        let on_fold = piece.fold.as_deref() == Some(c.name.as_str());
        f.corners.push(f.pts.len());
        match c.segment {
            Segment::Line => {
                f.pts.push(p0);
                f.fold.push(on_fold);
            }
            Segment::Cubic { c1, c2 } => {
                // Chord error of n even steps ≤ max|B''| / (8 n²), |B''| ≤ 6 max(|Δ²P|).
                let d2 = dist(add(p0, c2), mul(c1, 2.0)).max(dist(add(c1, p3), mul(c2, 2.0)));
                let n = ((6.0 * d2 / (8.0 * FLATTEN_TOL)).sqrt().ceil() as usize).clamp(2, 2000);
                let n = n + n % 2;
                for k in 0..n {
                    if k == n / 2 {
                        f.middles.push(f.pts.len());
                    }
                    let p = bezier([p0, c1, c2, p3], k as f64 / n as f64);
                    f.pts.push(p);
                    f.fold.push(on_fold);
                }
            }
        }
    }
    f
}

/// The polygon `pts` with each edge moved outwards by its own distance `d[i]` (mitred, the
/// mitre limited to four times the largest distance). Vertex i of the result goes with
/// vertex i of `pts`.
fn offset(pts: &[P2], d: &[f64]) -> Vec<P2> {
    let n = pts.len();
    let sign = signed_area(pts).signum();
    let normal = |i: usize| {
        let e = sub(pts[(i + 1) % n], pts[i]);
        let l = e[0].hypot(e[1]).max(1e-300);
        mul([e[1], -e[0]], sign / l)
    };
    let limit = 4.0 * d.iter().cloned().fold(0.0, f64::max);
    (0..n)
        .map(|i| {
            let j = (i + n - 1) % n;
            let (n0, n1) = (normal(j), normal(i));
            let det = cross(n0, n1);
            let p = if det.abs() < 1e-9 {
                add(pts[i], mul(n1, d[i]))
            } else {
                // The offset q = p − v with n0·q = d0 and n1·q = d1.
                let (r0, r1) = (d[j], d[i]);
                let q = [
                    (r0 * n1[1] - r1 * n0[1]) / det,
                    (n0[0] * r1 - n1[0] * r0) / det,
                ];
                add(pts[i], q)
            };
            let off = sub(p, pts[i]);
            let l = off[0].hypot(off[1]);
            if l > limit && l > 0.0 {
                add(pts[i], mul(off, limit / l))
            } else {
                p
            }
        })
        .collect()
}

fn write_block(o: &mut Out, piece: &Piece, name: &str) -> Result<(), String> {
    let cs = &piece.outline.corners;
    if cs.len() < 2 {
        return Err("the outline has fewer than two corners".into());
    }
    let finite = |p: &P2| p.iter().all(|v| v.is_finite());
    let controls = cs.iter().flat_map(|c| match c.segment {
        Segment::Line => vec![c.at],
        Segment::Cubic { c1, c2 } => vec![c.at, c1, c2],
    });
    if !controls
        .chain(piece.grain)
        .chain(piece.notches.iter().copied())
        .all(|p| finite(&p))
        || !piece.seam_allowance.is_finite()
        || piece.seam_allowance < 0.0
    {
        return Err("coordinates or seam allowance are not finite numbers".into());
    }
    let flat = flatten(piece);
    if flat.pts.len() < 3 || signed_area(&flat.pts) == 0.0 {
        return Err("the outline encloses no area".into());
    }
    let sa = piece.seam_allowance;
    let d: Vec<f64> = flat
        .fold
        .iter()
        .map(|&f| if f { 0.0 } else { sa })
        .collect();
    let cut = if sa > 0.0 {
        offset(&flat.pts, &d)
    } else {
        flat.pts.clone()
    };

    o.pair(0, "BLOCK");
    o.pair(8, "1");
    o.pair(2, name);
    o.pair(70, 0);
    o.point(10, [0.0, 0.0]);
    o.pair(3, name);
    o.polyline("1", &cut);
    let lines: &[&[P2]] = if sa > 0.0 {
        &[&cut, &flat.pts]
    } else {
        &[&cut]
    };
    for (k, pts) in lines.iter().enumerate() {
        if k == 1 {
            o.polyline("14", pts);
        }
        flat.corners
            .iter()
            .for_each(|&i| o.point_entity("2", pts[i]));
        flat.middles
            .iter()
            .for_each(|&i| o.point_entity("3", pts[i]));
    }
    for &p in &piece.notches {
        let (q, _, e, _) = closest_on_loop(&flat.pts, p);
        let edge = sub(flat.pts[(e + 1) % flat.pts.len()], flat.pts[e]);
        let l = edge[0].hypot(edge[1]);
        let sign = signed_area(&flat.pts).signum();
        if d[e] > 0.0 && l > 0.0 {
            let out = mul([edge[1], -edge[0]], sign * d[e] / l);
            o.line("4", add(q, out), q);
        } else {
            o.point_entity("4", q);
        }
    }
    o.line("7", piece.grain[0], piece.grain[1]);
    if let Some(i) = cs.iter().position(|c| Some(&c.name) == piece.fold.as_ref()) {
        o.line("6", cs[i].at, cs[(i + 1) % cs.len()].at);
    }
    // Piece system text near the middle of the piece, 5 mm high.
    let n = flat.pts.len() as f64;
    let centre = mul(flat.pts.iter().fold([0.0; 2], |a, &p| add(a, p)), 1.0 / n);
    let quantity = if piece.copies == Copies::Pair { 2 } else { 1 };
    let texts = [
        format!("Piece Name: {}", piece.name),
        format!("Quantity: {quantity}"),
    ];
    for (i, t) in texts.iter().enumerate() {
        o.text(t, [centre[0], centre[1] - 0.008 * i as f64], 5.0);
    }
    o.pair(0, "ENDBLK");
    o.pair(8, "1");
    Ok(())
}
