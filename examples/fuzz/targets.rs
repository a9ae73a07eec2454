//! The fuzz targets: one per reader, each a function from the bytes of a file to `Ok` or an
//! error message. A target calls the reader as a user's file would reach it (parse, then
//! validate where the public path validates), so an `Err` is a clear refusal and only a panic,
//! an abort, a hang or a runaway allocation is a finding. Shared by the harness
//! (`examples/fuzz/main.rs`) and the corpus replay (`tests/fuzz_corpus.rs`).

use std::path::Path;

/// One reader under fuzz.
pub struct Target {
    /// Its name: `--reader NAME` and its corpus folder `tests/fuzz/NAME/`.
    pub name: &'static str,
    /// The extension a saved case gets (`obj`, `svg`, …).
    pub ext: &'static str,
    /// Whether the input is text (structure-aware text mutations apply).
    pub text: bool,
    /// Words and fragments of the format that mutations insert.
    pub dictionary: &'static [&'static str],
    /// Reads one input.
    pub run: fn(&[u8]) -> Result<(), String>,
}

/// Every target, in the order the documentation lists them.
pub fn all() -> Vec<Target> {
    vec![
        Target {
            name: "obj",
            ext: "obj",
            text: true,
            dictionary: &[
                "v ", "vt ", "vn ", "f ", "g ", "o ", "usemtl ", "mtllib ", "s off", "/", "//",
                "-1", "0", "\n", "#",
            ],
            run: obj,
        },
        Target {
            name: "svg",
            ext: "svg",
            text: true,
            dictionary: &[
                "<g>",
                "</g>",
                "<path d=\"",
                "\"/>",
                "<rect ",
                "<polygon points=\"",
                "<circle ",
                "viewBox=\"",
                "width=\"",
                "height=\"",
                "transform=\"",
                "matrix(",
                "scale(",
                "rotate(",
                "translate(",
                "M",
                "L",
                "C",
                "Q",
                "A",
                "Z",
                "H",
                "V",
                "mm",
                "cm",
                "in",
                "id=\"",
                "<!--",
                "-->",
                "<![CDATA[",
                "]]>",
                "&amp;",
                "<?xml ?>",
                "<defs>",
                "<use href=\"#",
                "class=\"",
                "style=\"",
            ],
            run: svg,
        },
        Target {
            name: "dxf",
            ext: "dxf",
            text: true,
            dictionary: &[
                "  0\n",
                "SECTION\n",
                "ENDSEC\n",
                "EOF\n",
                "  2\nENTITIES\n",
                "  2\nBLOCKS\n",
                "POLYLINE\n",
                "VERTEX\n",
                "SEQEND\n",
                "LINE\n",
                "POINT\n",
                "TEXT\n",
                "BLOCK\n",
                "ENDBLK\n",
                "INSERT\n",
                " 10\n",
                " 20\n",
                " 30\n",
                "  8\n",
                "  1\n",
                " 66\n",
                "  9\n$INSUNITS\n",
                " 70\n",
                "Piece Name: ",
                "Quantity: ",
            ],
            run: dxf,
        },
        Target {
            name: "pattern",
            ext: "json",
            text: true,
            dictionary: &[
                "{",
                "}",
                "[",
                "]",
                ",",
                ":",
                "\"pieces\"",
                "\"name\"",
                "\"outline\"",
                "\"corners\"",
                "\"seams\"",
                "\"fold\"",
                "\"pair\"",
                "\"notches\"",
                "\"grain\"",
                "null",
                "true",
                "[0.0, 0.0]",
            ],
            run: pattern,
        },
        Target {
            name: "fabric",
            ext: "json",
            text: true,
            dictionary: &[
                "{",
                "}",
                "[",
                "]",
                ",",
                ":",
                "\"format\"",
                "\"emilion-fabric-1\"",
                "\"kes\"",
                "\"curves\"",
                "\"warp\"",
                "\"weft\"",
                "\"loading\"",
                "\"unloading\"",
                "\"weight\"",
                "\"thickness\"",
                "\"LT\"",
                "\"WT\"",
                "\"RT\"",
                "\"EMT\"",
                "\"G\"",
                "\"2HG\"",
                "\"2HG5\"",
                "\"B\"",
                "\"2HB\"",
                "\"unit\"",
                "\"value\"",
                "\"gf/cm\"",
                "\"%\"",
                "\"mg/cm2\"",
                "\"mm\"",
                "null",
            ],
            run: fabric,
        },
        Target {
            name: "bvh",
            ext: "bvh",
            text: true,
            dictionary: &[
                "HIERARCHY\n",
                "ROOT ",
                "JOINT ",
                "End Site",
                "{\n",
                "}\n",
                "OFFSET ",
                "CHANNELS ",
                "6 ",
                "3 ",
                "Xposition ",
                "Yposition ",
                "Zposition ",
                "Xrotation ",
                "Yrotation ",
                "Zrotation ",
                "MOTION\n",
                "Frames: ",
                "Frame Time: ",
                "\n",
            ],
            run: bvh,
        },
        Target {
            name: "c3d",
            ext: "c3d",
            text: false,
            dictionary: &[
                "POINT",
                "USED",
                "SCALE",
                "RATE",
                "LABELS",
                "UNITS",
                "Y_SCREEN",
                "\u{50}",
                "T",
                "mm",
                "\u{ff}\u{ff}",
                "\u{0}\u{0}",
            ],
            run: c3d,
        },
        Target {
            name: "pts",
            ext: "pts",
            text: true,
            dictionary: &["version: 1\n", "n_points: ", "{\n", "}\n", "\n", " "],
            run: pts,
        },
        Target {
            name: "facade",
            ext: "cga",
            text: true,
            dictionary: &[
                "// axiom ",
                " size ",
                "-->",
                "split(x){",
                "split(y){",
                "repeat(x,",
                "repeat(y,",
                "insert(window, window_cross)",
                "}",
                "|",
                "~",
                ":",
                "window",
                "wall",
                "door",
                "balcony",
                "Facade",
                "Floor",
                "Tile",
                "\n",
            ],
            run: facade,
        },
        Target {
            name: "image",
            ext: "bin",
            text: false,
            dictionary: &[
                "\u{89}PNG\r\n\u{1a}\n",
                "IHDR",
                "IDAT",
                "IEND",
                "PLTE",
                "tRNS",
                "\u{ff}\u{d8}\u{ff}",
                "\u{ff}\u{c0}",
                "\u{ff}\u{c4}",
                "\u{ff}\u{da}",
                "\u{ff}\u{d9}",
                "BM",
                "P6\n",
                "P5\n",
                "255\n",
                "II*\0",
                "MM\0*",
                "RIFF",
                "WEBPVP8 ",
            ],
            run: image,
        },
        Target {
            name: "script",
            ext: "rhai",
            text: true,
            dictionary: &[],
            run: script,
        },
    ]
}

/// The target called `name`.
pub fn by_name(name: &str) -> Option<Target> {
    all().into_iter().find(|t| t.name == name)
}

fn text(data: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(data)
}

fn obj(data: &[u8]) -> Result<(), String> {
    use emilion::geometry::obj::{
        obj_mesh_from_text, obj_polygons_from_text, obj_surface_from_text,
    };
    let (t, p) = (text(data), Path::new("fuzz.obj"));
    let surface = obj_surface_from_text(&t, p).map(|(v, tris)| {
        assert!(
            tris.iter().flatten().all(|&i| i < v.len()),
            "surface index out of range"
        );
    });
    let polygons = obj_polygons_from_text(&t, p).map(|o| {
        for f in &o.faces {
            assert!(f.corners.iter().all(|c| c[0] < o.positions.len()));
        }
    });
    let mesh = obj_mesh_from_text(&t, p).map(|m| {
        assert!(m.triangles.iter().flatten().all(|&i| i < m.positions.len()));
    });
    surface.and(polygons).and(mesh).map_err(|e| e.to_string())
}

fn svg(data: &[u8]) -> Result<(), String> {
    use emilion::garment::formats::svg::parse_pattern_svg;
    let options = emilion::garment::SvgOptions::default();
    let pattern = parse_pattern_svg(&text(data), Path::new("fuzz.svg"), &options)
        .map_err(|e| e.to_string())?;
    pattern.validate().map_err(|e| e.to_string())
}

fn dxf(data: &[u8]) -> Result<(), String> {
    let pattern = emilion::garment::parse_pattern_dxf(data, Path::new("fuzz.dxf"))
        .map_err(|e| e.to_string())?;
    pattern.validate().map_err(|e| e.to_string())
}

fn pattern(data: &[u8]) -> Result<(), String> {
    use emilion::garment::formats::json::parse_pattern_json;
    let pattern =
        parse_pattern_json(&text(data), Path::new("fuzz.json")).map_err(|e| e.to_string())?;
    pattern.validate().map_err(|e| e.to_string())?;
    pattern.expanded().map(|_| ()).map_err(|e| e.to_string())
}

fn fabric(data: &[u8]) -> Result<(), String> {
    emilion::kes::fabric::parse_fabric(&text(data), "fuzz.json")
        .map(|_| ())
        .map_err(|e| e.to_string())
}

fn bvh(data: &[u8]) -> Result<(), String> {
    let motion =
        emilion::body::Motion::parse_bvh(&text(data), "fuzz.bvh").map_err(|e| e.to_string())?;
    let last = motion.frame_count().saturating_sub(1);
    for f in [0, last] {
        let _ = motion.joint_positions(f);
    }
    let _ = motion.duration();
    Ok(())
}

fn c3d(data: &[u8]) -> Result<(), String> {
    let trial = emilion::body::markers::parse_c3d(data, "fuzz.c3d").map_err(|e| e.to_string())?;
    let _ = trial.invalid_count();
    let _ = trial.infer_up();
    if trial.frames > 0 && trial.markers() > 0 {
        let _ = trial.world(trial.frames - 1, trial.markers() - 1);
    }
    Ok(())
}

fn pts(data: &[u8]) -> Result<(), String> {
    emilion::face::landmarks::parse_pts(&text(data), Path::new("fuzz.pts"))
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// A rule file as `facade_from_rules` uses it: parsed, then derived at its own size.
fn facade(data: &[u8]) -> Result<(), String> {
    let g = emilion::facade::grammar::Grammar::parse(&text(data))?;
    g.derive(g.size.0, g.size.1)?;
    Ok(())
}

fn image(data: &[u8]) -> Result<(), String> {
    emilion::geometry::image::photo_formats::decode_photo(data, Path::new("fuzz.img"))
        .map(|_| ())
        .map_err(|e| e.to_string())
}

thread_local! {
    static ENGINE: rhai::Engine = {
        let mut e = emilion::script::build_engine();
        e.on_print(|_| {});
        e.on_debug(|_, _, _| {});
        e
    };
}

/// A script: run with `out` set to a scratch folder (every generated script writes there), under
/// a 1 s time budget as `emilion run --max-seconds 1` gives it: a legitimately long run (say
/// `s.run(1e5)` on a small cloth, 10⁷ steps) must stop at its budget with an error, not hang.
///
/// It runs under `--limit max_particles=500000` too: the default 4 000 000 particles lets a script
/// mesh or build a cloth that needs more than the harness's 1 GB cap (case 160194 of seed 1:
/// `cloth_patch(1.2, 1.21, 0.001)`, 1.7e6 vertices, a 563 MB buffer on top of the mesher's).
fn script(data: &[u8]) -> Result<(), String> {
    emilion::limits::set_deadline(std::time::Duration::from_secs(1));
    let mut limits = emilion::limits::get();
    limits.max_particles = 500_000;
    emilion::limits::set(limits);
    let out = std::env::temp_dir().join(format!("emilion-fuzz-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&out);
    let mut scope = rhai::Scope::new();
    scope.push("out", out.display().to_string());
    ENGINE.with(|e| {
        e.run_with_scope(&mut scope, &text(data))
            .map_err(|e| e.to_string())
    })
}
