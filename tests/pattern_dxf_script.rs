//! DXF-AAMA export from a script (`scripts/pattern_to_dxf.rhai`, `pattern.save_dxf`): a
//! pattern written by the script reads back into the same pattern — pieces corner by corner
//! and along their curves, seams (pairs of edges), notches, grain lines and placements, all
//! coordinates within 0.01 mm — for the A-shirt's garment table and the hand-written AAMA
//! shirt fixture, in each unit. The written file is also read by the Python `ezdxf` library
//! (its auditor and its entities, independent of our reader) where it is installed
//! (`EMILION_PYTHON`, else `python3`); the test says it skipped where not.
#![cfg(feature = "scripting")]

use std::path::{Path, PathBuf};
use std::process::Command;

use emilion::garment::{
    read_garment, read_pattern_dxf, write_pattern_json, Outline, Pattern, Segment, P2,
};
use emilion::script::run_file;

/// 0.01 mm, the acceptance tolerance on coordinates (m).
const TOL: f64 = 1e-5;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the script on `pattern` and returns the folder it wrote.
fn run_script(pattern: &Path, name: &str, units: &str) -> PathBuf {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("pattern_to_dxf_{name}_{units}"));
    let _ = std::fs::remove_dir_all(&out);
    let sets: Vec<(String, String)> = [
        ("out", out.display().to_string()),
        ("pattern", pattern.display().to_string()),
        ("name", name.to_string()),
        ("units", units.to_string()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    if let Err(e) = run_file(&root().join("scripts/pattern_to_dxf.rhai"), &sets) {
        panic!("scripts/pattern_to_dxf.rhai failed:\n{e}");
    }
    out.join("pattern_to_dxf")
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The outline sampled densely: each segment at 400 parameter steps.
fn dense(o: &Outline) -> Vec<P2> {
    let cs = &o.corners;
    let mut pts = Vec::new();
    for (i, c) in cs.iter().enumerate() {
        let end = cs[(i + 1) % cs.len()].at;
        let steps = if c.segment == Segment::Line { 1 } else { 400 };
        pts.extend((0..steps).map(|k| c.segment.point(c.at, end, k as f64 / steps as f64)));
    }
    pts
}

/// Distance from `p` to the closed polygon `poly`.
fn to_polygon(poly: &[P2], p: P2) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let l2 = d[0] * d[0] + d[1] * d[1];
            let t = if l2 > 0.0 {
                (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            dist(p, [a[0] + t * d[0], a[1] + t * d[1]])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Largest distance between two outlines, both ways, on dense samples.
fn outline_gap(a: &Outline, b: &Outline) -> f64 {
    let (pa, pb) = (dense(a), dense(b));
    let ab = pa.iter().map(|&p| to_polygon(&pb, p)).fold(0.0, f64::max);
    let ba = pb.iter().map(|&p| to_polygon(&pa, p)).fold(0.0, f64::max);
    ab.max(ba)
}

/// Checks that `back` is `original` within [`TOL`]; returns the worst corner, outline and
/// notch distances (m).
fn assert_same(original: &Pattern, back: &Pattern, what: &str) -> [f64; 3] {
    let mut worst = [0.0f64; 3];
    let names = |p: &Pattern| p.pieces.iter().map(|x| x.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(original), names(back), "{what}: pieces");
    for (a, b) in original.pieces.iter().zip(&back.pieces) {
        let ca: Vec<(&str, P2)> = a
            .outline
            .corners
            .iter()
            .map(|c| (c.name.as_str(), c.at))
            .collect();
        let cb: Vec<(&str, P2)> = b
            .outline
            .corners
            .iter()
            .map(|c| (c.name.as_str(), c.at))
            .collect();
        assert_eq!(
            ca.len(),
            cb.len(),
            "{what} {}: corners {ca:?} vs {cb:?}",
            a.name
        );
        for (x, y) in ca.iter().zip(&cb) {
            assert_eq!(x.0, y.0, "{what} {}: corner names {ca:?} vs {cb:?}", a.name);
            let d = dist(x.1, y.1);
            worst[0] = worst[0].max(d);
            assert!(d <= TOL, "{what} {}: corner {} moved {d} m", a.name, x.0);
        }
        let gap = outline_gap(&a.outline, &b.outline);
        worst[1] = worst[1].max(gap);
        assert!(gap <= TOL, "{what} {}: outlines {gap} m apart", a.name);
        assert_eq!(
            a.notches.len(),
            b.notches.len(),
            "{what} {}: notches",
            a.name
        );
        for (p, q) in a.notches.iter().zip(&b.notches) {
            let d = dist(*p, *q);
            worst[2] = worst[2].max(d);
            assert!(d <= TOL, "{what} {}: notch {p:?} vs {q:?}", a.name);
        }
        for k in 0..2 {
            assert!(
                dist(a.grain[k], b.grain[k]) <= TOL,
                "{what} {}: grain",
                a.name
            );
        }
        assert_eq!(
            (a.copies, &a.fold),
            (b.copies, &b.fold),
            "{what} {}",
            a.name
        );
        assert!(
            (a.seam_allowance - b.seam_allowance).abs() <= TOL,
            "{what} {}: seam allowance {} vs {}",
            a.name,
            a.seam_allowance,
            b.seam_allowance
        );
        match (&a.placement, &b.placement) {
            (None, None) => {}
            (Some(p), Some(q)) => {
                assert_eq!((p.side, &p.anchor, &p.level), (q.side, &q.anchor, &q.level));
                assert!(
                    (p.x - q.x).abs() <= 1e-9 && (p.dz - q.dz).abs() <= 1e-9,
                    "{what}"
                );
            }
            _ => panic!(
                "{what} {}: placement {:?} vs {:?}",
                a.name, a.placement, b.placement
            ),
        }
    }
    // Seams: the same pairs of edges (piece, from-corner, to-corner), the same way round.
    assert_eq!(original.seams, back.seams, "{what}: seams");
    worst
}

#[test]
fn aaron_round_trips_through_dxf_from_a_script() {
    let source = root().join("scripts/patterns/aaron.garment.json");
    let original = read_garment(&source).unwrap();
    assert_eq!((original.pieces.len(), original.seams.len()), (2, 4));
    for units in ["mm", "cm", "m", "in"] {
        let dir = run_script(&source, "aaron", units);
        let back = read_pattern_dxf(&dir.join("aaron.dxf")).unwrap();
        let w = assert_same(&original, &back, &format!("aaron ({units})"));
        println!(
            "aaron ({units}): worst corner {:.2e} mm, outline {:.2e} mm, notch {:.2e} mm",
            w[0] * 1e3,
            w[1] * 1e3,
            w[2] * 1e3
        );
        // The seams' edges as geometry: both ends of each edge where the original's are.
        for s in &back.seams {
            for e in [&s.a, &s.b] {
                let at = |p: &Pattern, c: &str| {
                    let piece = p.pieces.iter().find(|x| x.name == e.piece).unwrap();
                    piece.outline.corners[piece.outline.corner_index(c).unwrap()].at
                };
                for c in [&e.from, &e.to] {
                    assert!(dist(at(&original, c), at(&back, c)) <= TOL, "{}", s.name);
                }
            }
        }
    }
    let mm = run_script(&source, "aaron", "mm");
    ezdxf_check(&mm.join("aaron.dxf"), &original, 1000.0, 4);
}

#[test]
fn notches_on_curves_and_lines_round_trip() {
    // The A-shirt (no notches of its own) with a notch on each piece's first curve, at a third
    // of its parameter, and one in the middle of its first straight edge, as a JSON pattern.
    let mut original = read_garment(root().join("scripts/patterns/aaron.garment.json")).unwrap();
    for piece in &mut original.pieces {
        let cs = piece.outline.corners.clone();
        let n = cs.len();
        let on = |kind: bool| {
            let i = (0..n)
                .find(|&i| (cs[i].segment == Segment::Line) == kind)
                .unwrap();
            cs[i].segment.point(
                cs[i].at,
                cs[(i + 1) % n].at,
                if kind { 0.5 } else { 1.0 / 3.0 },
            )
        };
        piece.notches = vec![on(false), on(true)];
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("pattern_to_dxf_notched");
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("notched.json");
    write_pattern_json(&original, &json).unwrap();
    let out = run_script(&json, "notched", "mm");
    let back = read_pattern_dxf(&out.join("notched.dxf")).unwrap();
    let w = assert_same(&original, &back, "notched aaron (mm)");
    println!("notched aaron (mm): worst notch {:.2e} mm", w[2] * 1e3);
    ezdxf_check(&out.join("notched.dxf"), &original, 1000.0, 4);
}

#[test]
fn aama_shirt_fixture_round_trips_through_dxf_from_a_script() {
    // The hand-written AAMA fixture (in inches, a pair and a piece on the fold), as the script
    // sees it: pairs doubled and the fold unfolded.
    let source = root().join("tests/data/patterns_dxf/shirt_aama.dxf");
    let original = read_pattern_dxf(&source).unwrap().expanded().unwrap();
    let names: Vec<&str> = original.pieces.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["FRONT_l", "FRONT_r", "BACK"]);
    for units in ["in", "mm"] {
        let dir = run_script(&source, "shirt", units);
        let back = read_pattern_dxf(&dir.join("shirt.dxf")).unwrap();
        let w = assert_same(&original, &back, &format!("shirt ({units})"));
        println!(
            "shirt ({units}): worst corner {:.2e} mm, outline {:.2e} mm, notch {:.2e} mm",
            w[0] * 1e3,
            w[1] * 1e3,
            w[2] * 1e3
        );
    }
    let inches = run_script(&source, "shirt", "in");
    ezdxf_check(&inches.join("shirt.dxf"), &original, 1.0 / 0.0254, 1);
}

#[test]
fn bad_options_are_named() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("pattern_to_dxf_bad");
    std::fs::create_dir_all(&dir).unwrap();
    for (opts, want) in [
        ("#{ units: \"furlong\" }", "furlong"),
        ("#{ unit: \"mm\" }", "unknown option `unit`"),
        ("#{ units: 4 }", "`units` must be a string"),
    ] {
        let script = dir.join("bad.rhai");
        std::fs::write(
            &script,
            format!(
                "let p = garment::pattern(\"{}\");\np.save_dxf(\"{}\", {opts});\n",
                root().join("scripts/patterns/aaron.garment.json").display(),
                dir.join("x.dxf").display()
            ),
        )
        .unwrap();
        let e = run_file(&script, &[]).unwrap_err().to_string();
        assert!(e.contains(want), "{e}");
        assert!(e.contains(":2:"), "the script line: {e}");
    }
}

/// What `ezdxf` sees in the file, as JSON: the auditor's errors, `$INSUNITS`, the ENTITIES
/// texts, and per block its texts, layer 2 points, layer 4 line ends / points, layer 7 lines
/// and layer 14 polyline vertices.
const EZDXF_DUMP: &str = r#"
import json, sys
import ezdxf
doc = ezdxf.readfile(sys.argv[1])
auditor = doc.audit()
def xy(p):
    return [p[0], p[1]]
out = {"errors": [str(e.message) for e in auditor.errors],
       "version": doc.dxfversion,
       "insunits": doc.header.get("$INSUNITS", 0),
       "texts": [e.dxf.text for e in doc.modelspace() if e.dxftype() == "TEXT"],
       "inserts": [e.dxf.name for e in doc.modelspace() if e.dxftype() == "INSERT"],
       "blocks": {}}
for b in doc.blocks:
    if b.name.startswith("*"):
        continue
    d = {"texts": [], "turn": [], "notch": [], "grain": [], "sew": []}
    for e in b:
        t, layer = e.dxftype(), e.dxf.layer
        if t == "TEXT":
            d["texts"].append([e.dxf.text, xy(e.dxf.insert)])
        elif t == "POINT" and layer == "2":
            d["turn"].append(xy(e.dxf.location))
        elif layer == "4":
            d["notch"].append(xy(e.dxf.end) if t == "LINE" else xy(e.dxf.location))
        elif t == "LINE" and layer == "7":
            d["grain"].append([xy(e.dxf.start), xy(e.dxf.end)])
        elif t == "POLYLINE" and layer == "14":
            d["sew"].append([xy(v.dxf.location) for v in e.vertices])
    out["blocks"][b.name] = d
print(json.dumps(out))
"#;

/// Reads `file` with `ezdxf` and checks it against `pattern` (file units per metre
/// `per_m`, `$INSUNITS` `insunits`), without our reader.
fn ezdxf_check(file: &Path, pattern: &Pattern, per_m: f64, insunits: i64) {
    let python = std::env::var("EMILION_PYTHON").unwrap_or_else(|_| "python3".into());
    let probe = Command::new(&python).args(["-c", "import ezdxf"]).output();
    if !probe.map(|o| o.status.success()).unwrap_or(false) {
        println!(
            "skipped: the ezdxf check needs Python with ezdxf ({python} has none; set \
             EMILION_PYTHON to a Python where `pip install ezdxf` ran)"
        );
        return;
    }
    let o = Command::new(&python)
        .args(["-c", EZDXF_DUMP])
        .arg(file)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "ezdxf: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        v["errors"].as_array().unwrap().len(),
        0,
        "ezdxf audit: {}",
        v["errors"]
    );
    assert_eq!(v["version"], "AC1009");
    assert_eq!(v["insunits"].as_i64(), Some(insunits));
    let p2 = |x: &serde_json::Value| -> P2 {
        [
            x[0].as_f64().unwrap() / per_m,
            x[1].as_f64().unwrap() / per_m,
        ]
    };
    let texts: Vec<&str> = v["texts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap())
        .collect();
    assert_eq!(v["inserts"].as_array().unwrap().len(), pattern.pieces.len());
    // Each seam as one layer 15 text, both edges named.
    for s in &pattern.seams {
        let want = format!(
            "Seam: {} | {}: {} > {} | {}: {} > {}",
            s.name, s.a.piece, s.a.from, s.a.to, s.b.piece, s.b.from, s.b.to
        );
        assert!(texts.contains(&want.as_str()), "{want} not in {texts:?}");
    }
    let blocks = v["blocks"].as_object().unwrap();
    for piece in &pattern.pieces {
        let name_text = format!("Piece Name: {}", piece.name);
        let (_, b) = blocks
            .iter()
            .find(|(_, b)| {
                b["texts"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|t| t[0] == name_text.as_str())
            })
            .unwrap_or_else(|| panic!("no block for {}", piece.name));
        let turn: Vec<P2> = b["turn"].as_array().unwrap().iter().map(p2).collect();
        let sew: Vec<P2> = b["sew"][0]
            .as_array()
            .map_or(Vec::new(), |s| s.iter().map(p2).collect());
        let labels: Vec<(String, P2)> = b["texts"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|t| {
                Some((
                    t[0].as_str()?.strip_prefix("Corner: ")?.to_string(),
                    p2(&t[1]),
                ))
            })
            .collect();
        assert_eq!(labels.len(), piece.outline.corners.len(), "{}", piece.name);
        for (c, (label, at)) in piece.outline.corners.iter().zip(&labels) {
            assert_eq!(&c.name, label, "{}", piece.name);
            assert!(dist(c.at, *at) <= TOL, "{} {}: label", piece.name, c.name);
            assert!(
                turn.iter().any(|&t| dist(t, c.at) <= TOL),
                "{} {}: turn point",
                piece.name,
                c.name
            );
            if piece.seam_allowance > 0.0 {
                assert!(
                    sew.iter().any(|&s| dist(s, c.at) <= TOL),
                    "{} {}: sew line",
                    piece.name,
                    c.name
                );
            }
        }
        let notches: Vec<P2> = b["notch"].as_array().unwrap().iter().map(p2).collect();
        assert_eq!(notches.len(), piece.notches.len(), "{}", piece.name);
        for n in &piece.notches {
            assert!(
                notches.iter().any(|&q| dist(q, *n) <= TOL),
                "{}: notch {n:?} in {notches:?}",
                piece.name
            );
        }
        let g = &b["grain"][0];
        assert!(dist(p2(&g[0]), piece.grain[0]) <= TOL && dist(p2(&g[1]), piece.grain[1]) <= TOL);
    }
    println!(
        "ezdxf: {} read with no audit error, entities as written",
        file.display()
    );
}
