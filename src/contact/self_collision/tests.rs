//! Tests of the cloth–cloth response, regressions named after the bugs they caught.

use super::*;

/// A held triangle driven through another held one (a clamped border pushed into cloth
/// that friction holds on a body) is a crossing nothing free can undo. The last resort
/// stopped every free vertex of the cloth then, on every step: here a free triangle a
/// metre away. It keeps its motion now, and the crossing is reported unresolved.
#[test]
fn held_vertices_crossing_do_not_stop_the_rest_of_the_cloth_regression() {
    let tris = [[0, 1, 2], [3, 4, 5], [6, 7, 8]];
    let tri = |o: Vec3| {
        [
            o + Vec3::new(-0.05, -0.05, 0.0),
            o + Vec3::new(0.1, -0.05, 0.0),
            o + Vec3::new(-0.05, 0.1, 0.0),
        ]
    };
    let x0: Vec<Vec3> = [
        tri(Vec3::new(0.0, 0.0, 0.005)),
        tri(Vec3::new(0.01, 0.01, 0.0)),
        tri(Vec3::new(1.0, 0.0, 0.0)),
    ]
    .concat();
    let dt = 0.01;
    // the first triangle moves 1 cm down through the second; the third drifts along x
    let mut v: Vec<Vec3> = (0..9)
        .map(|i| match i {
            0..=2 => Vec3::new(0.0, 0.0, -1.0),
            6..=8 => Vec3::new(0.3, 0.0, 0.0),
            _ => Vec3::zeros(),
        })
        .collect();
    let mut x: Vec<Vec3> = x0.iter().zip(&v).map(|(p, q)| p + q * dt).collect();
    let inv_mass = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    let mut sc = SelfCollision::new(&tris, &x0);
    let rep = sc.respond(&x0, &mut x, &mut v, &inv_mass, dt, 0.003, 0.0);
    assert!(rep.unresolved > 0, "{rep:?}");
    assert_eq!(rep.stopped, 0, "{rep:?}");
    for i in 6..9 {
        assert!(
            (x[i].x - x0[i].x - 0.003).abs() < 1e-12,
            "vertex {i} stopped: {rep:?}"
        );
    }
}

/// A vertex falling onto a triangle 1 mm below it is held off, unless both lie in one
/// pass-through zone.
#[test]
fn a_pass_through_zone_exempts_its_pairs() {
    let tris = [[0, 1, 2], [3, 4, 5]];
    let x0 = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.1, 0.0, 0.0),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::new(0.02, 0.02, 0.001),
        Vec3::new(0.12, 0.02, 0.05),
        Vec3::new(0.02, 0.12, 0.05),
    ];
    let dt = 0.01;
    let v0: Vec<Vec3> = (0..6)
        .map(|i| {
            if i == 3 {
                Vec3::new(0.0, 0.0, -0.5)
            } else {
                Vec3::zeros()
            }
        })
        .collect();
    let run = |zones: &[u32]| {
        let mut sc = SelfCollision::new(&tris, &x0);
        sc.set_zones(zones);
        let mut v = v0.clone();
        let mut x: Vec<Vec3> = x0.iter().zip(&v).map(|(p, q)| p + q * dt).collect();
        // the lower triangle is held (its motion prescribed)
        let inv_mass = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        sc.respond(&x0, &mut x, &mut v, &inv_mass, dt, 0.003, 0.0);
        x[3].z
    };
    let held = run(&[]);
    assert!(held > 0.0, "the vertex went through: z = {held}");
    let passed = run(&[1; 6]);
    assert!(
        passed < 0.0,
        "the zone did not let it through: z = {passed}"
    );
}
