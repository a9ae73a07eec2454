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
