//! Tracking outputs: BVH export read back by the BVH reader reproduces the joints; swing
//! metrics follow known motions (turning body, wrist on a circle, symmetric pose); the
//! broadcast overlay draws where joints project and tiles the cameras; bad input and
//! unwritable paths give errors naming the problem.

use std::path::{Path, PathBuf};

use emilion::body::bvh::{bvh_to_world, Motion};
use emilion::geometry::Camera;
use emilion::geometry::Vec3;
use emilion::tracking::bvh_export::{
    to_bvh_string, write_bvh, write_joints_csv, TrackingOutputError,
};
use emilion::tracking::joints::{joint_index, JOINT_COUNT, TRACKING_JOINTS};
use emilion::tracking::overlay::{
    broadcast_frame, draw_skeleton, draw_skeleton_styled, write_overlay_png, SkeletonStyle,
};
use emilion::tracking::swing_metrics::{swing_metrics, try_swing_metrics, write_swing_metrics};
use image::RgbImage;
use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

type Pose = [Vec3; JOINT_COUNT];

/// A fresh, empty folder under the target's test temp dir.
fn temp_dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("tracking_outputs")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn j(name: &str) -> usize {
    joint_index(name).unwrap()
}

/// A standing person, left-right symmetric about x = 0, facing −y (metres, z up).
fn standing() -> Pose {
    let mut p = [Vec3::zeros(); JOINT_COUNT];
    let set = |p: &mut Pose, n: &str, x: f64, y: f64, z: f64| p[j(n)] = Vec3::new(x, y, z);
    set(&mut p, "pelvis", 0.0, 0.0, 1.0);
    set(&mut p, "spine", 0.0, 0.02, 1.25);
    set(&mut p, "neck", 0.0, 0.01, 1.5);
    set(&mut p, "head", 0.0, 0.0, 1.75);
    for (s, sx) in [("l", 1.0), ("r", -1.0)] {
        set(&mut p, &format!("{s}_shoulder"), 0.2 * sx, 0.02, 1.45);
        set(&mut p, &format!("{s}_elbow"), 0.25 * sx, 0.03, 1.17);
        set(&mut p, &format!("{s}_wrist"), 0.27 * sx, 0.0, 0.92);
        set(&mut p, &format!("{s}_hip"), 0.1 * sx, 0.0, 0.95);
        set(&mut p, &format!("{s}_knee"), 0.11 * sx, -0.02, 0.52);
        set(&mut p, &format!("{s}_ankle"), 0.11 * sx, 0.03, 0.09);
    }
    p
}

fn rot(axis: [f64; 3], deg: f64) -> Matrix3<f64> {
    *Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::from(axis)), deg.to_radians())
        .matrix()
}

/// Forward kinematics of the rest pose with a local rotation per joint (applied to the bones
/// to its children), the root rotation and translation: a rigid skeleton.
fn pose_fk(rest: &Pose, local: &[Matrix3<f64>; JOINT_COUNT], root: Vec3) -> Pose {
    let mut g = [Matrix3::identity(); JOINT_COUNT];
    let mut out = [Vec3::zeros(); JOINT_COUNT];
    for (k, t) in TRACKING_JOINTS.iter().enumerate() {
        match t.parent {
            None => {
                g[k] = local[k];
                out[k] = root;
            }
            Some(p) => {
                g[k] = g[p] * local[k];
                out[k] = out[p] + g[p] * (rest[k] - rest[p]);
            }
        }
    }
    out
}

/// Twenty frames of a rigid skeleton: the root turns and travels, limbs bend and twist
/// about varied axes (up to ~100°).
fn rigid_motion() -> Vec<Pose> {
    let rest = standing();
    (0..20)
        .map(|f| {
            let s = f as f64 / 19.0;
            let local: [Matrix3<f64>; JOINT_COUNT] = std::array::from_fn(|k| {
                if k == 0 {
                    rot([0.0, 0.0, 1.0], 170.0 * s) * rot([1.0, 0.0, 0.0], 15.0 * s)
                } else {
                    let a = k as f64;
                    rot([a.sin(), a.cos(), 0.5 + 0.1 * a], (20.0 + 4.0 * a) * s)
                }
            });
            pose_fk(&rest, &local, Vec3::new(0.3 * s, -0.5 * s, 1.0 + 0.05 * s))
        })
        .collect()
}

#[test]
fn bvh_round_trip_reproduces_rigid_motion() {
    let frames = rigid_motion();
    let dir = temp_dir("bvh");
    let path = dir.join("rigid.bvh");
    write_bvh(&path, &frames, 30.0).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let motion = Motion::parse_bvh(&text, "rigid.bvh").unwrap();
    assert_eq!(motion.frame_count(), 20);
    assert!((motion.frame_time() - 1.0 / 30.0).abs() < 1e-9);
    for end in [
        "head_End",
        "l_wrist_End",
        "r_wrist_End",
        "l_ankle_End",
        "r_ankle_End",
    ] {
        assert!(motion.joint_index(end).is_some(), "no end site {end}");
    }
    let mut worst: f64 = 0.0;
    for (f, frame) in frames.iter().enumerate() {
        let got = motion.joint_positions(f);
        // the root channels, mapped with bvh_to_world, are the pelvis
        let v = motion.frame(f);
        let root = bvh_to_world(Vec3::new(v[0], v[1], v[2]));
        assert!((root - frame[0]).norm() < 1e-7, "frame {f}: root {root:?}");
        for (k, t) in TRACKING_JOINTS.iter().enumerate() {
            let b = motion.joint_index(t.name).unwrap();
            worst = worst.max((got[b] - frame[k]).norm());
        }
    }
    println!("BVH round trip: max joint error {:.3e} m", worst);
    assert!(worst < 0.5e-3, "max joint error {worst} m");
}

#[test]
fn bvh_keeps_directions_when_lengths_vary() {
    let mut frames = rigid_motion();
    for (f, frame) in frames.iter_mut().enumerate() {
        // stretch every bone by a frame-dependent factor
        let orig = *frame;
        for (k, t) in TRACKING_JOINTS.iter().enumerate() {
            if let Some(p) = t.parent {
                let scale = 1.0 + 0.02 * ((f + k) % 5) as f64;
                frame[k] = frame[p] + (orig[k] - orig[p]) * scale;
            }
        }
    }
    let text = to_bvh_string(&frames, 25.0, None).unwrap();
    let motion = Motion::parse_bvh(&text, "stretched").unwrap();
    let mut worst: f64 = 0.0;
    for (f, frame) in frames.iter().enumerate() {
        let got = motion.joint_positions(f);
        for (k, t) in TRACKING_JOINTS.iter().enumerate() {
            if let Some(p) = t.parent {
                let (bk, bp) = (
                    motion.joint_index(t.name).unwrap(),
                    motion.joint_index(TRACKING_JOINTS[p].name).unwrap(),
                );
                let a = (got[bk] - got[bp]).normalize();
                let b = (frame[k] - frame[p]).normalize();
                // joints with several children keep a best fit, not every direction
                if [0usize, 1].contains(&p) {
                    continue;
                }
                worst = worst.max(a.angle(&b).to_degrees());
            }
        }
    }
    println!("stretched bones: max direction error {worst:.2e}°");
    assert!(worst < 1e-3, "direction error {worst}°");
}

#[test]
fn joints_csv_has_header_and_rows() {
    let frames = rigid_motion();
    let path = temp_dir("csv").join("joints.csv");
    write_joints_csv(&path, &frames, 50.0).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 21);
    assert!(lines[0].starts_with("frame,time,pelvis_x,pelvis_y,pelvis_z,spine_x"));
    assert!(lines[0].ends_with("r_ankle_x,r_ankle_y,r_ankle_z"));
    let row: Vec<f64> = lines[2].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(row.len(), 2 + 3 * JOINT_COUNT);
    assert_eq!(row[0], 1.0);
    assert!((row[1] - 0.02).abs() < 1e-15);
    assert_eq!(row[2 + 3 * 6 + 2], frames[1][6].z);
}

#[test]
fn rotations_follow_a_turning_body() {
    let rest = standing();
    let (fps, rate) = (60.0, 360.0); // one full turn per second
    let frames: Vec<Pose> = (0..90)
        .map(|f| {
            let r = rot([0.0, 0.0, 1.0], rate * f as f64 / fps);
            std::array::from_fn(|k| r * rest[k])
        })
        .collect();
    let m = try_swing_metrics(&frames, fps).unwrap();
    assert_eq!(m.time.len(), 90);
    let mut worst: f64 = 0.0;
    for f in 0..90 {
        let expect = rate * f as f64 / fps;
        worst = worst
            .max((m.pelvis_deg[f] - expect).abs())
            .max((m.shoulder_deg[f] - expect).abs());
        assert!(
            m.x_factor_deg[f].abs() < 1e-9,
            "frame {f}: {}",
            m.x_factor_deg[f]
        );
    }
    println!("turning body: max rotation error {worst:.2e}° over 540°");
    assert!(worst < 0.1, "rotation error {worst}°");
    // twist the shoulders 30° against the pelvis: X-factor 30
    let mut twisted = rest;
    for n in [
        "spine",
        "neck",
        "head",
        "l_shoulder",
        "l_elbow",
        "l_wrist",
        "r_shoulder",
        "r_elbow",
        "r_wrist",
    ] {
        twisted[j(n)] = rot([0.0, 0.0, 1.0], 30.0) * rest[j(n)];
    }
    let m = swing_metrics(&[twisted], 30.0);
    assert!(
        (m.x_factor_deg[0] - 30.0).abs() < 1e-9,
        "{}",
        m.x_factor_deg[0]
    );
}

#[test]
fn hand_speed_on_a_circle() {
    let rest = standing();
    let (fps, r, omega) = (240.0, 0.3, 2.0 * std::f64::consts::PI * 1.5);
    let frames: Vec<Pose> = (0..200)
        .map(|f| {
            let t = f as f64 / fps;
            let mut p = rest;
            p[j("l_wrist")] = Vec3::new(0.1, -0.3, 1.0)
                + Vec3::new((omega * t).cos(), 0.0, (omega * t).sin()) * r;
            p
        })
        .collect();
    let m = swing_metrics(&frames, fps);
    let expect = r * omega;
    let worst = m
        .l_hand_speed
        .iter()
        .map(|v| (v - expect).abs() / expect)
        .fold(0.0, f64::max);
    println!("wrist on a circle: speed {expect:.4} m/s, max relative error {worst:.2e}");
    assert!(worst < 0.01, "relative speed error {worst}");
    assert!(m.r_hand_speed.iter().all(|v| v.abs() < 1e-12));
}

#[test]
fn centre_of_mass_of_a_symmetric_pose() {
    let p = standing();
    let m = swing_metrics(&[p], 30.0);
    let c = m.com[0];
    println!("standing centre of mass: {c:?}");
    assert!(c.x.abs() < 1e-9, "com x {}", c.x);
    assert!(
        c.z > p[j("l_hip")].z && c.z < p[j("l_shoulder")].z,
        "com z {}",
        c.z
    );
}

#[test]
fn swing_metric_files_are_written() {
    let frames = rigid_motion();
    let dir = temp_dir("metrics");
    let m = swing_metrics(&frames, 30.0);
    let paths = write_swing_metrics(&dir, "swing", &m).unwrap();
    assert_eq!(paths.len(), 5);
    for p in &paths {
        assert!(std::fs::metadata(p).unwrap().len() > 0, "{}", p.display());
    }
    let csv = std::fs::read_to_string(dir.join("swing.csv")).unwrap();
    assert!(csv.starts_with(
        "time,pelvis_deg,shoulder_deg,x_factor_deg,com_x,com_y,com_z,l_hand_speed,r_hand_speed\n"
    ));
    assert_eq!(csv.lines().count(), 21);
}

/// A camera 4 m in front of the body (at −y), looking at it (+y), `w × h` pixels.
fn front_camera(w: u32, h: u32) -> Camera {
    let r = Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0);
    let c = Vector3::new(0.0, -4.0, 1.2);
    let f = w as f64;
    Camera::new(f, f, w as f64 / 2.0, h as f64 / 2.0, r, -(r * c), w, h)
}

fn pixel_of(cam: &Camera, p: &Vec3) -> (u32, u32) {
    let uv = cam.project(p).unwrap();
    (uv[0].floor() as u32, uv[1].floor() as u32)
}

#[test]
fn overlay_draws_projected_joints() {
    let pose = standing();
    let cam = front_camera(320, 240);
    let mut img = RgbImage::new(320, 240);
    draw_skeleton(&mut img, &cam, &pose, [255, 0, 0]);
    let (x, y) = pixel_of(&cam, &pose[0]);
    assert_eq!(
        img.get_pixel(x, y).0,
        [255, 0, 0],
        "pelvis pixel ({x}, {y})"
    );
    assert_eq!(img.get_pixel(2, 2).0, [0, 0, 0], "background");

    let style = SkeletonStyle::tracked();
    let mut img = RgbImage::new(320, 240);
    draw_skeleton_styled(&mut img, &cam, &pose, &style);
    let (lx, ly) = pixel_of(&cam, &pose[j("l_wrist")]);
    let (rx, ry) = pixel_of(&cam, &pose[j("r_wrist")]);
    assert_eq!(img.get_pixel(lx, ly).0, style.left);
    assert_eq!(img.get_pixel(rx, ry).0, style.right);
    assert_ne!(style.left, style.right);
    // the middle of the left forearm is drawn in the left colour
    let mid = (pose[j("l_elbow")] + pose[j("l_wrist")]) * 0.5;
    let (mx, my) = pixel_of(&cam, &mid);
    assert_eq!(img.get_pixel(mx, my).0, style.left);
}

#[test]
fn broadcast_tiles_cameras() {
    let pose = standing();
    let mut truth = pose;
    for p in truth.iter_mut() {
        p.x += 0.3;
    }
    let cams: Vec<Camera> = (0..4).map(|_| front_camera(160, 120)).collect();
    let images: Vec<RgbImage> = (0..4).map(|_| RgbImage::new(160, 120)).collect();
    let pic = broadcast_frame(&images, &cams, &pose, Some(&truth));
    assert_eq!(pic.dimensions(), (320, 240));
    let (x, y) = pixel_of(&cams[3], &pose[j("head")]);
    assert_eq!(
        pic.get_pixel(x + 160, y + 120).0,
        SkeletonStyle::tracked().centre
    );
    let (x, y) = pixel_of(&cams[2], &pose[j("l_knee")]);
    assert_eq!(pic.get_pixel(x, y + 120).0, SkeletonStyle::tracked().left);
    let (x, y) = pixel_of(&cams[1], &truth[j("head")]);
    assert_eq!(pic.get_pixel(x + 160, y).0, SkeletonStyle::truth().centre);

    let pic = broadcast_frame(&images[..3], &cams[..3], &pose, None);
    assert_eq!(pic.dimensions(), (320, 240));
    let pic = broadcast_frame(&[], &[], &pose, None);
    assert_eq!(pic.dimensions(), (0, 0));

    let dir = temp_dir("overlay");
    let path = dir.join("broadcast.png");
    write_overlay_png(&path, &images, &cams, &pose, Some(&truth)).unwrap();
    let back = image::open(&path).unwrap();
    assert_eq!((back.width(), back.height()), (320, 240));
}

#[test]
fn joints_behind_the_camera_do_not_panic() {
    let pose = standing();
    // looking away from the body: everything behind
    let r = Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, -1.0, 0.0);
    let c = Vector3::new(0.0, -4.0, 1.2);
    let away = Camera::new(300.0, 300.0, 160.0, 120.0, r, -(r * c), 320, 240);
    let mut img = RgbImage::new(320, 240);
    draw_skeleton(&mut img, &away, &pose, [255, 255, 255]);
    assert!(img.pixels().all(|p| p.0 == [0, 0, 0]));
    // a camera inside the body: some joints in front, some behind, some at the camera
    let inside = Camera::new(
        300.0,
        300.0,
        160.0,
        120.0,
        Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0),
        -(Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0) * pose[0]),
        320,
        240,
    );
    let mut bad = pose;
    bad[5] = Vec3::new(f64::NAN, 0.0, 1.0);
    draw_skeleton(&mut img, &inside, &bad, [255, 255, 255]);
    let _ = broadcast_frame(&[img], &[inside, away], &bad, Some(&pose));
}

fn message(e: TrackingOutputError) -> String {
    e.to_string()
}

#[test]
fn bad_input_is_reported() {
    let frames = rigid_motion();
    let dir = temp_dir("errors");
    let e = message(write_bvh(&dir.join("a.bvh"), &frames, 0.0).unwrap_err());
    assert!(e.contains("fps") && e.contains('0'), "{e}");
    let e = message(write_joints_csv(&dir.join("a.csv"), &frames, -3.0).unwrap_err());
    assert!(e.contains("fps"), "{e}");
    let e = message(write_bvh(&dir.join("a.bvh"), &[], 30.0).unwrap_err());
    assert!(e.contains("no frames"), "{e}");

    let mut nan = frames.clone();
    nan[3][j("l_wrist")].y = f64::NAN;
    let e = message(to_bvh_string(&nan, 30.0, None).unwrap_err());
    assert!(e.contains("frame 3") && e.contains("l_wrist"), "{e}");
    let e = message(try_swing_metrics(&nan, 30.0).unwrap_err());
    assert!(e.contains("frame 3") && e.contains("l_wrist"), "{e}");

    let missing = dir.join("no_such_dir").join("out.bvh");
    let e = write_bvh(&missing, &frames, 30.0).unwrap_err();
    assert!(matches!(e, TrackingOutputError::Io { .. }));
    assert!(message(e).contains("no_such_dir/out.bvh"));
    let m = swing_metrics(&frames, 30.0);
    let e = message(write_swing_metrics(&dir.join("no_such_dir"), "s", &m).unwrap_err());
    assert!(e.contains("no_such_dir"), "{e}");
    let img = vec![RgbImage::new(16, 16)];
    let cam = vec![front_camera(16, 16)];
    let e = message(
        write_overlay_png(&dir.join("no_such_dir/o.png"), &img, &cam, &frames[0], None)
            .unwrap_err(),
    );
    assert!(e.contains("no_such_dir"), "{e}");
    let e = message(write_overlay_png(&dir.join("o.png"), &[], &[], &frames[0], None).unwrap_err());
    assert!(e.contains("no"), "{e}");
}
