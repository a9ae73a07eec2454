//! The MakeHuman mannequin, CMU BVH clips and their retargeting, checked against the figures
//! documented in `../shared/data/README.md` (sections `bodies/makehuman/` and
//! `motion/cmu_bvh/`) and against the BVH clip itself.

use std::path::PathBuf;
use std::sync::OnceLock;

use emilion::body::{
    signed_volume, Animation, BodyError, Mannequin, Motion, Pose, RetargetOptions,
};
use emilion::geometry::Vec3;
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

fn data() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"))
}

fn mannequin() -> &'static Mannequin {
    static M: OnceLock<Mannequin> = OnceLock::new();
    M.get_or_init(|| Mannequin::load_makehuman(&data().join("bodies/makehuman")).unwrap())
}

fn clip(name: &str) -> Motion {
    Motion::load_bvh(&data().join("motion/cmu_bvh").join(name)).unwrap()
}

fn walk() -> &'static Animation {
    static A: OnceLock<Animation> = OnceLock::new();
    A.get_or_init(|| {
        Animation::new(
            mannequin().clone(),
            clip("002_01.bvh"),
            RetargetOptions::default(),
        )
        .unwrap()
    })
}

// ---------------------------------------------------------------- mannequin

#[test]
fn mesh_loads_as_documented() {
    let m = mannequin();
    let p = m.rest_positions();
    // group `body`: vertices 1–13,380, 13,378 quads
    assert_eq!(p.len(), 13_380);
    assert_eq!(m.triangles().len(), 2 * 13_378);
    assert!(m.triangles().iter().flatten().all(|&v| v < p.len()));
    assert_eq!(m.base_indices()[0], 0);
    assert_eq!(*m.base_indices().last().unwrap(), 13_379);
    // spans y = −8.17 … 8.49 dm: about 1.67 m, put on the floor
    let zmin = p.iter().map(|q| q.z).fold(f64::INFINITY, f64::min);
    let zmax = p.iter().map(|q| q.z).fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(zmin, 0.0);
    assert!((zmax - 1.666).abs() < 0.02, "height {zmax}");
    // left/right symmetric about x = 0
    let xmid = 0.5
        * (p.iter().map(|q| q.x).fold(f64::INFINITY, f64::min)
            + p.iter().map(|q| q.x).fold(f64::NEG_INFINITY, f64::max));
    assert!(xmid.abs() < 0.01, "x centre {xmid}");
    // outward winding: positive enclosed volume, of a human (about 50–80 litres)
    let vol = signed_volume(p, m.triangles());
    assert!(vol > 0.045 && vol < 0.09, "signed volume {vol} m³");
}

#[test]
fn skeleton_as_documented() {
    let m = mannequin();
    let s = m.skeleton();
    assert_eq!(s.len(), 163);
    assert_eq!(s.joints().len(), 326);
    // parents before children
    for (i, b) in s.bones().iter().enumerate() {
        assert!(b.parent.is_none_or(|p| p < i), "{}", b.name);
    }
    // README: root head near (0, 0.56, −0.76) dm, head bone's head near y = 6.98 dm (MakeHuman
    // frame, before the 8.17 dm lift onto the floor)
    let lift = 0.817;
    let root = &s.bones()[s.bone_index("root").unwrap()];
    assert!((root.head - Vec3::new(0.0, 0.076, 0.056 + lift)).norm() < 0.005);
    let head = &s.bones()[s.bone_index("head").unwrap()];
    assert!((head.head.z - (0.698 + lift)).abs() < 0.005);
    // the body faces −y (eyes in front of the head joint), its left side is +x
    let joint = |n: &str| s.joint(n).unwrap().rest;
    assert!(joint("eye.L____head").y < joint("head____head").y - 0.05);
    assert!(joint("upperarm01.L____head").x > 0.1 && joint("upperarm01.R____head").x < -0.1);
    for name in [
        "upperleg01.L",
        "lowerleg01.L",
        "foot.L",
        "upperarm01.L",
        "spine01",
    ] {
        assert!(m.bone_names().any(|n| n == name), "{name}");
    }
}

#[test]
fn weights_are_normalised() {
    let m = mannequin();
    let w = m.weights();
    assert_eq!(w.len(), m.rest_positions().len());
    for v in 0..w.len() {
        let sum: f64 = w.influences(v).map(|(_, x)| x).sum();
        assert!((sum - 1.0).abs() < 1e-12, "vertex {v}: {sum}");
        assert!(w
            .influences(v)
            .all(|(b, x)| x > 0.0 && b < m.skeleton().len()));
    }
    assert!(w.max_influences() <= 9, "{}", w.max_influences()); // README: up to 9
}

#[test]
fn identity_pose_reproduces_rest_mesh() {
    let m = mannequin();
    let mut out = Vec::new();
    m.skin(&m.rest_pose(), &mut out);
    let err = out
        .iter()
        .zip(m.rest_positions())
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(err <= 1e-12, "{err}");
    // one rigid motion for all bones moves the skin rigidly (weights sum to one)
    let g = Isometry3::from_parts(
        Translation3::new(0.3, -1.0, 0.2),
        UnitQuaternion::from_euler_angles(0.4, -0.2, 1.1),
    );
    let pose = Pose::from_transforms(vec![g; m.skeleton().len()]);
    m.skin(&pose, &mut out);
    for (a, b) in out.iter().zip(m.rest_positions()) {
        assert!((a - g.transform_point(&(*b).into()).coords).norm() < 1e-12);
    }
}

// ---------------------------------------------------------------- BVH

fn real_joints(m: &Motion) -> usize {
    m.joints().iter().filter(|j| !j.end_site).count()
}

#[test]
fn both_bvh_variants_parse() {
    let a = clip("002_01.bvh");
    assert_eq!(a.joints()[0].name, "RL_BoneRoot");
    assert_eq!((real_joints(&a), a.channel_count()), (101, 306));
    assert_eq!(a.frame_count(), 171);
    let b = clip("005_01.bvh");
    assert_eq!(b.joints()[0].name, "CC_Base_Hip");
    assert_eq!((real_joints(&b), b.channel_count()), (100, 303));
    assert_eq!(b.frame_count(), 299);
    for (m, d) in [(&a, 2.85), (&b, 4.98)] {
        assert!((m.frame_time() - 1.0 / 60.0).abs() < 1e-5);
        assert!((m.duration() - d).abs() < 0.01, "{}", m.duration());
    }
}

#[test]
fn bvh_bone_lengths_are_constant() {
    for name in ["002_01.bvh", "005_01.bvh"] {
        let m = clip(name);
        let p0 = m.joint_positions(0);
        for k in 0..m.frame_count() {
            let p = m.joint_positions(k);
            for (j, joint) in m.joints().iter().enumerate() {
                let Some(q) = joint.parent else { continue };
                let (l0, l) = ((p0[j] - p0[q]).norm(), (p[j] - p[q]).norm());
                assert!(
                    (l - l0).abs() <= 1e-6 * l0.max(1e-3),
                    "{name} {} {k}",
                    joint.name
                );
            }
        }
    }
}

#[test]
fn bvh_feet_near_floor_in_every_frame() {
    // README: in every frame of every clip the lowest joint is 4–14 cm above the floor
    for name in [
        "002_01", "002_02", "002_03", "002_05", "005_01", "006_01", "007_01", "007_02",
    ] {
        let m = clip(&format!("{name}.bvh"));
        // README: about 4–14 cm (the run 002_03 reaches 14.02 cm with both feet in the air);
        // body joints only (not the exporter's RL_BoneRoot, which lies on the floor)
        let body: Vec<usize> = (0..m.joints().len())
            .filter(|&j| m.joints()[j].name.starts_with("CC_Base_"))
            .collect();
        for k in 0..m.frame_count() {
            let p = m.joint_positions(k);
            let low = body.iter().map(|&j| p[j].z).fold(f64::INFINITY, f64::min);
            assert!((0.04..=0.145).contains(&low), "{name} frame {k}: {low}");
        }
        // README: figures are 156–176 cm tall in frame 0, end sites included
        let p = m.joint_positions(0);
        let (lo, hi) = body
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &j| {
                (lo.min(p[j].z), hi.max(p[j].z))
            });
        assert!(
            (1.555..=1.765).contains(&(hi - lo)),
            "{name}: {} m tall",
            hi - lo
        );
    }
}

#[test]
fn bvh_root_travel() {
    // README: 002_01 advances 3.82 m along the horizontal BVH z axis (world −y)
    let m = clip("002_01.bvh");
    let hip = m.joint_index("CC_Base_Hip").unwrap();
    let d = m.joint_positions(m.frame_count() - 1)[hip] - m.joint_positions(0)[hip];
    let horizontal = (d.x * d.x + d.y * d.y).sqrt();
    assert!((horizontal - 3.82).abs() < 0.05, "{d:?}");
    assert!(d.y < -3.7, "walks toward −y: {d:?}");
}

fn bvh_text() -> String {
    std::fs::read_to_string(data().join("motion/cmu_bvh/002_01.bvh")).unwrap()
}

fn parse_error_line(text: &str) -> (usize, String) {
    match Motion::parse_bvh(text, "test.bvh") {
        Err(e @ BodyError::Parse { line, .. }) => {
            let msg = e.to_string();
            assert!(msg.starts_with(&format!("test.bvh:{line}:")), "{msg}");
            (line, msg)
        }
        other => panic!(
            "expected a parse error, got {:?}",
            other.map(|m| m.frame_count())
        ),
    }
}

#[test]
fn malformed_bvh_is_an_error_with_its_line() {
    let text = bvh_text();
    let lines: Vec<&str> = text.lines().collect();
    // truncated in the hierarchy
    let cut = lines[..300].join("\n");
    assert_eq!(parse_error_line(&cut).0, 300);
    // truncated in the motion data (frame 100 missing its second half)
    let l = lines[672 + 100];
    let half = &l[..l.len() / 2];
    let cut = format!("{}\n{}", lines[..672 + 100].join("\n"), half.trim_end());
    let (line, msg) = parse_error_line(&cut);
    assert_eq!(line, 773);
    assert!(msg.contains("frame 100"), "{msg}");
    // a bad number on line 700
    let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    bad[699] = bad[699].replacen("0.", "0.x", 1);
    let (line, msg) = parse_error_line(&bad.join("\n"));
    assert_eq!(line, 700);
    assert!(msg.contains("0.x"), "{msg}");
    // a bad offset in the hierarchy, an unknown channel, a missing frame count
    let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    bad[19] = "OFFSET -0.214775 4x7.666340 -0.325811".into();
    assert_eq!(parse_error_line(&bad.join("\n")).0, 20);
    let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    bad[8] = "CHANNELS 3 Zrotation Yrotation Wrotation".into();
    assert_eq!(parse_error_line(&bad.join("\n")).0, 9);
    let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    bad[671] = "Frames: many".into();
    assert_eq!(parse_error_line(&bad.join("\n")).0, 672);
    // extra data after the declared frames
    let extra = format!("{text}1 2 3\n");
    assert_eq!(parse_error_line(&extra).0, lines.len() + 1);
}

#[test]
fn truncated_bvh_never_panics() {
    let text = bvh_text();
    let end = text.trim_end().len();
    for cut in (0..end).step_by(997) {
        assert!(
            Motion::parse_bvh(&text[..cut], "t.bvh").is_err(),
            "cut at {cut}"
        );
    }
    for junk in [
        "",
        "HIERARCHY",
        "HIERARCHY ROOT a { } MOTION Frames: 1 Frame Time: 0.1",
    ] {
        // the last one is valid: one joint, no channel, one empty frame
        let r = Motion::parse_bvh(junk, "j.bvh");
        assert_eq!(r.is_ok(), junk.ends_with("0.1"), "{junk}");
    }
    let r = Motion::parse_bvh("HIERARCHY ROOT a { } MOTION Frames: 0 Frame Time: 0.1", "z");
    assert!(r.is_err());
    let nested: String = (0..100_000)
        .map(|i| format!("JOINT b{i} {{ OFFSET 0 1 0 "))
        .collect();
    let deep = format!("HIERARCHY ROOT a {{ {nested} MOTION");
    assert!(Motion::parse_bvh(&deep, "deep").is_err());
}

#[test]
fn missing_file_names_the_file() {
    let path = data().join("motion/cmu_bvh/no_such_clip.bvh");
    let err = Motion::load_bvh(&path).unwrap_err();
    assert!(matches!(err, BodyError::Io { .. }));
    assert!(err.to_string().contains("no_such_clip.bvh"), "{err}");
    let err = load_err(&data().join("no_such_dir"));
    assert!(err.to_string().contains("base.obj"), "{err}");
}

fn scratch_dir(file: &str) -> PathBuf {
    std::env::temp_dir().join(format!("emilion_body_{}_{file}", std::process::id()))
}

/// A scratch copy of the MakeHuman folder with one file replaced.
fn makehuman_with(file: &str, text: &str) -> PathBuf {
    let dir = scratch_dir(file);
    std::fs::create_dir_all(&dir).unwrap();
    for f in ["base.obj", "default.mhskel", "default_weights.mhw"] {
        let src = data().join("bodies/makehuman").join(f);
        if f == file {
            std::fs::write(dir.join(f), text).unwrap();
        } else {
            std::fs::copy(src, dir.join(f)).unwrap();
        }
    }
    dir
}

fn load_err(dir: &std::path::Path) -> BodyError {
    match Mannequin::load_makehuman(dir) {
        Ok(_) => panic!("{}: loaded", dir.display()),
        Err(e) => e,
    }
}

#[test]
fn malformed_makehuman_files_are_errors() {
    let src = data().join("bodies/makehuman");
    let obj = std::fs::read_to_string(src.join("base.obj")).unwrap();
    let lines: Vec<&str> = obj.lines().collect();
    // a bad coordinate on line 20 (a `v` line)
    assert!(lines[19].starts_with("v "));
    let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    bad[19] = "v 1.0 nan? 2.0".into();
    let dir = makehuman_with("base.obj", &bad.join("\n"));
    let err = load_err(&dir);
    assert!(matches!(err, BodyError::Parse { line: 20, .. }), "{err}");
    assert!(err.to_string().contains("base.obj:20:"), "{err}");
    // cut before the skin faces: no face in group `body`
    let dir = makehuman_with("base.obj", &lines[..30_000].join("\n"));
    let err = load_err(&dir);
    assert!(err.to_string().contains("body"), "{err}");
    // a joint that refers to a missing vertex
    let skel = std::fs::read_to_string(src.join("default.mhskel")).unwrap();
    assert!(skel.contains("\"root____head\": ["));
    let bad = skel.replacen("\"root____head\": [", "\"root____head\": [99999, ", 1);
    let err = load_err(&makehuman_with("default.mhskel", &bad));
    assert!(
        err.to_string().contains("default.mhskel") && err.to_string().contains("99999"),
        "{err}"
    );
    // broken JSON: the error names the file and the line
    let cut = &skel[..skel.len() / 2];
    let dir = makehuman_with("default.mhskel", cut);
    let err = load_err(&dir);
    assert!(
        matches!(err, BodyError::Parse { line, .. } if line > 1),
        "{err}"
    );
    // weights for an unknown bone
    let w = std::fs::read_to_string(src.join("default_weights.mhw")).unwrap();
    let dir = makehuman_with(
        "default_weights.mhw",
        &w.replacen("\"spine01\"", "\"spine99\"", 1),
    );
    let err = load_err(&dir);
    assert!(err.to_string().contains("spine99"), "{err}");
    for f in ["base.obj", "default.mhskel", "default_weights.mhw"] {
        let _ = std::fs::remove_dir_all(scratch_dir(f));
    }
}

#[test]
fn retargeting_needs_the_cc_base_joints() {
    let text = "HIERARCHY\nROOT CC_Base_Hip\n{\n OFFSET 0 100 0\n CHANNELS 6 Xposition \
                Yposition Zposition Zrotation Yrotation Xrotation\n End Site\n {\n  OFFSET 0 10 0\n \
                }\n}\nMOTION\nFrames: 2\nFrame Time: 0.0333\n0 0 0 0 0 0\n1 0 0 0 0 0\n";
    let m = Motion::parse_bvh(text, "tiny.bvh").unwrap();
    assert_eq!((m.frame_count(), m.joints().len()), (2, 2));
    assert!((m.joint_positions(1)[1] - Vec3::new(0.01, 0.0, 1.1)).norm() < 1e-12);
    let Err(err) = Animation::new(mannequin().clone(), m, RetargetOptions::default()) else {
        panic!("retargeted a clip without CC_Base joints");
    };
    assert!(
        err.to_string().contains("tiny.bvh") && err.to_string().contains("CC_Base_"),
        "{err}"
    );
}

// ---------------------------------------------------------------- animation

/// Sample times over the first 2 s of the walk, on and between frames.
fn times() -> impl Iterator<Item = f64> {
    (0..=240).map(|i| i as f64 / 120.0)
}

/// Largest relative change, over `times`, of the skinned limb lengths of `a`: for each
/// swung chain the distance from its first head to the joint it points to (hip → knee,
/// knee → ankle, ...), and for every bone of the trunk and the head, its head → tail. Joint
/// positions are means of their marker vertices (the `joint-*` cubes), each skinned with its
/// own weights. Joints defined by skin vertices instead (mid-thigh, neck rings) are left to
/// [`worst_skin_joint_change`]: they show the skin's own blending, not the skeleton's.
fn worst_limb_change(a: &Animation, times: impl Iterator<Item = f64>) -> (f64, String) {
    let m = a.mannequin();
    let s = m.skeleton();
    let mut limbs: Vec<(String, String)> = a
        .swing_map()
        .iter()
        .map(|w| {
            (
                s.bones()[s.bone_index(&w.bone).unwrap()].head_joint.clone(),
                w.toward.clone(),
            )
        })
        .collect();
    let trunk = [
        "root", "spine05", "spine04", "spine03", "spine02", "spine01", "neck01", "neck02",
    ];
    for n in trunk.into_iter().chain(["neck03", "head"]) {
        let b = &s.bones()[s.bone_index(n).unwrap()];
        limbs.push((b.head_joint.clone(), b.tail_joint.clone()));
    }
    let skin = m.rest_positions().len();
    let marker = |j: &str| s.joint(j).unwrap().vertices.iter().all(|&v| v >= skin);
    limbs.retain(|(h, t)| marker(h) && marker(t));
    assert!(limbs.len() >= 12 + 6, "{limbs:?}");
    worst_change(a, &limbs, times)
}

/// Largest relative change of every bone's head → tail distance, joints skinned as above
/// (including joints defined by skin vertices).
fn worst_skin_joint_change(a: &Animation, times: impl Iterator<Item = f64>) -> (f64, String) {
    let bones = a.mannequin().skeleton().bones();
    let all: Vec<_> = bones
        .iter()
        .map(|b| (b.head_joint.clone(), b.tail_joint.clone()))
        .collect();
    worst_change(a, &all, times)
}

fn worst_change(
    a: &Animation,
    limbs: &[(String, String)],
    times: impl Iterator<Item = f64>,
) -> (f64, String) {
    let m = a.mannequin();
    let len = |pose: &Pose, (h, t): &(String, String)| {
        (m.skinned_joint(pose, h).unwrap() - m.skinned_joint(pose, t).unwrap()).norm()
    };
    let rest = m.rest_pose();
    let rest_len: Vec<f64> = limbs.iter().map(|l| len(&rest, l)).collect();
    let mut worst = (0.0, String::new());
    for t in times {
        let pose = a.pose_at(t);
        for (l, l0) in limbs.iter().zip(&rest_len) {
            let err = (len(&pose, l) / l0 - 1.0).abs();
            if err > worst.0 {
                worst = (err, format!("{} → {} at t = {t:.3}", l.0, l.1));
            }
        }
    }
    worst
}

#[test]
fn retargeted_limbs_keep_their_length() {
    let worst = worst_limb_change(walk(), times());
    println!(
        "002_01: largest limb length change {:.3} % ({})",
        100.0 * worst.0,
        worst.1
    );
    assert!(worst.0 < 0.02, "{worst:?}");
    // joints on the skin (thigh and neck rings) move with the blended skin: a few mm
    let skin = worst_skin_joint_change(walk(), times());
    println!(
        "002_01: largest skin-joint distance change {:.3} % ({})",
        100.0 * skin.0,
        skin.1
    );
    assert!(skin.0 < 0.08, "{skin:?}");
}

#[test]
fn other_rig_variant_and_fast_motion_retarget() {
    // 005_01 (ROOT CC_Base_Hip) walks, 002_05 punches: limbs keep their length, the body
    // stays on the floor and in place
    for name in ["005_01.bvh", "002_05.bvh"] {
        let a =
            Animation::new(mannequin().clone(), clip(name), RetargetOptions::default()).unwrap();
        let dt = a.motion().frame_time();
        let ts = (0..a.motion().frame_count())
            .step_by(7)
            .map(|k| k as f64 * dt + 0.5 * dt);
        let worst = worst_limb_change(&a, ts);
        println!(
            "{name}: largest limb length change {:.3} % ({})",
            100.0 * worst.0,
            worst.1
        );
        assert!(worst.0 < 0.02, "{name}: {worst:?}");
        let mut out = Vec::new();
        let m = a.mannequin();
        let hip = |pose: &Pose| {
            0.5 * (m.skinned_joint(pose, "upperleg01.L____head").unwrap()
                + m.skinned_joint(pose, "upperleg01.R____head").unwrap())
        };
        let hip_rest = hip(&m.rest_pose());
        for k in (0..a.motion().frame_count()).step_by(7) {
            let t = k as f64 * dt;
            a.vertices_at(t, &mut out);
            let low = out.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
            assert!(
                low > -0.03 && low < 0.10,
                "{name} frame {k}: lowest vertex {low}"
            );
            // in place: the hip centre is pinned horizontally, and bobs below its rest height
            let d = hip(&a.pose_at(t)) - hip_rest;
            assert!(
                d.x.hypot(d.y) < 1e-3,
                "{name} frame {k}: hip centre moved {d:?}"
            );
            assert!(
                d.z < 0.03 && d.z > -0.25,
                "{name} frame {k}: hip height {d:?}"
            );
        }
    }
}

/// Angle (degrees) at `b` between `a` and `c`.
fn angle(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    (a - b).angle(&(c - b)).to_degrees()
}

#[test]
fn retargeted_joint_angles_follow_the_clip() {
    // knee and elbow angles of the skinned mannequin match the BVH skeleton's
    let a = walk();
    let m = a.mannequin();
    let bvh = a.motion();
    let limbs = [
        (
            ["Thigh", "Calf", "Foot"],
            ["upperleg01", "lowerleg01", "foot"],
        ),
        (
            ["Upperarm", "Forearm", "Hand"],
            ["upperarm01", "lowerarm01", "wrist"],
        ),
    ];
    let mut worst: f64 = 0.0;
    for k in 0..120 {
        let pose = a.frame_pose(k);
        let q = bvh.joint_positions(k);
        for side in ["L", "R"] {
            let b = |n: &str| q[bvh.joint_index(&format!("CC_Base_{side}_{n}")).unwrap()];
            let s = |n: &str| {
                m.skinned_joint(pose, &format!("{n}.{side}____head"))
                    .unwrap()
            };
            for (bj, mj) in &limbs {
                let clip_angle = angle(b(bj[0]), b(bj[1]), b(bj[2]));
                worst = worst.max((angle(s(mj[0]), s(mj[1]), s(mj[2])) - clip_angle).abs());
            }
        }
    }
    println!("largest knee/elbow angle difference: {worst:.2}°");
    assert!(worst < 3.0, "{worst}");
}

#[test]
fn retargeted_walk_steps_in_place() {
    let a = walk();
    let m = a.mannequin();
    let mut out = Vec::new();
    let (mut left, mut right) = (Vec::new(), Vec::new());
    let mut lowest = f64::INFINITY;
    let rest_centre = centre(m.rest_positions());
    let mut travel: f64 = 0.0;
    for t in times() {
        a.vertices_at(t, &mut out);
        lowest = out.iter().map(|p| p.z).fold(lowest, f64::min);
        let c = centre(&out) - rest_centre;
        travel = travel.max((c.x * c.x + c.y * c.y).sqrt());
        let pose = a.pose_at(t);
        left.push(m.skinned_joint(&pose, "foot.L____head").unwrap().z);
        right.push(m.skinned_joint(&pose, "foot.R____head").unwrap().z);
    }
    let lift = |h: &[f64]| {
        h.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
            - h.iter().fold(f64::INFINITY, |a, &b| a.min(b))
    };
    let corr = correlation(&left, &right);
    println!(
        "lowest vertex {lowest:.4} m, ankle lifts {:.3} / {:.3} m, L/R correlation {corr:.2}, \
         horizontal travel {travel:.3} m",
        lift(&left),
        lift(&right)
    );
    assert!(lowest > -0.03, "{lowest}");
    assert!(lift(&left) > 0.05 && lift(&right) > 0.05);
    assert!(corr < -0.3, "feet must alternate: {corr}");
    assert!(travel < 0.2, "{travel}");
    // the feet stay near the floor: some vertex touches down in every sample
    for t in times().step_by(10) {
        a.vertices_at(t, &mut out);
        let low = out.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        assert!(low < 0.05, "t = {t}: lowest vertex {low}");
    }
}

fn centre(p: &[Vec3]) -> Vec3 {
    p.iter().sum::<Vec3>() / p.len() as f64
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

#[test]
fn travel_is_kept_without_in_place() {
    let options = RetargetOptions {
        in_place: false,
        start_time: 0.5,
        ..Default::default()
    };
    let a = Animation::new(mannequin().clone(), clip("002_01.bvh"), options).unwrap();
    assert!((a.duration() - 2.35).abs() < 1e-3);
    let (mut p0, mut p1) = (Vec::new(), Vec::new());
    a.vertices_at(0.0, &mut p0);
    a.vertices_at(a.duration(), &mut p1);
    let d = centre(&p1) - centre(&p0);
    // the clip's hip advances about 3.82 m × (2.33 / 2.83) over this span, scaled to the
    // mannequin's smaller hip height
    let expected = a.scale() * 3.82 * (2.85 - 0.5 - 1.0 / 60.0) / (2.85 - 1.0 / 60.0);
    assert!((-d.y - expected).abs() < 0.15, "{d:?} vs {expected}");
}

#[test]
fn skinning_is_fast() {
    let a = walk();
    let mut out = Vec::new();
    a.vertices_at(0.0, &mut out);
    let n = 200;
    let start = std::time::Instant::now();
    for i in 0..n {
        a.vertices_at(i as f64 * 0.01, &mut out);
    }
    let each = start.elapsed().as_secs_f64() / n as f64;
    println!(
        "vertices_at: {:.3} ms for {} vertices",
        each * 1e3,
        out.len()
    );
    assert!(each < 0.01, "{each} s");
}
