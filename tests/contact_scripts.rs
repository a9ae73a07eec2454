//! The contact scripts end to end, each checked independently of the engine's own contact
//! code: the final cloth (read back from the OBJ the script wrote) must have no vertex inside a
//! body — analytic sphere, box and floor; for the mannequin, a ray-parity inside test against
//! the body mesh the script wrote — and no intersecting (edge, triangle) pair, by the exact
//! test in `support::intersections`. Each script must also write its frames.
#![cfg(feature = "scripting")]

mod support;

use std::path::{Path, PathBuf};

use emilion::geometry::{read_obj, ExportFrame, TriMesh};

/// Vertices and triangles of an OBJ without texture coordinates (a body mesh).
/// A cloth OBJ written by a script (+Y up, metres), back in the engine's frame (+Z up).
fn read_cloth(path: &Path) -> TriMesh {
    let mut m = read_obj(path).unwrap();
    for p in m.positions.iter_mut() {
        *p = ExportFrame::Y_UP_METRES.to_engine(p);
    }
    m
}

/// A body OBJ (positions and faces only, +Y up), back in the engine's frame.
fn read_plain_obj(path: &Path) -> TriMesh {
    let text = std::fs::read_to_string(path).unwrap();
    let mut m = TriMesh::default();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).map(|s| s.parse().unwrap()).collect();
                let p = emilion::geometry::Vec3::new(c[0], c[1], c[2]);
                m.positions.push(ExportFrame::Y_UP_METRES.to_engine(&p));
            }
            Some("f") => {
                let c: Vec<usize> = it
                    .map(|s| s.split('/').next().unwrap().parse::<usize>().unwrap() - 1)
                    .collect();
                m.triangles.push([c[0], c[1], c[2]]);
            }
            _ => {}
        }
    }
    m
}
use emilion::script::run_file;
use support::intersections::{count_edge_triangle_intersections, segment_triangle_intersect_exact};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `scripts/NAME.rhai` into a fresh folder with extra `sets`; returns the folder.
fn run(name: &str, sets: &[(&str, &str)]) -> PathBuf {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("contact")
        .join(name);
    let _ = std::fs::remove_dir_all(&out);
    std::fs::create_dir_all(&out).unwrap();
    let mut all = vec![("out".to_string(), out.display().to_string())];
    all.extend(sets.iter().map(|(k, v)| (k.to_string(), v.to_string())));
    if let Err(e) = run_file(&root().join("scripts").join(format!("{name}.rhai")), &all) {
        panic!("scripts/{name}.rhai failed:\n{e}");
    }
    out.join(name)
}

fn points(m: &TriMesh) -> Vec<[f64; 3]> {
    m.positions.iter().map(|v| [v.x, v.y, v.z]).collect()
}

fn frames(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .unwrap()
        .filter(|e| {
            let n = e.as_ref().unwrap().file_name();
            let n = n.to_string_lossy();
            n.starts_with("frame_") && n.ends_with(".png")
        })
        .count()
}

/// Height of the lowest vertex (m).
fn lowest_z(m: &TriMesh) -> f64 {
    m.positions
        .iter()
        .map(|p| p.z)
        .fold(f64::INFINITY, f64::min)
}

fn no_self_intersection(m: &TriMesh, what: &str) {
    let k = count_edge_triangle_intersections(&points(m), &m.triangles);
    assert_eq!(
        k, 0,
        "{what}: {k} intersecting cloth (edge, triangle) pairs"
    );
}

#[test]
fn drape_sphere_no_penetration_no_intersection() {
    let dir = run("drape_sphere", &[]);
    assert_eq!(frames(&dir), 10);
    let cloth = read_cloth(&dir.join("drape_sphere.obj"));
    let worst = cloth
        .positions
        .iter()
        .map(|p| p.norm() - 0.3)
        .fold(f64::INFINITY, f64::min);
    assert!(worst >= 0.0, "a vertex is {} m inside the sphere", -worst);
    // it draped: the cloth hangs below the sphere's equator
    let lowest = lowest_z(&cloth);
    assert!(
        lowest < -0.05,
        "cloth lowest point {lowest} m: it did not drape"
    );
    no_self_intersection(&cloth, "drape_sphere");
}

#[test]
fn drape_table_no_penetration_no_intersection() {
    let dir = run("drape_table", &[]);
    assert_eq!(frames(&dir), 8);
    let cloth = read_cloth(&dir.join("drape_table.obj"));
    for p in &cloth.positions {
        let inside_table = p.x.abs() < 0.4 && p.y.abs() < 0.4 && p.z > 0.0 && p.z < 0.75;
        assert!(
            !inside_table && p.z >= 0.0,
            "vertex inside the table or floor at {p:?}"
        );
    }
    // the corners hang below the table top: folds over the corners
    let lowest = lowest_z(&cloth);
    assert!(
        lowest < 0.6,
        "lowest point {lowest} m: the cloth did not fall over the edges"
    );
    no_self_intersection(&cloth, "drape_table");
}

#[test]
fn self_fold_lands_on_itself_without_intersection() {
    let dir = run("self_fold", &[]);
    assert_eq!(frames(&dir), 12);
    let cloth = read_cloth(&dir.join("self_fold.obj"));
    assert!(
        cloth.positions.iter().all(|p| p.z >= 0.0),
        "a vertex is under the floor"
    );
    // folded: the cloth now covers about half its width, in two layers
    let (lo, hi) = emilion::geometry::mesh::bounds(&cloth.positions);
    assert!(hi.x - lo.x < 0.45, "x span {}: not folded", hi.x - lo.x);
    no_self_intersection(&cloth, "self_fold");
}

/// Inside a closed mesh by the parity of crossings of a ray (exact segment tests; the ray
/// direction is irrational-looking so that it misses edges and vertices).
fn inside_mesh(p: [f64; 3], body: &TriMesh, pts: &[[f64; 3]]) -> bool {
    let far = [p[0] + 31.7, p[1] + 17.3, p[2] + 23.9];
    body.triangles
        .iter()
        .filter(|t| segment_triangle_intersect_exact(p, far, pts[t[0]], pts[t[1]], pts[t[2]]))
        .count()
        % 2
        == 1
}

#[test]
fn mannequin_walk_two_seconds_without_penetration() {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data");
    let dir = run("mannequin_walk", &[("data", data)]);
    assert_eq!(frames(&dir), 10);
    let skirt = read_cloth(&dir.join("skirt.obj"));
    let body = read_plain_obj(&dir.join("mannequin.obj"));
    let pts = points(&body);
    let inside: Vec<usize> = skirt
        .positions
        .iter()
        .enumerate()
        .filter(|(_, p)| inside_mesh([p.x, p.y, p.z], &body, &pts))
        .map(|(i, _)| i)
        .collect();
    assert!(
        inside.is_empty(),
        "skirt vertices inside the mannequin: {inside:?}"
    );
    // regression: the gathered waistband followed the nearest body vertices, stacked several
    // rim particles on one vertex and folded the rim through itself (265 intersections)
    no_self_intersection(&skirt, "mannequin_walk skirt");
    // no penetration at any step, as the solver's own count says
    let csv = std::fs::read_to_string(dir.join("mannequin_walk_stats.csv")).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = head.iter().position(|h| *h == "penetrating").unwrap();
    let worst = lines
        .filter_map(|l| l.split(',').nth(col).and_then(|v| v.parse::<u64>().ok()))
        .max()
        .unwrap();
    assert_eq!(worst, 0, "vertices inside the mannequin at some step");
    // the skirt is worn: it stays around the hips, hem below them
    let (lo, hi) = emilion::geometry::mesh::bounds(&skirt.positions);
    assert!(
        hi.z > 0.95 && lo.z < 0.7,
        "skirt spans z {}..{}",
        lo.z,
        hi.z
    );
}
