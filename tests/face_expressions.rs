//! Face animation: the CANDIDE-3 reader and model, MPEG-4 FAPs on the MediaPipe mesh, Bézier
//! muscles, expression sliders and the ARKit-52 glTF export. Checked against facts that do not
//! come from the code: the published counts of CANDIDE-3, its mirror symmetry, MPEG-4's FAP
//! definition (value / 1024 × FAPU), the lips and eyelids of the canonical mesh, Apple's names.

use std::path::{Path, PathBuf};

use emilion::face::blendshapes::{arkit_displacements, write_arkit_glb, ARKIT_NAMES};
use emilion::face::candide::Candide;
use emilion::face::expressions::{Expressions, BASIC_EXPRESSIONS};
use emilion::face::fap::{FapRig, Fapus, TRACKED_FAPS};
use emilion::face::muscles::MuscleRig;
use emilion::face::{FaceError, FaceMesh};
use emilion::geometry::Vec3;

fn mesh() -> FaceMesh {
    FaceMesh::mediapipe().expect("MediaPipe canonical mesh in ../shared/data")
}

fn candide() -> Candide {
    Candide::load(&Candide::default_path()).expect("candide3.wfm in ../shared/data")
}

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir()
        .join(format!("emilion-face-expr-{}", std::process::id()))
        .join(name)
}

// ---------------------------------------------------------------- CANDIDE-3

#[test]
fn candide_counts_indices_and_names() {
    let c = candide();
    // CANDIDE-3.1.6 as published: 113 vertices, 184 triangles, 65 AUs, 14 SUs.
    assert_eq!(c.vertices.len(), 113);
    assert_eq!(c.faces.len(), 184);
    assert_eq!(c.animation_units.len(), 65);
    assert_eq!(c.shape_units.len(), 14);
    assert!(c.faces.iter().flatten().all(|&i| (i as usize) < 113));
    for u in c.animation_units.iter().chain(&c.shape_units) {
        assert!(!u.displacements.is_empty(), "{}", u.label);
        assert!(u.displacements.iter().all(|(i, _)| *i < 113));
    }
    // 11 action-unit vectors + 54 FAPs (3–42, 51–64).
    let faps: Vec<u8> = c.animation_units.iter().filter_map(|u| u.fap).collect();
    assert_eq!(faps.len(), 54);
    let expected: Vec<u8> = (3..=42).chain(51..=64).collect();
    assert_eq!(faps, expected);
    let jaw = &c.animation_units[c.fap_index(3).unwrap()];
    assert_eq!(jaw.name, "open_jaw");
    assert_eq!(jaw.fapu, Some(emilion::face::fap::FapUnit::Mns));
    assert_eq!(
        c.animation_units[c.fap_index(19).unwrap()].fapu,
        Some(emilion::face::fap::FapUnit::Irisd)
    );
    assert_eq!(c.animation_units[c.fap_index(23).unwrap()].fapu, None); // eyeball: angle unit
    assert_eq!(c.animation_units[0].name, "Upper lip raiser (AU10)");
    assert_eq!(c.shape_units[0].name, "Head height");
    assert_eq!(c.shape_units[13].name, "Chin width");
    assert_eq!(c.find_unit("jaw drop"), Some((false, 1)));
    assert_eq!(c.global_motion.len(), 3);
    assert_eq!(c.global_motion[1], [1.0, 1.0, 1.0]);
    // Zero parameters: the neutral mask.
    assert_eq!(c.apply(&[], &[]), c.vertices);
}

#[test]
fn candide_fapus_and_symmetric_units() {
    let c = candide();
    let f = c.fapus().unwrap();
    eprintln!("CANDIDE FAPUs (model units): {f:?}");
    for v in [f.mw, f.mns, f.ens, f.es, f.irisd] {
        assert!(v > 0.0 && v < 2.0);
    }
    // A face: the pupils about as far apart as the mouth is wide, eyes above the nose.
    assert!((f.es / f.mw - 1.0).abs() < 0.5, "ES/MW {}", f.es / f.mw);
    assert!(f.irisd < f.mns && f.mns < f.ens && f.ens < f.es);
    // The same ratios on the MediaPipe mesh (an independent face) within 20 %.
    let m = Fapus::mediapipe(&mesh()).unwrap();
    eprintln!("MediaPipe FAPUs (m): {m:?}");
    for (a, b) in [
        (f.es / f.mw, m.es / m.mw),
        (f.mns / f.mw, m.mns / m.mw),
        (f.ens / f.es, m.ens / m.es),
    ] {
        assert!(
            (a / b - 1.0).abs() < 0.2,
            "CANDIDE ratio {a} vs MediaPipe {b}"
        );
    }

    // Symmetric units keep mirror pairs mirrored; lateral FAPs mirror each other.
    let mirror = c.mirror_map();
    let paired = mirror
        .iter()
        .enumerate()
        .filter(|&(i, &j)| {
            let (p, q) = (c.vertices[i], c.vertices[j]);
            (p.x + q.x).abs() < 1e-6 && (p.y - q.y).abs() < 1e-6 && (p.z - q.z).abs() < 1e-6
        })
        .count();
    assert_eq!(paired, 113, "CANDIDE-3.1.4+ is symmetric");
    let lateral = |n: &str| {
        ["_l_", "_r_", "_lm", "_rm", "difference"]
            .iter()
            .any(|s| n.contains(s))
    };
    let mut checked = 0;
    for (shape, units) in [(false, &c.animation_units), (true, &c.shape_units)] {
        for (k, u) in units.iter().enumerate() {
            if lateral(&u.name) || u.fap == Some(15) || u.fap == Some(64) {
                continue; // one-sided units, shift_jaw and bend_nose move sideways
            }
            let mut p = vec![0.0; units.len()];
            p[k] = 0.7;
            let g = if shape {
                c.apply(&p, &[])
            } else {
                c.apply(&[], &p)
            };
            for (i, &j) in mirror.iter().enumerate() {
                let (a, b) = (g[i], g[j]);
                let err = (a.x + b.x)
                    .abs()
                    .max((a.y - b.y).abs())
                    .max((a.z - b.z).abs());
                assert!(
                    err < 1e-6,
                    "{} breaks symmetry at vertices {i}/{j}: {err}",
                    u.label
                );
            }
            checked += 1;
        }
    }
    eprintln!("{checked} symmetric CANDIDE units checked");
    assert!(checked >= 25);
    // FAP 3 at 1024 moves the chin (vertex 10) down by exactly one MNS.
    let mut a = vec![0.0; 65];
    a[c.fap_index(3).unwrap()] = 1024.0;
    let g = c.apply(&[], &a);
    assert!((c.vertices[10].y - g[10].y - f.mns).abs() < 1e-12);
}

#[test]
fn candide_errors_name_file_and_line() {
    let good = std::fs::read_to_string(Candide::default_path()).unwrap();
    let path = Path::new("broken.wfm");
    // A vertex coordinate that is not a number on line 41.
    let lines: Vec<&str> = good.lines().collect();
    assert!(lines[40].split_whitespace().count() == 3);
    let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    bad[40] = "0.1 zero 0.3".into();
    let e = Candide::parse(&bad.join("\n"), path).unwrap_err();
    assert!(matches!(e, FaceError::Parse { line: 41, .. }), "{e}");
    assert!(e.to_string().starts_with("broken.wfm:41:"), "{e}");
    // A face index past the vertices.
    let face_line = lines.iter().position(|l| l.contains("FACE LIST")).unwrap() + 2;
    let mut bad: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    bad[face_line] = "0 11 113".into();
    let e = Candide::parse(&bad.join("\n"), path).unwrap_err();
    assert!(
        matches!(e, FaceError::Parse { line, .. } if line == face_line + 1),
        "{e}"
    );
    assert!(e.to_string().contains("113"), "{e}");
    // A truncated file: the vertex list ends early.
    let e = Candide::parse(&lines[..60].join("\n"), path).unwrap_err();
    assert!(
        matches!(e, FaceError::Parse { .. }) && e.to_string().contains("broken.wfm"),
        "{e}"
    );
    // A missing file is an I/O error naming it.
    let e = Candide::load(Path::new("no/such/file.wfm")).unwrap_err();
    assert!(matches!(e, FaceError::Io { .. }) && e.to_string().contains("no/such/file.wfm"));
}

// ---------------------------------------------------------------- FAPs

#[test]
fn faps_move_their_feature_point_exactly_and_stay_local() {
    let m = mesh();
    let rig = FapRig::new(&m).unwrap();
    let required = [
        3u8, 4, 5, 6, 7, 12, 13, 19, 20, 21, 22, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42,
        61, 62, 63,
    ];
    for n in required.iter().chain(&TRACKED_FAPS) {
        assert!(rig.index_of(*n).is_some(), "FAP {n} missing");
    }
    let mut out = Vec::with_capacity(m.positions.len());
    for (k, f) in rig.faps.iter().enumerate() {
        let fapu = rig.fapus.get(f.unit);
        for value in [f.range.1, 0.5 * f.range.0, 137.0] {
            let mut v = vec![0.0; rig.len()];
            v[k] = value;
            rig.apply(&m.positions, &v, &mut out);
            let moved = out[f.feature_vertex] - m.positions[f.feature_vertex];
            let expect = f.direction * (value / 1024.0 * fapu);
            assert!(
                (moved - expect).norm() < 1e-12,
                "{} at {value}: {moved:?} vs {expect:?}",
                f.name
            );
            assert!(out.iter().all(|p| p.iter().all(|c| c.is_finite())));
            // Outside the zone (the listed vertices) nothing moves, and the zone is local:
            // geodesic distances exceed straight ones, so nothing farther than the radius
            // (plus the spread of the seed vertices, 1.5 cm) from the feature point moves.
            // The jaw FAPs have a plateau out to the lower lip: 8 cm.
            let zone: Vec<u32> = rig.displacement(k).iter().map(|d| d.0).collect();
            let reach = if [3, 14, 15].contains(&f.number) {
                0.08 + f.radius
            } else {
                0.015 + f.radius
            };
            let fp = m.positions[f.feature_vertex];
            for (i, (a, b)) in out.iter().zip(&m.positions).enumerate() {
                if !zone.contains(&(i as u32)) {
                    assert_eq!(a, b, "{} moves vertex {i} outside its zone", f.name);
                }
                if a != b {
                    assert!((b - fp).norm() < reach, "{} moves far vertex {i}", f.name);
                }
            }
            assert!(
                zone.len() < m.positions.len() / 2,
                "{}: zone of {} vertices",
                f.name,
                zone.len()
            );
        }
        assert!(
            f.range.0 < f.range.1 && f.range.0 <= 0.0,
            "{} range {:?}",
            f.name,
            f.range
        );
    }
    // Linearity: the sum of two FAPs is the sum of their displacements.
    let (a, b) = (rig.index_of(3).unwrap(), rig.index_of(12).unwrap());
    let mut v = vec![0.0; rig.len()];
    v[a] = 400.0;
    rig.apply(&m.positions, &v, &mut out);
    let da: Vec<Vec3> = out.iter().zip(&m.positions).map(|(p, q)| p - q).collect();
    v[a] = 0.0;
    v[b] = -250.0;
    rig.apply(&m.positions, &v, &mut out);
    let db: Vec<Vec3> = out.iter().zip(&m.positions).map(|(p, q)| p - q).collect();
    v[a] = 400.0;
    rig.apply(&m.positions, &v, &mut out);
    for i in 0..out.len() {
        assert!((out[i] - m.positions[i] - da[i] - db[i]).norm() < 1e-15);
    }
}

#[test]
fn open_jaw_opens_the_mouth_and_keeps_upper_face() {
    let m = mesh();
    let rig = FapRig::new(&m).unwrap();
    let k = rig.index_of(3).unwrap();
    let max = rig.faps[k].range.1;
    let drop = max / 1024.0 * rig.fapus.mns;
    assert!(
        (0.015..0.03).contains(&drop),
        "jaw drop {drop} m at the top of the range"
    );
    let mut v = vec![0.0; rig.len()];
    v[k] = max;
    let mut out = Vec::new();
    rig.apply(&m.positions, &v, &mut out);
    let gap = |p: &[Vec3]| (p[13] - p[14]).norm();
    let (g0, g1) = (gap(&m.positions), gap(&out));
    eprintln!(
        "open_jaw {max}: drop {:.2} mm, lip gap {:.2} → {:.2} mm",
        drop * 1e3,
        g0 * 1e3,
        g1 * 1e3
    );
    assert!(
        (g1 - g0 - drop).abs() < 0.1 * drop,
        "gap grows {} for drop {drop}",
        g1 - g0
    );
    // Chin and lower lip move down by the full drop; upper lip, nose and eyes stay.
    for i in [152, 17, 14] {
        assert!(
            (m.positions[i].y - out[i].y - drop).abs() < 1e-12,
            "vertex {i}"
        );
    }
    for i in [
        13, 0, 37, 267, 82, 312, 1, 4, 159, 145, 386, 374, 33, 263, 10,
    ] {
        assert_eq!(out[i], m.positions[i], "vertex {i} moved");
    }
    // Lip FAPs keep to their lip: lower_t_midlip leaves the lower lip, raise_b_midlip the
    // upper lip.
    for (fap, still) in [
        (4, [14, 17, 87, 317]),
        (5, [13, 0, 82, 312]),
        (8, [14, 402, 317, 318]),
        (10, [13, 311, 312, 310]),
    ] {
        let mut v = vec![0.0; rig.len()];
        v[rig.index_of(fap).unwrap()] = 300.0;
        let mut o2 = Vec::new();
        rig.apply(&m.positions, &v, &mut o2);
        for i in still {
            assert_eq!(o2[i], m.positions[i], "FAP {fap} moves vertex {i}");
        }
    }
    // The mouth corners follow part of the way (between lips and jaw).
    let c = m.positions[61].y - out[61].y;
    assert!(c > 0.0 && c < drop, "corner moves {c}");
}

#[test]
fn faps_mirror_and_eyelids_close() {
    let m = mesh();
    let rig = FapRig::new(&m).unwrap();
    let mirror = m.mirror_map();
    let pairs = [
        (6, 7),
        (8, 9),
        (10, 11),
        (12, 13),
        (19, 20),
        (21, 22),
        (31, 32),
        (33, 34),
        (35, 36),
        (37, 38),
        (39, 40),
        (41, 42),
        (61, 62),
    ];
    let dense = |k: usize| {
        let mut d = vec![Vec3::zeros(); m.positions.len()];
        for &(i, x) in rig.displacement(k) {
            d[i as usize] = x;
        }
        d
    };
    for (l, r) in pairs {
        let (kl, kr) = (rig.index_of(l).unwrap(), rig.index_of(r).unwrap());
        assert_eq!(rig.faps[kl].range, rig.faps[kr].range, "FAP {l}/{r}");
        let (a, b) = (rig.faps[kl].direction, rig.faps[kr].direction);
        assert!(
            (a - Vec3::new(-b.x, b.y, b.z)).norm() < 1e-9,
            "FAP {l}/{r} directions"
        );
        assert!(
            m.positions[rig.faps[kl].feature_vertex].x > 0.0,
            "FAP {l} on the left (+x)"
        );
        let (dl, dr) = (dense(kl), dense(kr));
        for i in 0..dl.len() {
            let j = mirror[i];
            let e = (dl[i] - Vec3::new(-dr[j].x, dr[j].y, dr[j].z)).norm();
            // at the end of the range, within 1e-9 m
            assert!(e * 1024.0 < 1e-9, "FAP {l}/{r} vertex {i}/{j}: {e}");
        }
    }
    // Eyelids: at the top of the range the upper lid meets the lower lid, both eyes; the
    // other lid does not move.
    for (fap, upper, lower) in [
        (19, 386, 374),
        (20, 159, 145),
        (21, 374, 386),
        (22, 145, 159),
    ] {
        let k = rig.index_of(fap).unwrap();
        let mut v = vec![0.0; rig.len()];
        v[k] = rig.faps[k].range.1;
        let mut out = Vec::new();
        rig.apply(&m.positions, &v, &mut out);
        let d = (out[upper] - out[lower]).norm();
        eprintln!(
            "FAP {fap} at {:.0}: lids {:.3} mm apart (neutral {:.2} mm)",
            v[k],
            d * 1e3,
            (m.positions[upper] - m.positions[lower]).norm() * 1e3
        );
        assert!(d < 1e-3, "FAP {fap}: lids {d} m apart");
        assert_eq!(
            out[lower], m.positions[lower],
            "FAP {fap} moves the other lid"
        );
        // The whole rim closes, not only the middle.
        let (u, l) = if upper > 200 {
            (
                emilion::face::fap::zone::LEFT_UPPER_LID,
                emilion::face::fap::zone::LEFT_LOWER_LID,
            )
        } else {
            (
                emilion::face::fap::zone::RIGHT_UPPER_LID,
                emilion::face::fap::zone::RIGHT_LOWER_LID,
            )
        };
        for (a, b) in u.iter().zip(&l) {
            assert!(
                (out[*a] - out[*b]).norm() < 1e-3,
                "FAP {fap}: rim {a}/{b} open"
            );
        }
    }
}

#[test]
fn fap_apply_does_not_allocate_and_fits_adapted_faces() {
    let m = mesh();
    let rig = FapRig::new(&m).unwrap();
    let mut out = Vec::with_capacity(m.positions.len());
    let cap = out.capacity();
    let ptr = out.as_ptr();
    let v: Vec<f64> = rig.faps.iter().map(|f| 0.3 * f.range.1).collect();
    for _ in 0..100 {
        rig.apply(&m.positions, &v, &mut out);
    }
    assert_eq!((out.capacity(), out.as_ptr()), (cap, ptr));
    // Bad input never panics: short values, short neutral.
    rig.apply(&m.positions[..10], &v, &mut out);
    assert_eq!(out.len(), 10);
    rig.apply(&m.positions, &[], &mut out);
    assert_eq!(out, m.positions);
    // A face 1.2 times larger gets FAPUs 1.2 times larger.
    let mut big = m.clone();
    big.positions.iter_mut().for_each(|p| *p *= 1.2);
    let rb = FapRig::new(&big).unwrap();
    assert!((rb.fapus.mns / rig.fapus.mns - 1.2).abs() < 1e-12);
    // A mesh that is not in MediaPipe order is refused with a parameter error.
    let mut small = m.clone();
    small.positions.truncate(100);
    small.uvs.truncate(100);
    small.triangles.retain(|t| t.iter().all(|&i| i < 100));
    assert!(matches!(
        FapRig::new(&small),
        Err(FaceError::Parameter { .. })
    ));
}

// ---------------------------------------------------------------- muscles and sliders

#[test]
fn muscles_and_sliders() {
    let m = mesh();
    let muscles = MuscleRig::mediapipe(&m).unwrap();
    let mut out = Vec::new();
    // Zygomatic major pulls its corner up and out, and nothing on the other side moves.
    let k = muscles.index_of("zygomatic_major_l").unwrap();
    let mut a = vec![0.0; muscles.len()];
    a[k] = 1.0;
    muscles.apply(&m.positions, &a, &mut out);
    let d = out[291] - m.positions[291];
    assert!(
        d.x > 1e-3 && d.y > 1e-3,
        "zygomatic moves the corner by {d:?}"
    );
    assert_eq!(out[61], m.positions[61]);
    // The upper-lip orbicularis does not drag the lower lip middle.
    let k = muscles.index_of("orbicularis_upper").unwrap();
    let mut a = vec![0.0; muscles.len()];
    a[k] = 1.0;
    muscles.apply(&m.positions, &a, &mut out);
    assert!((out[13] - m.positions[13]).norm() > 1e-3);
    assert_eq!(out[14], m.positions[14]);

    let e = Expressions::new(&m).unwrap();
    for n in BASIC_EXPRESSIONS.iter().chain(&[
        "Mouth width",
        "Mouth corners",
        "Right eyebrow - surprise",
    ]) {
        assert!(e.index_of(n).is_some(), "slider {n}");
    }
    assert_eq!(e.names().len(), e.len());
    // Zero sliders: exactly the neutral mesh.
    e.apply(&m.positions, &vec![0.0; e.len()], &mut out);
    assert_eq!(out, m.positions);
    // Smile: both corners up and outward.
    e.apply(
        &m.positions,
        &e.values(&[("smile", 1.0)]).unwrap(),
        &mut out,
    );
    let (l, r) = (out[291] - m.positions[291], out[61] - m.positions[61]);
    eprintln!(
        "smile: left corner {:.2?} mm, right corner {:.2?} mm",
        (l * 1e3).as_slice(),
        (r * 1e3).as_slice()
    );
    assert!(l.y > 2e-3 && r.y > 2e-3 && l.x > 1e-3 && r.x < -1e-3);
    assert!((l.y - r.y).abs() < 1e-9 && (l.x + r.x).abs() < 1e-9);
    // Surprise: brows up; eyes wider open.
    e.apply(
        &m.positions,
        &e.values(&[("surprise", 1.0)]).unwrap(),
        &mut out,
    );
    for i in [105, 334, 107, 336, 70, 300] {
        assert!(out[i].y - m.positions[i].y > 3e-3, "brow vertex {i}");
    }
    assert!((out[159] - out[145]).norm() > (m.positions[159] - m.positions[145]).norm());
    // Sadness lowers the corners, anger lowers the inner brows.
    e.apply(
        &m.positions,
        &e.values(&[("sadness", 1.0)]).unwrap(),
        &mut out,
    );
    assert!(out[61].y < m.positions[61].y && out[291].y < m.positions[291].y);
    e.apply(
        &m.positions,
        &e.values(&[("anger", 1.0)]).unwrap(),
        &mut out,
    );
    assert!(out[107].y < m.positions[107].y && out[336].y < m.positions[336].y);
    assert!(e.values(&[("no such slider", 1.0)]).is_err());
}

// ---------------------------------------------------------------- ARKit export

#[test]
fn arkit_glb_round_trip() {
    let m = mesh();
    let faps = FapRig::new(&m).unwrap();
    let muscles = MuscleRig::mediapipe(&m).unwrap();
    assert_eq!(ARKIT_NAMES.len(), 52);
    assert_eq!(
        (ARKIT_NAMES[0], ARKIT_NAMES[17], ARKIT_NAMES[51]),
        ("eyeBlinkLeft", "jawOpen", "tongueOut")
    );
    let shapes = arkit_displacements(&faps, &muscles, m.positions.len()).unwrap();
    let zero: Vec<&str> = shapes
        .iter()
        .filter(|(_, d)| d.iter().all(|v| *v == Vec3::zeros()))
        .map(|(n, _)| n.as_str())
        .collect();
    eprintln!("zero shapes: {zero:?}");
    assert!(zero
        .iter()
        .all(|n| n.starts_with("eyeLook") || *n == "tongueOut"));
    assert_eq!(zero.len(), 9);

    let path = tmp("face.glb");
    write_arkit_glb(&path, &m, &faps, &muscles).unwrap();
    let b = std::fs::read(&path).unwrap();
    let u32_at = |at: usize| u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&b[..4], b"glTF");
    assert_eq!(u32_at(8), b.len());
    let jl = u32_at(12);
    let json: serde_json::Value = serde_json::from_slice(&b[20..20 + jl]).unwrap();
    let root = gltf_json::Root::from_slice(&b[20..20 + jl]).unwrap();
    assert_eq!(root.meshes.len(), 1);
    let prim = &root.meshes[0].primitives[0];
    let targets = prim.targets.as_ref().unwrap();
    assert_eq!(targets.len(), 52);
    let names: Vec<&str> = json["meshes"][0]["extras"]["targetNames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(names, ARKIT_NAMES);
    let bin = 20 + jl + 8;
    // Reads vertex `i` of a VEC3 f32 accessor.
    let read = |acc: usize, i: usize| -> [f32; 3] {
        let a = &json["accessors"][acc];
        let v = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        assert_eq!(a["count"], 468);
        let at = bin + v["byteOffset"].as_u64().unwrap() as usize + 12 * i;
        std::array::from_fn(|k| {
            f32::from_le_bytes(b[at + 4 * k..at + 4 * k + 4].try_into().unwrap())
        })
    };
    let target = |name: &str| {
        targets[ARKIT_NAMES.iter().position(|n| *n == name).unwrap()]
            .positions
            .unwrap()
            .value()
    };
    let pos = prim
        .attributes
        .iter()
        .find(|(s, _)| format!("{s:?}").contains("Positions"))
        .unwrap()
        .1
        .value();
    assert!((read(pos, 152)[1] as f64 - m.positions[152].y).abs() < 1e-7);
    // jawOpen moves the chin down, not the forehead.
    let chin = read(target("jawOpen"), 152);
    assert!(chin[1] < -0.01, "jawOpen chin {chin:?}");
    assert_eq!(read(target("jawOpen"), 10), [0.0; 3]);
    // eyeBlinkLeft closes the left eye (+x): 386 onto 374; the right eye stays.
    let up = read(target("eyeBlinkLeft"), 386);
    let closed = m.positions[386] + Vec3::new(up[0] as f64, up[1] as f64, up[2] as f64);
    assert!(
        (closed - m.positions[374]).norm() < 1e-3,
        "left eye not closed"
    );
    assert_eq!(read(target("eyeBlinkLeft"), 159), [0.0; 3]);
    // The CSV lists the 52 names with their largest displacement.
    let csv = std::fs::read_to_string(path.with_extension("csv")).unwrap();
    assert_eq!(csv.lines().count(), 53);
    assert!(csv.lines().nth(18).unwrap().starts_with("jawOpen,"));
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}
