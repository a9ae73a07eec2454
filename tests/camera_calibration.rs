//! Cameras and calibration (issue 8, item 2): a synthetic camera is recovered from noisy and
//! noise-free 3D–2D correspondences, the JSON camera format round-trips, and bad inputs give
//! errors that name the problem (and the file).

use std::path::PathBuf;

use emilion::geometry::camera::{Camera, CameraError};
use emilion::tracking::calibration::{calibrate, dlt, Calibration, CalibrationError};
use nalgebra::{Rotation3, Vector3};

/// Deterministic SplitMix64 generator with uniform and Gaussian draws.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Standard normal (Box–Muller).
    fn gauss(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

fn true_camera() -> Camera {
    Camera {
        fx: 400.0,
        fy: 400.0,
        cx: 162.0,
        cy: 118.0,
        k1: -0.08,
        k2: 0.01,
        rotation: Rotation3::from_euler_angles(0.15, -0.3, 0.08).into_inner(),
        translation: Vector3::new(0.2, -0.1, 0.4),
        width: 320,
        height: 240,
    }
}

/// 60 points seen by `cam`: random pixels inside the image (10 px margin), random depths
/// 2–4 m, back-projected to world coordinates; and their exact distorted projections.
fn scene(cam: &Camera, seed: u64) -> (Vec<Vector3<f64>>, Vec<[f64; 2]>) {
    let mut rng = Rng(seed);
    let mut pts = Vec::new();
    let mut px = Vec::new();
    for _ in 0..60 {
        let u = 10.0 + rng.uniform() * (cam.width as f64 - 20.0);
        let v = 10.0 + rng.uniform() * (cam.height as f64 - 20.0);
        let z = 2.0 + 2.0 * rng.uniform();
        let n = cam.undistort_pixel_to_normalized([u, v]);
        let pc = Vector3::new(n[0] * z, n[1] * z, z);
        let pw = cam.rotation.transpose() * (pc - cam.translation);
        let q = cam.project(&pw).expect("point is in front");
        assert!((q[0] - u).abs() < 1e-9 && (q[1] - v).abs() < 1e-9);
        pts.push(pw);
        px.push(q);
    }
    (pts, px)
}

fn rotation_error_deg(a: &Camera, b: &Camera) -> f64 {
    let d = a.rotation * b.rotation.transpose();
    ((d.trace() - 1.0) / 2.0)
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

fn report(label: &str, c: &Calibration, truth: &Camera) -> (f64, f64) {
    let f_err = ((c.camera.fx - truth.fx) / truth.fx)
        .abs()
        .max(((c.camera.fy - truth.fy) / truth.fy).abs());
    let pp_err = (c.camera.cx - truth.cx)
        .abs()
        .max((c.camera.cy - truth.cy).abs());
    let rot = rotation_error_deg(&c.camera, truth);
    let tr = (c.camera.translation - truth.translation).norm();
    eprintln!(
        "{label}: focal rel err {:.3e} ({:.4} %), principal point err {pp_err:.4} px, \
         rotation err {rot:.5} deg, translation err {:.3} mm, k1 {:.5}, k2 {:.5}, \
         rms {:.4} px, iterations {}, converged {}",
        f_err,
        100.0 * f_err,
        tr * 1000.0,
        c.camera.k1,
        c.camera.k2,
        c.rms_px,
        c.iterations,
        c.converged
    );
    (f_err, pp_err)
}

#[test]
fn calibration_recovers_camera_from_noisy_points() {
    let truth = true_camera();
    let (pts, mut px) = scene(&truth, 0x5EED_0008);
    let mut rng = Rng(42);
    for q in &mut px {
        q[0] += 0.1 * rng.gauss();
        q[1] += 0.1 * rng.gauss();
    }
    let c = calibrate(&pts, &px, truth.width, truth.height).expect("calibration");
    let (f_err, pp_err) = report("noisy (sigma 0.1 px)", &c, &truth);
    assert!(f_err < 0.005, "focal error {f_err}");
    assert!(pp_err < 1.0, "principal point error {pp_err}");
    let rot = rotation_error_deg(&c.camera, &truth);
    assert!(rot < 0.2, "rotation error {rot} deg");
    let tr = (c.camera.translation - truth.translation).norm();
    assert!(tr < 0.005, "translation error {tr} m");
    assert!(c.rms_px <= 0.2, "rms {}", c.rms_px);
    assert!((c.camera.rotation.determinant() - 1.0).abs() < 1e-9);
    c.camera.validate().expect("calibrated camera is valid");
}

#[test]
fn calibration_is_exact_without_noise() {
    let truth = true_camera();
    let (pts, px) = scene(&truth, 0x5EED_0008);
    let c = calibrate(&pts, &px, truth.width, truth.height).expect("calibration");
    let (f_err, pp_err) = report("noise-free", &c, &truth);
    assert!(f_err < 1e-6, "focal error {f_err}");
    assert!(pp_err < 1e-4, "principal point error {pp_err}");
    assert!((c.camera.k1 - truth.k1).abs() < 1e-6, "k1 {}", c.camera.k1);
    assert!(c.rms_px < 1e-6, "rms {}", c.rms_px);
    assert!(c.converged);
}

fn tmp_path(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("emilion-camera-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

#[test]
fn json_round_trip_is_exact() {
    let cam = true_camera();
    let path = tmp_path("roundtrip.json");
    cam.save(&path).expect("save");
    let back = Camera::load(&path).expect("load");
    assert_eq!(back, cam);
    let text = std::fs::read_to_string(&path).expect("read");
    assert!(
        text.contains("\"intrinsics\"") && text.contains("\"extrinsics\""),
        "{text}"
    );
    assert_eq!(
        Camera::from_json(&cam.to_json().expect("json")).expect("parse"),
        cam
    );
}

#[test]
fn too_few_points_is_a_clear_error() {
    let truth = true_camera();
    let (pts, px) = scene(&truth, 1);
    let err = calibrate(&pts[..5], &px[..5], 320, 240).expect_err("5 points must fail");
    assert_eq!(err, CalibrationError::TooFewPoints { got: 5, needed: 6 });
    let msg = err.to_string();
    assert!(
        msg.contains("too few points") && msg.contains('5') && msg.contains('6'),
        "{msg}"
    );
}

#[test]
fn coplanar_points_are_rejected_by_dlt() {
    let truth = true_camera();
    let mut rng = Rng(7);
    // points on the plane z = 3 in camera-ish coordinates, rotated into the world
    let pts: Vec<Vector3<f64>> = (0..20)
        .map(|_| {
            let pc = Vector3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 3.0);
            truth.rotation.transpose() * (pc - truth.translation)
        })
        .collect();
    let px: Vec<[f64; 2]> = pts
        .iter()
        .map(|p| truth.project(p).expect("front"))
        .collect();
    let err = dlt(&pts, &px).expect_err("coplanar must fail");
    assert!(
        matches!(
            err,
            CalibrationError::DegeneratePoints {
                shape: "coplanar",
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("coplanar"), "{err}");
    let err = calibrate(&pts, &px, 320, 240).expect_err("coplanar must fail");
    assert!(err.to_string().contains("coplanar"), "{err}");
    // collinear too
    let line: Vec<Vector3<f64>> = (0..10)
        .map(|i| Vector3::new(0.1 * i as f64, 0.0, 3.0))
        .collect();
    let lpx = vec![[1.0, 2.0]; 10];
    let err = dlt(&line, &lpx).expect_err("collinear must fail");
    assert!(err.to_string().contains("collinear"), "{err}");
}

#[test]
fn nan_input_is_a_clear_error() {
    let truth = true_camera();
    let (mut pts, px) = scene(&truth, 3);
    pts[4].y = f64::NAN;
    let err = calibrate(&pts, &px, 320, 240).expect_err("NaN must fail");
    assert_eq!(
        err,
        CalibrationError::NonFinite {
            what: "3D point",
            index: 4
        }
    );
    assert!(
        err.to_string().contains("non-finite") && err.to_string().contains('4'),
        "{err}"
    );
}

#[test]
fn json_missing_fx_names_file_and_field() {
    let cam = true_camera();
    let mut v: serde_json::Value =
        serde_json::from_str(&cam.to_json().expect("json")).expect("valid json");
    v["intrinsics"]
        .as_object_mut()
        .expect("object")
        .remove("fx");
    let path = tmp_path("missing_fx.json");
    std::fs::write(&path, v.to_string()).expect("write");
    let err = Camera::load(&path).expect_err("missing fx must fail");
    assert!(matches!(&err, CameraError::MissingField { field, .. } if field == "intrinsics.fx"));
    let msg = err.to_string();
    assert!(
        msg.contains("missing_fx.json") && msg.contains("intrinsics.fx"),
        "{msg}"
    );
    assert!(msg.contains("missing field"), "{msg}");
}

#[test]
fn json_nan_value_names_file_and_field() {
    // JSON has no NaN: writers emit `null` (serde_json) or the bare token `NaN` (Python).
    let cam = true_camera();
    let mut v: serde_json::Value =
        serde_json::from_str(&cam.to_json().expect("json")).expect("valid json");
    v["extrinsics"]["translation"][1] = serde_json::Value::Null;
    let path = tmp_path("nan_translation.json");
    std::fs::write(&path, v.to_string()).expect("write");
    let err = Camera::load(&path).expect_err("null must fail");
    let msg = err.to_string();
    assert!(matches!(err, CameraError::NotFinite { .. }), "{err:?}");
    assert!(
        msg.contains("nan_translation.json") && msg.contains("extrinsics.translation[1]"),
        "{msg}"
    );
    assert!(msg.contains("not a finite number"), "{msg}");

    let text = cam
        .to_json()
        .expect("json")
        .replacen("\"cy\": 118.0", "\"cy\": NaN", 1);
    assert!(text.contains("NaN"));
    let path = tmp_path("nan_token.json");
    std::fs::write(&path, text).expect("write");
    let msg = Camera::load(&path)
        .expect_err("NaN token must fail")
        .to_string();
    assert!(
        msg.contains("nan_token.json") && msg.contains("invalid JSON"),
        "{msg}"
    );

    // saving a camera holding NaN fails before writing, naming the field
    let mut bad = cam.clone();
    bad.fy = f64::NAN;
    let path = tmp_path("never_written.json");
    let msg = bad
        .save(&path)
        .expect_err("NaN must not be saved")
        .to_string();
    assert!(
        msg.contains("never_written.json") && msg.contains("intrinsics.fy"),
        "{msg}"
    );
    assert!(!path.exists());
}

#[test]
fn invalid_rotation_and_focal_are_rejected() {
    let mut cam = true_camera();
    cam.rotation[(0, 0)] += 1e-3;
    let msg = cam.validate().expect_err("not orthonormal").to_string();
    assert!(
        msg.contains("extrinsics.rotation") && msg.contains("not a rotation"),
        "{msg}"
    );
    let mut cam = true_camera();
    cam.fx = -3.0;
    let path = tmp_path("neg_focal.json");
    let file: emilion::geometry::camera::JsonCamera = (&cam).into();
    std::fs::write(&path, serde_json::to_string(&file).expect("ser")).expect("write");
    let msg = Camera::load(&path).expect_err("negative focal").to_string();
    assert!(
        msg.contains("neg_focal.json") && msg.contains("intrinsics.fx"),
        "{msg}"
    );
    assert!(msg.contains("positive focal"), "{msg}");
}
