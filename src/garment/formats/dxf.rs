//! DXF-AAMA pattern files (ASTM D6673, the garment industry's exchange format) read into a
//! [`Pattern`]. The writer is [`super::dxf_write`].
//!
//! The DXF syntax (ASCII or binary, R12 to 2018) is parsed by the `dxf` crate; a light pass of
//! our own over ASCII files adds line numbers to messages and catches what the crate skips
//! silently (unknown entity types, numbers that do not parse).
//!
//! # AAMA conventions read
//! - One BLOCK per piece, placed by an INSERT (its translation, rotation, scales and a
//!   (0, 0, −1) extrusion, which mirrors x, are applied; the first INSERT of a block counts,
//!   row/column arrays are not expanded). A block is a piece when it has geometry on layer 1 or
//!   14 or a `Piece Name:` text. With no such block, the ENTITIES section is one piece; with
//!   piece blocks, boundary geometry outside them is an error.
//! - Piece system text (TEXT/MTEXT): `Piece Name: X` names the piece (else the block name);
//!   `Quantity: N` gives [`Copies::Pair`](crate::garment::Copies::Pair) for even N ≥ 2, else `One`.
//!   Style system text: `Style Name:` names the pattern (else the file stem); `Units: ENGLISH`
//!   (inches) or `METRIC` (mm), also `CM`, `M`; without it `$INSUNITS`; without both,
//!   millimetres.
//! - Layer 1 boundary (cut line), 14 sew line: LINE, POLYLINE, LWPOLYLINE (bulges), ARC and
//!   CIRCLE, chained end to end within 0.01 mm into one closed loop each. The outline is the
//!   sew line when there is one, else the boundary; the seam allowance is the mean distance
//!   from the sew line to the boundary along the sew line's outward normal, over the parts
//!   where they differ (a fold or an edge without allowance counts for nothing).
//! - Layer 2 turn points and 3 curve points (POINTs within 0.1 mm of the outline). The
//!   corners are the turn points (the outline's vertex within 0.1 mm of one moves onto it);
//!   between two, the polyline becomes a straight line, or one cubic Bézier fitted by least
//!   squares (from chord-length and from even parameters, the better fit kept) when one
//!   follows every vertex within 0.05 mm; else
//!   the run is split at a curve point (or the worst vertex), which becomes a corner too. A
//!   polyline with no turn or curve point on it has a corner at every vertex. Corners are
//!   named `c0`, `c1`, … counter-clockwise from the lowest (then leftmost) corner, unless
//!   `Corner: NAME` texts stand at them (within 0.1 mm): then they take those names, and the
//!   corner of the first label comes first.
//! - Annotation text beyond AAMA (`annotation.rs`, what [`super::dxf_write`] writes):
//!   `Seam: NAME | PIECE: FROM > TO | PIECE: FROM > TO [| aligned]` in the ENTITIES section
//!   gives the seams (their pieces and corners must exist), `Placement: side=… anchor=…
//!   level=… x=… dz=…` in a piece's block its placement (x and dz in file units).
//! - Layer 4 and 80–83 notches (POINT, LINE or polyline): the point of the shape nearest the
//!   outline, projected onto it. Layer 6 mirror line: the straight edge lying on it (within
//!   0.5 mm; collinear edges on it are merged) is the fold. Layer 7 grain line (LINE or
//!   polyline: its longest segment, in drawing order); without one, vertical.
//! - Other layers (5, 8–13, 15, 84–87, non-AAMA names) are ignored, but an entity type other
//!   than LINE, POLYLINE, LWPOLYLINE, ARC, CIRCLE, POINT, TEXT, MTEXT, ATTDEF, ATTRIB or INSERT
//!   on an AAMA layer is an error (a HATCH on layer 1 is not silently dropped). Grading, sizes
//!   other than the one drawn, drill holes and internal lines are not read; entity-level
//!   extrusion directions are ignored (the drawing is taken as seen from +z).
//!
//! # Errors
//! [`PatternError::Parse`] (file, line) for what is not a DXF file or has malformed numbers
//! outside the piece blocks; [`PatternError::Piece`] (file, piece, and the entity's line, or
//! its index and handle in binary files) for the rest: a boundary that does not close (the gap
//! in mm and where), two loops on one layer, no boundary, a sew line outside the boundary, a
//! non-AAMA entity type on an AAMA layer, coordinates that are not finite numbers, a mirror
//! line on no straight edge. In binary files the entity types the `dxf` crate does not know
//! cannot be seen, so they are skipped without a word.

pub(crate) mod annotation;
pub(crate) mod flatten;
pub(crate) mod geom;
mod piece;
mod scan;

use std::path::Path;

use ::dxf::entities::{Entity, EntityType};
use ::dxf::{Drawing, DxfError};

use crate::garment::error::PatternError;
use crate::garment::pattern::{Pattern, Piece, Seam};
use piece::{build, collect, Xf};

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
    let data = crate::limits::read(path).map_err(|source| PatternError::Io {
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
    let scan = scanned.map_err(|(line, msg, block)| {
        match block.and_then(|b| drawing.blocks().find(|x| x.name == b)) {
            Some(b) => {
                let name = value_of(&texts(&b.entities), "piece name");
                cx.piece(
                    &name.unwrap_or(b.name.clone()),
                    format!("line {line}: {msg}"),
                )
            }
            None => cx.parse(line, msg),
        }
    })?;

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
                let xf = Xf::insert(scale, loc, base, f).ok_or_else(|| {
                    cx.piece(
                        &b.name,
                        "its INSERT has an invalid location, scale or rotation",
                    )
                })?;
                // Extrusion (0, 0, −1): the insert is seen from below, x mirrored.
                if i.extrusion_direction.z < 0.0 {
                    xf.mirrored_x()
                } else {
                    xf
                }
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
        let mut piece = build(raw, unique.clone(), &xf).map_err(|m| cx.piece(&unique, m))?;
        if let Some(v) = value_of(&texts(&ents), annotation::PLACEMENT) {
            let p = annotation::parse_placement(&v, 1.0 / scale);
            piece.placement = Some(p.map_err(|m| cx.piece(&unique, m))?);
        }
        pieces.push(piece);
    }
    let seams = read_seams(&top_texts, &pieces).map_err(|m| cx.parse(0, m))?;
    Ok(Pattern {
        name,
        source: path.display().to_string(),
        pieces,
        seams,
    })
}

/// The seams of the `Seam:` annotation texts, each edge checked against the pieces read.
fn read_seams(texts: &[String], pieces: &[Piece]) -> Result<Vec<Seam>, String> {
    let mut seams = Vec::new();
    for t in texts {
        let Some((k, v)) = t.split_once(':') else {
            continue;
        };
        if !k.trim().eq_ignore_ascii_case(annotation::SEAM) {
            continue;
        }
        let s = annotation::parse_seam(v.trim())?;
        for e in [&s.a, &s.b] {
            let p = pieces
                .iter()
                .find(|p| p.name == e.piece)
                .ok_or_else(|| format!("seam '{}': no piece '{}'", s.name, e.piece))?;
            for c in [&e.from, &e.to] {
                if p.outline.corner_index(c).is_none() {
                    return Err(format!(
                        "seam '{}': piece '{}' has no corner '{c}'",
                        s.name, e.piece
                    ));
                }
            }
        }
        seams.push(s);
    }
    Ok(seams)
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
