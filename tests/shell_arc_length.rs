//! Arc length through buckling (`src/shell/arc_length.rs`), against the elastica: a clamped
//! strip compressed by a dead end load buckles at P_cr = π² EI / (4 L²) and its post-buckling
//! path is P / P_cr = (2 K(k) / π)², k = sin(α/2), α the free end's rotation (K the complete
//! elliptic integral of the first kind).

use emilion::shell::arc_length::{arc_length, ArcLengthParameters};
use emilion::shell::{Discretisation, ShellMaterial, ShellParameters, ShellProblem};

/// K(k) by the arithmetic–geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut g) = (1.0, (1.0 - k * k).sqrt());
    while (a - g).abs() > 1e-15 {
        (a, g) = (0.5 * (a + g), (a * g).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

/// P / P_cr of the clamped–free elastica whose free end has turned by `alpha` (rad).
fn elastica_load(alpha: f64) -> f64 {
    (2.0 * elliptic_k((0.5 * alpha).sin()) / std::f64::consts::PI).powi(2)
}

#[test]
fn the_elliptic_integral_has_its_tabulated_values() {
    assert!((elliptic_k(0.0) - std::f64::consts::FRAC_PI_2).abs() < 1e-14);
    assert!((elliptic_k(0.5) - 1.685_750_354_812_596).abs() < 1e-12);
    assert!((elliptic_k(0.5f64.sqrt()) - 1.854_074_677_301_372).abs() < 1e-12);
}

#[test]
fn a_compressed_strip_follows_the_elastica_through_buckling() {
    let (l, b, t) = (1.0, 0.1, 0.01);
    let e = 12.0 / (t * t * t); // D = E t³/12 = 1 N·m, EI = D b
    let p_cr = std::f64::consts::PI.powi(2) * b / (4.0 * l * l);
    // the end load P_cr along −x over the free edge (¼, ½, ¼), tilted by a thousandth of a
    // radian downwards: the imperfection that picks the buckling direction
    let point_loads = [(0.0, 0.25), (0.5 * b, 0.5), (b, 0.25)]
        .iter()
        .map(|&(y, w)| ([l, y], [-w * p_cr, 0.0, -1e-3 * w * p_cr]))
        .collect();
    let problem = ShellProblem {
        point_loads,
        ..ShellProblem::clamped_strip(
            l,
            b,
            21,
            3,
            ShellMaterial::isotropic(e, 0.0, t, 0.0).unwrap(),
        )
    };
    let disc = Discretisation::new(problem, ShellParameters::default()).unwrap();
    let params = ArcLengthParameters {
        step: 0.02,
        max_step: 0.5,
        ..Default::default()
    };
    let (mut u, mut lambda) = (Vec::new(), 0.0);
    let mut rows = Vec::new();
    let path = arc_length(&disc, &mut u, &mut lambda, &params, &mut |lam, u| {
        let f = disc.field_at([l, 0.5 * b], u).unwrap();
        let a1 = nalgebra::Vector3::x() + f[1];
        let alpha = (-a1.z).atan2(a1.x);
        rows.push((alpha.to_degrees(), lam, elastica_load(alpha)));
        alpha < 120f64.to_radians()
    })
    .unwrap();
    let mut worst = 0.0f64;
    for &(alpha, lam, reference) in &rows {
        let err = (lam - reference) / reference;
        println!(
            "α {alpha:7.2}°  P/P_cr {lam:.5}  elastica {reference:.5}  {:+.3} %",
            100.0 * err
        );
        if alpha >= 10.0 {
            worst = worst.max(err.abs());
        }
    }
    let iterations: usize = path.iter().map(|p| p.iterations).sum();
    println!(
        "{} points, {iterations} corrector iterations, worst {:.3} %",
        path.len(),
        100.0 * worst
    );
    assert!(
        rows.last().unwrap().0 >= 120.0,
        "the path stopped at {:?}",
        rows.last()
    );
    assert!(
        rows.iter().filter(|r| r.0 >= 10.0).count() >= 8,
        "too few points past 10°"
    );
    assert!(worst < 0.01, "worst error {worst} against the elastica");
}

/// Snap-through, past a limit point: a shallow sinusoidal arch (span L, rise e = 4r, r = t/√12
/// the radius of gyration), pinned at immovable supports, under the load q₀ sin(πx/L). Shallow
/// arch theory solves it in one mode: with a the crown's height (e at rest), the load is
/// q₀ L⁴/(π⁴ EI) = (e − a) + a (e² − a²)/(4r²), which rises to its limit 8r at a = 2r, falls back
/// to 0 at a = −2r and rises again (the arch inverted). The asymmetric mode would branch off at
/// a = 0, past the limit point; the symmetric path is followed.
#[test]
fn a_shallow_arch_snaps_through_its_limit_point_at_the_one_mode_load() {
    use emilion::shell::problem::{Constraint, Direction};
    use emilion::shell::Surface;
    let (l, b, t): (f64, f64, f64) = (1.0, 0.1, 0.01);
    let e_mod = 12.0 / (t * t * t); // D = 1 N·m per unit width
    let r = t / 12f64.sqrt();
    let rise = 4.0 * r;
    let along = 21;
    // the reference load: q₀ = π⁴ D r / L⁴, so that λ reads q₀ L⁴/(π⁴ EI) in units of r
    let q_ref = std::f64::consts::PI.powi(4) * r / l.powi(4);
    let base = ShellProblem::clamped_strip(
        l,
        b,
        along,
        3,
        ShellMaterial::isotropic(e_mod, 0.0, t, 0.0).unwrap(),
    );
    let pinned = |v: [f64; 3]| Constraint::Value(Direction::Fixed(v));
    let pins = vec![
        pinned([1.0, 0.0, 0.0]),
        pinned([0.0, 1.0, 0.0]),
        pinned([0.0, 0.0, 1.0]),
    ];
    let h = l / (along - 1) as f64;
    let share = |i: usize, n: usize, d: f64| if i == 0 || i == n - 1 { 0.5 * d } else { d };
    let point_loads = base
        .nodes
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let area = share(k % along, along, h) * share(k / along, 3, 0.5 * b);
            let q = q_ref * (std::f64::consts::PI * p[0] / l).sin();
            (*p, [0.0, 0.0, -q * area])
        })
        .collect();
    let problem = ShellProblem {
        surface: Surface::SineArch { span: l, rise },
        edges: [pins.clone(), pins, vec![], vec![]],
        point_loads,
        ..base
    };
    let disc = Discretisation::new(problem, ShellParameters::default()).unwrap();
    let params = ArcLengthParameters {
        step: 0.2 * r,
        max_step: 2.0 * r,
        ..Default::default()
    };
    let one_mode = |a: f64| (rise - a) + a * (rise * rise - a * a) / (4.0 * r * r);
    let (mut u, mut lambda) = (Vec::new(), 0.0);
    let mut rows = Vec::new();
    arc_length(&disc, &mut u, &mut lambda, &params, &mut |lam, u| {
        let a = rise + disc.displacement_at([0.5 * l, 0.5 * b], u).unwrap()[2];
        rows.push((a / r, lam, one_mode(a) / r));
        println!(
            "point a/r {:.4} λ {lam:.5} one mode {:.5}",
            a / r,
            one_mode(a) / r
        );
        a > -3.0 * r
    })
    .unwrap();
    let mut worst = 0.0f64;
    for &(a, lam, reference) in &rows {
        println!("a/r {a:7.3}  q̄/r {lam:8.4}  one mode {reference:8.4}");
        worst = worst.max((lam - reference).abs());
    }
    let peak = rows.iter().map(|r| r.1).fold(f64::NEG_INFINITY, f64::max);
    let after = rows.iter().skip_while(|r| r.1 < peak).map(|r| r.1);
    let trough = after.fold(f64::INFINITY, f64::min);
    println!("{} points: limit load {peak:.4} r (8 r), lowest after it {trough:.4} r (0), worst {worst:.4} r", rows.len());
    assert!(
        rows.last().unwrap().0 <= -3.0,
        "the path stopped at {:?}",
        rows.last()
    );
    // the limit and the trough within 2 % of the limit load; the path within 3 %
    assert!((peak - 8.0).abs() < 0.16, "limit load {peak} r against 8 r");
    assert!(trough.abs() < 0.16, "trough {trough} r against 0");
    assert!(
        worst < 0.24,
        "the path strays {worst} r from the one-mode curve"
    );
}
