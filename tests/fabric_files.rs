//! Fabric files (`emilion-fabric-1`): the example fabrics, bad files whose errors name the
//! file and the field, write → read round trips, and the run-time import of the Wang 2011
//! fabrics checked against values computed by hand from their tables.

use std::path::{Path, PathBuf};

use emilion::kes::fabric::parse_fabric;
use emilion::kes::{
    import_wang, import_wang_dir, read_fabric, read_fabric_dir, write_fabric, Curve, FabricSpec,
    KesError, KesParam,
};

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn wang_dir() -> PathBuf {
    PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/fabrics/wang2011"
    ))
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("emilion-{tag}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

/// Every SI value of `a` and `b` agrees to 1e-12 relative; `path` may differ.
fn assert_same_spec(a: &FabricSpec, b: &FabricSpec) {
    assert_eq!(a.name, b.name);
    assert_eq!(a.description, b.description);
    assert_eq!(a.provenance, b.provenance);
    assert!(close(a.density, b.density, 1e-12), "{}", a.name);
    assert!(close(a.tensile_fm, b.tensile_fm, 1e-12), "{}", a.name);
    assert_eq!(a.thickness.is_some(), b.thickness.is_some());
    if let (Some(x), Some(y)) = (a.thickness, b.thickness) {
        assert!(close(x, y, 1e-12));
    }
    for (da, db) in [(&a.warp, &b.warp), (&a.weft, &b.weft)] {
        assert_eq!(
            da.values.keys().collect::<Vec<_>>(),
            db.values.keys().collect::<Vec<_>>()
        );
        for (p, v) in &da.values {
            assert!(close(*v, db.get(*p).unwrap(), 1e-12), "{} {p:?}", a.name);
        }
    }
    let slots = |s: &FabricSpec| {
        let c = &s.curves;
        [
            c.tensile_warp.clone(),
            c.tensile_weft.clone(),
            c.tensile_bias.clone(),
            c.shear.clone(),
            c.bending_warp.clone(),
            c.bending_weft.clone(),
            c.bending_bias.clone(),
        ]
    };
    for (k, (ca, cb)) in slots(a).into_iter().zip(slots(b)).enumerate() {
        assert_eq!(ca.is_some(), cb.is_some(), "{} curve {k}", a.name);
        let (Some(ca), Some(cb)) = (ca, cb) else {
            continue;
        };
        for (pa, pb) in [(&ca.loading, &cb.loading), (&ca.unloading, &cb.unloading)] {
            assert_eq!(pa.len(), pb.len(), "{} curve {k}", a.name);
            for (p, q) in pa.iter().zip(pb) {
                for i in 0..2 {
                    assert!(
                        (p[i] - q[i]).abs() <= 1e-12 * p[i].abs(),
                        "{} curve {k}: {p:?} vs {q:?}",
                        a.name
                    );
                }
            }
        }
    }
}

// ---------------------------------------------------------------- our example fabrics

#[test]
fn example_fabrics_have_full_kes_sets_in_si() {
    let specs = read_fabric_dir(&repo("kawabata/fabrics")).unwrap();
    let names: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["shirting-cotton", "suiting-hesc"]);
    for s in &specs {
        assert_eq!(s.warp.values.len(), 17, "{}", s.name);
        assert_eq!(s.weft.values.len(), 17, "{}", s.name);
        assert!(s.provenance.contains("not a measured fabric"), "{}", s.name);
        assert!(s.curves.tensile_warp.is_none() && s.curves.shear.is_none());
        // default protocol: Fm = 500 gf/cm = 490.3325 N/m
        assert!(close(s.tensile_fm, 490.3325, 1e-12));
    }
    let suiting = &specs[1];
    assert!(close(suiting.density, 0.22, 1e-12)); // 22 mg/cm²
    assert!(close(suiting.thickness.unwrap(), 0.6e-3, 1e-12));
    let w = &suiting.warp;
    assert!(close(w.get(KesParam::Emt).unwrap(), 0.047, 1e-12));
    assert!(close(suiting.weft.get(KesParam::Emt).unwrap(), 0.12, 1e-12));
    assert!(close(w.get(KesParam::Lt).unwrap(), 0.55, 1e-12));
    assert!(close(w.get(KesParam::Rt).unwrap(), 0.75, 1e-12));
    // G 0.575 gf/(cm·deg) × 56.18797
    assert!(close(w.get(KesParam::G).unwrap(), 32.3080827, 1e-7));
    assert!(close(
        w.get(KesParam::Hg52).unwrap(),
        1.15 * 0.980665,
        1e-12
    ));
    assert!(close(w.get(KesParam::B).unwrap(), 0.10 * 9.80665e-5, 1e-12));
    assert!(close(
        suiting.weft.get(KesParam::Hb2).unwrap(),
        0.035 * 9.80665e-3,
        1e-12
    ));
    let shirting = &specs[0];
    assert!(close(shirting.density, 0.12, 1e-12));
    assert!(close(
        shirting.warp.get(KesParam::Emt).unwrap(),
        0.03,
        1e-12
    ));
    assert!(close(
        shirting.weft.get(KesParam::Emt).unwrap(),
        0.06,
        1e-12
    ));
    assert!(close(
        shirting.warp.get(KesParam::G).unwrap(),
        0.9 * 56.18797,
        1e-6
    ));
}

#[test]
fn example_fabrics_round_trip_through_write_and_read() {
    let dir = temp_dir("fabric-rt");
    for name in ["suiting-hesc", "shirting-cotton"] {
        let spec = read_fabric(&repo(&format!("kawabata/fabrics/{name}.json"))).unwrap();
        let out = dir.join(format!("{name}.json"));
        write_fabric(&out, &spec).unwrap();
        let back = read_fabric(&out).unwrap();
        assert_eq!(back.path, out.display().to_string());
        assert_same_spec(&spec, &back);
        // written in KES units
        let text = std::fs::read_to_string(&out).unwrap();
        for unit in [
            "\"mg/cm2\"",
            "\"gf.cm2/cm\"",
            "\"gf/(cm.deg)\"",
            "\"%\"",
            "\"gf/cm\"",
        ] {
            assert!(text.contains(unit), "{name}: no {unit}");
        }
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn a_spec_with_curves_round_trips() {
    let mut spec = read_fabric(&repo("kawabata/fabrics/shirting-cotton.json")).unwrap();
    spec.path = String::new();
    spec.thickness = None;
    spec.tensile_fm = 49.03325; // 50 gf/cm
    spec.curves.tensile_warp = Some(Curve {
        loading: vec![[0.0, 0.0], [0.01, 12.3], [0.03, 49.2]],
        unloading: vec![[0.03, 49.2], [0.02, 20.0], [0.005, 0.0]],
    });
    spec.curves.shear = Some(Curve {
        loading: vec![[-0.1, -3.0], [0.0, 0.1], [0.1, 3.2]],
        unloading: Vec::new(),
    });
    spec.curves.bending_bias = Some(Curve {
        loading: vec![[0.0, 0.0], [25.0, 1.7e-4], [250.0, 2.2e-3]],
        unloading: Vec::new(),
    });
    let dir = temp_dir("fabric-curves");
    let out = dir.join("sub/curves.json");
    write_fabric(&out, &spec).unwrap();
    let back = read_fabric(&out).unwrap();
    assert_same_spec(&spec, &back);
    // 50 gf/cm and the strain in % on disk
    let text = std::fs::read_to_string(&out).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert!(close(
        v["protocol"]["tensile_fm"]["value"].as_f64().unwrap(),
        50.0,
        1e-12
    ));
    assert!(close(
        v["curves"]["tensile_warp"]["loading"][2][0]
            .as_f64()
            .unwrap(),
        3.0,
        1e-12
    ));
    assert_eq!(v["curves"]["bending_bias"]["x_unit"], "1/cm");
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn writing_a_spec_that_could_not_be_read_back_is_an_error() {
    let mut spec = read_fabric(&repo("kawabata/fabrics/suiting-hesc.json")).unwrap();
    spec.warp.set(KesParam::B, f64::NAN);
    let dir = temp_dir("fabric-bad-write");
    let out = dir.join("nan.json");
    let err = write_fabric(&out, &spec).unwrap_err().to_string();
    assert!(
        err.contains("nan.json") && err.contains("kes.warp.B"),
        "{err}"
    );
    assert!(!out.exists());
    spec.warp.set(KesParam::B, 1e-5);
    spec.weft.set(KesParam::G, -1.0);
    let err = write_fabric(&out, &spec).unwrap_err().to_string();
    assert!(err.contains("kes.weft.G"), "{err}");
    std::fs::remove_dir_all(dir).ok();
}

// ---------------------------------------------------------------- bad files

#[test]
fn bad_files_name_the_file_and_the_field() {
    let cases = [
        ("missing_weight.json", "`weight`", "missing"),
        ("wrong_unit.json", "kes.warp.B", "gf/cm"),
        ("negative_g.json", "kes.weft.G", "≥ 0"),
        ("nan_value.json", "kes.warp.EMT", "number"),
        ("string_value.json", "weight.value", "number"),
        ("bad_curve.json", "curves.shear.loading[2]", "increase"),
        (
            "short_curve.json",
            "curves.tensile_warp.loading",
            "2 points",
        ),
        ("curve_unit.json", "curves.bending_weft.x_unit", "deg"),
        ("unknown_key.json", "colour", "unknown"),
        ("unknown_param.json", "kes.warp.BB", "unknown KES parameter"),
        ("rt_over_100.json", "kes.weft.RT", "100 %"),
    ];
    for (file, field, problem) in cases {
        let path = repo("tests/data/fabrics_bad").join(file);
        let err = read_fabric(&path).expect_err(file);
        assert!(matches!(err, KesError::Field { .. }), "{file}: {err:?}");
        let msg = err.to_string();
        assert!(msg.contains(file), "{msg}");
        assert!(msg.contains(field), "{file}: {msg}");
        assert!(msg.contains(problem), "{file}: {msg}");
    }
}

#[test]
fn json_syntax_errors_name_file_line_and_column() {
    // the missing comma is on line 3, before `"unit"` at column 26
    let path = repo("tests/data/fabrics_bad/syntax_error.json");
    let err = read_fabric(&path).unwrap_err();
    match &err {
        KesError::Syntax { line, column, .. } => {
            assert_eq!((*line, *column), (3, 26), "{err}");
        }
        e => panic!("{e:?}"),
    }
    assert!(err.to_string().contains("syntax_error.json:3:26:"), "{err}");
    // a file cut short: the error is at its end (line 3, after the last newline)
    let err = read_fabric(&repo("tests/data/fabrics_bad/malformed.json")).unwrap_err();
    assert!(matches!(err, KesError::Syntax { line: 3, .. }), "{err:?}");
    assert!(err.to_string().contains("malformed.json:3:"), "{err}");
    // a file that is not there
    let err = read_fabric(&repo("tests/data/fabrics_bad/absent.json")).unwrap_err();
    assert!(matches!(err, KesError::Io { .. }) && err.to_string().contains("absent.json"));
}

#[test]
fn more_bad_values_in_memory() {
    let head =
        r#""format": "emilion-fabric-1", "name": "t", "weight": {"value": 20, "unit": "mg/cm2"}"#;
    let cases = [
        // number too large for f64
        (format!(r#"{{ {head}, "thickness": {{"value": 1e999, "unit": "mm"}} }}"#), "mem.json:1:"),
        (
            format!(r#"{{ {head}, "kes": {{"warp": {{"LT": {{"value": 1.2, "unit": "-"}}}}}} }}"#),
            "kes.warp.LT",
        ),
        (
            format!(r#"{{ {head}, "kes": {{"bias": {{}}}} }}"#),
            "kes.bias",
        ),
        (
            format!(r#"{{ {head}, "kes": {{"warp": {{"B": {{"value": 0.1}}}}}} }}"#),
            "kes.warp.B",
        ),
        (
            format!(
                r#"{{ {head}, "curves": {{"shear": {{"x_unit": "deg", "y_unit": "gf/cm", "loading": [[0, 0], [1, 2]], "unloading": [[1, 2]]}}}} }}"#
            ),
            "curves.shear.unloading",
        ),
        (
            format!(
                r#"{{ {head}, "curves": {{"shear": {{"x_unit": "deg", "y_unit": "gf/cm", "loading": [[0, 0], [1, "2"]]}}}} }}"#
            ),
            "curves.shear.loading[1]",
        ),
        (
            format!(r#"{{ {head}, "curves": {{"drape": {{}}}} }}"#),
            "curves.drape",
        ),
        (
            format!(r#"{{ {head}, "protocol": {{"tensile_fm": {{"value": 0, "unit": "gf/cm"}}}} }}"#),
            "protocol.tensile_fm",
        ),
        (
            r#"{ "format": "emilion-fabric-1", "name": "t", "weight": {"value": -2, "unit": "mg/cm2"} }"#
                .to_string(),
            "weight",
        ),
        (
            r#"{ "format": "emilion-fabric-2", "name": "t", "weight": {"value": 2, "unit": "mg/cm2"} }"#
                .to_string(),
            "format",
        ),
        (r#"[1, 2]"#.to_string(), "(root)"),
    ];
    for (text, field) in cases {
        let err = parse_fabric(&text, "mem.json")
            .expect_err(&text)
            .to_string();
        assert!(err.contains("mem.json"), "{err}");
        assert!(err.contains(field), "{text}\n→ {err}");
    }
    // the same text with valid values reads
    let ok = format!(r#"{{ {head}, "kes": {{"warp": {{"LT": {{"value": 1.0, "unit": "-"}}}}}} }}"#);
    assert!(parse_fabric(&ok, "mem.json").is_ok());
}

#[test]
fn kes_parameter_names() {
    let names = [
        "EMT", "LT", "WT", "RT", "G", "2HG", "2HG5", "B", "2HB", "LC", "WC", "RC", "T0", "TM",
        "MIU", "MMD", "SMD",
    ];
    for n in names {
        assert_eq!(KesParam::from_name(n).map(|p| p.name()), Some(n));
    }
    assert_eq!(KesParam::from_name("2HG5"), Some(KesParam::Hg52));
    assert_eq!(KesParam::from_name("2HB"), Some(KesParam::Hb2));
    assert_eq!(KesParam::from_name("emt"), None);
}

// ---------------------------------------------------------------- Wang 2011 import

fn point_at(c: &[[f64; 2]], x: f64) -> [f64; 2] {
    *c.iter()
        .find(|p| (p[0] - x).abs() < 1e-9 * x.abs().max(1.0))
        .unwrap_or_else(|| panic!("no sample at {x}"))
}

#[test]
fn wang_denim_matches_hand_computed_values() {
    let dir = wang_dir();
    if !dir.exists() {
        eprintln!("skipped: {} not found", dir.display());
        return;
    }
    let d = import_wang(&dir.join("11oz-black-denim.json")).unwrap();
    assert_eq!(d.name, "11oz-black-denim");
    assert!(close(d.density, 0.324, 1e-12));
    assert!(d.warp.values.is_empty() && d.weft.values.is_empty());
    for s in [
        "11oz-black-denim.json",
        "10.1145/2010324.1964966",
        "ARCSim",
        "u taken as the warp",
    ] {
        assert!(d.provenance.contains(s), "provenance lacks {s}");
    }
    let c = &d.curves;
    // tensile warp: 35 samples, 0 … 1/6
    let tw = &c.tensile_warp.as_ref().unwrap().loading;
    assert_eq!(tw.len(), 35);
    assert_eq!(tw[0], [0.0, 0.0]);
    // ε = 0.5 %: k = 2 (205.352005 + 0.03 (232.027634 − 205.352005)) = 412.30454774,
    // F = 1.005 · k · 0.0050125 = 2.07700993 N/m
    assert!(close(tw[1][0], 0.005, 1e-12));
    assert!(close(tw[1][1], 2.07700993, 1e-8), "{:?}", tw[1]);
    // small-strain slope ≈ 2 c11 = 410.70 N/m
    assert!(close(tw[1][1] / tw[1][0], 410.704, 0.02));
    // end: ε = 1/6, F = 7/6 · 2 · 232.027634 · 13/72 = 97.7523828 N/m
    let end = tw.last().unwrap();
    assert!(close(end[0], 1.0 / 6.0, 1e-12));
    assert!(close(end[1], 97.7523828, 1e-8), "{end:?}");
    // weft: c22 row 5: 7/6 · 2 · 1051.55712 · 13/72 = 443.01712 N/m; Fm = the larger end
    let tf = c.tensile_weft.as_ref().unwrap().loading.last().unwrap();
    assert!(close(tf[1], 443.01712, 1e-8), "{tf:?}");
    assert!(close(d.tensile_fm, 443.01712, 1e-8));
    // bias, row 3: (7/6)(13/72) · 2 (225.951050 + 1059.59741 + 2 · 62.095657 + 83.992020)/4
    // = 157.325918 N/m at 1/6; at 0.5 %: 3.27218091 N/m; slope at 0 → (c11 + c22 + 2 c12 + c33)/2
    // = 646.547 N/m
    let tb = &c.tensile_bias.as_ref().unwrap().loading;
    assert!(close(tb.last().unwrap()[1], 157.325918, 1e-8), "{tb:?}");
    assert!(close(tb[1][1], 3.27218091, 1e-8), "{:?}", tb[1]);
    assert!(close(tb[1][1] / tb[1][0], 646.547, 0.02));
    // shear at 4°: c33 = 53.387184 + 3φ (83.992020 − 53.387184), H = c33/2 φ + 9.80665 tan φ
    // = 2.77305844 N/m; 17 samples 0 … 8°
    let sh = &c.shear.as_ref().unwrap().loading;
    assert_eq!(sh.len(), 17);
    assert!(close(sh.last().unwrap()[0], 8f64.to_radians(), 1e-12));
    let s4 = point_at(sh, 4f64.to_radians());
    assert!(close(s4[1], 2.77305844, 1e-8), "{s4:?}");
    // bending weft = hinge row 0: M(10 1/m) = 60.286175e-6 · 10; M(2.5 1/m) =
    // lerp(64.196457, 60.286175, 0.25)e-6 · 2.5 = 158.047216e-6 N
    let bw = &c.bending_weft.as_ref().unwrap().loading;
    assert!(close(point_at(bw, 10.0)[1], 60.286175e-5, 1e-12));
    assert!(close(point_at(bw, 2.5)[1], 158.047216e-6, 1e-8));
    // bending bias = row 1: M(10) = 59.671982e-6 · 10
    let bb = &c.bending_bias.as_ref().unwrap().loading;
    assert!(close(point_at(bb, 10.0)[1], 59.671982e-5, 1e-12));
    // bending warp = row 2; M(30) = 120.569740e-6 · 30 = 3.6170922e-3 N; beyond, the table's
    // drop to 79.78e-6 at 40 1/m makes M fall (3.587e-3 at 32.5), so the curve ends at 30
    let bp = &c.bending_warp.as_ref().unwrap().loading;
    assert_eq!(bp.len(), 13);
    assert!(close(bp.last().unwrap()[0], 30.0, 1e-12));
    assert!(close(bp.last().unwrap()[1], 3.6170922e-3, 1e-8));
}

#[test]
fn all_ten_wang_fabrics_import_with_sane_curves_and_round_trip() {
    let dir = wang_dir();
    if !dir.exists() {
        eprintln!("skipped: {} not found", dir.display());
        return;
    }
    let out = temp_dir("wang-import");
    let files = import_wang_dir(&dir, &out).unwrap();
    assert_eq!(files.len(), 10);
    let stems: Vec<String> = files
        .iter()
        .map(|f| f.file_stem().unwrap().to_string_lossy().to_string())
        .collect();
    let mut sorted = stems.clone();
    sorted.sort();
    assert_eq!(stems, sorted);
    assert_eq!(stems[0], "11oz-black-denim");
    assert_eq!(stems[9], "white-swim-solid");
    let densities = [
        0.324, 0.284, 0.187, 0.276, 0.224, 0.228, 0.220, 0.113, 0.128, 0.204,
    ];
    for (f, rho) in files.iter().zip(densities) {
        let src = dir.join(f.file_name().unwrap());
        let direct = import_wang(&src).unwrap();
        let back = read_fabric(f).unwrap();
        assert_same_spec(&direct, &back);
        assert!(close(back.density, rho, 1e-12), "{}", back.name);
        let c = &back.curves;
        for (what, curve) in [
            ("tensile_warp", &c.tensile_warp),
            ("tensile_weft", &c.tensile_weft),
            ("tensile_bias", &c.tensile_bias),
            ("shear", &c.shear),
            ("bending_warp", &c.bending_warp),
            ("bending_weft", &c.bending_weft),
            ("bending_bias", &c.bending_bias),
        ] {
            let l = &curve.as_ref().unwrap_or_else(|| panic!("{what}")).loading;
            assert!(l.len() >= 2, "{} {what}", back.name);
            assert_eq!(l[0], [0.0, 0.0], "{} {what}", back.name);
            assert!(curve.as_ref().unwrap().unloading.is_empty());
            assert!(l.windows(2).all(|w| w[1][0] > w[0][0]));
            if what != "tensile_bias" {
                // warp, weft, shear and bending rise (c11, c22 and c33 of rows 0 and 3 are
                // positive in all ten tables; bending is kept where M rises)
                assert!(
                    l.windows(2).all(|w| w[1][1] > w[0][1]),
                    "{} {what} not rising",
                    back.name
                );
            }
            let xmax = l.last().unwrap()[0];
            let ok = match what {
                "shear" => close(xmax, 8f64.to_radians(), 1e-12),
                w if w.starts_with("tensile") => close(xmax, 1.0 / 6.0, 1e-12),
                _ => xmax > 0.0 && xmax <= 40.0 + 1e-12,
            };
            assert!(ok, "{} {what}: ends at {xmax}", back.name);
        }
        let end = |c: &Option<Curve>| c.as_ref().unwrap().loading.last().unwrap()[1];
        assert!(close(
            back.tensile_fm,
            end(&c.tensile_warp).max(end(&c.tensile_weft)),
            1e-12
        ));
    }
    std::fs::remove_dir_all(out).ok();
}

#[test]
fn a_broken_wang_file_is_an_error_naming_it() {
    let dir = temp_dir("wang-bad");
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("broken.json");
    std::fs::write(
        &f,
        r#"{"density": 0.2, "stretching": [[1, 2, 3, 4]], "bending": []}"#,
    )
    .unwrap();
    let err = import_wang(&f).unwrap_err().to_string();
    assert!(
        err.contains("broken.json") && err.contains("stretching"),
        "{err}"
    );
    std::fs::write(&f, r#"{"density": "heavy"}"#).unwrap();
    let err = import_wang(&f).unwrap_err().to_string();
    assert!(
        err.contains("broken.json") && err.contains("density"),
        "{err}"
    );
    std::fs::remove_dir_all(dir).ok();
}
