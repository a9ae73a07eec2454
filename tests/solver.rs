//! Solver tests: the multigrid-preconditioned CG gives the same answer as block-Jacobi CG,
//! iteration counts stay flat with resolution, and runs are bit-for-bit deterministic.

use emilion::cloth::{
    ClothModel, FabricParameters, PreconditionerKind, Simulation, SimulationParameters,
};

fn hang(n: usize, params: SimulationParameters) -> Simulation {
    let model = ClothModel::grid(1.0, 1.0, n, n, FabricParameters::default()).unwrap();
    let mut sim = Simulation::new(model, params).unwrap();
    sim.pin(&[(n - 1) * n, n * n - 1]).unwrap();
    sim
}

#[test]
fn multigrid_and_block_jacobi_agree() {
    let tight = SimulationParameters {
        cg_tolerance: 1e-10,
        cg_max_iterations: 5000,
        ..Default::default()
    };
    let mut mg = hang(
        24,
        SimulationParameters {
            preconditioner: PreconditionerKind::Multigrid,
            ..tight
        },
    );
    let mut bj = hang(
        24,
        SimulationParameters {
            preconditioner: PreconditionerKind::BlockJacobi,
            ..tight
        },
    );
    assert!(mg.multigrid_levels() > 1 && bj.multigrid_levels() == 1);
    let (mut it_mg, mut it_bj) = (0, 0);
    for _ in 0..60 {
        let a = mg.step().unwrap();
        let b = bj.step().unwrap();
        assert!(a.converged && b.converged);
        it_mg += a.cg_iterations;
        it_bj += b.cg_iterations;
    }
    let dev = mg
        .state
        .x
        .iter()
        .zip(&bj.state.x)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(
        dev < 1e-6,
        "multigrid and block-Jacobi solutions differ by {dev} m"
    );
    assert!(
        it_mg * 5 < it_bj,
        "multigrid {it_mg} vs block-Jacobi {it_bj} iterations"
    );
}

#[test]
fn multigrid_iterations_do_not_grow_with_resolution() {
    let mean_iters = |n: usize| {
        let mut sim = hang(n, SimulationParameters::default());
        sim.run_steps(60, |_, st| {
            assert!(
                st.converged,
                "n = {n}, step {}: residual {}",
                st.step, st.residual
            );
            Ok(())
        })
        .unwrap();
        sim.stats
            .iter()
            .map(|s| s.cg_iterations as f64)
            .sum::<f64>()
            / sim.stats.len() as f64
    };
    let (a, b) = (mean_iters(24), mean_iters(96));
    eprintln!("mean CG iterations: 24² {a:.2}, 96² {b:.2}");
    assert!(b <= a * 1.5 + 0.5, "iterations grew from {a} to {b}");
}

#[test]
fn runs_are_bit_identical() {
    let run = || {
        let mut sim = hang(40, SimulationParameters::default());
        sim.run_steps(40, |_, _| Ok(())).unwrap();
        sim.state
    };
    let (a, b) = (run(), run());
    assert!(a.x.iter().zip(&b.x).all(|(p, q)| p
        .iter()
        .zip(q.iter())
        .all(|(u, v)| u.to_bits() == v.to_bits())));
    assert!(a.v.iter().zip(&b.v).all(|(p, q)| p
        .iter()
        .zip(q.iter())
        .all(|(u, v)| u.to_bits() == v.to_bits())));
}

/// Regression: while sewing, velocities were capped only after the positions had moved, so a
/// step whose solve pulled hard (a stiff thread across a wide gap) moved particles by
/// centimetres, and contact then flung a trouser leg by decimetres. No particle may move more
/// than the sewing's speed limit allows in a step.
#[test]
fn sewing_caps_the_motion_of_every_step() {
    use emilion::cloth::Sewing;
    let n = 8;
    let mut model = ClothModel::grid(1.0, 1.0, n, n, FabricParameters::default()).unwrap();
    let x = model.mesh.positions.clone();
    // a slow thread between opposite corners, and the cloth laid out stretched by 30 % (as a
    // pre-positioned garment may be locally): its recoil is far faster than sewing allows
    let sewing = Sewing::add_to(&mut model, &[(0, n * n - 1)], &x, (300.0, 5.0), 0.3);
    let limit = sewing.max_speed;
    let params = SimulationParameters::default();
    let dt = params.dt;
    let mut sim = Simulation::new(model, params).unwrap();
    for p in sim.state.x.iter_mut() {
        *p *= 1.3;
    }
    sim.sewing = Some(sewing);
    for _ in 0..10 {
        let before = sim.state.x.clone();
        sim.step().unwrap();
        let moved = sim
            .state
            .x
            .iter()
            .zip(&before)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(
            moved <= limit * dt * (1.0 + 1e-9),
            "a particle moved {moved} m in a step (limit {} m)",
            limit * dt
        );
    }
}
