//! Fitting the generic face to a real photo (the astronaut, landmarks placed by hand), the
//! outputs people look at, the step-by-step adaptation with undo from a script, and bad inputs.
#![cfg(feature = "scripting")]

use std::path::{Path, PathBuf};
use std::process::Command;

use emilion::face::fit_run::load_photos;
use emilion::face::render::Texture;

fn temp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("face_fit")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(script: &str, sets: &[String]) -> (bool, String, String) {
    let mut c = Command::new(env!("CARGO_BIN_EXE_emilion"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["run", script]);
    for s in sets {
        c.args(["--set", s]);
    }
    let o = c.output().unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn astronaut() -> PathBuf {
    emilion::geometry::files::data_dir().join("images/astronaut.png")
}

#[test]
fn astronaut_fit_reprojects_the_landmarks_within_three_percent() {
    let out = temp("astronaut");
    let (ok, stdout, stderr) = run("scripts/face_fit.rhai", &[format!("out={}", out.display())]);
    assert!(ok, "{stdout}\n{stderr}");
    let last = stdout.lines().last().unwrap();
    println!("{last}");
    assert!(
        last.starts_with("landmark_err_iod_pct=") && last.ends_with(" images=1"),
        "{last}"
    );
    let err: f64 = last["landmark_err_iod_pct=".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(err <= 3.0, "landmark error {err} % of IOD");
    for f in [
        "face.obj",
        "face.mtl",
        "face.png",
        "face.glb",
        "fit.csv",
        "overlay_astronaut.png",
        "render_front.png",
        "render_left.png",
        "render_right.png",
        "error_map.png",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    // the texture looks like the person: at the mesh vertices the photo sees frontally, the
    // texture's colour is the photo's colour where the fitted camera projects the vertex
    let d = folder_with(
        "texture",
        &std::fs::read_to_string("tests/data/faces/astronaut.pts").unwrap(),
        true,
    );
    let (fit, report) = emilion::face::fit_run::fit_folder(
        &d,
        None,
        &d.join("out"),
        &emilion::face::adapt::AdaptOptions::default(),
        512,
    )
    .unwrap();
    assert!(
        report.texture_coverage > 0.7,
        "coverage {}",
        report.texture_coverage
    );
    let tex = Texture::load(&d.join("out/face.png")).unwrap();
    let photo = image::open(astronaut()).unwrap().into_rgb8();
    let cam = &fit.cameras[0];
    let normals = fit.mesh.vertex_normals();
    let (mut sum, mut n) = (0.0, 0usize);
    for (i, p) in fit.mesh.positions.iter().enumerate() {
        let to_cam = (cam.center() - p).normalize();
        if normals[i].dot(&to_cam) < 0.7 {
            continue;
        }
        let Some(px) = cam.project(p) else { continue };
        let q = photo.get_pixel(px[0].round() as u32, px[1].round() as u32);
        let uv = fit.mesh.uvs[i];
        let t = tex.sample(uv[0] as f32, uv[1] as f32);
        sum += (0..3)
            .map(|k| (t[k] as f64 - q[k] as f64).abs())
            .sum::<f64>()
            / 3.0;
        n += 1;
    }
    let mean = sum / n as f64;
    println!("texture vs photo at {n} frontal vertices: mean difference {mean:.1} grey levels");
    assert!(
        n > 150 && mean < 12.0,
        "{n} vertices, mean difference {mean}"
    );
}

#[test]
fn steps_can_be_undone_from_a_script() {
    let out = temp("steps");
    let (ok, stdout, stderr) = run(
        "scripts/face_fit_steps.rhai",
        &[format!("out={}", out.display())],
    );
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("undid deform"), "{stdout}");
    assert!(stdout
        .lines()
        .last()
        .unwrap()
        .starts_with("landmark_err_iod_pct="));
    // undo with nothing done is an error the script sees
    let script = out.join("undo.rhai");
    // the script lives in the temporary folder: its relative paths would be taken from there,
    // and the sandbox lets it read the landmarks given on the command line
    std::fs::write(
        &script,
        "let f = face_fit_start(data_dir() + \"/images\", #{ pts: pts });\nf.undo();\n",
    )
    .unwrap();
    let pts = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/faces");
    let (ok, _, stderr) = run(
        script.to_str().unwrap(),
        &[format!("pts={}", pts.display())],
    );
    assert!(!ok && stderr.contains("undo.rhai:2"), "{stderr}");
}

fn folder_with(name: &str, pts_text: &str, with_photo: bool) -> PathBuf {
    let d = temp(name);
    if with_photo {
        std::fs::copy(astronaut(), d.join("astronaut.png")).unwrap();
    }
    std::fs::write(d.join("astronaut.pts"), pts_text).unwrap();
    d
}

#[test]
fn bad_photo_folders_give_clear_errors() {
    let good = std::fs::read_to_string("tests/data/faces/astronaut.pts").unwrap();
    // wrong landmark count
    let mut lines: Vec<&str> = good.lines().collect();
    let last_point = lines.len() - 2;
    lines.remove(last_point);
    let short = lines.join("\n").replace("n_points: 68", "n_points: 67");
    let d = folder_with("count", &short, true);
    let e = load_photos(&d, None).unwrap_err().to_string();
    assert!(
        e.contains("astronaut.pts") && e.contains("68") && e.contains("67"),
        "{e}"
    );
    // a landmark outside the photo
    let outside = good.replacen(&good.lines().nth(3).unwrap().to_string(), "600.0 20.0", 1);
    let d = folder_with("outside", &outside, true);
    let e = load_photos(&d, None).unwrap_err().to_string();
    assert!(
        e.contains("astronaut.pts") && e.contains("point 0") && e.contains("512×512"),
        "{e}"
    );
    // landmarks without their photo
    let d = folder_with("missing", &good, false);
    let e = load_photos(&d, None).unwrap_err().to_string();
    assert!(e.contains("astronaut.pts") && e.contains("no photo"), "{e}");
    // a folder that does not exist, from the script
    let (ok, _, stderr) = run(
        "scripts/face_fit.rhai",
        &[
            "images=/nonexistent/photos".into(),
            format!("out={}", temp("none").display()),
        ],
    );
    assert!(!ok && stderr.contains("/nonexistent/photos"), "{stderr}");
    // a good folder loads
    let d = folder_with("good", &good, true);
    let set = load_photos(&d, None).unwrap();
    assert_eq!(set.names, ["astronaut"]);
    assert_eq!(set.views[0].landmarks.len(), 68);
}
