//! The A-shirt (FreeSewing `aaron`) sewn and draped on the MakeHuman mannequin for 1.5 s, with
//! the acceptance checked independently of the engine's own contact code: every seam
//! closed to 1 mm (distances of the sewn vertex pairs), no cloth vertex inside the body (ray
//! parity against the skin mesh), no self-intersection (exact edge–triangle tests, sewn
//! vertices merged first), and the shirt hanging from the shoulders.

mod support;

use std::path::PathBuf;

use emilion::body::Mannequin;
use emilion::cloth::{FabricParameters, SimulationParameters};
use emilion::garment::{dress, read_garment, DressParameters};
use support::intersections::count_edge_triangle_intersections;

#[test]
fn aaron_is_sewn_and_draped_without_penetration_or_self_intersection() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let pattern = read_garment(root.join("scripts/patterns/aaron.garment.json")).unwrap();
    let man = Mannequin::load_makehuman(&root.join("../shared/data/bodies/makehuman")).unwrap();
    let mut params = DressParameters::default();
    params.mesh.edge_length = 0.015;
    let mut d = dress(
        &pattern,
        FabricParameters::default(),
        &man,
        &params,
        SimulationParameters::default(),
    )
    .unwrap();
    let sim = &mut d.simulation;
    let steps = sim.steps_for(1.5);
    sim.run_steps(steps, |_, _| Ok(())).unwrap();
    let x = &sim.state.x;
    // gravity is on: the seams closed and the garment settled
    assert!(sim.params.gravity[2] < -9.0, "still sewing at the end");
    // every seam closed to a millimetre
    let mut rep: Vec<usize> = (0..x.len()).collect();
    for s in &d.garment.seams {
        for &(a, b) in &s.pairs {
            let gap = (x[a] - x[b]).norm();
            assert!(
                gap <= 1e-3,
                "seam {}: pair {a}–{b} is {:.2} mm apart",
                s.name,
                gap * 1e3
            );
            rep[b.max(a)] = rep[a.min(b)];
        }
    }
    // no vertex inside the body
    let skin: Vec<[f64; 3]> = man
        .rest_positions()
        .iter()
        .map(|p| [p.x, p.y, p.z])
        .collect();
    let pts: Vec<[f64; 3]> = x.iter().map(|p| [p.x, p.y, p.z]).collect();
    let inside = support::inside::count_inside(&pts, &skin, man.triangles());
    assert_eq!(inside, 0, "{inside} garment vertices inside the body");
    // no self-intersection once sewn vertices are one
    for i in 0..rep.len() {
        let mut r = rep[i];
        while rep[r] != r {
            r = rep[r];
        }
        rep[i] = r;
    }
    let tris: Vec<[usize; 3]> = d
        .garment
        .mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| rep[i]))
        .collect();
    assert_eq!(count_edge_triangle_intersections(&pts, &tris), 0);
    // hanging from the shoulders: the shoulder seams are the highest part, above 1.3 m, and
    // the hem hangs below the waist (MakeHuman stands 1.67 m, waist near 1.08 m)
    let top = x.iter().fold(f64::MIN, |m, p| m.max(p.z));
    let low = x.iter().fold(f64::MAX, |m, p| m.min(p.z));
    let shoulder = d
        .garment
        .seams
        .iter()
        .filter(|s| s.name.starts_with("shoulder"))
        .flat_map(|s| s.pairs.iter().map(|&(a, _)| x[a].z))
        .fold(f64::MIN, f64::max);
    assert!(
        shoulder > 1.3 && top - shoulder < 0.03,
        "shoulder seam at {shoulder}, top {top}"
    );
    assert!(low < 1.0, "hem at {low}");
}
