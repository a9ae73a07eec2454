//! Script bindings of the facade pipeline: analysing a photo (rectification, parse, grammar),
//! its read-outs, its parse and the label map brought into its frame for scoring, and its
//! output files.

use std::sync::Arc;

use rhai::{Array, Dynamic, Map, INT};

use super::convert::{finite, rt_err, RResult};
use super::facade::Labels;
use super::paths::{read_opt, read_path, write_folder};
use super::{function, getter, modules::ApiBuilder, register};
use crate::facade::analysis::{analyze, Analysis, Options, Rectify};
use crate::facade::facade_mesh::MeshParams;
use crate::facade::grammar::Body;
use crate::facade::homography::warp_labels;
use crate::facade::outputs::{write_generated, write_outputs, OutputOptions};
use crate::facade::rasterize::{rasterize, round_trip};
use crate::facade::rule_file::read_rules;
use crate::facade::{Class, FacadeParse};

/// An analysed photo as a script handle (shared, never copied).
#[derive(Debug, Clone)]
pub struct FacadeAnalysis(pub Arc<Analysis>);

/// A pair of fractions `[a, b]` with 0 < a < b ≤ 1.
fn fractions(d: &Dynamic, what: &str) -> RResult<(f64, f64)> {
    let arr = d
        .read_lock::<Array>()
        .ok_or_else(|| rt_err(format!("`{what}` must be an array [min, max]")))?;
    if arr.len() != 2 {
        return Err(rt_err(format!("`{what}` must have 2 numbers")));
    }
    let (a, b) = (finite(&arr[0], what)?, finite(&arr[1], what)?);
    if !(a > 0.0 && a < b && b <= 1.0) {
        return Err(rt_err(format!(
            "`{what}` must satisfy 0 < min < max ≤ 1, got [{a}, {b}]"
        )));
    }
    Ok((a, b))
}

/// Options from a script map.
fn options(m: &Map) -> RResult<Options> {
    let mut o = Options::default();
    for (k, v) in m {
        match k.as_str() {
            "rectify" => {
                o.rectify = match v.clone().into_string().ok().as_deref() {
                    Some("auto") => Rectify::Auto,
                    Some("none") => Rectify::None,
                    _ => return Err(rt_err("`rectify` must be \"auto\" or \"none\"")),
                }
            }
            "corners" => {
                let arr = v
                    .read_lock::<Array>()
                    .ok_or_else(|| rt_err("`corners` must be an array of 4 points [x, y]"))?;
                if arr.len() != 4 {
                    return Err(rt_err("`corners` must hold 4 points: top-left, top-right, bottom-right, bottom-left"));
                }
                let mut c = [[0.0; 2]; 4];
                for (i, p) in arr.iter().enumerate() {
                    let (x, y) = fractions_free(p, "corners")?;
                    c[i] = [x, y];
                }
                o.rectify = Rectify::Corners(c);
            }
            "floor" => o.priors.floor = fractions(v, "floor")?,
            "tile" => o.priors.tile = fractions(v, "tile")?,
            "window" => o.priors.window = fractions(v, "window")?,
            other => {
                return Err(rt_err(format!(
                    "unknown facade option `{other}` (known: rectify, corners, floor, tile, window)"
                )))
            }
        }
    }
    Ok(o)
}

/// A point `[x, y]` of finite numbers.
fn fractions_free(d: &Dynamic, what: &str) -> RResult<(f64, f64)> {
    let arr = d
        .read_lock::<Array>()
        .ok_or_else(|| rt_err(format!("each of `{what}` must be a point [x, y]")))?;
    if arr.len() != 2 {
        return Err(rt_err(format!("each of `{what}` must be a point [x, y]")));
    }
    Ok((finite(&arr[0], what)?, finite(&arr[1], what)?))
}

/// Positive finite factors from a script array.
fn factors(d: &Dynamic, what: &str) -> RResult<Vec<f64>> {
    let arr = d
        .read_lock::<Array>()
        .ok_or_else(|| rt_err(format!("`{what}` must be an array of numbers")))?;
    arr.iter()
        .map(|v| {
            let f = finite(v, what)?;
            if f > 0.0 {
                Ok(f)
            } else {
                Err(rt_err(format!("`{what}` factors must be > 0, got {f}")))
            }
        })
        .collect()
}

/// Reads the rule file at `rules` and writes the facades it generates (see
/// `facade::from_rules`).
fn from_rules(rules: &str, out: &str, stem: &str, m: &Map) -> RResult<Array> {
    let (mut scale, mut texture) = (0.01, None::<String>);
    let mut opts = OutputOptions {
        widths: vec![1.0],
        heights: vec![],
    };
    for (k, v) in m {
        match k.as_str() {
            "scale" => {
                scale = finite(v, "scale")?;
                if scale <= 0.0 {
                    return Err(rt_err(format!(
                        "`scale` must be > 0 m per unit, got {scale}"
                    )));
                }
            }
            "texture" => {
                texture = Some(
                    v.clone()
                        .into_string()
                        .map_err(|_| rt_err("`texture` must be the path of a PNG"))?,
                )
            }
            "widths" => opts.widths = factors(v, "widths")?,
            "heights" => opts.heights = factors(v, "heights")?,
            other => {
                return Err(rt_err(format!(
                    "unknown option `{other}` (known: scale, texture, widths, heights)"
                )))
            }
        }
    }
    let grammar = read_rules(&read_path(rules)?).map_err(|e| rt_err(e.to_string()))?;
    let params = MeshParams::new(scale, grammar.size);
    let files = write_generated(
        &grammar,
        &params,
        read_opt(texture.as_deref())?.as_deref(),
        &write_folder(out)?,
        stem,
        &opts,
    )
    .map_err(|e| rt_err(e.to_string()))?;
    Ok(files
        .into_iter()
        .map(|p| Dynamic::from(p.display().to_string()))
        .collect())
}

fn run(path: &str, o: &Options) -> RResult<FacadeAnalysis> {
    analyze(&read_path(path)?, o)
        .map(|a| FacadeAnalysis(Arc::new(a)))
        .map_err(|e| rt_err(e.to_string()))
}

/// Registers the facade pipeline functions.
pub fn register(engine: &mut ApiBuilder) {
    engine.register_type_with_name::<FacadeAnalysis>("FacadeAnalysis");
    function!(
        engine,
        "facade::analyze",
        alias = "analyze_facade",
        ["path: String", "FacadeAnalysis"],
        "Analyses a facade photo: automatic rectification from its vanishing points, floors and
tiles by mutual information, the irreducible tile and its window, the shape grammar. An
unreadable file is an error; a failed rectification or parse is reported by `problem`.",
        |path: &str| run(path, &Options::default())
    );
    function!(
        engine,
        "facade::analyze",
        alias = "analyze_facade",
        ["path: String", "options: Map", "FacadeAnalysis"],
        "As `facade::analyze(path)` with options: `rectify` (\"auto\" or \"none\"), `corners`
(four points [x, y] in photo pixels, top-left, top-right, bottom-right, bottom-left: the
facade quadrilateral to rectify instead), `floor` and `tile` ([min, max] as fractions of the
photo's height and width), `window` ([min, max] fractions of a tile).",
        |path: &str, m: Map| run(path, &options(&m)?)
    );
    getter!(
        engine,
        "problem",
        ["a: FacadeAnalysis", "String"],
        "Why the analysis failed or fell back (rectification failed, no facade found), or \"\".",
        |a: &mut FacadeAnalysis| a.0.problem().unwrap_or_default()
    );
    getter!(
        engine,
        "seconds",
        ["a: FacadeAnalysis", "Map"],
        "Seconds per stage: #{read, rectify, floors, tiles, irreducible, window} (or parse
when it failed), and total.",
        |a: &mut FacadeAnalysis| {
            let mut m = Map::new();
            for (k, v) in &a.0.seconds {
                m.insert((*k).into(), Dynamic::from_float(*v));
            }
            m.insert("total".into(), Dynamic::from_float(a.0.total_seconds()));
            m
        }
    );
    getter!(
        engine,
        "megapixels",
        ["a: FacadeAnalysis", "float"],
        "Size of the photo in megapixels.",
        |a: &mut FacadeAnalysis| a.0.photo.width() as f64 * a.0.photo.height() as f64 / 1e6
    );
    getter!(
        engine,
        "structure",
        ["a: FacadeAnalysis", "Map"],
        "The parse: #{floor, tile (pixels), floors, tiles (cells of the layout), windows (the windows
of the grammar: those found one by one, or the layout's cells holding a window), element (the
library element recognised for the windows and inserted by the grammar, e.g. `window_cross`),
element_score (the share of the mean window's variance its front view explains),
element_scores (that share for every window element of the library), frame and sill (the
width of the frame round the windows and the height of the sill below them, pixels, 0 for
none: tile refinement), window_elements (the element each window rule inserts, e.g.
#{Window: \"window_sash\", Window2: \"window_cross\"}: windows of another size whose own
element differs get their own), rules (the rule file)}; empty when the parse failed.",
        |a: &mut FacadeAnalysis| {
            let mut m = Map::new();
            if let Ok((g, s)) = &a.0.parse {
                for (k, v) in [
                    ("floor", s.floor as INT),
                    ("tile", s.tile as INT),
                    ("floors", s.count.0 as INT),
                    ("tiles", s.count.1 as INT),
                    ("frame", s.refinement.frame as INT),
                    ("sill", s.refinement.sill as INT),
                    (
                        "windows",
                        if !s.from_windows {
                            s.present.iter().filter(|&&p| p).count()
                        } else {
                            s.windows.len()
                        } as INT,
                    ),
                ] {
                    m.insert(k.into(), Dynamic::from_int(v));
                }
                if let Some(e) = a.0.elements.iter().find(|e| e.class == Class::Window) {
                    let score = e.scores.iter().find(|s| s.0 == e.element).map_or(0.0, |s| s.1);
                    m.insert("element".into(), Dynamic::from(e.element.clone()));
                    m.insert("element_score".into(), Dynamic::from_float(score));
                    let all: Map = e
                        .scores
                        .iter()
                        .map(|(n, v)| (n.as_str().into(), Dynamic::from_float(*v)))
                        .collect();
                    m.insert("element_scores".into(), Dynamic::from_map(all));
                }
                let per_rule: Map = g
                    .rules
                    .iter()
                    .filter_map(|(n, b)| match b {
                        Body::Insert {
                            class: Class::Window,
                            element,
                        } => Some((n.as_str().into(), Dynamic::from(element.clone()))),
                        _ => None,
                    })
                    .collect();
                m.insert("window_elements".into(), Dynamic::from_map(per_rule));
                m.insert("rules".into(), Dynamic::from(g.to_text()));
            }
            m
        }
    );
    register!(
        engine,
        "facade_parse",
        ["a: FacadeAnalysis", "FacadeParse"],
        "The parse as the scorer reads it (rectified frame): the grammar derived at the photo's
size, a class per pixel and the window rectangles; all wall when the parse failed.",
        |a: &mut FacadeAnalysis| -> RResult<FacadeParse> {
            let (w, h) = (a.0.gray.width, a.0.gray.height);
            match &a.0.parse {
                Ok((g, _)) => Ok(rasterize(
                    &g.derive(w as f64, h as f64).map_err(rt_err)?,
                    w,
                    h,
                )),
                Err(_) => Ok(FacadeParse::all_wall(w, h)),
            }
        }
    );
    register!(
        engine,
        "rectified_labels",
        ["a: FacadeAnalysis", "labels: FacadeLabels", "FacadeLabels"],
        "A label map of the photo brought into the analysis' rectified frame (nearest pixel;
outside the photo: ignored), to score the parse where it was made.",
        |a: &mut FacadeAnalysis, l: Labels| -> RResult<Labels> {
            let (w, h) = (a.0.gray.width, a.0.gray.height);
            if (l.0.width, l.0.height) != (a.0.photo.width(), a.0.photo.height()) {
                return Err(rt_err(format!(
                    "label map {}×{} does not match the photo {}×{}",
                    l.0.width,
                    l.0.height,
                    a.0.photo.width(),
                    a.0.photo.height()
                )));
            }
            warp_labels(&l.0, &a.0.homography, w, h)
                .map(Labels)
                .ok_or_else(|| rt_err("the rectification is singular"))
        }
    );
    register!(
        engine,
        "facade_round_trip",
        ["a: FacadeAnalysis", "float"],
        "Share of pixels on which the rule file, read back and derived at the photo's size,
agrees with the parse (1 = lossless); 0 when the parse failed.",
        |a: &mut FacadeAnalysis| -> RResult<f64> {
            match &a.0.parse {
                Ok((g, _)) => round_trip(g, a.0.gray.width, a.0.gray.height).map_err(rt_err),
                Err(_) => Ok(0.0),
            }
        }
    );
    function!(
        engine,
        "facade::from_rules",
        alias = "facade_from_rules",
        [
            "rules: String",
            "out: String",
            "stem: String",
            "options: Map",
            "Array"
        ],
        "Reads a rule file (as `write_facade_outputs` writes them, or written by hand: `split`,
`repeat`, class leaves and `insert(window, window_cross)` of the element library) and writes
the 3D facades it generates at its own size times each factor: out/STEM_w1.obj/.mtl/.glb and a
render STEM_w1.png, … Options: #{scale (metres per facade unit, 0.01), texture (the PNG its
sizes refer to, none by default), widths ([1.0]), heights ([])}. Errors name the file and line.
Returns the paths.",
        |rules: &str, out: &str, stem: &str, options: Map| -> RResult<Array> {
            from_rules(rules, out, stem, &options)
        }
    );
    register!(
        engine,
        "write_facade_outputs",
        ["a: FacadeAnalysis", "dir: String", "stem: String", "Array"],
        "Writes STEM_overlay.png (always: the structure over the rectified photo, or the
segments seen when the analysis failed) and, after a parse, STEM_rectified.png,
STEM_labels.png, STEM.cga (the rules) and 3D facades at 1×, 0.75× and 1.5× the width
(STEM_w1.obj/.mtl/.glb, …, textured with the rectified photo) with a render of each
(STEM_w1.png, …). Returns the paths.",
        |a: &mut FacadeAnalysis, dir: &str, stem: &str| -> RResult<Array> {
            let files = write_outputs(&a.0, &write_folder(dir)?, stem, &OutputOptions::default())
                .map_err(|e| rt_err(e.to_string()))?;
            Ok(files
                .into_iter()
                .map(|p| Dynamic::from(p.display().to_string()))
                .collect())
        }
    );
}
