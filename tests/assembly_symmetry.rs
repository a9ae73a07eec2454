//! The multigrid stores a grid cloth's matrix as symmetric 3×3 blocks (upper triangles only), which
//! is right only if every assembled block is symmetric, bit for bit, and `A(i, j) = A(j, i)ᵀ`.
//! These tests assemble wrinkled, sheared, moving grid cloths under each material law (linear,
//! measured with internal friction, Choi–Ko) in general storage and check that, then check that
//! the symmetric storage holds exactly the same matrix.

use std::path::Path;
use std::sync::Arc;

use emilion::cloth::solver::assembly::{Assembly, AssemblyInputs};
use emilion::cloth::{ClothModel, FabricParameters, MaterialLaw};
use emilion::geometry::Vec3;
use emilion::kes::{lab, read_fabric};

/// A 14×11 grid, prestrained (compressed along x, stretched along y), with seeded out-of-plane
/// and in-plane perturbations so that springs, shear cells and bending lines all bend and shear.
fn wrinkled(
    fabric: FabricParameters,
    law: Option<Arc<dyn MaterialLaw>>,
    choi_ko: bool,
) -> ClothModel {
    let mut m = ClothModel::grid(0.4, 0.3, 14, 11, fabric).unwrap();
    if let Some(law) = law {
        m.set_law(law);
    }
    if choi_ko {
        m.enable_choi_ko();
    }
    m.prestrain(-0.04, 0.02);
    m.perturb(Vec3::new(0.0, 0.0, 1.0), 0.01, 7);
    m.perturb(Vec3::new(1.0, 0.3, 0.0).normalize(), 0.004, 11);
    m
}

fn velocities(n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|i| {
            let t = i as f64;
            Vec3::new((0.37 * t).sin(), (0.11 * t).cos(), 0.5 * (0.23 * t).sin()) * 0.1
        })
        .collect()
}

/// Assembles `model` three times (so that friction states are set and then slip), in general
/// storage and in symmetric storage, and checks symmetry and that both hold the same matrix.
fn check(model: &ClothModel, what: &str) {
    let inp = AssemblyInputs {
        dt: 1.0 / 120.0,
        gravity: Vec3::new(0.0, 0.0, -9.81),
        matrix: true,
    };
    let x0 = model.mesh.positions.clone();
    let v = velocities(x0.len());
    let mut general = Assembly::new(model);
    let mut symmetric = Assembly::new(model);
    assert!(
        symmetric.a.store_symmetric(),
        "{what}: grid rows fit the symmetric storage"
    );
    for k in 0..3 {
        let x: Vec<Vec3> = x0
            .iter()
            .zip(&v)
            .map(|(p, w)| p + w * (0.02 * k as f64))
            .collect();
        general.assemble(model, &x, &v, inp);
        symmetric.assemble(model, &x, &v, inp);
    }
    let a = &general.a;
    assert!(!a.values.is_empty());
    for i in 0..a.rows() {
        for k in a.row_ptr[i]..a.row_ptr[i + 1] {
            let j = a.cols[k] as usize;
            let b = a.values[k];
            for r in 0..3 {
                for c in 0..3 {
                    assert_eq!(
                        b[(r, c)].to_bits(),
                        b[(c, r)].to_bits(),
                        "{what}: block ({i}, {j}) not symmetric at ({r}, {c})"
                    );
                }
            }
            let kt = (a.row_ptr[j]..a.row_ptr[j + 1])
                .find(|&q| a.cols[q] as usize == i)
                .expect("symmetric pattern");
            assert_eq!(
                b.map(f64::to_bits),
                a.values[kt].transpose().map(f64::to_bits),
                "{what}: A({i}, {j}) ≠ A({j}, {i})ᵀ"
            );
            assert_eq!(
                b.map(f64::to_bits),
                symmetric.a.block(k).map(f64::to_bits),
                "{what}: symmetric storage differs at block ({i}, {j})"
            );
        }
    }
    for (p, q) in general.b.iter().zip(&symmetric.b) {
        assert_eq!(
            p.map(f64::to_bits),
            q.map(f64::to_bits),
            "{what}: right-hand sides differ"
        );
    }
}

#[test]
fn grid_blocks_are_symmetric_under_the_linear_law() {
    check(
        &wrinkled(FabricParameters::default(), None, false),
        "linear",
    );
}

#[test]
fn grid_blocks_are_symmetric_under_the_measured_law_with_friction() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("kawabata/fabrics/shirting-cotton.json");
    let spec = read_fabric(&path).unwrap();
    let (fabric, law) = lab::measured_fabric(&spec).unwrap();
    assert!(law.has_friction(), "the fabric has hysteresis");
    check(&wrinkled(fabric, Some(Arc::new(law)), false), "measured");
}

#[test]
fn grid_blocks_are_symmetric_under_choi_ko() {
    check(
        &wrinkled(FabricParameters::default(), None, true),
        "Choi–Ko",
    );
}
