//! Issue 48: long runs stop when the run is cancelled (`limits::cancel`, as a signal or the
//! `--max-seconds` watchdog does): `Simulation::run_steps` and the script runs `run`,
//! `run(seconds, callback)` and `run_frames` check once per step or frame. Cancelling is
//! process-wide and permanent, so this file holds one test.
#![cfg(feature = "scripting")]

use emilion::cloth::{ClothModel, FabricParameters, Simulation, SimulationParameters};
use emilion::script::build_engine;

#[test]
fn a_cancelled_run_stops_with_an_error_instead_of_hanging() {
    let model = ClothModel::grid(1.0, 1.0, 4, 4, FabricParameters::default()).unwrap();
    let mut sim = Simulation::new(model, SimulationParameters::default()).unwrap();
    // before: runs go on
    sim.run_steps(3, |_, _| Ok(())).unwrap();
    assert_eq!(sim.state.step, 3);
    // a callback cancels the run after step 5: the run stops at its next step
    let mut seen = 0;
    let e = sim
        .run_steps(50_000_000, |s, _| {
            seen += 1;
            if s.state.step == 5 {
                emilion::limits::cancel();
            }
            Ok(())
        })
        .unwrap_err();
    assert!(e.to_string().contains("cancelled"), "{e}");
    assert_eq!((seen, sim.state.step), (2, 5));
    // every script run stops too, at once
    for run in [
        "sim.run(100000.0);",
        "sim.run(100000.0, |t| true);",
        "sim.run_frames(100000, 24.0, |t| true);",
    ] {
        let script = format!("let sim = simulation(cloth_grid(1.0, 1.0, 4, 4, fabric())); {run}");
        let e = build_engine().run(&script).unwrap_err();
        assert!(e.to_string().contains("cancelled"), "{run}: {e}");
    }
}
