//! The mannequin as the garment pipeline sees it: its frame from the inertia matrix, its front
//! and back silhouettes and its landmark heights, checked against the MakeHuman body of
//! `../shared/data/bodies/makehuman/` (documented there: metres, z up, facing −y, left +x).

use std::path::PathBuf;

use emilion::body::Mannequin;
use emilion::garment::{BodyFrame, Silhouettes};
use emilion::geometry::Vec3;

fn mannequin() -> Mannequin {
    let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"))
        .join("bodies/makehuman");
    Mannequin::load_makehuman(&dir).expect("mannequin loads")
}

#[test]
fn frame_from_inertia_matches_the_documented_axes() {
    let m = mannequin();
    let f = BodyFrame::of(m.rest_positions(), m.triangles()).unwrap();
    assert!(f.up.dot(&Vec3::z()) > 0.99, "up {:?}", f.up);
    assert!(f.front.dot(&-Vec3::y()) > 0.99, "front {:?}", f.front);
    assert!(f.left.dot(&Vec3::x()) > 0.99, "left {:?}", f.left);
    // the symmetry plane passes through the centroid: |x| of the centroid is small
    assert!(f.origin.x.abs() < 0.01, "origin {:?}", f.origin);
    // turned and moved, the frame turns and moves with the body
    let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 1.1);
    let moved: Vec<Vec3> = m
        .rest_positions()
        .iter()
        .map(|p| rot * p + Vec3::new(1.0, 2.0, 3.0))
        .collect();
    let g = BodyFrame::of(&moved, m.triangles()).unwrap();
    assert!(g.up.dot(&(rot * f.up)) > 0.999);
    assert!(g.front.dot(&(rot * f.front)) > 0.999);
    assert!((g.origin - (rot * f.origin + Vec3::new(1.0, 2.0, 3.0))).norm() < 1e-9);
}

#[test]
fn landmarks_are_in_human_order_and_proportion() {
    let m = mannequin();
    let f = BodyFrame::of(m.rest_positions(), m.triangles()).unwrap();
    let sil = Silhouettes::of(f, m.rest_positions(), m.triangles(), 0.005).unwrap();
    let l = sil.landmarks().unwrap();
    let tall = l.top - l.floor;
    let rel = |h: f64| (h - l.floor) / tall;
    let order = [
        l.floor, l.ankle, l.knee, l.crotch, l.hip, l.waist, l.chest, l.armpit, l.shoulder, l.neck,
        l.top,
    ];
    assert!(order.windows(2).all(|w| w[0] < w[1]), "{l:?}");
    // anthropometric proportions of an adult (Drillis & Contini): crotch ≈ 0.47–0.50 of the
    // stature, waist ≈ 0.6, shoulder ≈ 0.82
    assert!(
        (0.42..0.53).contains(&rel(l.crotch)),
        "crotch {}",
        rel(l.crotch)
    );
    assert!(
        (0.55..0.66).contains(&rel(l.waist)),
        "waist {}",
        rel(l.waist)
    );
    assert!(
        (0.78..0.86).contains(&rel(l.shoulder)),
        "shoulder {}",
        rel(l.shoulder)
    );
}
