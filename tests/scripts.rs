//! The scripting layer end to end: every script under `scripts/` runs and writes its files,
//! errors carry script positions, the binary's `run`, `repl` and `doc` subcommands work, and
//! every registered function (module functions by their `module::name`) is used by some script;
//! the old flat names kept as aliases need not be.
#![cfg(feature = "scripting")]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use emilion::script::docs::api_entries;
use emilion::script::{build_engine, function_names, run_file};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty folder under the target's test temp dir.
fn temp_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("scripts")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn script_paths() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("scripts"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rhai"))
        .collect();
    v.sort();
    v
}

/// Runs `scripts/NAME.rhai` with `out` set to a temp folder; returns the folder.
fn run_script(name: &str) -> PathBuf {
    let out = temp_dir(name);
    let sets = vec![("out".to_string(), out.display().to_string())];
    if let Err(e) = run_file(&root().join("scripts").join(format!("{name}.rhai")), &sets) {
        panic!("scripts/{name}.rhai failed:\n{e}");
    }
    out
}

fn assert_files(dir: &Path, files: &[&str]) {
    for f in files {
        let p = dir.join(f);
        let len = std::fs::metadata(&p)
            .unwrap_or_else(|_| panic!("{} missing", p.display()))
            .len();
        assert!(len > 0, "{} is empty", p.display());
    }
}

#[test]
fn hang_script() {
    let out = run_script("hang");
    assert_files(&out, &["hang.png", "hang.obj", "hang_stats.csv"]);
}

#[test]
fn drop_script() {
    let out = run_script("drop");
    assert_files(&out, &["drop.png", "drop.glb"]);
}

#[test]
fn demo_script() {
    let out = run_script("demo");
    assert_files(
        &out,
        &["demo.png", "demo.obj", "demo.glb", "demo_stats.csv"],
    );
}

#[test]
fn tour_script() {
    let out = run_script("tour");
    assert_files(
        &out.join("tour"),
        &[
            "tour.png",
            "tour_small.png",
            "tour.obj",
            "tour.glb",
            "tour_stats.csv",
            "tour_stats.json",
        ],
    );
}

#[test]
fn other_scripts_run() {
    for p in script_paths() {
        let name = p.file_stem().unwrap().to_str().unwrap().to_string();
        // the contact scripts run in tests/contact_scripts.rs, the garments in
        // tests/garment_scripts.rs, the buckle_* scripts in tests/buckling.rs and the tracking
        // scripts in tests/tracking_track.rs (golf: tests/golf_sequence.rs), the face scripts in tests/face_track.rs and tests/face_fit.rs,
        // with their checks; facade_train (minutes on its defaults) in tests/facade_learned.rs
        // on a few photos
        if [
            "hang",
            "drop",
            "demo",
            "tour",
            "drape_sphere",
            "drape_table",
            "self_fold",
            "mannequin_walk",
            "aaron",
            "penelope",
            "paco",
            "buckle_square",
            "buckle_cylinder",
            "buckle_sleeve",
            "make_sequence",
            "track_body",
            "golf_markers",
            "golf_sequence",
            "golf_track",
            "make_face_sequence",
            "face_track",
            "face_fit",
            "face_fit_steps",
            "facade_train",
        ]
        .contains(&name.as_str())
        {
            continue;
        }
        let out = run_script(&name);
        for e in std::fs::read_dir(&out).unwrap() {
            let p = e.unwrap().path();
            if p.is_file() {
                assert!(
                    std::fs::metadata(&p).unwrap().len() > 0,
                    "{} is empty",
                    p.display()
                );
            }
        }
    }
}

fn write_script(name: &str, body: &str) -> PathBuf {
    let p = temp_dir(name).join(format!("{name}.rhai"));
    std::fs::write(&p, body).unwrap();
    p
}

#[test]
fn error_names_the_line() {
    let p = write_script(
        "bad_grid",
        "let x = 1;\nlet y = cloth_grid(-1.0, 1.0, 4, 4, fabric());\n",
    );
    let e = run_file(&p, &[]).expect_err("a negative width must fail");
    let text = e.to_string();
    assert_eq!(e.position.map(|p| p.0), Some(2), "{text}");
    assert!(text.contains(":2:"), "{text}");
    assert!(
        text.contains("cloth_grid(-1.0"),
        "the source line is shown: {text}"
    );
}

#[test]
fn negative_density_is_named() {
    let p = write_script("bad_fabric", "let f = fabric(#{ density: -1 });\n");
    let text = run_file(&p, &[])
        .expect_err("negative density must fail")
        .to_string();
    assert!(text.contains("density"), "{text}");
    let p = write_script("bad_fabric_set", "let f = fabric();\nf.shear = -2.0;\n");
    let text = run_file(&p, &[])
        .expect_err("negative shear must fail")
        .to_string();
    assert!(text.contains("shear") && text.contains(":2:"), "{text}");
    let p = write_script("bad_key", "let f = fabric(#{ densty: 0.1 });\n");
    let text = run_file(&p, &[])
        .expect_err("unknown keys must fail")
        .to_string();
    assert!(text.contains("densty"), "{text}");
}

#[test]
fn a_bad_rule_file_is_named_with_its_line() {
    let dir = temp_dir("bad_rules_file");
    let rules = dir.join("bad.cga");
    std::fs::write(
        &rules,
        "// axiom F size 10 10\nF --> split(z) { 1: W }\nW --> wall\n",
    )
    .unwrap();
    let p = write_script(
        "bad_rules",
        &format!(
            "let f = facade_from_rules(\"{}\", \"{}\", \"x\", #{{}});\n",
            rules.display(),
            dir.display()
        ),
    );
    let text = run_file(&p, &[])
        .expect_err("a bad direction must fail")
        .to_string();
    assert!(
        text.contains("bad.cga") && text.contains("line 2"),
        "{text}"
    );
    let p = write_script(
        "bad_rules_option",
        "let f = facade_from_rules(\"scripts/townhouse.cga\", \"out\", \"x\", #{ scale: -1.0 });\n",
    );
    let text = run_file(&p, &[])
        .expect_err("a negative scale must fail")
        .to_string();
    assert!(text.contains("scale"), "{text}");
}

#[test]
fn buckling_parameters_are_checked() {
    for (name, src, what) in [
        (
            "bad_perturbed",
            "let c = cloth_grid(0.5, 0.5, 5, 5, fabric());\nlet p = c.perturbed(-1.0, 3);\n",
            "amplitude",
        ),
        (
            "bad_compression",
            "let s = simulation(cloth_grid(0.5, 0.5, 5, 5, fabric()));\nlet r = s.compression(1.0 / 0.0);\n",
            "strain",
        ),
        (
            "bad_release",
            "let s = simulation(cloth_grid(0.5, 0.5, 5, 5, fabric()));\ns.compression_release(#{ strain: -0.1 });\n",
            "strain",
        ),
        (
            "bad_prestrain",
            "let c = cloth_grid(0.5, 0.5, 5, 5, fabric());\nlet p = c.prestrained(0.05, -1.5);\n",
            "strain_y",
        ),
        (
            "bad_prestrain_nan",
            "let c = cloth_grid(0.5, 0.5, 5, 5, fabric());\nlet p = c.prestrained(0.0 / 0.0, 0.0);\n",
            "strain_x",
        ),
        (
            "bad_cylinder",
            "let s = simulation(cloth_grid(0.5, 0.5, 5, 5, fabric()));\ns.add_cylinder([0.0, 0.0, 0.0], [0.0, 0.0, 0.0], 0.1, 1.0);\n",
            "axis",
        ),
    ] {
        let p = write_script(name, src);
        let text = run_file(&p, &[]).expect_err(name).to_string();
        assert!(text.contains(what) && text.contains(":2:"), "{name}: {text}");
    }
}

#[test]
fn set_values_are_typed() {
    let p = write_script(
        "sets",
        "if n != 3 || x != 0.5 || !flag || name != \"abc\" { throw \"wrong --set values\"; }\n",
    );
    let sets: Vec<(String, String)> = [("n", "3"), ("x", "0.5"), ("flag", "true"), ("name", "abc")]
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    run_file(&p, &sets).unwrap();
}

#[test]
fn binary_reports_script_errors() {
    let p = write_script(
        "bin_bad",
        "let x = 1;\nlet y = cloth_grid(-1.0, 1.0, 4, 4, fabric());\n",
    );
    let o = Command::new(env!("CARGO_BIN_EXE_emilion"))
        .arg("run")
        .arg(&p)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains(&format!("{}:2:", p.display())), "{stderr}");
}

#[test]
fn repl_reads_piped_lines() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_emilion"))
        .arg("repl")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(b"let f = fabric();\nf.density = 0.25;\nf.density * 2.0\n")
        .unwrap();
    let o = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains("=> 0.5"), "{stdout}");
}

/// How a registered name shows in scripts: `name(` or `module::name(` for functions, `.prop`
/// for properties.
fn usage(name: &str) -> String {
    if let Some(p) = name.strip_prefix("get$") {
        format!(".{p}")
    } else if let Some(p) = name.strip_prefix("set$") {
        format!(".{p} =")
    } else {
        format!("{name}(")
    }
}

/// The lab scripts under `kawabata/`.
fn lab_script_paths() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("kawabata"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rhai"))
        .collect();
    v.sort();
    v
}

/// Runs `emilion run kawabata/NAME.rhai` with `sets`; returns stdout.
fn run_lab_script(name: &str, sets: &[(&str, String)]) -> String {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_emilion"));
    cmd.current_dir(root())
        .arg("run")
        .arg(format!("kawabata/{name}.rhai"));
    for (k, v) in sets {
        cmd.arg("--set").arg(format!("{k}={v}"));
    }
    let o = cmd.output().unwrap();
    assert!(
        o.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// The lab scripts on the coarse rig mesh (the rigs' accuracy on both meshes is tested in
/// `tests/kes.rs`; here the scripts, their printout and their plots).
#[test]
fn lab_scripts_run_and_write_plots() {
    let fabric = root().join("tests/data/fabrics_small/shirting-cotton.json");
    for name in ["tensile", "shear", "bending"] {
        let out = temp_dir(&format!("lab_{name}"));
        let stdout = run_lab_script(
            name,
            &[
                ("fabric", fabric.display().to_string()),
                ("out", out.display().to_string()),
                ("meshes", "coarse".into()),
            ],
        );
        assert!(stdout.contains("measured"), "{name}: {stdout}");
        let pngs = std::fs::read_dir(&out)
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .path()
                    .extension()
                    .is_some_and(|x| x == "png")
            })
            .count();
        assert!(pngs >= 1, "{name}: no plot in {}", out.display());
    }
    let stdout = run_lab_script(
        "fit",
        &[
            ("fabric", fabric.display().to_string()),
            ("tests", "tensile".into()),
        ],
    );
    assert!(stdout.contains("fitted stretch_damping"), "{stdout}");
}

#[test]
fn lab_all_script_ends_with_the_summary_line() {
    let out = temp_dir("lab_all");
    let stdout = run_lab_script(
        "all",
        &[
            (
                "fabrics",
                root()
                    .join("tests/data/fabrics_small")
                    .display()
                    .to_string(),
            ),
            ("out", out.display().to_string()),
            ("meshes", "coarse".into()),
        ],
    );
    let last = stdout.lines().last().unwrap_or("");
    assert!(
        last.starts_with("worst_curve_rms_pct=")
            && last.contains(" worst_param_err_pct=")
            && last.ends_with(" fabrics=1"),
        "{last}"
    );
    assert!(out.join("summary.csv").exists() && out.join("summary.md").exists());
}

#[test]
fn every_function_is_used_by_a_script() {
    let all: String = script_paths()
        .into_iter()
        .chain(lab_script_paths())
        .collect::<Vec<_>>()
        .iter()
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    let engine = build_engine();
    let aliases: Vec<String> = api_entries(&engine)
        .into_iter()
        .filter(|e| e.alias_of().is_some())
        .map(|e| e.name)
        .collect();
    let names = function_names(&engine);
    assert!(names.len() > 30, "{names:?}");
    assert!(
        names.iter().filter(|n| n.contains("::")).count() > 30,
        "the module functions are listed: {names:?}"
    );
    let unused: Vec<_> = names
        .iter()
        .filter(|n| !aliases.contains(n) && !all.contains(&usage(n)))
        .collect();
    assert!(
        unused.is_empty(),
        "registered but used by no script: {unused:?}"
    );
}

#[test]
fn doc_lists_every_function() {
    let dir = temp_dir("doc");
    let o = Command::new(env!("CARGO_BIN_EXE_emilion"))
        .arg("doc")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(dir.join("api.md")).unwrap();
    let json = std::fs::read_to_string(dir.join("api.json")).unwrap();
    assert!(json.contains("\"functions\""));
    for n in function_names(&build_engine()) {
        let shown = match n.split_once('$') {
            Some((_, p)) => format!("`.{p}`"),
            None => format!("`{n}`"),
        };
        assert!(md.contains(&shown), "api.md does not document {n}");
    }
    assert!(
        md.contains("cloth::grid(width: float"),
        "signatures carry parameter names"
    );
    assert!(md.contains("## Module `cloth`") && md.contains("## Aliases kept for one release"));
    assert!(
        json.contains("\"module\": \"cloth\"") && json.contains("\"aliasOf\": \"cloth::grid\"")
    );
}
