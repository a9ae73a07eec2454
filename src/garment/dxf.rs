//! DXF-AAMA pattern files (ASTM D6673, the garment industry's exchange format) read into a
//! [`Pattern`]. The writer is [`super::dxf_write`].
//!
//! The DXF syntax (ASCII or binary, R12 to 2018) is parsed by the `dxf` crate; a light pass of
//! our own over ASCII files adds line numbers to messages and catches what the crate skips
//! silently (unknown entity types, numbers that do not parse).
//!
//! # AAMA conventions read
//! - One BLOCK per piece, placed by an INSERT (its translation, rotation and scales are
//!   applied; the first INSERT of a block counts). A block is a piece when it has geometry on
//!   layer 1 or 14 or a `Piece Name:` text. With no such block, the ENTITIES section is one
//!   piece.
//! - Piece system text (TEXT/MTEXT): `Piece Name: X` names the piece (else the block name);
//!   `Quantity: N` gives [`Copies::Pair`] for even N ≥ 2, else [`Copies::One`]. Style system
//!   text: `Style Name:` names the pattern (else the file stem); `Units: ENGLISH` (inches) or
//!   `METRIC` (mm), also `CM`, `M`; without it `$INSUNITS`; without both, millimetres.
//! - Layer 1 boundary (cut line), 14 sew line: LINE, POLYLINE, LWPOLYLINE (bulges), ARC and
//!   CIRCLE, chained end to end within 0.01 mm into one closed loop each. The outline is the
//!   sew line when there is one, else the boundary; the seam allowance is the mean distance
//!   from the sew line to the boundary along the sew line's outward normal, over the parts
//!   where they differ (a fold or an edge without allowance counts for nothing).
//! - Layer 2 turn points and 3 curve points (POINTs within 0.1 mm of the outline). The
//!   corners are the turn points; between two, the polyline becomes a straight line, or one
//!   cubic Bézier fitted by least squares when one follows every vertex within 0.05 mm; else
//!   the run is split at a curve point (or the worst vertex), which becomes a corner too. A
//!   polyline with no turn or curve point on it has a corner at every vertex. Corners are
//!   named `c0`, `c1`, … counter-clockwise from the lowest (then leftmost) corner.
//! - Layer 4 and 80–83 notches (POINT, LINE or polyline): the point of the shape nearest the
//!   outline, projected onto it. Layer 6 mirror line: the straight edge lying on it (within
//!   0.5 mm; collinear edges on it are merged) is the fold. Layer 7 grain line (LINE or
//!   polyline: its longest segment, in drawing order); without one, vertical.
//! - Other layers (5, 8–13, 15, 84–87, non-AAMA names) are ignored, but an entity type other
//!   than LINE, POLYLINE, LWPOLYLINE, ARC, CIRCLE, POINT, TEXT, MTEXT, ATTDEF, ATTRIB or INSERT
//!   on an AAMA layer is an error (a HATCH on layer 1 is not silently dropped). Grading, sizes
//!   other than the one drawn, drill holes and internal lines are not read.

pub(crate) mod geom;
mod scan;

use std::path::Path;

use ::dxf::entities::{Entity, EntityType};
use ::dxf::{Drawing, DxfError};

use super::error::PatternError;
use super::pattern::{Copies, Corner, Outline, Pattern, Piece, Segment, P2};
use geom::{add, closest_on_loop, dist, mul, signed_area, Path as GPath};

/// Tolerance for chaining boundary pieces end to end (m).
const CHAIN_TOL: f64 = 1e-5;
/// How far a turn or curve point may lie from the outline (m).
const MARK_TOL: f64 = 1e-4;
/// How far a fitted cubic may pass from a polyline vertex (m).
const FIT_TOL: f64 = 5e-5;
/// How far the ends of a fold edge may lie from the mirror line (m).
const FOLD_TOL: f64 = 5e-4;

/// Entity types allowed on AAMA layers.
const ALLOWED: &[&str] = &[
    "LINE",
    "POLYLINE",
    "VERTEX",
    "SEQEND",
    "LWPOLYLINE",
    "ARC",
    "CIRCLE",
    "POINT",
    "TEXT",
    "MTEXT",
    "ATTDEF",
    "ATTRIB",
    "INSERT",
];

/// Reads a DXF-AAMA pattern file.
pub fn read_pattern_dxf(path: &Path) -> Result<Pattern, PatternError> {
    let data = std::fs::read(path).map_err(|source| PatternError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_pattern_dxf(&data, path)
}

/// Reads a DXF-AAMA pattern from the bytes of a file; `path` names it in messages.
pub fn parse_pattern_dxf(data: &[u8], path: &Path) -> Result<Pattern, PatternError> {
    let cx = Cx { path };
    let loaded = std::panic::catch_unwind(|| Drawing::load(&mut std::io::Cursor::new(data)));
    let scanned = scan::scan(data);
    let ascii = !matches!(scanned, Ok(None));
    let drawing = match loaded {
        Ok(Ok(d)) => d,
        Ok(Err(e)) => {
            let line = if ascii { dxf_error_line(&e) } else { 0 };
            return Err(cx.parse(line, format!("not a readable DXF file: {e}")));
        }
        Err(_) => return Err(cx.parse(0, "not a readable DXF file (the DXF parser gave up)")),
    };
    let scan = scanned.map_err(|(line, msg)| cx.parse(line, msg))?;

    let top: Vec<Entity> = drawing.entities().cloned().collect();
    let top_texts = texts(&top);
    let all_texts: Vec<String> = drawing
        .blocks()
        .flat_map(|b| texts(&b.entities))
        .chain(top_texts.iter().cloned())
        .collect();
    let scale = units(&top_texts, &all_texts, &drawing).map_err(|m| cx.parse(0, m))?;
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    let name = value_of(&top_texts, "style name")
        .or(stem)
        .unwrap_or_default();

    // Candidate pieces: blocks with AAMA piece content, else the ENTITIES section.
    let mut jobs: Vec<(String, Option<String>, Vec<Entity>, Xf)> = Vec::new();
    for b in drawing.blocks().filter(|b| !b.name.starts_with('*')) {
        let ents = &b.entities;
        if !(has_outline(ents) || value_of(&texts(ents), "piece name").is_some()) {
            continue;
        }
        let insert = top.iter().find_map(|e| match &e.specific {
            EntityType::Insert(i) if i.name.eq_ignore_ascii_case(&b.name) => Some(i),
            _ => None,
        });
        let xf = match insert {
            Some(i) => {
                let loc = [i.location.x, i.location.y];
                let base = [b.base_point.x, b.base_point.y];
                let f = [i.x_scale_factor, i.y_scale_factor, i.rotation];
                Xf::insert(scale, loc, base, f)
                    .ok_or_else(|| cx.piece(&b.name, "its INSERT has a zero or invalid scale"))?
            }
            None => Xf::insert(scale, [0.0; 2], [0.0; 2], [1.0, 1.0, 0.0]).unwrap_or(Xf::ID),
        };
        jobs.push((b.name.clone(), Some(b.name.clone()), ents.clone(), xf));
    }
    let top_lines = scan.as_ref().and_then(|s| s.lines_of(None, top.len()));
    if jobs.is_empty() {
        let xf = Xf::insert(scale, [0.0; 2], [0.0; 2], [1.0, 1.0, 0.0]).unwrap_or(Xf::ID);
        let piece_name = value_of(&top_texts, "piece name").unwrap_or_else(|| name.clone());
        if !has_outline(&top) {
            return Err(cx.parse(0, "no pattern piece: no boundary (layer 1) in any block"));
        }
        jobs.push((piece_name, None, top, xf));
    } else if let Some(k) = top
        .iter()
        .position(|e| layer_of(e) == Some(1) && is_curve(e))
    {
        let at = locate(&top, k, top_lines.as_deref(), None);
        let line = top_lines.as_ref().map_or(0, |l| l[k]);
        return Err(cx.parse(
            line,
            format!("{at}: boundary geometry outside any piece block"),
        ));
    } else if let Some(r) = scan.as_ref().and_then(|s| unknown(s, None)) {
        let layer = aama_layer(&r.layer).unwrap_or(0);
        let msg = format!(
            "{} on layer {layer} ({}) is not an AAMA entity",
            r.kind,
            role(layer)
        );
        return Err(cx.parse(r.line, msg));
    }

    let mut pieces: Vec<Piece> = Vec::new();
    for (fallback, block, ents, xf) in jobs {
        let piece_name = value_of(&texts(&ents), "piece name").unwrap_or(fallback);
        let mut unique = piece_name.clone();
        let mut k = 2;
        while pieces.iter().any(|p| p.name == unique) {
            unique = format!("{piece_name}_{k}");
            k += 1;
        }
        let lines = scan
            .as_ref()
            .and_then(|s| s.lines_of(block.as_deref(), ents.len()));
        if let Some(s) = &scan {
            if let Some(r) = unknown(s, block.as_deref()) {
                let layer = aama_layer(&r.layer).unwrap_or(0);
                let msg = format!(
                    "line {}: {} on layer {} ({}) is not an AAMA entity",
                    r.line,
                    r.kind,
                    layer,
                    role(layer)
                );
                return Err(cx.piece(&unique, msg));
            }
        }
        let raw = collect(&ents, lines.as_deref(), block.as_deref(), xf.tol())
            .map_err(|m| cx.piece(&unique, m))?;
        let piece = build(raw, unique.clone(), &xf).map_err(|m| cx.piece(&unique, m))?;
        pieces.push(piece);
    }
    Ok(Pattern {
        name,
        source: path.display().to_string(),
        pieces,
        seams: Vec::new(),
    })
}

/// The first entity of `block` (`None`: the ENTITIES section) of a type not allowed on the
/// AAMA layer it is on.
fn unknown<'s>(s: &'s scan::Scan, block: Option<&str>) -> Option<&'s scan::Record> {
    s.records.iter().find(|r| {
        r.block.as_deref() == block
            && aama_layer(&r.layer).is_some()
            && !ALLOWED.contains(&r.kind.as_str())
    })
}

struct Cx<'a> {
    path: &'a Path,
}

impl Cx<'_> {
    fn parse(&self, line: usize, message: impl Into<String>) -> PatternError {
        PatternError::Parse {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
        }
    }
    fn piece(&self, piece: &str, message: impl Into<String>) -> PatternError {
        PatternError::Piece {
            source_name: self.path.display().to_string(),
            piece: piece.to_string(),
            message: message.into(),
        }
    }
}

fn dxf_error_line(e: &DxfError) -> usize {
    use DxfError::*;
    match e {
        ParseFloatError(_, o) | ParseIntError(_, o) | ParseError(o) | UnexpectedCode(_, o) => *o,
        UnexpectedByte(_, o) | UnexpectedEnumValue(o) | ExpectedTableType(o) => *o,
        WrongValueType(o) => *o,
        UnexpectedCodePair(cp, _) => cp.offset,
        _ => 0,
    }
}

/// A block-to-pattern transform, `p ↦ a p + t`, the units included (m).
#[derive(Clone, Copy)]
struct Xf {
    a: [[f64; 2]; 2],
    t: P2,
}

impl Xf {
    const ID: Xf = Xf {
        a: [[1.0, 0.0], [0.0, 1.0]],
        t: [0.0, 0.0],
    };
    /// `p ↦ units · (loc + R(rot) · diag(sx, sy) · (p − base))`; `f` = [sx, sy, rot°].
    fn insert(units: f64, loc: P2, base: P2, f: [f64; 3]) -> Option<Xf> {
        let (s, c) = f[2].to_radians().sin_cos();
        let a = [
            [units * c * f[0], -units * s * f[1]],
            [units * s * f[0], units * c * f[1]],
        ];
        let mut xf = Xf { a, t: [0.0; 2] };
        let ab = xf.linear(base);
        xf.t = [units * loc[0] - ab[0], units * loc[1] - ab[1]];
        let ok = xf.a.iter().flatten().chain(&xf.t).all(|v| v.is_finite());
        (ok && xf.det().abs() > 0.0).then_some(xf)
    }
    fn linear(&self, p: P2) -> P2 {
        [
            self.a[0][0] * p[0] + self.a[0][1] * p[1],
            self.a[1][0] * p[0] + self.a[1][1] * p[1],
        ]
    }
    fn apply(&self, p: P2) -> P2 {
        add(self.linear(p), self.t)
    }
    fn det(&self) -> f64 {
        self.a[0][0] * self.a[1][1] - self.a[0][1] * self.a[1][0]
    }
    /// Metres per block unit.
    fn metres(&self) -> f64 {
        self.det().abs().sqrt()
    }
    /// The chaining tolerance in block units.
    fn tol(&self) -> f64 {
        CHAIN_TOL / self.metres()
    }
}

fn aama_layer(name: &str) -> Option<u32> {
    let n: u32 = name.trim().parse().ok()?;
    matches!(n, 1..=15 | 80..=87).then_some(n)
}

fn layer_of(e: &Entity) -> Option<u32> {
    aama_layer(&e.common.layer)
}

fn role(layer: u32) -> &'static str {
    match layer {
        1 => "boundary",
        2 => "turn points",
        3 => "curve points",
        4 | 80..=83 => "notches",
        5 => "grade reference",
        6 => "mirror line",
        7 => "grain line",
        8 => "internal lines",
        9 => "stripe reference",
        10 => "plaid reference",
        11 => "internal cut-outs",
        13 => "drill holes",
        14 => "sew line",
        15 => "annotation",
        84..=87 => "quality validation curves",
        _ => "unused",
    }
}

fn is_curve(e: &Entity) -> bool {
    use EntityType::*;
    matches!(
        e.specific,
        Line(_) | Polyline(_) | LwPolyline(_) | Arc(_) | Circle(_)
    )
}

fn has_outline(ents: &[Entity]) -> bool {
    ents.iter()
        .any(|e| matches!(layer_of(e), Some(1 | 14)) && is_curve(e))
}

/// The text lines of TEXT and MTEXT entities.
fn texts(ents: &[Entity]) -> Vec<String> {
    let mut out = Vec::new();
    for e in ents {
        let s = match &e.specific {
            EntityType::Text(t) => t.value.clone(),
            EntityType::MText(m) => format!("{}{}", m.extended_text.concat(), m.text),
            _ => continue,
        };
        out.extend(s.split("\\P").flat_map(|l| l.lines()).map(str::to_string));
    }
    out
}

/// The value of the first `key: value` text with this key (case-insensitive).
fn value_of(texts: &[String], key: &str) -> Option<String> {
    texts.iter().find_map(|t| {
        let (k, v) = t.split_once(':')?;
        k.trim()
            .eq_ignore_ascii_case(key)
            .then(|| v.trim().to_string())
            .filter(|v| !v.is_empty())
    })
}

/// Metres per drawing unit.
fn units(top: &[String], all: &[String], drawing: &Drawing) -> Result<f64, String> {
    use ::dxf::enums::Units as U;
    if let Some(v) = value_of(top, "units").or_else(|| value_of(all, "units")) {
        let l = v.to_ascii_lowercase();
        return match l.as_str() {
            "english" | "inch" | "inches" | "in" => Ok(0.0254),
            "metric" | "mm" | "millimeter" | "millimeters" | "millimetre" | "millimetres" => {
                Ok(0.001)
            }
            "cm" | "centimeter" | "centimeters" | "centimetre" | "centimetres" => Ok(0.01),
            "m" | "meter" | "meters" | "metre" | "metres" => Ok(1.0),
            _ => Err(format!(
                "unknown units 'Units: {v}' (ENGLISH, METRIC, CM or M)"
            )),
        };
    }
    Ok(match drawing.header.default_drawing_units {
        U::Inches => 0.0254,
        U::Feet => 0.3048,
        U::Centimeters => 0.01,
        U::Meters => 1.0,
        _ => 0.001,
    })
}

/// Where entity `k` of a list is, for messages.
fn locate(ents: &[Entity], k: usize, lines: Option<&[usize]>, block: Option<&str>) -> String {
    if let Some(l) = lines.and_then(|l| l.get(k)) {
        return format!("line {l}");
    }
    let h = ents[k].common.handle.0;
    let within = block.map_or("the ENTITIES section".to_string(), |b| format!("block {b}"));
    if h != 0 {
        format!("entity {} of {within} (handle {h:X})", k + 1)
    } else {
        format!("entity {} of {within}", k + 1)
    }
}

/// What one piece's entities say, in block coordinates.
#[derive(Default)]
struct Raw {
    boundary: Vec<GPath>,
    sew: Vec<GPath>,
    turn: Vec<P2>,
    curve: Vec<P2>,
    notches: Vec<Vec<P2>>,
    mirror: Vec<(Vec<P2>, String)>,
    grain: Vec<(Vec<P2>, String)>,
    quantity: Option<u32>,
}

/// Sorts the entities of one piece by layer. `tol` (block units) bounds arc flattening.
fn collect(
    ents: &[Entity],
    lines: Option<&[usize]>,
    block: Option<&str>,
    tol: f64,
) -> Result<Raw, String> {
    let mut raw = Raw {
        quantity: value_of(&texts(ents), "quantity").and_then(|q| {
            q.split(|c: char| !c.is_ascii_digit())
                .find_map(|d| d.parse().ok())
        }),
        ..Raw::default()
    };
    for (k, e) in ents.iter().enumerate() {
        let Some(layer) = layer_of(e) else { continue };
        let at = locate(ents, k, lines, block);
        let xy = |p: &::dxf::Point| [p.x, p.y];
        let (pts, closed): (Vec<P2>, bool) = match &e.specific {
            EntityType::Line(l) => (vec![xy(&l.p1), xy(&l.p2)], false),
            EntityType::Polyline(p) => {
                let v: Vec<(P2, f64)> = p.vertices().map(|v| (xy(&v.location), v.bulge)).collect();
                (with_bulges(&v, p.is_closed(), tol), p.is_closed())
            }
            EntityType::LwPolyline(p) => {
                let v: Vec<(P2, f64)> = p.vertices.iter().map(|v| ([v.x, v.y], v.bulge)).collect();
                (with_bulges(&v, p.is_closed(), tol), p.is_closed())
            }
            EntityType::Arc(a) => {
                let sweep = (a.end_angle - a.start_angle).rem_euclid(360.0);
                let sweep = if sweep == 0.0 { 360.0 } else { sweep }.to_radians();
                let (c, a0) = (xy(&a.center), a.start_angle.to_radians());
                let mut pts = geom::arc_points(c, a.radius, a0, sweep, tol);
                let a1 = a0 + sweep;
                pts.push([c[0] + a.radius * a1.cos(), c[1] + a.radius * a1.sin()]);
                (pts, false)
            }
            EntityType::Circle(c) => {
                let tau = std::f64::consts::TAU;
                (
                    geom::arc_points(xy(&c.center), c.radius, 0.0, tau, tol),
                    true,
                )
            }
            EntityType::ModelPoint(p) => (vec![xy(&p.location)], false),
            EntityType::Insert(i) if block.is_some() => {
                return Err(format!(
                    "{at}: nested INSERT of block {} is not supported",
                    i.name
                ));
            }
            EntityType::Text(_)
            | EntityType::MText(_)
            | EntityType::Attribute(_)
            | EntityType::AttributeDefinition(_)
            | EntityType::Insert(_)
            | EntityType::Vertex(_)
            | EntityType::Seqend(_) => continue,
            other => {
                let kind = format!("{other:?}");
                let kind = kind.split(['(', ' ']).next().unwrap_or("entity");
                return Err(format!(
                    "{at}: {kind} on layer {layer} ({}) is not an AAMA entity",
                    role(layer)
                ));
            }
        };
        if pts.iter().flatten().any(|v| !v.is_finite()) {
            return Err(format!("{at}: coordinates are not finite numbers"));
        }
        let is_point = matches!(e.specific, EntityType::ModelPoint(_));
        match layer {
            1 | 14 if !is_point => {
                let path = GPath { pts, closed, at };
                if layer == 1 {
                    raw.boundary.push(path);
                } else {
                    raw.sew.push(path);
                }
            }
            2 if is_point => raw.turn.push(pts[0]),
            3 if is_point => raw.curve.push(pts[0]),
            4 | 80..=83 => raw.notches.push(pts),
            6 if pts.len() >= 2 => raw.mirror.push((pts, at)),
            7 if pts.len() >= 2 => raw.grain.push((pts, at)),
            _ => {}
        }
    }
    Ok(raw)
}

/// Polyline vertices with bulges turned into arcs.
fn with_bulges(v: &[(P2, f64)], closed: bool, tol: f64) -> Vec<P2> {
    let mut out = Vec::new();
    for (i, &(p, b)) in v.iter().enumerate() {
        let next = v.get(i + 1).or(if closed { v.first() } else { None });
        match next {
            Some(&(q, _)) => out.extend(geom::bulge_points(p, q, b, tol)),
            None => out.push(p),
        }
    }
    out
}

/// The single closed loop of one layer, in pattern coordinates (m), counter-clockwise.
fn one_loop(paths: Vec<GPath>, what: &str, xf: &Xf) -> Result<Option<Vec<P2>>, String> {
    if paths.is_empty() {
        return Ok(None);
    }
    let loops = geom::chain(paths, xf.tol()).map_err(|o| {
        let mm = o.gap * xf.metres() * 1000.0;
        format!(
            "{}: the {what} does not close: gap of {mm:.3} mm between ({}, {}) and ({}, {}) \
             (file units, block coordinates)",
            o.at, o.end[0], o.end[1], o.nearest[0], o.nearest[1]
        )
    })?;
    match loops.len() {
        0 => Err(format!("the {what} is empty")),
        1 => {
            let mut pts: Vec<P2> = loops[0].iter().map(|&p| xf.apply(p)).collect();
            let area = signed_area(&pts);
            if pts.len() < 3 || !area.is_finite() || area.abs() < 1e-12 {
                return Err(format!("the {what} encloses no area"));
            }
            if area < 0.0 {
                pts.reverse();
            }
            Ok(Some(pts))
        }
        n => Err(format!(
            "{n} closed loops in the {what}; a piece has one (internal cut-outs go on layer 11)"
        )),
    }
}

/// Assembles one piece from its sorted entities.
fn build(raw: Raw, name: String, xf: &Xf) -> Result<Piece, String> {
    let boundary = one_loop(raw.boundary, "boundary (layer 1)", xf)?
        .ok_or("no boundary (layer 1): the piece has no cut line")?;
    let sew = one_loop(raw.sew, "sew line (layer 14)", xf)?;
    if let Some(s) = &sew {
        if signed_area(s) >= signed_area(&boundary) {
            return Err("the sew line (layer 14) is not inside the boundary (layer 1)".into());
        }
    }
    let mut pts = sew.clone().unwrap_or_else(|| boundary.clone());

    // Turn and curve points on the outline become flagged vertices (inserted on edges).
    let turn: Vec<P2> = raw.turn.iter().map(|&p| xf.apply(p)).collect();
    let curve: Vec<P2> = raw.curve.iter().map(|&p| xf.apply(p)).collect();
    let mut flags = vec![(false, false); pts.len()];
    let mut marked = false;
    for (marks, is_turn) in [(&turn, true), (&curve, false)] {
        for &m in marks.iter() {
            let (q, d, edge, t) = closest_on_loop(&pts, m);
            if d > MARK_TOL {
                continue;
            }
            marked = true;
            let next = (edge + 1) % pts.len();
            let k = if dist(q, pts[edge]) <= MARK_TOL && t < 0.5 {
                edge
            } else if dist(q, pts[next]) <= MARK_TOL {
                next
            } else {
                pts.insert(edge + 1, q);
                flags.insert(edge + 1, (false, false));
                edge + 1
            };
            if is_turn {
                flags[k].0 = true;
            } else {
                flags[k].1 = true;
            }
        }
    }
    let corner: Vec<bool> = flags.iter().map(|f| f.0 || !marked).collect();
    let prefer: Vec<bool> = flags.iter().map(|f| f.1).collect();
    let fitted = geom::fit_loop(&pts, &corner, &prefer, FIT_TOL);
    let mut corners: Vec<(P2, Segment)> = fitted.iter().map(|&(i, s)| (pts[i], s)).collect();

    // The fold: the straight edges on the mirror line, merged into one.
    let mut fold = None;
    if let Some((m, at)) = raw.mirror.first() {
        let (a, b) = (xf.apply(m[0]), xf.apply(m[m.len() - 1]));
        let n = corners.len();
        let on = |i: usize| {
            matches!(corners[i].1, Segment::Line)
                && geom::dist_to_line(a, b, corners[i].0) <= FOLD_TOL
                && geom::dist_to_line(a, b, corners[(i + 1) % n].0) <= FOLD_TOL
        };
        let flags: Vec<bool> = (0..n).map(on).collect();
        let len = |i: usize| dist(corners[i].0, corners[(i + 1) % n].0);
        let mut best: Option<(usize, usize, f64)> = None;
        for i in (0..n).filter(|&i| flags[i] && !flags[(i + n - 1) % n]) {
            let k = (0..n).take_while(|&j| flags[(i + j) % n]).count();
            let total: f64 = (0..k).map(|j| len((i + j) % n)).sum();
            if best.is_none_or(|b| total > b.2) {
                best = Some((i, k, total));
            }
        }
        let (i, k, _) = best.ok_or_else(|| {
            format!("{at}: the mirror line (layer 6) lies on no straight edge of the outline")
        })?;
        let drop: Vec<usize> = (1..k).map(|j| (i + j) % n).collect();
        let mut kept = Vec::new();
        let mut fold_at = 0;
        for (j, c) in corners.iter().enumerate() {
            if j == i {
                fold_at = kept.len();
            }
            if !drop.contains(&j) {
                kept.push(*c);
            }
        }
        corners = kept;
        fold = Some(fold_at);
    }

    // Name from the lowest-leftmost corner, counter-clockwise.
    let at: Vec<P2> = corners.iter().map(|c| c.0).collect();
    let first = geom::lowest_leftmost(&at);
    corners.rotate_left(first);
    let n = corners.len();
    let fold = fold.map(|f| format!("c{}", (f + n - first) % n));
    let outline = Outline {
        corners: corners
            .iter()
            .enumerate()
            .map(|(i, &(at, segment))| Corner {
                name: format!("c{i}"),
                at,
                segment,
            })
            .collect(),
    };

    let grain = match raw.grain.first() {
        Some((g, at)) => {
            let g: Vec<P2> = g.iter().map(|&p| xf.apply(p)).collect();
            let (a, b) = g
                .windows(2)
                .map(|w| (w[0], w[1]))
                .max_by(|x, y| dist(x.0, x.1).total_cmp(&dist(y.0, y.1)))
                .unwrap_or((g[0], g[0]));
            if dist(a, b) <= 0.0 {
                return Err(format!("{at}: the grain line (layer 7) has no length"));
            }
            [a, b]
        }
        None => {
            let (lo, hi) = at.iter().fold(([f64::MAX; 2], [f64::MIN; 2]), |(l, h), p| {
                (
                    [l[0].min(p[0]), l[1].min(p[1])],
                    [h[0].max(p[0]), h[1].max(p[1])],
                )
            });
            let c = mul(add(lo, hi), 0.5);
            let h = (hi[1] - lo[1]) / 4.0;
            [[c[0], c[1] - h], [c[0], c[1] + h]]
        }
    };

    let notches = raw
        .notches
        .iter()
        .filter(|s| !s.is_empty())
        .map(|s| {
            let s: Vec<P2> = s.iter().map(|&p| xf.apply(p)).collect();
            let mut cands = s.clone();
            for w in s.windows(2) {
                for e in 0..pts.len() {
                    let (a, b) = (pts[e], pts[(e + 1) % pts.len()]);
                    cands.extend(geom::segment_intersection(w[0], w[1], a, b));
                }
            }
            let best = cands
                .iter()
                .map(|&c| closest_on_loop(&pts, c))
                .min_by(|x, y| x.1.total_cmp(&y.1));
            best.map_or(s[0], |b| b.0)
        })
        .collect();

    let seam_allowance = match &sew {
        Some(s) => geom::mean_offset(s, &boundary, 400, FIT_TOL).unwrap_or(0.0),
        None => 0.0,
    };
    let copies = match raw.quantity {
        Some(q) if q >= 2 && q % 2 == 0 => Copies::Pair,
        _ => Copies::One,
    };
    Ok(Piece {
        name,
        outline,
        grain,
        seam_allowance,
        notches,
        fold,
        copies,
        placement: None,
    })
}
