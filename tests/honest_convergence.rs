//! Convergence that cannot lie (issue 48): the implicit step rejects a system that overflows,
//! judges convergence on the true residual, catches an energy blow-up, retries a failing step
//! split in halves, and says where and why it stops. The normal scenes still converge, with
//! no retry and no energy gained.

use std::any::Any;

use emilion::cloth::{
    ClothError, ClothModel, FabricParameters, Simulation, SimulationParameters, StepEnd, StepStage,
};

/// A `n` × `n` cloth of 1 m × 1 m pinned at the two corners of its y = +0.5 edge.
fn hang(n: usize, fabric: FabricParameters, params: SimulationParameters) -> Simulation {
    let model = ClothModel::grid(1.0, 1.0, n, n, fabric).unwrap();
    let mut sim = Simulation::new(model, params).unwrap();
    sim.pin(&[(n - 1) * n, n * n - 1]).unwrap();
    sim
}

/// The step, time and cause of a divergence error.
fn diverged(e: ClothError) -> (u64, f64, String) {
    match e {
        ClothError::Diverged { step, time, cause } => (step, time, cause),
        other => panic!("expected a divergence, got {other}"),
    }
}

/// The number after `key` in `text`.
fn number_after(text: &str, key: &str) -> f64 {
    let rest = &text[text.find(key).unwrap_or_else(|| panic!("{key} in {text}")) + key.len()..];
    rest.split(|c: char| !(c.is_ascii_digit() || "+-.e".contains(c)))
        .find(|s| !s.is_empty())
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn gravity_of_minus_1e160_is_an_error_not_a_converged_step() {
    // before: `converged = true` after 0 CG iterations, and the cloth did not move
    let params = SimulationParameters {
        gravity: [0.0, 0.0, -1e160],
        ..Default::default()
    };
    let mut sim = hang(8, FabricParameters::default(), params);
    let x0 = sim.state.x.clone();
    let (step, time, cause) = diverged(sim.step().unwrap_err());
    assert_eq!((step, time), (0, 0.0));
    // the error names a particle and its force: its weight m g, at rest
    let i = number_after(&cause, "force on particle ") as usize;
    let tuple = &cause[cause.find('(').unwrap() + 1..cause.find(')').unwrap()];
    let fz: f64 = tuple.split(", ").nth(2).unwrap().trim().parse().unwrap();
    let weight = -sim.model.mass[i] * 1e160;
    assert!(
        (fz - weight).abs() <= 1e-3 * weight.abs(),
        "force {fz:e} on particle {i}, weight {weight:e}: {cause}"
    );
    // nothing was taken: no statistics, the state as it was
    assert!(sim.stats.is_empty());
    assert_eq!(sim.state.step, 0);
    assert_eq!(sim.state.x, x0);
}

#[test]
fn stretch_stiffness_of_1e300_is_an_error_not_a_converged_step() {
    let fabric = FabricParameters {
        stretch_warp: 1e300,
        stretch_weft: 1e300,
        ..Default::default()
    };
    let mut sim = hang(8, fabric, SimulationParameters::default());
    let x0 = sim.state.x.clone();
    let (step, _, cause) = diverged(sim.run_steps(6, |_, _| Ok(())).unwrap_err());
    assert_eq!(step, 0);
    assert!(
        cause.contains("overflowing force on particle") || cause.contains("stiffness at particle"),
        "{cause}"
    );
    assert!(sim.stats.is_empty() && sim.state.x == x0);
}

#[test]
fn the_stiff_light_cloth_at_dt_1_is_caught_not_reported_converged() {
    // before: it gained 6.4e6 J over 20 s, ended above its pins and reported converged
    let fabric = FabricParameters {
        stretch_warp: 1e7,
        stretch_weft: 1e7,
        density: 0.001,
        ..Default::default()
    };
    let params = SimulationParameters {
        dt: 1.0,
        ..Default::default()
    };
    let mut sim = hang(32, fabric, params);
    let x0 = sim.state.x.clone();
    let (step, time, cause) = diverged(sim.run_steps(20, |_, _| Ok(())).unwrap_err());
    eprintln!("{cause}");
    // caught by the energy balance of its first step, found at the start of the second
    assert_eq!((step, time), (0, 0.0));
    assert!(cause.contains("energy blow-up"), "{cause}");
    // the most gravity can give a 1 g cloth of 1 m × 1 m pinned at its top edge: its weight
    // falling its diagonal
    let gravity_bound = 0.001 * 9.81 * 2f64.sqrt();
    let before = number_after(&cause, "rose from ");
    let after = number_after(&cause, "J to ");
    assert!(
        after - before > 1e4 * gravity_bound,
        "{before} J -> {after} J: {cause}"
    );
    // rewound to the start of the step that gained it
    assert!(sim.stats.is_empty());
    assert_eq!((sim.state.step, sim.state.time), (0, 0.0));
    assert_eq!(sim.state.x, x0);
}

#[test]
fn normal_hang_and_drape_still_converge_with_no_retry_and_no_energy_gained() {
    use emilion::scenes;
    for (name, mut sim) in [
        ("hang", scenes::hang(24).unwrap()),
        ("drape", scenes::drape(24).unwrap()),
    ] {
        let tol = sim.params.cg_tolerance;
        let e0 = sim.energy();
        sim.run_steps(90, |_, st| {
            assert!(
                st.converged && st.residual <= tol && st.retries == 0,
                "{name} step {}: {st:?}",
                st.step
            );
            Ok(())
        })
        .unwrap();
        assert_eq!((sim.unconverged_steps, sim.retried_steps), (0, 0));
        // released at rest, driven by nothing but gravity: no energy gained
        let e = sim.energy();
        let (total0, total) = (e0.0 + e0.1 + e0.2, e.0 + e.1 + e.2);
        assert!(total < total0, "{name}: {total0} J -> {total} J");
    }
}

/// A stage that moves particle `victim` 1 cm off its pin after every step longer than
/// `longest` s: a failure that a smaller step does not have.
#[derive(Debug)]
struct KnockOffPin {
    victim: usize,
    longest: f64,
}

impl StepStage for KnockOffPin {
    fn respond(&mut self, end: StepEnd<'_>) {
        if end.dt > self.longest {
            end.x[self.victim].x += 0.01;
        }
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

#[test]
fn a_step_that_fails_whole_is_retried_in_halves_like_two_half_steps() {
    let n = 12;
    let dt = 1.0 / 120.0;
    let params = SimulationParameters {
        dt,
        ..Default::default()
    };
    let knocked = |steps: u64| {
        let mut sim = hang(n, FabricParameters::default(), params);
        sim.add_stage(Box::new(KnockOffPin {
            victim: n * n - 1,
            longest: 0.75 * dt,
        }));
        sim.run_steps(steps, |_, _| Ok(())).unwrap();
        sim
    };
    let halves = |steps: u64| {
        let half = SimulationParameters {
            dt: dt / 2.0,
            ..params
        };
        let mut sim = hang(n, FabricParameters::default(), half);
        sim.run_steps(steps, |_, _| Ok(())).unwrap();
        sim
    };
    // one retried step is exactly two steps of dt/2 (the retry starts CG from zero, as a
    // fresh simulation does)
    let (sim, half) = (knocked(1), halves(2));
    assert_eq!(sim.stats[0].retries, 1, "{:?}", sim.stats);
    assert_eq!(sim.retried_steps, 1);
    assert_eq!(sim.state.time, dt);
    assert_eq!(sim.state.x, half.state.x);
    assert_eq!(sim.state.v, half.state.v);
    // every step is retried the same way; the warm start of the half steps then differs,
    // within the solver's tolerance
    let (sim, half) = (knocked(30), halves(60));
    assert!(sim.stats.iter().all(|s| s.retries == 1 && s.converged));
    assert_eq!(sim.retried_steps, 30);
    let d = sim
        .state
        .x
        .iter()
        .zip(&half.state.x)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    eprintln!("30 retried steps against 60 half steps: {d:.3e} m apart");
    assert!(d < 1e-3, "{d} m");
}

#[test]
fn a_step_that_fails_at_every_split_stops_with_where_and_why() {
    let n = 8;
    let mut sim = hang(
        n,
        FabricParameters::default(),
        SimulationParameters::default(),
    );
    sim.run_steps(2, |_, _| Ok(())).unwrap();
    let (x, v) = (sim.state.x.clone(), sim.state.v.clone());
    sim.add_stage(Box::new(KnockOffPin {
        victim: n * n - 1,
        longest: 0.0,
    }));
    let (step, time, cause) = diverged(sim.step().unwrap_err());
    assert_eq!(step, 2);
    assert!((time - 2.0 / 120.0).abs() < 1e-15);
    assert!(
        cause.contains(&format!("particle {} left its pin", n * n - 1))
            && cause.contains("16 substeps"),
        "{cause}"
    );
    // the state is back at the start of the failing step
    assert_eq!((sim.state.x, sim.state.v), (x, v));
    assert_eq!(sim.stats.len(), 2);
}

/// `sim.run` in a script surfaces the error with the script's line.
#[cfg(feature = "scripting")]
#[test]
fn sim_run_surfaces_the_overflow_error_with_the_script_line() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("honest_convergence");
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("case.rhai");
    std::fs::write(
        &script,
        "let cloth = cloth_grid(1.0, 1.0, 8, 8, fabric());\n\
         let sim = simulation(cloth, #{ gravity: [0.0, 0.0, -1e160] });\n\
         sim.pin_corners(\"top\");\n\
         sim.run(0.05);\n\
         print(\"not reached\");\n",
    )
    .unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_emilion"))
        .arg("run")
        .arg(&script)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("case.rhai:4"), "{err}");
    assert!(
        err.contains("diverged at step 0") && err.contains("force on particle"),
        "{err}"
    );
    assert!(!String::from_utf8_lossy(&o.stdout).contains("not reached"));
}
