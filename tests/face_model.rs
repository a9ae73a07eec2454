//! The generic face mesh and the iBUG landmark table: the mesh's documented invariants, the
//! table's symmetry on the mesh, and `.pts` files (good and bad).

use emilion::face::landmarks::{
    check_inside, inter_ocular_distance, landmark_positions, parse_pts, read_pts, write_pts,
    IBUG68_MIRROR, IBUG68_TO_MEDIAPIPE,
};
use emilion::face::model::{FaceMesh, CHIN, FOREHEAD, LEFT_EYE_OUTER, NOSE_TIP, RIGHT_EYE_OUTER};
use std::path::Path;

#[test]
fn canonical_mesh_has_documented_landmarks() {
    let m = FaceMesh::mediapipe().unwrap();
    assert_eq!(m.vertex_count(), 468);
    assert_eq!(m.triangles.len(), 898);
    // metres: the right outer eye corner at (−4.446, 2.664, 3.173) cm (given to 1e-5 m)
    let r = m.positions[RIGHT_EYE_OUTER];
    assert!(
        (r.x + 0.04446).abs() < 5e-6
            && (r.y - 0.02664).abs() < 5e-6
            && (r.z - 0.03173).abs() < 5e-6
    );
    let l = m.positions[LEFT_EYE_OUTER];
    assert!((l.x + r.x).abs() < 1e-9 && (l.y - r.y).abs() < 1e-9);
    let (lo, hi) = m.bounds();
    assert_eq!(m.positions[NOSE_TIP].z, hi.z);
    assert_eq!(m.positions[CHIN].y, lo.y);
    assert_eq!(m.positions[FOREHEAD].y, hi.y);
    assert!(m.width() > 0.12 && m.width() < 0.18, "width {}", m.width());
    // outward normals: the nose tip's normal points to +z
    let n = m.vertex_normals();
    assert!(n[NOSE_TIP].z > 0.8, "nose normal {:?}", n[NOSE_TIP]);
}

#[test]
fn ibug_table_is_mirror_symmetric_on_the_mesh() {
    let m = FaceMesh::mediapipe().unwrap();
    let p = landmark_positions(&m);
    for i in 0..68 {
        let j = IBUG68_MIRROR[i];
        assert_eq!(IBUG68_MIRROR[j], i);
        let (a, b) = (p[i], p[j]);
        let err = ((a.x + b.x).powi(2) + (a.y - b.y).powi(2) + (a.z - b.z).powi(2)).sqrt();
        assert!(err < 1e-4, "point {i} and its mirror {j} differ by {err} m");
        if i == j {
            assert!(
                a.x.abs() < 1e-6,
                "central point {i} off the plane: x = {}",
                a.x
            );
        }
        // the subject's right side has x < 0
        if (36..=41).contains(&i) || (17..=21).contains(&i) || i < 8 {
            assert!(
                a.x < 0.0,
                "point {i} should be on the subject's right, x = {}",
                a.x
            );
        }
    }
    for pair in IBUG68_TO_MEDIAPIPE {
        assert!(pair[0] < 468 && pair[1] < 468);
    }
}

#[test]
fn ibug_points_are_in_anatomical_order() {
    let m = FaceMesh::mediapipe().unwrap();
    let p = landmark_positions(&m);
    // brows above eyes above nose tip above mouth above chin
    let brow = (p[19].y + p[24].y) / 2.0;
    let eye = (p[36].y + p[45].y) / 2.0;
    assert!(
        brow > eye && eye > p[30].y && p[30].y > p[51].y && p[51].y > p[57].y && p[57].y > p[8].y
    );
    // bridge descends to the tip, which sticks out most
    for k in 27..30 {
        assert!(p[k].y > p[k + 1].y, "bridge point {k} not above {}", k + 1);
    }
    assert!(p[30].z > p[27].z);
    // eye corners: outer further out than inner; upper lids above lower lids
    assert!(p[36].x < p[39].x && p[45].x > p[42].x);
    assert!(p[37].y > p[41].y && p[38].y > p[40].y && p[43].y > p[47].y && p[44].y > p[46].y);
    // lips: upper outer above inner upper above inner lower above outer lower
    assert!(p[51].y > p[62].y && p[62].y >= p[66].y && p[66].y > p[57].y);
    // jaw goes down from ear to chin and up again
    for k in 0..8 {
        assert!(p[k].y > p[k + 1].y, "jaw point {k} below {}", k + 1);
    }
}

#[test]
fn pts_round_trip_and_errors() {
    let dir = std::env::temp_dir().join("emilion_face_model_pts");
    std::fs::create_dir_all(&dir).unwrap();
    let pts: Vec<[f64; 2]> = (0..68)
        .map(|i| [10.0 + i as f64, 20.5 + 0.25 * i as f64])
        .collect();
    let f = dir.join("a.pts");
    write_pts(&f, &pts).unwrap();
    let back = read_pts(&f).unwrap();
    assert_eq!(back, pts);
    assert!(
        (inter_ocular_distance(&pts) - ((9.0f64).powi(2) + (2.25f64).powi(2)).sqrt()).abs() < 1e-12
    );

    let bad = |text: &str| parse_pts(text, Path::new("x.pts")).unwrap_err().to_string();
    let e = bad("version: 1\nn_points: 2\n{\n1 2\n3 4\n}\n");
    assert!(
        e.contains("x.pts") && e.contains("68") && e.contains("2"),
        "{e}"
    );
    let e = bad("version: 1\nn_points: 68\n{\n1 2\n3 q\n}\n");
    assert!(e.contains("x.pts:5") && e.contains("`q`"), "{e}");
    let e = bad("version: 1\nn_points: 68\n1 2\n");
    assert!(e.contains("x.pts:3"), "{e}");
    let e = read_pts(&dir.join("missing.pts")).unwrap_err().to_string();
    assert!(e.contains("missing.pts"), "{e}");

    let mut outside = pts.clone();
    outside[40] = [700.0, 10.0];
    let e = check_inside(&outside, 512, 512, "b.pts")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("b.pts") && e.contains("point 40") && e.contains("512×512"),
        "{e}"
    );
    check_inside(&pts, 512, 512, "a.pts").unwrap();
}
