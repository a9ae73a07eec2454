//! Grading (docs/sweeps.md): a pattern and the mannequin scaled to another size, checked
//! against the linear map's exact effect — corners and placements scaled, polygon areas by
//! girth × height, the mannequin's height, width and enclosed volume (girth² × height), feet
//! left on the floor, every bone end's height — and bad factors named.

use std::path::PathBuf;

use emilion::body::{signed_volume, Mannequin};
use emilion::garment::read_garment;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Shoelace area of a piece's corners (m²).
fn corner_area(c: &[[f64; 2]]) -> f64 {
    (0..c.len())
        .map(|i| {
            let (a, b) = (c[i], c[(i + 1) % c.len()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
        / 2.0
}

#[test]
fn a_graded_pattern_is_the_pattern_scaled_across_and_along() {
    let p = read_garment(root().join("scripts/patterns/aaron.garment.json")).unwrap();
    let g = p.graded(1.06, 1.06).unwrap();
    assert_eq!(
        (g.pieces.len(), g.seams.len()),
        (p.pieces.len(), p.seams.len())
    );
    for (a, b) in p.pieces.iter().zip(&g.pieces) {
        let ca: Vec<[f64; 2]> = a.outline.corners.iter().map(|c| c.at).collect();
        let cb: Vec<[f64; 2]> = b.outline.corners.iter().map(|c| c.at).collect();
        let ratio = corner_area(&cb) / corner_area(&ca);
        assert!((ratio - 1.06 * 1.06).abs() < 1e-12, "{}: {ratio}", a.name);
        if let (Some(pa), Some(pb)) = (&a.placement, &b.placement) {
            assert!((pb.x - 1.06 * pa.x).abs() < 1e-15 && (pb.dz - 1.06 * pa.dz).abs() < 1e-15);
        }
        assert_eq!(a.seam_allowance, b.seam_allowance);
    }
    let across = p.graded(1.1, 1.0);
    if let Ok(across) = across {
        let c0 = p.pieces[0].outline.corners[1].at;
        let c1 = across.pieces[0].outline.corners[1].at;
        assert!((c1[0] - 1.1 * c0[0]).abs() < 1e-15 && c1[1] == c0[1]);
    }
    for (g, h, name) in [(3.0, 1.0, "girth"), (1.0, f64::NAN, "height")] {
        let e = p.graded(g, h).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains("0.5 to 2"), "{e}");
    }
}

#[test]
fn a_graded_mannequin_is_the_mannequin_scaled_with_its_feet_on_the_floor() {
    let dir = emilion::geometry::files::data_dir().join("bodies/makehuman");
    if !dir.join("base.obj").is_file() {
        eprintln!("skipped: no MakeHuman data in {}", dir.display());
        return;
    }
    let m = Mannequin::load_makehuman(&dir).unwrap();
    let (girth, height) = (1.1, 0.95);
    let g = m.graded(girth, height).unwrap();
    let extent = |m: &Mannequin, k: usize| {
        let v = m.rest_positions().iter().map(|p| p[k]);
        let lo = v.clone().fold(f64::INFINITY, f64::min);
        (lo, v.fold(f64::NEG_INFINITY, f64::max) - lo)
    };
    let (floor, tall) = extent(&g, 2);
    assert!(floor.abs() < 1e-12, "{floor}");
    assert!((tall - height * extent(&m, 2).1).abs() < 1e-12);
    assert!((extent(&g, 0).1 - girth * extent(&m, 0).1).abs() < 1e-12);
    let v0 = signed_volume(m.rest_positions(), m.triangles());
    let v1 = signed_volume(g.rest_positions(), g.triangles());
    assert!(
        (v1 / v0 - girth * girth * height).abs() < 1e-9,
        "{}",
        v1 / v0
    );
    // the skeleton moves with the skin: heights × height, from the floor
    let (b0, b1) = (m.skeleton().bones(), g.skeleton().bones());
    assert_eq!(b0.len(), b1.len());
    for (a, b) in b0.iter().zip(b1) {
        assert!((b.head.z - height * a.head.z).abs() < 1e-12, "{}", a.name);
        assert!((b.tail.z - height * a.tail.z).abs() < 1e-12, "{}", a.name);
    }
    let e = m.graded(0.1, 1.0).unwrap_err().to_string();
    assert!(e.contains("girth") && e.contains("0.5 to 2"), "{e}");
}
