//! Physics acceptance tests of the cloth core against analytic answers: a hanging strip's
//! static equilibrium, the heavy elastica cantilever, stiffness stability, integrator agreement,
//! energy behaviour, exact constraints and divergence detection.

use emilion::cloth::elements::SpringKind;
use emilion::cloth::{
    ClothError, ClothModel, FabricParameters, Integrator, Simulation, SimulationParameters,
    Trajectory,
};
use emilion::geometry::Vec3;

fn undamped(stretch: f64, shear: f64, bend: f64) -> FabricParameters {
    FabricParameters {
        density: 0.15,
        stretch_warp: stretch,
        stretch_weft: stretch,
        shear,
        bend_warp: bend,
        bend_weft: bend,
        stretch_damping: 0.0,
        bend_damping: 0.0,
        air_drag: 0.0,
    }
}

/// 1 m × 0.1 m strip, warp along x, hanging along −x from its x = +0.5 edge.
#[test]
fn hanging_strip_tension_equals_weight_below() {
    let (nx, ny) = (51, 3);
    let e = 14.7; // N/m: analytic elongation ρ g L² / (2E) = 5 cm
    let fabric = FabricParameters {
        air_drag: 5.0,
        ..undamped(e, 0.0, 0.0)
    };
    let model = ClothModel::grid(1.0, 0.1, nx, ny, fabric).unwrap();
    let g = 9.81;
    let params = SimulationParameters {
        dt: 0.01,
        gravity: [-g, 0.0, 0.0],
        cg_tolerance: 1e-10,
        cg_max_iterations: 2000,
        ..Default::default()
    };
    let mut sim = Simulation::new(model, params).unwrap();
    let top: Vec<usize> = (0..ny).map(|i| i * nx + nx - 1).collect();
    sim.pin(&top).unwrap();
    sim.run_steps(3000, |_, _| Ok(())).unwrap();
    let vmax = sim.state.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    assert!(vmax < 1e-6, "not settled: max speed {vmax}");
    let m = &sim.model;
    let law = &*m.law;
    let mut checked = 0;
    for s in &m.springs {
        let SpringKind::Stretch { warp_weight } = s.kind else {
            continue;
        };
        if warp_weight != 1.0 {
            continue;
        }
        let (i, ja, jb) = (s.a / nx, s.a % nx, s.b % nx);
        let j = ja.min(jb);
        let below: f64 = (0..=j).map(|jj| m.mass[i * nx + jj]).sum::<f64>() * g;
        let t = s.eval(law, &sim.state.x[s.a], &sim.state.x[s.b]).tension;
        assert!(
            (t - below).abs() <= 0.01 * below,
            "row {i} spring {j}: tension {t} vs weight below {below}"
        );
        checked += 1;
    }
    assert_eq!(checked, (nx - 1) * ny);
    let analytic = 0.15 * g * 1.0 / (2.0 * e);
    eprintln!("hanging strip: {checked} warp springs within 1% of the weight below");
    for i in 0..ny {
        let len = (sim.state.x[i * nx + nx - 1] - sim.state.x[i * nx]).norm();
        let elong = len - 1.0;
        eprintln!("hanging strip row {i}: elongation {elong:.6} m, analytic {analytic:.6} m");
        assert!(
            (elong - analytic).abs() <= 0.01 * analytic,
            "row {i}: elongation {elong} vs {analytic}"
        );
    }
}

/// Tip angle (degrees below horizontal) of a strip of free length `l` clamped horizontally,
/// for λ = qL³/B.
fn cantilever_tip_angle(lambda: f64) -> f64 {
    let l = 0.2;
    let free_segments = 40;
    let dx = l / free_segments as f64;
    let nx = free_segments + 2; // columns 0 and 1 are clamped
    let width = 0.01;
    let q = 0.15 * 9.81;
    let b = q * l * l * l / lambda;
    let fabric = FabricParameters {
        air_drag: 0.5,
        ..undamped(2e4, 100.0, b)
    };
    let model = ClothModel::grid(dx * (nx - 1) as f64, width, nx, 2, fabric).unwrap();
    let params = SimulationParameters {
        dt: 0.005,
        cg_tolerance: 1e-9,
        cg_max_iterations: 5000,
        ..Default::default()
    };
    let mut sim = Simulation::new(model, params).unwrap();
    sim.pin(&[0, 1, nx, nx + 1]).unwrap();
    sim.run_steps(1600, |_, _| Ok(())).unwrap();
    let vmax = sim.state.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    assert!(vmax < 1e-5, "λ = {lambda}: not settled, max speed {vmax}");
    let (a, b) = (sim.state.x[nx - 2], sim.state.x[nx - 1]);
    let d = b - a;
    (-d.z).atan2(d.x).to_degrees()
}

/// The dihedral hinge (the bending element of triangle meshes) stores the energy of the
/// continuum, (B/2) κ² per unit area, on a strip bent into a circular arc about either axis.
#[test]
fn dihedral_hinges_store_the_bending_energy_of_an_arc() {
    let (nx, ny) = (31, 7);
    let (l, w) = (0.3, 0.06);
    let b = 0.01;
    let f = FabricParameters {
        bend_warp: b,
        bend_weft: 2.0 * b,
        ..undamped(0.0, 0.0, 0.0)
    };
    let mesh = emilion::geometry::grid_mesh(l, w, nx, ny).unwrap();
    let model = ClothModel::from_mesh(mesh, f).unwrap();
    let mut sim = Simulation::new(model, SimulationParameters::default()).unwrap();
    let rest = sim.model.mesh.positions.clone();
    for (kappa, along_warp) in [(4.0, true), (9.0, true), (4.0, false)] {
        let r = 1.0 / kappa;
        for (p, q) in sim.state.x.iter_mut().zip(&rest) {
            let (s, t) = if along_warp { (q.x, q.y) } else { (q.y, q.x) };
            let (u, z) = (r * (s / r).sin(), r * (1.0 - (s / r).cos()));
            *p = if along_warp {
                Vec3::new(u, t, z)
            } else {
                Vec3::new(t, u, z)
            };
        }
        let (_, _, e) = sim.energy();
        // hinges sit on interior edges: the bent length is one spacing short of the strip
        let (len, width, bb) = if along_warp {
            (l - l / 30.0, w, b)
        } else {
            (w - w / 6.0, l, 2.0 * b)
        };
        let expected = 0.5 * bb * kappa * kappa * len * width;
        eprintln!("arc κ = {kappa}, warp = {along_warp}: hinge energy {e:.6e} J, continuum {expected:.6e} J");
        assert!(
            (e - expected).abs() <= 0.01 * expected,
            "energy {e} vs {expected}"
        );
    }
}

#[test]
fn cantilever_matches_heavy_elastica() {
    // ../shared/reference/elastica-table.txt: λ → tip angle (deg)
    for (lambda, expected) in [(1.0, 9.460), (5.0, 39.935), (10.0, 60.312)] {
        let got = cantilever_tip_angle(lambda);
        eprintln!("cantilever λ = {lambda}: tip angle {got:.3}° (elastica {expected}°)");
        assert!(
            (got - expected).abs() <= 2.0,
            "λ = {lambda}: tip angle {got:.3}° vs elastica {expected}°"
        );
    }
}

fn corner_pinned(n: usize, fabric: FabricParameters, params: SimulationParameters) -> Simulation {
    let model = ClothModel::grid(1.0, 1.0, n, n, fabric).unwrap();
    let mut sim = Simulation::new(model, params).unwrap();
    sim.pin(&[(n - 1) * n, n * n - 1]).unwrap();
    sim
}

#[test]
fn implicit_is_stable_on_stiff_cloth_where_explicit_diverges() {
    let fabric = FabricParameters {
        stretch_warp: 1e4,
        stretch_weft: 1e4,
        ..Default::default()
    };
    let dt = 1.0 / 30.0;
    let params = SimulationParameters {
        dt,
        cg_tolerance: 1e-6,
        cg_max_iterations: 2000,
        ..Default::default()
    };
    let mut imp = corner_pinned(16, fabric, params);
    imp.run_steps(90, |_, st| {
        assert!(
            st.converged && st.residual <= 1e-6,
            "step {} residual {}",
            st.step,
            st.residual
        );
        Ok(())
    })
    .unwrap();
    let (lo, hi) = emilion::geometry::mesh::bounds(&imp.state.x);
    assert!(
        lo.z > -1.2 && hi.z <= 1e-9,
        "implicit cloth left the plausible box: {lo:?} {hi:?}"
    );
    let mut exp = corner_pinned(
        16,
        fabric,
        SimulationParameters {
            integrator: Integrator::Explicit,
            ..params
        },
    );
    let err = exp.run_steps(90, |_, _| Ok(())).unwrap_err();
    assert!(matches!(err, ClothError::Diverged { .. }), "{err}");
    assert!(exp.state.x.iter().all(|p| p.iter().all(|c| c.is_finite())));
}

#[test]
fn unconverged_solves_are_reported() {
    let mut sim = corner_pinned(
        16,
        FabricParameters::default(),
        SimulationParameters::default(),
    );
    sim.run_steps(30, |_, _| Ok(())).unwrap();
    sim.params.cg_tolerance = 1e-14;
    sim.params.cg_max_iterations = 1;
    let st = sim.step().unwrap();
    assert!(
        !st.converged && st.cg_iterations == 1 && st.residual > 1e-14,
        "{st:?}"
    );
    assert_eq!(sim.unconverged_steps, 1);
}

#[test]
fn explicit_and_implicit_agree_on_a_slow_scene() {
    let fabric = undamped(50.0, 5.0, 1e-5);
    let dt = 1e-4;
    let base = SimulationParameters {
        dt,
        gravity: [0.0, 0.0, -1.0],
        cg_tolerance: 1e-10,
        ..Default::default()
    };
    let mut imp = corner_pinned(8, fabric, base);
    let mut exp = corner_pinned(
        8,
        fabric,
        SimulationParameters {
            integrator: Integrator::Explicit,
            ..base
        },
    );
    let steps = imp.steps_for(1.0);
    imp.run_steps(steps, |_, _| Ok(())).unwrap();
    exp.run_steps(steps, |_, _| Ok(())).unwrap();
    let dev = imp
        .state
        .x
        .iter()
        .zip(&exp.state.x)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    let travel = imp
        .state
        .x
        .iter()
        .zip(&imp.model.mesh.positions)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(travel > 0.05, "scene did not move ({travel} m)");
    eprintln!(
        "explicit vs implicit: max deviation {dev:.3e} m after 1 s (max travel {travel:.3} m)"
    );
    assert!(dev < 1e-3, "max deviation {dev} m after 1 s");
}

#[test]
fn undamped_explicit_conserves_energy() {
    let fabric = undamped(50.0, 5.0, 1e-5);
    let params = SimulationParameters {
        dt: 2e-4,
        integrator: Integrator::Explicit,
        ..Default::default()
    };
    let mut sim = corner_pinned(8, fabric, params);
    let steps = sim.steps_for(10.0);
    let (mut e0, mut dev, mut kmax) = (None, 0.0f64, 0.0f64);
    sim.run_steps(steps, |_, st| {
        let e0 = *e0.get_or_insert(st.total);
        dev = dev.max((st.total - e0).abs());
        kmax = kmax.max(st.kinetic);
        Ok(())
    })
    .unwrap();
    assert!(kmax > 0.01, "scene too quiet: max kinetic {kmax} J");
    eprintln!(
        "explicit energy drift {dev:.3e} J = {:.4}% of max kinetic {kmax:.4} J",
        100.0 * dev / kmax
    );
    assert!(
        dev <= 0.01 * kmax,
        "energy drift {dev} J vs max kinetic {kmax} J"
    );
}

#[test]
fn undamped_implicit_energy_never_grows() {
    let fabric = undamped(1000.0, 10.0, 1e-5);
    let params = SimulationParameters {
        dt: 1.0 / 120.0,
        cg_tolerance: 1e-9,
        cg_max_iterations: 3000,
        ..Default::default()
    };
    let mut sim = corner_pinned(16, fabric, params);
    let mut prev: Option<f64> = None;
    let mut kmax = 0.0f64;
    sim.run_steps(240, |_, st| {
        if let Some(p) = prev {
            assert!(
                st.total <= p + 1e-9 * p.abs().max(1e-3),
                "step {}: energy grew {p} → {}",
                st.step,
                st.total
            );
        }
        prev = Some(st.total);
        kmax = kmax.max(st.kinetic);
        Ok(())
    })
    .unwrap();
    assert!(kmax > 0.01);
}

#[test]
fn pinned_and_attached_particles_follow_their_targets() {
    let n = 12;
    let mut sim = corner_pinned(
        n,
        FabricParameters::default(),
        SimulationParameters::default(),
    );
    sim.attach(
        &[0, n - 1],
        Trajectory::Oscillation {
            amplitude: [0.1, 0.0, 0.2],
            frequency: 1.5,
        },
    )
    .unwrap();
    sim.attach(
        &[n / 2],
        Trajectory::Keyframes(vec![
            (0.0, [0.0; 3]),
            (0.5, [0.0, 0.0, 0.3]),
            (1.0, [0.2, 0.0, 0.3]),
        ]),
    )
    .unwrap();
    for _ in 0..150 {
        sim.step().unwrap();
        let t = sim.state.time;
        for (i, target) in sim.attachment_targets(t) {
            let err = (sim.state.x[i] - target).norm();
            assert!(
                err <= 1e-9,
                "t = {t}: particle {i} is {err} m off its target"
            );
        }
    }
    let t = sim.state.time;
    let want = Vec3::new(0.1, 0.0, 0.2) * (2.0 * std::f64::consts::PI * 1.5 * t).sin();
    let start = sim.model.mesh.positions[0];
    assert!((sim.state.x[0] - (start + want)).norm() < 1e-9);
}

#[test]
fn diverging_simulation_stops_with_step_and_cause() {
    let params = SimulationParameters {
        dt: 0.05,
        integrator: Integrator::Explicit,
        ..Default::default()
    };
    let mut sim = corner_pinned(16, FabricParameters::default(), params);
    let before = sim.state.clone();
    let mut last_ok = before.clone();
    let err = loop {
        match sim.step() {
            Ok(_) => last_ok = sim.state.clone(),
            Err(e) => break e,
        }
        assert!(sim.state.step < 1000, "never diverged");
    };
    let msg = err.to_string();
    assert!(msg.contains("step") && msg.contains("particle"), "{msg}");
    let ClothError::Diverged { step, .. } = err else {
        panic!("{err}")
    };
    assert_eq!(step, last_ok.step);
    assert_eq!(
        sim.state, last_ok,
        "state must be left as before the failing step"
    );
    assert!(sim.state.x.iter().all(|p| p.iter().all(|c| c.is_finite())));
}

#[test]
fn bad_parameters_are_named() {
    let f = FabricParameters {
        density: f64::NAN,
        ..Default::default()
    };
    let err = ClothModel::grid(1.0, 1.0, 4, 4, f).unwrap_err().to_string();
    assert!(err.contains("density"), "{err}");
    let model = ClothModel::grid(1.0, 1.0, 4, 4, FabricParameters::default()).unwrap();
    let err = Simulation::new(
        model,
        SimulationParameters {
            dt: -1.0,
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("dt"), "{err}");
    let mut sim = corner_pinned(
        4,
        FabricParameters::default(),
        SimulationParameters::default(),
    );
    assert!(sim.pin(&[99]).unwrap_err().to_string().contains("99"));
}

/// The floor, the simplest step stage: a cloth dropped flat from 0.3 m lands and rests on
/// the contact surface (floor height + thickness), never below the floor.
#[test]
fn dropped_cloth_rests_on_the_floor() {
    use emilion::contact::Floor;
    let model = ClothModel::grid(0.6, 0.6, 20, 20, FabricParameters::default()).unwrap();
    let mut sim = Simulation::new(model, SimulationParameters::default()).unwrap();
    let (height, thickness) = (-0.3, 0.004);
    sim.add_stage(Box::new(Floor { height, thickness }));
    sim.run_steps(240, |s, _| {
        let low = s.state.x.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        assert!(low >= height, "particle below the floor: z = {low}");
        Ok(())
    })
    .unwrap();
    for p in &sim.state.x {
        assert!(
            (p.z - (height + thickness)).abs() < 1e-6,
            "resting at z = {}",
            p.z
        );
    }
    let vmax = sim.state.v.iter().map(|v| v.norm()).fold(0.0, f64::max);
    assert!(vmax < 1e-6, "still moving at {vmax} m/s");
}
