//! Every script of `scripts/` and `kawabata/` runs from a temporary working directory (issue 47,
//! "paths that follow the script"): the built `emilion` binary is started in a fresh folder with
//! the script's absolute path and a relative `--set out=results`; the script must succeed,
//! write its files under that folder's `results/`, and leave the repository as it was. Its own
//! inputs (patterns, rule files, fabric files) are found from the script's folder, the shared
//! data through `data_dir()`. Scripts that need the shared data are skipped with a message when
//! it is absent.
//!
//! Long scripts run with the quick settings of [`QUICK`] (their own `--set` parameters) so the
//! whole test stays within about three minutes of a release build on two cores.
#![cfg(feature = "scripting")]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Instant, SystemTime};

use emilion::geometry::files::data_dir;

/// Quick settings (`--set` values, each the script's own parameter) of the scripts that take
/// long at their defaults. Scripts not listed run at their defaults.
const QUICK: &[(&str, &[&str])] = &[
    ("aaron", &["seconds=0.05", "edge=0.03"]),
    ("paco", &["seconds=0.05", "edge=0.03"]),
    ("penelope", &["seconds=0.05", "edge=0.03"]),
    ("drape_sphere", &["frames=2", "n=16"]),
    ("drape_table", &["frames=2", "n=16"]),
    ("buckle_cylinder", &["n=11", "rest=0.0"]),
    ("buckle_sleeve", &["n_around=12", "n_down=9"]),
    ("buckle_square", &["n=11"]),
    ("self_fold", &["n=10"]),
    ("wrinkle_wavelength", &["n=21"]),
    ("mannequin_walk", &["seconds=0.1", "nx=16", "ny=6"]),
    ("make_sequence", &["frames=2", "cameras=1"]),
    ("make_face_sequence", &["frames=2", "cameras=1"]),
    ("face_track", &["frames=2"]),
    ("track_body", &["frames=2"]),
    (
        "golf_sequence",
        &[
            "frames=2",
            "every=12",
            "width=160",
            "height=120",
            "cameras=1",
            "edge=0.04",
        ],
    ),
    ("golf_track", &["frames=2", "adapt_body=false"]),
    ("facades_eval", &["limit=2"]),
    ("facade_train", &["max_images=2", "samples=500", "trees=3"]),
    ("all", &["meshes=coarse", "limit=1"]),
    ("bending", &["meshes=coarse"]),
    ("shear", &["meshes=coarse"]),
    ("tensile", &["meshes=coarse"]),
    ("fit", &["tests=tensile"]),
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty working directory.
fn fresh_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("scripts_anywhere")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The `.rhai` files of `scripts/` and `kawabata/`, sorted.
fn all_scripts() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = ["scripts", "kawabata"]
        .iter()
        .flat_map(|d| std::fs::read_dir(root().join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rhai"))
        .collect();
    v.sort();
    v
}

/// Every file under `dir` (recursively) with its length and modification time, skipping the
/// build and version-control folders.
fn snapshot(dir: &Path, into: &mut BTreeMap<PathBuf, (u64, Option<SystemTime>)>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if name != "target" && name != ".git" {
                snapshot(&p, into);
            }
        } else if let Ok(m) = std::fs::metadata(&p) {
            into.insert(p, (m.len(), m.modified().ok()));
        }
    }
}

fn repository() -> BTreeMap<PathBuf, (u64, Option<SystemTime>)> {
    let mut m = BTreeMap::new();
    snapshot(&root(), &mut m);
    m
}

/// The non-empty files under `dir`, recursively.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut m = BTreeMap::new();
    if dir.is_dir() {
        snapshot(dir, &mut m);
    }
    m.into_iter()
        .filter(|(_, (len, _))| *len > 0)
        .map(|(p, _)| p)
        .collect()
}

/// Runs `emilion run SCRIPT` in `cwd` with `sets`; (success, stdout, stderr, seconds).
fn run_in(cwd: &Path, script: &Path, sets: &[&str]) -> (bool, String, String, f64) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_emilion"));
    cmd.current_dir(cwd).arg("run").arg(script);
    for s in sets {
        cmd.arg("--set").arg(s);
    }
    let t = Instant::now();
    let o = cmd.output().unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        t.elapsed().as_secs_f64(),
    )
}

fn quick(name: &str) -> &'static [&'static str] {
    QUICK
        .iter()
        .find(|(n, _)| *n == name)
        .map_or(&[], |(_, s)| s)
}

#[test]
fn every_script_runs_from_a_temporary_folder() {
    let before = repository();
    let data = data_dir();
    let data_present = data.is_dir();
    let (mut ran, mut skipped) = (Vec::new(), Vec::new());
    for script in all_scripts() {
        let folder = script
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_string_lossy();
        let name = script.file_stem().unwrap().to_string_lossy().into_owned();
        let label = format!("{folder}/{name}.rhai");
        let cwd = fresh_dir(&format!("{folder}_{name}"));
        let mut sets = vec!["out=results"];
        sets.extend(quick(&name));
        let (ok, stdout, stderr, seconds) = run_in(&cwd, &script, &sets);
        if !ok && !data_present && stderr.contains(&*data.to_string_lossy()) {
            println!(
                "skipped {label}: the shared data is absent ({})",
                data.display()
            );
            skipped.push(label);
            continue;
        }
        assert!(
            ok,
            "{label} failed from {} with {sets:?}:\n{stdout}\n{stderr}",
            cwd.display()
        );
        let source = std::fs::read_to_string(&script).unwrap();
        let written = files_under(&cwd.join("results"));
        if source.contains("is_def_var(\"out\")") {
            assert!(
                !written.is_empty(),
                "{label} wrote nothing under {}",
                cwd.join("results").display()
            );
        }
        // everything the script wrote is under `results/` (the default `out/` stays unused)
        let all = files_under(&cwd);
        assert_eq!(
            all.len(),
            written.len(),
            "{label} wrote outside results/: {all:?}"
        );
        println!(
            "{label}: {seconds:.1} s, {} files, --set {}",
            written.len(),
            sets.join(" --set ")
        );
        ran.push(label);
    }
    let after = repository();
    let changed: Vec<_> = after
        .iter()
        .filter(|(p, m)| before.get(*p) != Some(m))
        .map(|(p, _)| p)
        .collect();
    assert!(
        changed.is_empty(),
        "the scripts wrote into the repository: {changed:?}"
    );
    println!("{} scripts ran, {} skipped", ran.len(), skipped.len());
    let names: Vec<String> = all_scripts()
        .iter()
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    for (n, _) in QUICK {
        assert!(names.iter().any(|m| m == n), "QUICK names no script `{n}`");
    }
    assert!(ran.len() + skipped.len() >= 30);
}

#[test]
fn the_default_output_folder_is_out_and_the_script_name_under_the_working_directory() {
    let cwd = fresh_dir("default_out");
    let (ok, stdout, stderr, _) = run_in(&cwd, &root().join("scripts/hang.rhai"), &["n=8"]);
    assert!(ok, "{stdout}\n{stderr}");
    for f in ["hang.png", "hang.obj", "hang_stats.csv"] {
        let p = cwd.join("out/hang").join(f);
        assert!(p.is_file(), "{} missing", p.display());
    }
}

#[test]
fn command_line_paths_are_taken_from_the_working_directory() {
    // a rule file given by a relative `--set` path, in the working directory; the script's
    // own default (`townhouse.cga` beside it) is not used
    let cwd = fresh_dir("command_line");
    let rules = std::fs::read_to_string(root().join("scripts/townhouse.cga")).unwrap();
    std::fs::write(cwd.join("mine.cga"), rules).unwrap();
    let (ok, stdout, stderr, _) = run_in(
        &cwd,
        &root().join("scripts/facade_rules.rhai"),
        &["rules=mine.cga", "out=res"],
    );
    assert!(ok, "{stdout}\n{stderr}");
    assert!(!files_under(&cwd.join("res")).is_empty());
    assert_eq!(
        files_under(&cwd).len(),
        files_under(&cwd.join("res")).len() + 1
    );
    // a path the script itself names is the script folder's: without the file there, the
    // error names the script's folder
    let script = cwd.join("reads.rhai");
    std::fs::write(&script, "let f = kes::fabric(\"no_such_fabric.json\");\n").unwrap();
    let elsewhere = fresh_dir("command_line_elsewhere");
    let (ok, _, stderr, _) = run_in(&elsewhere, &script, &[]);
    assert!(!ok);
    assert!(
        stderr.contains(&*cwd.join("no_such_fabric.json").to_string_lossy()),
        "{stderr}"
    );
}

#[test]
fn data_dir_and_script_dir_are_absolute() {
    let cwd = fresh_dir("dirs");
    let script = cwd.join("dirs.rhai");
    std::fs::write(
        &script,
        "print(script_dir());\nprint(data_dir());\nprint(out_dir());\n",
    )
    .unwrap();
    let elsewhere = fresh_dir("dirs_elsewhere");
    let (ok, stdout, stderr, _) = run_in(&elsewhere, &script, &[]);
    assert!(ok, "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(Path::new(lines[0]), cwd);
    assert_eq!(Path::new(lines[1]), data_dir());
    assert_eq!(Path::new(lines[2]), elsewhere.join("out/dirs"));
}
