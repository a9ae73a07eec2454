//! Emilion's files read by the tools people use: Blender 5 (`bpy`) imports meshes upright and
//! at the right size, and plays the animation caches (USD, PC2 with its rest OBJ, animated
//! glTF) with every checked frame's points within 1e-6 m of the engine's; Pixar's validators
//! (`usd-core`'s UsdValidation) find no error in the USD stage.
//!
//! Needs a Python 3.13 with `bpy` and `usd-core`: `EMILION_PYTHON`, else the venv `.ci/run`
//! makes (`~/.cache/emilion/venv313`). Without one, the tests say so and pass without
//! checking. The mannequin scenes also need `../shared/data` (or `EMILION_DATA`).

use std::path::{Path, PathBuf};
use std::process::Command;

use emilion::geometry::pc2::read_pc2;
use emilion::geometry::{read_obj, ExportFrame, Vec3};
use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_emilion");
const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The Python with `bpy` and `pxr`, if there is one.
fn python() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("EMILION_PYTHON").map(PathBuf::from),
        std::env::var_os("HOME")
            .map(|h| PathBuf::from(h).join(".cache/emilion/venv313/bin/python")),
    ];
    for p in candidates.into_iter().flatten() {
        if let Some(v) = run_check(&p, &["probe"]) {
            if v["bpy"].is_string() && v["usd"].is_string() {
                return Some(p);
            }
        }
    }
    eprintln!(
        "skipped: no Python with bpy and usd-core (set EMILION_PYTHON, or run .ci/run once to make ~/.cache/emilion/venv313)"
    );
    None
}

/// Runs `tests/clients/check.py` with `args`; its last line of output as JSON.
fn run_check(python: &Path, args: &[&str]) -> Option<Value> {
    let out = Command::new(python)
        .arg(Path::new(ROOT).join("tests/clients/check.py"))
        .args(args)
        .output()
        .ok()?;
    if !out.status.success() {
        eprintln!(
            "check.py {args:?} failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(text.lines().last()?).ok()
}

fn check(python: &Path, args: &[&str]) -> Value {
    run_check(python, args).unwrap_or_else(|| panic!("check.py {args:?} gave no result"))
}

fn data_dir() -> Option<PathBuf> {
    let d = std::env::var_os("EMILION_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(ROOT).join("../shared/data"));
    if d.join("bodies/makehuman").is_dir() {
        Some(d)
    } else {
        eprintln!(
            "skipped: no data folder with bodies/makehuman at {}",
            d.display()
        );
        None
    }
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("emilion-clients-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs a script from the repository root with `--set` values.
fn run_script(script: &str, sets: &[(&str, &str)]) {
    let mut cmd = Command::new(BIN);
    cmd.current_dir(ROOT).arg("run").arg(script);
    for (k, v) in sets {
        cmd.arg("--set").arg(format!("{k}={v}"));
    }
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{script} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Blender's world-space vertices of object `k` at frame `f`.
fn frame_points(v: &Value, k: usize, f: u32) -> Vec<[f64; 3]> {
    v["objects"][k]["frames"][f.to_string()]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            [
                p[0].as_f64().unwrap(),
                p[1].as_f64().unwrap(),
                p[2].as_f64().unwrap(),
            ]
        })
        .collect()
}

fn object<'a>(v: &'a Value, name: &str) -> (usize, &'a Value) {
    let objs = v["objects"].as_array().unwrap();
    let k = objs
        .iter()
        .position(|o| o["name"].as_str().unwrap().starts_with(name))
        .unwrap_or_else(|| panic!("no object `{name}` in {objs:?}"));
    (k, &objs[k])
}

fn axis(o: &Value, which: &str, k: usize) -> f64 {
    o[which][k].as_f64().unwrap()
}

/// The largest distance between Blender's points and the engine's (metres, +Z up).
fn worst(blender: &[[f64; 3]], engine: &[Vec3], scale: f64) -> f64 {
    assert!(blender.len() >= engine.len());
    engine
        .iter()
        .zip(blender)
        .map(|(e, b)| (Vec3::new(b[0], b[1], b[2]) / scale - e).norm())
        .fold(0.0, f64::max)
}

#[test]
fn walking_mannequin_caches_play_the_engine_frames_in_blender() {
    let (Some(py), Some(data)) = (python(), data_dir()) else {
        return;
    };
    let out = tmp("walk");
    let data = data.display().to_string();
    let out_s = out.display().to_string();
    run_script(
        "scripts/mannequin_walk.rhai",
        &[
            ("out", &out_s),
            ("data", &data),
            ("seconds", "0.5"),
            ("cache", "all"),
            ("frame_objs", "true"),
        ],
    );
    let dir = out.join("mannequin_walk");
    let frames = [6u32, 12, 18, 24];
    // the engine's skirt at those frames: the OBJs saved in the run (+Y up, f64 text)
    let engine: Vec<Vec<Vec3>> = frames
        .iter()
        .map(|f| {
            let m = read_obj(&dir.join(format!("skirt_{f:02}.obj"))).unwrap();
            m.positions
                .iter()
                .map(|p| ExportFrame::Y_UP_METRES.to_engine(p))
                .collect()
        })
        .collect();
    let n = engine[0].len();
    let list = "6,12,18,24";

    // USD: Pixar's validators, then Blender's import
    let usd = dir.join("mannequin_walk.usda");
    let usd_s = usd.display().to_string();
    let v = check(&py, &["usd-validate", &usd_s]);
    assert_eq!(
        v["errors"].as_array().unwrap().len(),
        0,
        "USD validation: {v}"
    );
    let v = check(&py, &["blender-import", &usd_s, "--frames", list]);
    assert_eq!(
        (v["frame_start"].as_i64(), v["frame_end"].as_i64()),
        (Some(0), Some(24))
    );
    let (k, cloth) = object(&v, "cloth");
    assert_eq!(cloth["vertices"].as_u64(), Some(n as u64));
    let (_, body) = object(&v, "body_0");
    assert!(body["vertices"].as_u64().unwrap() > 10_000);
    for (f, e) in frames.iter().zip(&engine) {
        let d = worst(&frame_points(&v, k, *f), e, 1.0);
        assert!(d < 1e-6, "USD frame {f}: {d} m from the engine");
    }

    // glTF: one mesh, the cloth's vertices first
    let glb = dir.join("mannequin_walk.glb").display().to_string();
    let v = check(&py, &["blender-import", &glb, "--frames", list]);
    for (f, e) in frames.iter().zip(&engine) {
        let d = worst(&frame_points(&v, 0, *f), e, 1.0);
        assert!(d < 1e-6, "glTF frame {f}: {d} m from the engine");
    }

    // PC2 over its rest OBJ, through Blender's Mesh Cache modifier, and read back here
    let obj = dir.join("mannequin_walk.obj").display().to_string();
    let pc2 = dir.join("mannequin_walk.pc2");
    let v = check(
        &py,
        &[
            "blender-import",
            &obj,
            "--pc2",
            &pc2.display().to_string(),
            "--frames",
            list,
        ],
    );
    let back = read_pc2(&pc2).unwrap();
    assert_eq!((back.points, back.samples.len()), (n, 25));
    for (f, e) in frames.iter().zip(&engine) {
        let d = worst(&frame_points(&v, 0, *f), e, 1.0);
        assert!(d < 1e-6, "PC2 in Blender, frame {f}: {d} m from the engine");
        let mine: Vec<[f64; 3]> = back.samples[*f as usize]
            .iter()
            .map(|p| {
                let q = ExportFrame::Y_UP_METRES.to_engine(&Vec3::new(
                    p[0].into(),
                    p[1].into(),
                    p[2].into(),
                ));
                [q.x, q.y, q.z]
            })
            .collect();
        let d = worst(&mine, e, 1.0);
        assert!(d < 1e-6, "PC2 read back, frame {f}: {d} m from the engine");
    }
}

#[test]
fn meshes_stand_upright_at_their_size_in_blender() {
    let Some(py) = python() else {
        return;
    };
    let import = |path: &Path| check(&py, &["blender-import", &path.display().to_string()]);

    // the demo cloth hangs 0.87 m down from its pinned top edge, along Blender's −Z
    let out = tmp("demo");
    run_script("scripts/demo.rhai", &[("out", &out.display().to_string())]);
    for f in ["demo.glb", "demo.obj"] {
        let v = import(&out.join(f));
        let o = &v["objects"][0];
        let (z0, z1) = (axis(o, "min", 2), axis(o, "max", 2));
        assert!(
            (z1 - z0 - 0.87).abs() < 0.01 && z1.abs() < 1e-6,
            "{f}: Z from {z0} to {z1}"
        );
    }

    if data_dir().is_none() {
        return;
    }
    // a fitted face: taller (Z) than wide (X), thin front to back (Y)
    let out = tmp("face");
    run_script(
        "scripts/face_fit.rhai",
        &[("out", &out.display().to_string())],
    );
    for f in ["face.glb", "face.obj"] {
        let v = import(&out.join(f));
        let o = &v["objects"][0];
        let ext: Vec<f64> = (0..3)
            .map(|k| axis(o, "max", k) - axis(o, "min", k))
            .collect();
        assert!(
            ext[2] > ext[0] && ext[0] > ext[1] && (0.12..0.3).contains(&ext[2]),
            "{f}: extents {ext:?} m"
        );
    }

    // a facade: wide (X) and tall (Z), a few tens of centimetres deep (Y)
    let out = tmp("facade");
    run_script(
        "scripts/facade.rhai",
        &[("out", &out.display().to_string())],
    );
    for f in ["facade_w1.glb", "facade_w1.obj"] {
        let v = import(&out.join(f));
        let o = &v["objects"][0];
        let ext: Vec<f64> = (0..3)
            .map(|k| axis(o, "max", k) - axis(o, "min", k))
            .collect();
        assert!(
            ext[0] > 5.0 && ext[2] > 5.0 && ext[1] < 1.0,
            "{f}: extents {ext:?} m"
        );
        assert!(
            axis(o, "min", 2).abs() < 0.1,
            "{f}: the facade does not stand on Z = 0"
        );
    }
}

#[test]
fn dressed_mannequin_stands_upright_in_metres_and_millimetres() {
    let (Some(py), Some(data)) = (python(), data_dir()) else {
        return;
    };
    let data = data.display().to_string();
    // the A-shirt and its mannequin: a standing adult (1.5–1.9 m along Z, feet at Z = 0), the
    // shirt on the torso
    let out = tmp("aaron");
    run_script(
        "scripts/aaron.rhai",
        &[("out", &out.display().to_string()), ("seconds", "0.3")],
    );
    let v = check(
        &py,
        &[
            "blender-import",
            &out.join("aaron/mannequin.obj").display().to_string(),
        ],
    );
    let body = &v["objects"][0];
    let height = axis(body, "max", 2);
    assert!(
        (1.5..1.9).contains(&height) && axis(body, "min", 2).abs() < 0.01,
        "mannequin Z top {height} m"
    );
    let v = check(
        &py,
        &[
            "blender-import",
            &out.join("aaron/garment.glb").display().to_string(),
        ],
    );
    let shirt = &v["objects"][0];
    let (z0, z1) = (axis(shirt, "min", 2), axis(shirt, "max", 2));
    assert!(
        z0 > 0.5 * height && z1 < height && z1 - z0 > 0.3,
        "shirt from Z {z0} to {z1} m"
    );

    // the walking mannequin's OBJs in millimetres: the same figures × 1000
    let out = tmp("walk_mm");
    run_script(
        "scripts/mannequin_walk.rhai",
        &[
            ("out", &out.display().to_string()),
            ("data", &data),
            ("seconds", "0.0"),
            ("units", "mm"),
            ("cache", "none"),
        ],
    );
    let v = check(
        &py,
        &[
            "blender-import",
            &out.join("mannequin_walk/mannequin.obj")
                .display()
                .to_string(),
        ],
    );
    let top = axis(&v["objects"][0], "max", 2);
    assert!(
        (1500.0..1900.0).contains(&top),
        "mannequin top at {top} (mm expected)"
    );
}
