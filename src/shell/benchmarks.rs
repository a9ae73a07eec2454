//! The shell obstacle course (MacNeal–Harder 1985, Belytschko et al. 1985) and the plate and
//! cantilever checks, each as a problem builder and a run that returns the computed value, its
//! reference and the error. Linear cases are solved with one Newton step from rest; the heavy
//! cantilever with load stepping.

use std::f64::consts::PI;
use std::time::Instant;

use super::discretisation::Discretisation;
use super::error::ShellError;
use super::material::ShellMaterial;
use super::problem::{grid_nodes, Constraint, Direction, ShellParameters, ShellProblem};
use super::solve::{solve_linear, solve_static};
use super::surface::Surface;

/// One benchmark result.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchmarkResult {
    /// Case name.
    pub name: String,
    /// Number of sample points.
    pub points: usize,
    /// The computed value.
    pub value: f64,
    /// The reference value.
    pub reference: f64,
    /// Error: percent of the reference (or degrees for the cantilever's worst angle).
    pub error: f64,
    /// Wall time of build and solve (s).
    pub seconds: f64,
}

const X: Direction = Direction::Fixed([1.0, 0.0, 0.0]);
const Y: Direction = Direction::Fixed([0.0, 1.0, 0.0]);
const Z: Direction = Direction::Fixed([0.0, 0.0, 1.0]);
const N: Direction = Direction::Normal;

fn nodes_for(domain: [f64; 4], n: usize) -> Vec<[f64; 2]> {
    let (w, h) = (domain[1] - domain[0], domain[3] - domain[2]);
    let (n1, n2) = if w >= h {
        (n, (((n - 1) as f64) * h / w).round() as usize + 1)
    } else {
        ((((n - 1) as f64) * w / h).round() as usize + 1, n)
    };
    grid_nodes(domain, n1, n2.max(3))
}

fn result(
    name: &str,
    disc: &Discretisation,
    value: f64,
    reference: f64,
    t0: Instant,
) -> BenchmarkResult {
    BenchmarkResult {
        name: name.to_string(),
        points: disc.len(),
        value,
        reference,
        error: 100.0 * (value - reference) / reference,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// Square plate (side 1 m, t 0.01 m, E 1e9 Pa, ν 0.3) under uniform load on an `n` × `n`
/// grid, simply supported (w = 0 and no in-plane motion on the edges) or clamped (also no
/// rotation): the centre deflection in units of q a⁴/D against 0.00406 (simply supported) and
/// 0.00126 (clamped) (Timoshenko & Woinowsky-Krieger, tables 8 and 35).
pub fn square_plate(
    n: usize,
    clamped: bool,
    params: ShellParameters,
) -> Result<BenchmarkResult, ShellError> {
    let t0 = Instant::now();
    let (a, t, e, nu, q) = (1.0, 0.01, 1e9, 0.3, 1.0);
    let material = ShellMaterial::isotropic(e, nu, t, 0.0).map_err(ShellError::Invalid)?;
    let d = e * t * t * t / (12.0 * (1.0 - nu * nu));
    let mut edge = vec![
        Constraint::Value(X),
        Constraint::Value(Y),
        Constraint::Value(Z),
    ];
    if clamped {
        edge.push(Constraint::Slope(N));
    }
    let domain = [0.0, a, 0.0, a];
    let problem = ShellProblem {
        surface: Surface::Plane,
        domain,
        nodes: grid_nodes(domain, n, n),
        material,
        edges: [edge.clone(), edge.clone(), edge.clone(), edge],
        pins: vec![],
        area_load: [0.0, 0.0, -q],
        point_loads: vec![],
    };
    let disc = Discretisation::new(problem, params)?;
    let u = solve_linear(&disc)?;
    let w = -disc.displacement_at([0.5 * a, 0.5 * a], &u)?.z / (q * a.powi(4) / d);
    let (name, reference) = if clamped {
        ("plate_clamped", 0.00126)
    } else {
        ("plate_simply_supported", 0.00406)
    };
    Ok(result(name, &disc, w, reference, t0))
}

/// The tip angles of the elastica table (`../shared/reference/elastica-table.txt`): q L³/B and
/// the tip angle in degrees, for q L³/B in [1, 20].
pub const ELASTICA_TIP_ANGLES: [(f64, f64); 6] = [
    (1.0, 9.460),
    (2.0, 18.426),
    (5.0, 39.935),
    (8.0, 53.865),
    (10.0, 60.312),
    (20.0, 76.748),
];

/// A heavy cantilever strip (L 1 m, width 0.1 m, t 0.01 m, ν 0, B = E t³/12 = 1 N·m) clamped at
/// ξ¹ = 0, loaded by its own weight up to q L³/B = 20 (Newton load steps from one table row to the
/// next, at most 2.5 in q L³/B each: 11 in all), on `n` points
/// along its length: the tip angle at each q L³/B of [`ELASTICA_TIP_ANGLES`]. Returns the
/// (q L³/B, computed angle, reference angle) rows and the result for the worst row (error in
/// degrees).
pub fn heavy_cantilever(
    n: usize,
    params: ShellParameters,
) -> Result<(Vec<[f64; 3]>, BenchmarkResult), ShellError> {
    let t0 = Instant::now();
    let (l, b, t) = (1.0, 0.1, 0.01);
    let e = 12.0 / (t * t * t);
    let material = ShellMaterial::isotropic(e, 0.0, t, 0.0).map_err(ShellError::Invalid)?;
    let bend = e * t * t * t / 12.0;
    let lam_max = 20.0;
    let across = ((b / l * (n - 1) as f64).round() as usize + 1).max(3);
    let problem = ShellProblem {
        area_load: [0.0, 0.0, -lam_max * bend / l.powi(3)],
        ..ShellProblem::clamped_strip(l, b, n, across, material)
    };
    let mut disc = Discretisation::new(problem, params)?;
    let mut u = Vec::new();
    let mut angles = Vec::new();
    let mut from = 0.0;
    // Newton load steps from one table row to the next, about 2.5 in q L³/B at most
    for &(lam, reference) in &ELASTICA_TIP_ANGLES {
        disc.params.load_steps = ((lam - from) / 2.5).ceil().max(1.0) as usize;
        solve_static(&disc, &mut u, from / lam_max, lam / lam_max, &mut |_, _| {})?;
        let f = disc.field_at([l, 0.5 * b], &u)?;
        let a1 = nalgebra::Vector3::x() + f[1];
        angles.push([lam, (-a1.z).atan2(a1.x).to_degrees(), reference]);
        from = lam;
    }
    let worst = angles
        .iter()
        .cloned()
        .max_by(|a, b| (a[1] - a[2]).abs().total_cmp(&(b[1] - b[2]).abs()))
        .unwrap_or([0.0; 3]);
    let res = BenchmarkResult {
        name: "cantilever".into(),
        points: disc.len(),
        value: worst[1],
        reference: worst[2],
        error: worst[1] - worst[2],
        seconds: t0.elapsed().as_secs_f64(),
    };
    Ok((angles, res))
}

/// Scordelis–Lo roof (R 25, L 50, 40°, t 0.25, E 4.32e8, ν 0, 90 per unit area downwards),
/// one quarter (symmetry at mid-length and at the crown, rigid diaphragm at the end, free
/// straight edge), `n` points along the half-length: the vertical displacement at the middle
/// of the free edge against 0.3006 (the converged thin-shell value; 0.3024 is MacNeal–Harder's
/// reference, which includes shear deformation).
pub fn scordelis_lo(n: usize, params: ShellParameters) -> Result<BenchmarkResult, ShellError> {
    let t0 = Instant::now();
    let r = 25.0;
    let material = ShellMaterial::isotropic(4.32e8, 0.0, 0.25, 0.0).map_err(ShellError::Invalid)?;
    let domain = [0.0, 25.0, 0.0, r * 40f64.to_radians()];
    let problem = ShellProblem {
        surface: Surface::Cylinder { radius: r },
        domain,
        nodes: nodes_for(domain, n),
        material,
        edges: [
            vec![Constraint::Value(X), Constraint::Slope(N)],
            vec![Constraint::Value(Y), Constraint::Value(Z)],
            vec![Constraint::Value(Y), Constraint::Slope(N)],
            vec![],
        ],
        pins: vec![],
        area_load: [0.0, 0.0, -90.0],
        point_loads: vec![],
    };
    let disc = Discretisation::new(problem, params)?;
    let u = solve_linear(&disc)?;
    let w = -disc.displacement_at([0.0, domain[3]], &u)?.z;
    Ok(result("scordelis_lo", &disc, w, 0.3006, t0))
}

/// Pinched cylinder with rigid diaphragms (R 300, L 600, t 3, E 3e6, ν 0.3, P 1), one eighth
/// (symmetry at mid-length and on two axial planes, diaphragm at the end), `n` points along the
/// half-length: the radial displacement under the load against 1.8248e-5.
pub fn pinched_cylinder(n: usize, params: ShellParameters) -> Result<BenchmarkResult, ShellError> {
    let t0 = Instant::now();
    let r = 300.0;
    let material = ShellMaterial::isotropic(3e6, 0.3, 3.0, 0.0).map_err(ShellError::Invalid)?;
    let domain = [0.0, 300.0, 0.0, r * PI / 2.0];
    let problem = ShellProblem {
        surface: Surface::Cylinder { radius: r },
        domain,
        nodes: nodes_for(domain, n),
        material,
        edges: [
            vec![Constraint::Value(X), Constraint::Slope(N)],
            vec![Constraint::Value(Y), Constraint::Value(Z)],
            vec![Constraint::Value(Y), Constraint::Slope(N)],
            vec![Constraint::Value(Z), Constraint::Slope(N)],
        ],
        pins: vec![],
        area_load: [0.0; 3],
        point_loads: vec![([0.0, 0.0], [0.0, 0.0, -0.25])],
    };
    let disc = Discretisation::new(problem, params)?;
    let u = solve_linear(&disc)?;
    let w = -disc.displacement_at([0.0, 0.0], &u)?.z;
    Ok(result("pinched_cylinder", &disc, w, 1.8248e-5, t0))
}

/// Pinched hemisphere with an 18° hole (R 10, t 0.04, E 6.825e7, ν 0.3, forces ±2 on the full
/// shell), one quarter (symmetry planes x = 0 and y = 0, a vertical pin against the free
/// translation), `n` points along the equator: the displacement under the load along it
/// against 0.0924.
pub fn pinched_hemisphere(
    n: usize,
    params: ShellParameters,
) -> Result<BenchmarkResult, ShellError> {
    let t0 = Instant::now();
    let r = 10.0;
    let material =
        ShellMaterial::isotropic(6.825e7, 0.3, 0.04, 0.0).map_err(ShellError::Invalid)?;
    let domain = [0.0, r * PI / 2.0, 0.0, r * 72f64.to_radians()];
    let problem = ShellProblem {
        surface: Surface::Sphere { radius: r },
        domain,
        nodes: nodes_for(domain, n),
        material,
        edges: [
            vec![Constraint::Value(Y), Constraint::Slope(N)],
            vec![Constraint::Value(X), Constraint::Slope(N)],
            vec![],
            vec![],
        ],
        pins: vec![([r * PI / 4.0, 0.0], [0.0, 0.0, 1.0])],
        area_load: [0.0; 3],
        point_loads: vec![
            ([0.0, 0.0], [1.0, 0.0, 0.0]),
            ([r * PI / 2.0, 0.0], [0.0, -1.0, 0.0]),
        ],
    };
    let disc = Discretisation::new(problem, params)?;
    let u = solve_linear(&disc)?;
    let w = disc.displacement_at([0.0, 0.0], &u)?.x;
    Ok(result("pinched_hemisphere", &disc, w, 0.0924, t0))
}
