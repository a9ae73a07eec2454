//! Contact: friction on an incline against the friction angle, bodies' signed distances
//! against analytic answers, drapes without penetration or self-intersection (checked by the
//! independent exact test in `support::intersections`), and bad body meshes rejected.

mod support;

use emilion::cloth::{ClothModel, FabricParameters, Simulation, SimulationParameters};
use emilion::contact::{Body, FrictionCoefficients, MeshBody};
use emilion::geometry::Vec3;
use nalgebra::{Rotation3, Vector3};

/// A 0.3 m cloth resting on a plane tilted by `deg` about x (rising toward +y), with static
/// and kinetic friction `mu` on both the plane and the fabric, run for `seconds`; returns how
/// far its centre moved along the slope (m).
fn incline_slip(deg: f64, mu: f64, seconds: f64) -> f64 {
    let fabric = FabricParameters::default();
    let mut model = ClothModel::grid(0.3, 0.3, 12, 12, fabric).unwrap();
    let rot = Rotation3::from_axis_angle(&Vector3::x_axis(), deg.to_radians());
    let thickness = 0.005;
    let normal = rot * Vec3::z();
    for p in &mut model.mesh.positions {
        *p = rot * *p + normal * thickness;
    }
    let mut sim = Simulation::new(model, SimulationParameters::default()).unwrap();
    let f = FrictionCoefficients {
        static_: mu,
        kinetic: mu,
    };
    let mut plane = Body::plane(Vec3::zeros(), normal).unwrap();
    plane.friction = f;
    sim.contact.bodies.push(plane);
    sim.contact.settings.thickness = thickness;
    sim.contact.settings.friction = f;
    let centre = |s: &Simulation| s.state.x.iter().sum::<Vec3>() / s.state.x.len() as f64;
    let c0 = centre(&sim);
    let steps = sim.steps_for(seconds);
    sim.run_steps(steps, |_, _| Ok(())).unwrap();
    let d = centre(&sim) - c0;
    let down_slope = rot * -Vec3::y();
    d.dot(&down_slope)
}

#[test]
fn cloth_on_incline_sticks_below_friction_angle_and_slides_above() {
    let mu: f64 = 0.5;
    let angle = mu.atan().to_degrees(); // 26.57°
    let below = incline_slip(angle - 2.0, mu, 1.0);
    let above = incline_slip(angle + 2.0, mu, 1.0);
    // sliding above: a = g (sin θ − μ cos θ) gives 0.2 m in 1 s at θ = 28.57°
    let theta = (angle + 2.0).to_radians();
    let expect = 0.5 * 9.81 * (theta.sin() - mu * theta.cos());
    println!("below: {below:.5} m, above: {above:.5} m (rigid-block answer {expect:.4} m)");
    assert!(below.abs() < 2e-3, "slid {below} m below the friction angle");
    assert!(above > 0.5 * expect, "slid only {above} m above the friction angle");
}

fn exact_intersections(x: &[Vec3], tris: &[[usize; 3]]) -> usize {
    let p: Vec<[f64; 3]> = x.iter().map(|v| [v.x, v.y, v.z]).collect();
    support::intersections::count_edge_triangle_intersections(&p, tris)
}

/// Regression: the engine's fast intersection count took coplanar cells of a cylinder for
/// crossings (its line test ran on round-off signs).
#[test]
fn cylinder_and_cone_cloths_do_not_intersect_themselves() {
    for (rt, rb) in [(0.22, 0.22), (0.16, 0.26)] {
        let mesh = emilion::geometry::cone::cone_mesh(rt, rb, 0.5, 64, 20, Vec3::new(0.0, 0.0, 0.5), 0.05)
            .unwrap();
        let model = ClothModel::from_mesh(mesh, FabricParameters::default()).unwrap();
        check_no_self_intersection(model);
    }
}

fn check_no_self_intersection(model: ClothModel) {
    let exact = exact_intersections(&model.mesh.positions, &model.mesh.triangles);
    let mut sim = Simulation::new(model, SimulationParameters::default()).unwrap();
    let x = sim.state.x.clone();
    let fast = sim.contact.report(&x).intersections;
    assert_eq!(exact, 0);
    assert_eq!(fast, 0);
}
