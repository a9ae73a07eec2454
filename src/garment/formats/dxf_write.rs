//! DXF-AAMA export of a [`Pattern`], for CAD systems and for round trips through
//! [`super::dxf::read_pattern_dxf`].
//!
//! The file is ASCII DXF R12 (`AC1009`) in millimetres by default (`Units: METRIC` style text
//! and `$INSUNITS` = 4), as pattern CAD systems write it; [`DxfOptions::units`] picks
//! centimetres (`Units: CM`, 5), metres (`Units: M`, 6) or inches (`Units: ENGLISH`, 1)
//! instead (AAMA itself knows only METRIC and ENGLISH). One BLOCK per piece, placed by an
//! INSERT at the origin, holds
//! - layer 1: the boundary (cut line) as a closed POLYLINE: the sewing line offset by the seam
//!   allowance (mitred corners; no allowance along a fold), and the piece system text
//!   (`Piece Name:`, `Quantity:` 2 for a pair, else 1);
//! - layer 14: the sewing line (the outline), when the piece has a seam allowance;
//! - layer 2 turn points at the corners and layer 3 curve points at the middle of each curve,
//!   for both lines; curves are flattened to chords within 1 µm at even steps of their
//!   parameter (a notch on a straight edge is a vertex);
//! - layer 4 notches: a slit LINE from the cut line to the notch on the sewing line (a POINT
//!   when there is no allowance there), the notch projected onto the outline; layer 7 the
//!   grain line; layer 6 the mirror line of a piece cut on the fold;
//! - layer 15 annotation text (`dxf/annotation.rs`): each corner's name at the corner
//!   (`Corner: c3`) and the piece's placement (`Placement: side=front anchor=c0 …`).
//!
//! The seams are annotation text on layer 15 in the ENTITIES section, one per seam
//! (`Seam: side | front: c2 > c3 | back: c3' > c2'`).

use std::fmt::Write as _;
use std::path::Path;

use super::dxf::annotation;
use super::dxf::flatten::{flatten, offset};
use super::dxf::geom::{add, closest_on_loop, mul, signed_area, sub};
use crate::garment::error::PatternError;
use crate::garment::pattern::{Copies, Pattern, Piece, Segment, P2};

/// The length unit of a written DXF-AAMA file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DxfUnits {
    /// Millimetres (`Units: METRIC`, `$INSUNITS` 4): what AAMA CAD systems expect.
    #[default]
    Millimetres,
    /// Centimetres (`Units: CM`, `$INSUNITS` 5).
    Centimetres,
    /// Metres (`Units: M`, `$INSUNITS` 6).
    Metres,
    /// Inches (`Units: ENGLISH`, `$INSUNITS` 1).
    Inches,
}

impl DxfUnits {
    /// The unit named `mm`, `cm`, `m` or `in`.
    pub fn parse(name: &str) -> Result<DxfUnits, PatternError> {
        match name {
            "mm" => Ok(DxfUnits::Millimetres),
            "cm" => Ok(DxfUnits::Centimetres),
            "m" => Ok(DxfUnits::Metres),
            "in" => Ok(DxfUnits::Inches),
            _ => Err(PatternError::Parameter(format!(
                "DXF units '{name}': expected \"mm\", \"cm\", \"m\" or \"in\""
            ))),
        }
    }
    /// File units per metre.
    pub fn per_metre(self) -> f64 {
        match self {
            DxfUnits::Millimetres => 1000.0,
            DxfUnits::Centimetres => 100.0,
            DxfUnits::Metres => 1.0,
            DxfUnits::Inches => 1.0 / 0.0254,
        }
    }
    fn insunits(self) -> i32 {
        match self {
            DxfUnits::Millimetres => 4,
            DxfUnits::Centimetres => 5,
            DxfUnits::Metres => 6,
            DxfUnits::Inches => 1,
        }
    }
    fn style_text(self) -> &'static str {
        match self {
            DxfUnits::Millimetres => "METRIC",
            DxfUnits::Centimetres => "CM",
            DxfUnits::Metres => "M",
            DxfUnits::Inches => "ENGLISH",
        }
    }
}

/// How a pattern is written to DXF-AAMA.
#[derive(Debug, Clone, Copy, Default)]
pub struct DxfOptions {
    /// The file's length unit.
    pub units: DxfUnits,
}

/// Writes `pattern` as a DXF-AAMA file in millimetres.
pub fn write_pattern_dxf(pattern: &Pattern, path: &Path) -> Result<(), PatternError> {
    write_pattern_dxf_with(pattern, path, &DxfOptions::default())
}

/// Writes `pattern` as a DXF-AAMA file with `options`, creating the file's folder if needed.
pub fn write_pattern_dxf_with(
    pattern: &Pattern,
    path: &Path,
    options: &DxfOptions,
) -> Result<(), PatternError> {
    let text = pattern_to_dxf_with(pattern, options)?;
    let io = |source| PatternError::Io {
        path: path.to_path_buf(),
        source,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    std::fs::write(path, text).map_err(io)
}

/// The text of the DXF-AAMA file for `pattern`, in millimetres.
pub fn pattern_to_dxf(pattern: &Pattern) -> Result<String, PatternError> {
    pattern_to_dxf_with(pattern, &DxfOptions::default())
}

/// The text of the DXF-AAMA file for `pattern` with `options`.
pub fn pattern_to_dxf_with(
    pattern: &Pattern,
    options: &DxfOptions,
) -> Result<String, PatternError> {
    let per_m = options.units.per_metre();
    let seam_texts = seam_texts(pattern)?;
    let mut blocks = Out::new(per_m);
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

    let mut o = Out::new(per_m);
    o.section("HEADER");
    o.pair(9, "$ACADVER");
    o.pair(1, "AC1009");
    o.pair(9, "$INSUNITS");
    o.pair(70, options.units.insunits());
    o.pair(9, "$MEASUREMENT");
    o.pair(70, i32::from(options.units != DxfUnits::Inches));
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
    let layers = ["1", "2", "3", "4", "6", "7", "14", "15"];
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
    o.s.push_str(&blocks.s);
    o.pair(0, "ENDSEC");
    o.section("ENTITIES");
    let style = one_line(&pattern.name);
    let style_texts = [
        format!("Style Name: {style}"),
        format!("Units: {}", options.units.style_text()),
    ];
    for (i, t) in style_texts.iter().enumerate() {
        o.text("1", t, [0.0, -0.01 * (i as f64 + 1.0)], 5.0);
    }
    for (i, t) in seam_texts.iter().enumerate() {
        o.text("15", t, [0.0, -0.01 * (i as f64 + 3.0)], 5.0);
    }
    for n in &names {
        o.pair(0, "INSERT");
        o.pair(8, "1");
        o.pair(2, n);
        o.point(10, [0.0, 0.0]);
    }
    o.pair(0, "ENDSEC");
    o.pair(0, "EOF");
    Ok(o.s)
}

/// The seams as annotation texts, each checked against the pieces and corners it names.
fn seam_texts(pattern: &Pattern) -> Result<Vec<String>, PatternError> {
    let err = |message: String| PatternError::Parse {
        path: pattern.source.clone().into(),
        line: 0,
        message,
    };
    let mut out = Vec::new();
    for s in &pattern.seams {
        for e in [&s.a, &s.b] {
            let p = pattern
                .pieces
                .iter()
                .find(|p| p.name == e.piece)
                .ok_or_else(|| err(format!("seam '{}': no piece '{}'", s.name, e.piece)))?;
            for c in [&e.from, &e.to] {
                if p.outline.corner_index(c).is_none() {
                    let m = format!("seam '{}': piece '{}' has no corner '{c}'", s.name, e.piece);
                    return Err(err(m));
                }
            }
        }
        out.push(annotation::seam_text(s).map_err(err)?);
    }
    Ok(out)
}

fn one_line(s: &str) -> String {
    s.replace(['\r', '\n'], " ")
}

/// Group codes and values, one per line; points given in metres are written in file units.
struct Out {
    s: String,
    /// File units per metre.
    per_m: f64,
}

impl Out {
    fn new(per_m: f64) -> Out {
        Out {
            s: String::new(),
            per_m,
        }
    }
    fn pair(&mut self, code: i32, value: impl std::fmt::Display) {
        let _ = writeln!(self.s, "{code:>3}\n{value}");
    }
    fn num(&mut self, code: i32, v: f64) {
        let v = if v.abs() < 5e-7 { 0.0 } else { v };
        self.pair(code, format!("{v:.6}"));
    }
    /// A point given in metres, under `code`, `code + 10`, `code + 20`.
    fn point(&mut self, code: i32, p: P2) {
        self.num(code, p[0] * self.per_m);
        self.num(code + 10, p[1] * self.per_m);
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
    /// A TEXT on `layer` at `at` (m), `height_mm` millimetres high.
    fn text(&mut self, layer: &str, value: &str, at: P2, height_mm: f64) {
        self.pair(0, "TEXT");
        self.pair(8, layer);
        self.point(10, at);
        self.num(40, height_mm * 1e-3 * self.per_m);
        self.pair(1, one_line(value));
    }
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
    for c in cs {
        annotation::check_name(&c.name, "corner")?;
    }
    let placement = piece
        .placement
        .as_ref()
        .map(|p| annotation::placement_text(p, o.per_m))
        .transpose()?;
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
    let sign = signed_area(&flat.pts).signum();
    for &q in &flat.notches {
        let (_, _, e, _) = closest_on_loop(&flat.pts, q);
        let edge = sub(flat.pts[(e + 1) % flat.pts.len()], flat.pts[e]);
        let l = edge[0].hypot(edge[1]);
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
    // Corner names at the corners, in outline order (the first label is the first corner).
    for c in cs {
        o.text("15", &annotation::corner_text(&c.name), c.at, 2.0);
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
        o.text("1", t, [centre[0], centre[1] - 0.008 * i as f64], 5.0);
    }
    if let Some(t) = placement {
        o.text("15", &t, [centre[0], centre[1] - 0.016], 5.0);
    }
    o.pair(0, "ENDBLK");
    o.pair(8, "1");
    Ok(())
}
