//! SVG pattern import: FreeSewing output and generic drawings.
//!
//! **Pieces.** Every `<g>` with an `id` that directly holds a candidate sewing line is a
//! piece. Candidates are `<path>`, `<polygon>` and `<rect>` elements whose class has none of
//! the words `sa`, `help`, `hidden`, `note`, `mark`, `contrast`, `lashed`, `dotted`, `dashed`,
//! `scalebox`, `logo` and that are not grain or fold markers; the closed candidate of largest
//! area is the sewing line. (FreeSewing draws it with class `fabric`, `lining`, … or, for some
//! designs, no class at all.) A piece whose only candidates are open paths is an error that
//! names the gap between the path's end and its start. The piece takes the group's id; a
//! FreeSewing part group `fs-stack-D.P-part-D.P` gives `P`.
//!
//! **Markings.** The grain line is a path whose `marker-start` names a grainline marker, or
//! whose class or id contains `grain`; FreeSewing's cut-on-fold marker (`marker-start`
//! naming `cutonfold`) gives the fold edge: the straight outline segment lying on the line
//! through the marker's ends (the piece's `fold`), and, if there is no grain line, the grain
//! along the fold. Grain lines are oriented to point up (or right when horizontal); without
//! any, the grain is vertical through the middle of the piece. The seam allowance is the
//! median distance from the outline of the points of the paths of class `sa` (0.1 mm steps),
//! else [`SvgOptions::seam_allowance`]. Notches are `<use>` of `#notch`/`#bnotch` and
//! `<circle>`s whose class contains `notch`.
//!
//! **Geometry.** Transforms of groups and elements are applied; user units become metres from
//! the root's `width`/`height` and `viewBox` (FreeSewing: mm) unless
//! [`SvgOptions::metres_per_unit`] says otherwise, and y is flipped to point up. Segment end
//! points become corners, consecutive corners closer than [`SvgOptions::merge_distance`] are
//! merged, cubics whose control points lie on their chord become lines, the outline is made
//! counter-clockwise keeping the path's start as `c0`, and corners are named `c0, c1, …` in
//! that order. Other elements are ignored.
//!
//! The pieces of the reader are submodules: `xml` (the document), `path` (path data),
//! `transform` (transform lists) and `shape` (basic shapes and markings).

mod path;
mod shape;
mod transform;
mod xml;

use std::path::Path;

use self::path::{parse_path, SubPath};
use self::shape::{
    default_grain, dist, extent, fold_corner, infer_allowance, num_attr, orient_up, outline_of,
    polygon, rect,
};
use self::transform::{parse_transform, Affine};
use self::xml::Element;
use crate::garment::error::PatternError;
use crate::garment::pattern::{Pattern, Piece, P2};

/// How an SVG file is read.
#[derive(Debug, Clone, PartialEq)]
pub struct SvgOptions {
    /// Metres per SVG user unit; `None`: from the root's `width` and `viewBox` (a length
    /// without a unit, or no `width`, counts as CSS pixels, 1/96 in).
    pub metres_per_unit: Option<f64>,
    /// Seam allowance of pieces whose file does not show one (m).
    pub seam_allowance: f64,
    /// Consecutive outline corners closer than this are merged (m).
    pub merge_distance: f64,
}

impl Default for SvgOptions {
    fn default() -> Self {
        Self {
            metres_per_unit: None,
            seam_allowance: 0.01,
            merge_distance: 1e-5,
        }
    }
}

/// Class words that mark a path as something other than a sewing line.
const NOT_OUTLINE: [&str; 11] = [
    "sa", "help", "hidden", "note", "mark", "contrast", "lashed", "dotted", "dashed", "scalebox",
    "logo",
];
/// Elements whose content is never drawn as pattern pieces.
const SKIPPED: [&str; 12] = [
    "defs", "marker", "symbol", "clipPath", "mask", "pattern", "style", "script", "metadata",
    "title", "desc", "text",
];

/// Reads an SVG pattern (see the module doc), sets `source` to its path, and validates its
/// pieces. The pattern has no seams: they come from a garment table or are added by hand.
pub fn read_pattern_svg(
    path: impl AsRef<Path>,
    options: &SvgOptions,
) -> Result<Pattern, PatternError> {
    let path = path.as_ref();
    let pattern = parse_pattern_svg_file(path, options)?;
    pattern.validate()?;
    Ok(pattern)
}

/// Reads an SVG pattern without validating it.
pub(crate) fn parse_pattern_svg_file(
    path: &Path,
    options: &SvgOptions,
) -> Result<Pattern, PatternError> {
    let text = std::fs::read_to_string(path).map_err(|source| PatternError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_pattern_svg(&text, path, options)
}

/// Parses the text of an SVG pattern (`path` names it in errors) without validating it.
pub fn parse_pattern_svg(
    text: &str,
    path: &Path,
    options: &SvgOptions,
) -> Result<Pattern, PatternError> {
    let root = xml::parse(text).map_err(|e| PatternError::Syntax {
        path: path.to_path_buf(),
        line: e.line,
        column: e.column,
        message: e.message,
    })?;
    let ctx = Ctx {
        path,
        options,
        scale: units(&root, options, path)?,
    };
    let mut pieces = Vec::new();
    let root_t = transform_of(&root, &ctx)?;
    walk(&root, root_t, &ctx, &mut pieces)?;
    if pieces.is_empty() {
        return Err(PatternError::Parse {
            path: path.to_path_buf(),
            line: root.line,
            message: "no pattern piece found (no <g id=…> holding a closed path)".into(),
        });
    }
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(Pattern {
        name,
        source: path.display().to_string(),
        pieces,
        seams: Vec::new(),
    })
}

struct Ctx<'a> {
    path: &'a Path,
    options: &'a SvgOptions,
    /// Metres per user unit.
    scale: f64,
}

impl Ctx<'_> {
    fn parse_err(&self, line: usize, message: String) -> PatternError {
        PatternError::Parse {
            path: self.path.to_path_buf(),
            line,
            message,
        }
    }

    /// User units (after `t`) to metres, y up.
    fn to_m(&self, t: &Affine, p: P2) -> P2 {
        let q = t.apply(p);
        [q[0] * self.scale, -q[1] * self.scale]
    }
}

/// Length of an SVG length attribute in mm (`None` for a relative or missing one).
fn length_mm(v: &str) -> Option<f64> {
    let v = v.trim();
    let split = v
        .find(|c: char| c.is_ascii_alphabetic() || c == '%')
        .unwrap_or(v.len());
    let x: f64 = v[..split].trim().parse().ok()?;
    let per = match &v[split..] {
        "" | "px" => 25.4 / 96.0,
        "mm" => 1.0,
        "cm" => 10.0,
        "m" => 1000.0,
        "in" => 25.4,
        "pt" => 25.4 / 72.0,
        "pc" => 25.4 / 6.0,
        _ => return None,
    };
    Some(x * per)
}

fn units(root: &Element, options: &SvgOptions, path: &Path) -> Result<f64, PatternError> {
    if let Some(s) = options.metres_per_unit {
        if s.is_finite() && s > 0.0 {
            return Ok(s);
        }
        return Err(PatternError::Parameter(format!(
            "metres_per_unit {s} is not a positive number"
        )));
    }
    let view_w = root.attr("viewBox").and_then(|vb| {
        let v: Vec<f64> = vb
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter_map(|s| s.parse().ok())
            .collect();
        (v.len() == 4 && v[2] > 0.0).then(|| v[2])
    });
    let width = root.attr("width").and_then(length_mm);
    let mm = match (width, view_w) {
        (Some(w), Some(vw)) if w > 0.0 => w / vw,
        _ => 25.4 / 96.0,
    };
    if !mm.is_finite() || mm <= 0.0 {
        return Err(PatternError::Parse {
            path: path.to_path_buf(),
            line: root.line,
            message: "bad width/viewBox".into(),
        });
    }
    Ok(mm * 1e-3)
}

fn transform_of(el: &Element, ctx: &Ctx) -> Result<Affine, PatternError> {
    match el.attr("transform") {
        Some(t) => parse_transform(t).map_err(|e| ctx.parse_err(el.line, e)),
        None => Ok(Affine::IDENTITY),
    }
}

fn classes(el: &Element) -> Vec<&str> {
    el.attr("class")
        .map(|c| c.split_whitespace().collect())
        .unwrap_or_default()
}

fn walk(el: &Element, t: Affine, ctx: &Ctx, pieces: &mut Vec<Piece>) -> Result<(), PatternError> {
    for child in &el.children {
        let name = child.local_name();
        if SKIPPED.contains(&name) || name != "g" && name != "svg" {
            continue;
        }
        let ct = t.then_inner(&transform_of(child, ctx)?);
        if let (Some(id), "g") = (child.attr("id"), name) {
            if let Some(piece) = piece_of(child, id, &ct, ctx)? {
                pieces.push(piece);
            }
        }
        walk(child, ct, ctx, pieces)?;
    }
    Ok(())
}

/// The piece name from a group id (FreeSewing's part groups give the part's name).
fn piece_name(id: &str) -> String {
    match id
        .strip_prefix("fs-stack-")
        .and_then(|s| s.split_once("-part-"))
    {
        Some((_, part)) => part.rsplit('.').next().unwrap_or(part).to_string(),
        None => id.to_string(),
    }
}

/// A closed or open outline candidate in metres.
struct Candidate {
    sub: SubPath,
    line: usize,
    label: String,
}

fn piece_of(g: &Element, id: &str, t: &Affine, ctx: &Ctx) -> Result<Option<Piece>, PatternError> {
    let name = piece_name(id);
    let mut candidates = Vec::new();
    let (mut grain, mut fold_marker, mut sa_points, mut notches) =
        (None, None, Vec::new(), Vec::new());
    for el in &g.children {
        let tag = el.local_name();
        let et = t.then_inner(&transform_of(el, ctx)?);
        let cls = classes(el);
        let marker = el.attr("marker-start").unwrap_or("").to_ascii_lowercase();
        let label = el.attr("id").map_or_else(
            || format!("<{tag}> of line {}", el.line),
            |i| format!("'{i}'"),
        );
        if tag == "use" {
            let href = el.attr("href").unwrap_or("");
            if href == "#notch" || href == "#bnotch" {
                let xy = [num_attr(el, "x"), num_attr(el, "y")];
                notches.push(ctx.to_m(&et, xy));
            }
            continue;
        }
        if tag == "circle" {
            if cls.iter().any(|c| c.contains("notch")) {
                notches.push(ctx.to_m(&et, [num_attr(el, "cx"), num_attr(el, "cy")]));
            }
            continue;
        }
        let subs = match tag {
            "path" => parse_path(el.attr("d").unwrap_or("")).map_err(|e| {
                ctx.parse_err(el.line, format!("piece '{name}': path {label}: {e}"))
            })?,
            "polygon" | "polyline" => {
                polygon(el, tag == "polygon").map_err(|e| ctx.parse_err(el.line, e))?
            }
            "rect" => rect(el),
            _ => continue,
        };
        let subs: Vec<SubPath> = subs.into_iter().map(|s| to_metres(&s, &et, ctx)).collect();
        let lower_id = el.attr("id").unwrap_or("").to_ascii_lowercase();
        let ends = |subs: &[SubPath]| subs.first().map(|s| (s.start, s.end()));
        if marker.contains("grainline")
            || cls.iter().any(|c| c.contains("grain"))
            || lower_id.contains("grain")
        {
            grain = grain.or(ends(&subs));
        } else if marker.contains("cutonfold") {
            let with_grain = el
                .attr("data-text")
                .is_some_and(|d| d.to_ascii_lowercase().contains("grainline"));
            fold_marker = fold_marker.or(ends(&subs).map(|e| (e, with_grain)));
        } else if cls.contains(&"sa") {
            for s in &subs {
                sa_points.push(s.start);
                let mut prev = s.start;
                for seg in &s.segs {
                    let e = seg.end();
                    sa_points.push([(prev[0] + e[0]) / 2.0, (prev[1] + e[1]) / 2.0]);
                    sa_points.push(e);
                    prev = e;
                }
            }
        } else if !cls.iter().any(|c| NOT_OUTLINE.contains(c)) {
            candidates.extend(subs.into_iter().map(|sub| Candidate {
                sub,
                line: el.line,
                label: label.clone(),
            }));
        }
    }
    let merge = ctx.options.merge_distance;
    let closes = |s: &SubPath| s.closed || dist(s.start, s.end()) <= merge;
    let best = candidates
        .iter()
        .filter(|c| closes(&c.sub) && c.sub.segs.len() >= 2)
        .map(|c| (c, outline_of(&c.sub, merge)))
        .filter(|(_, o)| o.corners.len() >= 3)
        .max_by(|a, b| a.1.area().abs().total_cmp(&b.1.area().abs()));
    let Some((_, mut outline)) = best else {
        let open = candidates
            .iter()
            .filter(|c| !c.sub.segs.is_empty())
            .max_by(|a, b| extent(&a.sub).total_cmp(&extent(&b.sub)));
        return match open {
            Some(c) => Err(PatternError::Piece {
                source_name: ctx.path.display().to_string(),
                piece: name,
                message: format!(
                    "the sewing line ({}, line {}) does not close: its end ({:.1}, {:.1}) mm is {:.2} mm from its start ({:.1}, {:.1}) mm (y up)",
                    c.label,
                    c.line,
                    c.sub.end()[0] * 1e3,
                    c.sub.end()[1] * 1e3,
                    dist(c.sub.start, c.sub.end()) * 1e3,
                    c.sub.start[0] * 1e3,
                    c.sub.start[1] * 1e3
                ),
            }),
            None if id.starts_with("fs-stack-") && id.contains("-part-") => Err(PatternError::Piece {
                source_name: ctx.path.display().to_string(),
                piece: name,
                message: format!("part group '{id}' (line {}) has no sewing line", g.line),
            }),
            None => Ok(None),
        };
    };
    outline.make_ccw();
    for (i, c) in outline.corners.iter_mut().enumerate() {
        c.name = format!("c{i}");
    }
    let fold = fold_marker.and_then(|((a, b), _)| fold_corner(&outline, a, b));
    let grain = match (grain, fold_marker) {
        (Some(g), _) => orient_up(g),
        (None, Some(((a, b), _))) => orient_up((a, b)),
        (None, None) => default_grain(&outline),
    };
    let seam_allowance =
        infer_allowance(&outline, &sa_points).unwrap_or(ctx.options.seam_allowance);
    Ok(Some(Piece {
        name,
        outline,
        grain: [grain.0, grain.1],
        seam_allowance,
        notches,
        fold,
        copies: Default::default(),
        placement: None,
    }))
}

fn to_metres(s: &SubPath, t: &Affine, ctx: &Ctx) -> SubPath {
    let f = |p: P2| ctx.to_m(t, p);
    SubPath {
        start: f(s.start),
        segs: s.segs.iter().map(|g| g.mapped(&f)).collect(),
        closed: s.closed,
    }
}
