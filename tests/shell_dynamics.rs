//! The meshless shell in time (`src/shell/dynamics.rs`), against analytic answers: a clamped
//! strip released from its first mode vibrates at the Euler–Bernoulli frequency
//! ω₁ = 1.8751² √(D / (ρ L⁴)); Newmark's average acceleration keeps the amplitude and the
//! energy (through a large, nonlinear swing) while backward Euler damps them.

use emilion::shell::dynamics::{potential_energy, DynamicsParameters, Integrator, ShellDynamics};
use emilion::shell::{Discretisation, ShellMaterial, ShellParameters, ShellProblem};

const L: f64 = 1.0;
const B: f64 = 0.1;
/// β₁ L of a clamped–free beam.
const BETA_L: f64 = 1.875_104_068_711_961;

/// A strip L × B, t 0.01, ν 0, bending rigidity D = 1 N·m, 1 kg/m², clamped at ξ¹ = 0, under
/// the area load `q` (N/m², downwards), on `n` × 3 points.
fn strip(n: usize, q: f64) -> Discretisation {
    let t = 0.01;
    let e = 12.0 / (t * t * t);
    let problem = ShellProblem {
        area_load: [0.0, 0.0, -q],
        ..ShellProblem::clamped_strip(
            L,
            B,
            n,
            3,
            ShellMaterial::isotropic(e, 0.0, t, 1.0).unwrap(),
        )
    };
    Discretisation::new(problem, ShellParameters::default()).unwrap()
}

/// The first clamped–free mode shape, 0 at the clamp.
fn mode_one(x: f64) -> f64 {
    let b = BETA_L / L;
    let bl = BETA_L;
    let sigma = (bl.cosh() + bl.cos()) / (bl.sinh() + bl.sin());
    (b * x).cosh() - (b * x).cos() - sigma * ((b * x).sinh() - (b * x).sin())
}

fn tip_z(disc: &Discretisation, u: &[f64]) -> f64 {
    disc.displacement_at([L, 0.5 * B], u).unwrap()[2]
}

/// Runs the strip from its first mode (tip amplitude 1 mm) for `periods` analytic periods at
/// `steps_per_period`: the tip's zero-crossing times, its largest |z| between 1.75 and 2.25
/// periods (the second peak) over its start, and the analytic period.
fn vibrate(integrator: Integrator, steps_per_period: usize, periods: f64) -> (Vec<f64>, f64, f64) {
    let disc = strip(15, 0.0);
    let omega = BETA_L * BETA_L * (1.0 / L.powi(4)).sqrt();
    let period = 2.0 * std::f64::consts::PI / omega;
    let amp = 1e-3;
    let mut u = vec![0.0; 3 * disc.len()];
    for (j, p) in disc.problem.nodes.iter().enumerate() {
        u[3 * j + 2] = amp * mode_one(p[0]) / mode_one(L);
    }
    let params = DynamicsParameters {
        dt: period / steps_per_period as f64,
        integrator,
        ..Default::default()
    };
    let mut dynamics = ShellDynamics::new(&disc, None, params, u, Vec::new(), 0.0).unwrap();
    let mut z = tip_z(&disc, &dynamics.u);
    let z0 = z;
    let mut crossings = Vec::new();
    let mut second_peak = 0.0f64;
    let total = (periods * steps_per_period as f64).round() as usize;
    for _ in 0..total {
        dynamics.step(0.0).unwrap();
        let z1 = tip_z(&disc, &dynamics.u);
        if z.signum() != z1.signum() && z1 != 0.0 {
            crossings.push(dynamics.time - params.dt * z1 / (z1 - z));
        }
        if (1.75 * period..=2.25 * period).contains(&dynamics.time) {
            second_peak = second_peak.max(z1.abs());
        }
        z = z1;
    }
    println!(
        "{integrator:?}: tip {z0:.6e} at rest, crossings {crossings:?}, second peak {second_peak:.4e}, {:?}",
        dynamics.report
    );
    (crossings, second_peak / z0, period)
}

#[test]
fn a_clamped_strip_vibrates_at_the_euler_bernoulli_frequency_and_newmark_keeps_its_amplitude() {
    let (crossings, kept, period) = vibrate(Integrator::Newmark, 50, 2.5);
    assert!(crossings.len() >= 5, "{crossings:?}");
    // crossings every half period: the first to the fifth spans two periods
    let measured = 0.5 * (crossings[4] - crossings[0]);
    let err = (measured - period) / period;
    println!(
        "period {measured:.5} s against {period:.5} s: {:.3} %",
        100.0 * err
    );
    assert!(err.abs() < 0.01, "period {measured} against {period}");
    assert!((kept - 1.0).abs() < 0.01, "Newmark amplitude ratio {kept}");
}

#[test]
fn backward_euler_damps_the_same_vibration_by_its_amplification_factor() {
    let (_, kept, _) = vibrate(Integrator::BackwardEuler, 50, 2.5);
    // each step multiplies a mode's amplitude by 1/|1 − iωΔt|: 100 steps to the second peak
    let expected = (1.0 + (2.0 * std::f64::consts::PI / 50.0).powi(2)).powf(-50.0);
    println!("backward Euler kept {kept:.4} of the amplitude, {expected:.4} expected");
    assert!(
        (kept - expected).abs() < 0.02 * expected,
        "backward Euler kept {kept} of the amplitude, {expected} expected"
    );
}

/// Released flat under q L³/D = 10 (the elastica table's 60.3° at rest), the strip swings
/// through large rotations: Newmark keeps kinetic + potential energy near zero, backward Euler
/// loses it.
#[test]
fn newmark_keeps_the_energy_of_a_large_swing_and_backward_euler_loses_it() {
    let disc = strip(15, 10.0);
    let mut results = Vec::new();
    for integrator in [Integrator::Newmark, Integrator::BackwardEuler] {
        let params = DynamicsParameters {
            dt: 0.01,
            integrator,
            ..Default::default()
        };
        let mut d = ShellDynamics::new(&disc, None, params, Vec::new(), Vec::new(), 1.0).unwrap();
        let (mut worst, mut kinetic_max, mut last) = (0.0f64, 0.0f64, 0.0);
        let mut tip_min = 0.0f64;
        for s in 1..=100 {
            d.step(1.0).unwrap();
            tip_min = tip_min.min(tip_z(&disc, &d.u));
            if s % 20 == 0 {
                let k = d.kinetic_energy();
                let e = k + potential_energy(&disc, &d.u, 1.0);
                kinetic_max = kinetic_max.max(k);
                worst = worst.max(e.abs());
                last = e;
            }
        }
        println!(
            "{integrator:?}: largest |E| {worst:.4e} J, last E {last:.4e} J, largest kinetic {kinetic_max:.4e} J, lowest tip {tip_min:.3} m, {:?}",
            d.report
        );
        results.push((worst / kinetic_max, last / kinetic_max, tip_min));
    }
    let (newmark, euler) = (results[0], results[1]);
    // the tip falls more than 0.6 L: rotations past 60°, a large, nonlinear swing
    assert!(newmark.2 < -0.6, "tip only reached {}", newmark.2);
    assert!(
        newmark.0 < 0.005,
        "Newmark's energy drifted by {} of the kinetic",
        newmark.0
    );
    assert!(
        euler.1 < -0.05,
        "backward Euler kept its energy: {}",
        euler.1
    );
}

#[test]
fn bad_parameters_and_states_are_errors_naming_them() {
    use emilion::shell::arc_length::{arc_length, ArcLengthParameters};
    let disc = strip(15, 0.0);
    let n = 3 * disc.len();
    let run = |params: DynamicsParameters, u: Vec<f64>| {
        ShellDynamics::new(&disc, None, params, u, Vec::new(), 0.0)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    let nan_dt = DynamicsParameters {
        dt: f64::NAN,
        ..Default::default()
    };
    assert!(run(nan_dt, Vec::new()).contains("`dt`"));
    let ok = DynamicsParameters::default();
    assert!(run(ok, vec![0.0; n - 1]).contains(&format!("expected {n}")));
    let mut nan_u = vec![0.0; n];
    nan_u[4] = f64::NAN;
    assert!(run(ok, nan_u).contains("non-finite"));
    // arc length: a zero step, and a shell with no load to follow
    let (mut u, mut lambda) = (Vec::new(), 0.0);
    let zero_step = ArcLengthParameters {
        step: 0.0,
        ..Default::default()
    };
    let e = arc_length(&disc, &mut u, &mut lambda, &zero_step, &mut |_, _| true).unwrap_err();
    assert!(e.to_string().contains("0 < step"), "{e}");
    let e = arc_length(
        &disc,
        &mut u,
        &mut lambda,
        &Default::default(),
        &mut |_, _| true,
    )
    .unwrap_err();
    assert!(e.to_string().contains("needs a load"), "{e}");
}
