//! The KES-FB1 tensile and KES-FB2 pure-bending rigs on the meshless Kirchhoff–Love shell
//! (`src/shell/`) with a fabric's nonlinear law ([`FabricLaw`]: the cloth's measured law,
//! elastic backbone), solved by the shell's Newton method with load stepping, and compared with
//! the fabric's measured loading curves.
//!
//! - **Tensile** (KES-FB1): a strip of the standard's 5 cm gauge, narrower than its 20 cm (1 cm:
//!   the law is uniform across the width and warp and weft are uncoupled, so the force per
//!   width is the same), clamped at one end (no motion, no rotation); the other clamp holds its
//!   line (no motion across or out of the plane) and pulls along the strip with a uniform
//!   force per width raised in equal load steps to the protocol's maximum Fm. Read: force per
//!   width against the clamp's mean displacement / gauge.
//! - **Pure bending** (KES-FB2): a strip of the standard's 1 cm gauge, clamped at one end and
//!   loaded at the other by a uniform moment per width ([`Discretisation::add_edge_moment`]),
//!   raised in equal steps to the measured moment at the protocol's curvature amplitude
//!   (2.5 1/cm, or the end of the fabric's measured curve). A uniform moment bends the strip
//!   to a uniform curvature, read as the end clamp's rotation / gauge.
//!
//! Both rigs are load-controlled where the instruments are displacement-controlled: for an
//! elastic, monotone law the loading branch is the same set of points. The elastic shell has
//! no internal friction, so only loading branches are compared (the hysteresis of the
//! measured loops is not modelled).

use std::sync::Arc;

use super::calibrate::LawModel;
use super::fabric::{Curve, FabricSpec};
use super::lab::{curve_rms_pct, measurements};
use crate::cloth::{Direction, MaterialLaw};
use crate::shell::problem::grid_nodes;
use crate::shell::{
    Constraint, Direction as Along, Discretisation, FabricLaw, ShellError, ShellMaterial,
    ShellParameters, ShellProblem, Surface,
};

/// How the shell rigs sample and step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellRigOptions {
    /// Sample points along the tensile gauge (5 cm) and along the bending gauge (1 cm).
    pub points_along: usize,
    /// Load steps of the tensile test.
    pub tensile_steps: usize,
    /// Load steps of the bending test.
    pub bending_steps: usize,
    /// Discretisation and Newton parameters.
    pub params: ShellParameters,
}

impl Default for ShellRigOptions {
    fn default() -> Self {
        ShellRigOptions {
            points_along: 11,
            tensile_steps: 20,
            bending_steps: 15,
            params: ShellParameters::default(),
        }
    }
}

impl ShellRigOptions {
    /// Checks the counts (points along 5 to 201, steps 1 to 10 000).
    pub fn validate(&self) -> Result<(), String> {
        let counts = [
            ("points_along", self.points_along, 5, 201),
            ("tensile_steps", self.tensile_steps, 1, 10_000),
            ("bending_steps", self.bending_steps, 1, 10_000),
        ];
        for (name, v, lo, hi) in counts {
            if v < lo || v > hi {
                return Err(format!(
                    "shell rig option `{name}` must lie in [{lo}, {hi}], got {v}"
                ));
            }
        }
        self.params.validate()
    }
}

const X: Along = Along::Fixed([1.0, 0.0, 0.0]);
const Y: Along = Along::Fixed([0.0, 1.0, 0.0]);
const Z: Along = Along::Fixed([0.0, 0.0, 1.0]);

/// A flat strip `length` along the fabric direction `dir` (ξ¹ is the warp) × `width`, sampled
/// at about `length / (points − 1)`, clamped at its near end. Returns the problem, the far
/// edge's index and the unit vector along the strip.
fn strip(
    dir: Direction,
    length: f64,
    width: f64,
    points: usize,
    density: f64,
) -> (ShellProblem, usize, [f64; 3]) {
    let across = ((width / length * (points - 1) as f64).round() as usize).max(2) + 1;
    let (domain, nodes, near, far, axis) = match dir {
        Direction::Warp => {
            let d = [0.0, length, 0.0, width];
            (d, grid_nodes(d, points, across), 0, 1, [1.0, 0.0, 0.0])
        }
        Direction::Weft => {
            let d = [0.0, width, 0.0, length];
            (d, grid_nodes(d, across, points), 2, 3, [0.0, 1.0, 0.0])
        }
    };
    let mut edges: [Vec<Constraint>; 4] = Default::default();
    edges[near] = vec![
        Constraint::Value(X),
        Constraint::Value(Y),
        Constraint::Value(Z),
        Constraint::Slope(Along::Normal),
    ];
    let problem = ShellProblem {
        surface: Surface::Plane,
        domain,
        nodes,
        // replaced by the fabric law's initial-slope shell in `Discretisation::with_fabric_law`
        material: ShellMaterial {
            membrane: [[0.0; 3]; 3],
            bending: [[0.0; 3]; 3],
            density,
        },
        edges,
        pins: vec![],
        area_load: [0.0; 3],
        point_loads: vec![],
    };
    (problem, far, axis)
}

/// Points of the far edge `edge` of `domain`, `n` of them, for reading the clamp.
fn edge_samples(domain: [f64; 4], edge: usize, n: usize) -> Vec<[f64; 2]> {
    let (k, o) = (edge / 2, 1 - edge / 2);
    (0..n)
        .map(|i| {
            let mut p = [0.0; 2];
            p[k] = domain[edge];
            p[o] =
                domain[2 * o] + (domain[2 * o + 1] - domain[2 * o]) * (i as f64 + 0.5) / n as f64;
            p
        })
        .collect()
}

/// KES-FB1 tensile test on the shell along `dir` up to the force per width `fm` (N/m): the
/// loading path (engineering strain, N/m), from (0, 0).
pub fn shell_tensile(
    law: &FabricLaw,
    density: f64,
    dir: Direction,
    fm: f64,
    opts: &ShellRigOptions,
) -> Result<Vec<[f64; 2]>, ShellError> {
    opts.validate().map_err(ShellError::Invalid)?;
    if !(fm.is_finite() && fm > 0.0) {
        return Err(ShellError::Invalid(format!(
            "tensile test: maximum load must be positive and finite, got {fm} N/m"
        )));
    }
    let (gauge, width) = (0.05, 0.01);
    let (mut problem, far, axis) = strip(dir, gauge, width, opts.points_along, density);
    // the moving clamp holds its line: no motion across the strip or out of its plane
    let across = if far == 1 { Y } else { X };
    problem.edges[far] = vec![Constraint::Value(across), Constraint::Value(Z)];
    // a uniform force per width on the clamp line, by Gauss points along it
    let dom = problem.domain;
    let segs = 4 * opts.points_along;
    let (gp, gw) = crate::shell::problem::gauss_legendre(4);
    let seg = width / segs as f64;
    for s in 0..segs {
        for (g, w) in gp.iter().zip(gw) {
            let t = seg * (s as f64 + 0.5 * (g + 1.0));
            let p = if far == 1 {
                [dom[1], dom[2] + t]
            } else {
                [dom[0] + t, dom[3]]
            };
            let f = fm * w * 0.5 * seg;
            problem
                .point_loads
                .push((p, [axis[0] * f, axis[1] * f, axis[2] * f]));
        }
    }
    let mut params = opts.params;
    params.load_steps = opts.tensile_steps;
    let disc = Discretisation::with_fabric_law(problem, params, law.clone())?;
    let samples = edge_samples(dom, far, 8);
    let mut states: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut u = Vec::new();
    crate::shell::solve::solve_static(&disc, &mut u, 0.0, 1.0, &mut |lam, u| {
        states.push((lam, u.to_vec()))
    })?;
    let mut path = vec![[0.0, 0.0]];
    for (lam, u) in &states {
        let mut sum = 0.0;
        for p in &samples {
            let d = disc.displacement_at(*p, u)?;
            sum += d.x * axis[0] + d.y * axis[1] + d.z * axis[2];
        }
        path.push([sum / samples.len() as f64 / gauge, lam * fm]);
    }
    Ok(path)
}

/// KES-FB2 pure-bending test on the shell for curvature along `dir`, up to the moment per
/// width `m_max` (N): the loading path (curvature 1/m, moment per width N), from (0, 0).
pub fn shell_bending(
    law: &FabricLaw,
    density: f64,
    dir: Direction,
    m_max: f64,
    opts: &ShellRigOptions,
) -> Result<Vec<[f64; 2]>, ShellError> {
    opts.validate().map_err(ShellError::Invalid)?;
    if !(m_max.is_finite() && m_max > 0.0) {
        return Err(ShellError::Invalid(format!(
            "bending test: maximum moment must be positive and finite, got {m_max} N"
        )));
    }
    let (gauge, width) = (0.01, 0.004);
    let (problem, far, _) = strip(dir, gauge, width, opts.points_along, density);
    let mut params = opts.params;
    params.load_steps = opts.bending_steps;
    let mut disc = Discretisation::with_fabric_law(problem, params, law.clone())?;
    disc.add_edge_moment(far, m_max)?;
    let mut states: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut u = Vec::new();
    crate::shell::solve::solve_static(&disc, &mut u, 0.0, 1.0, &mut |lam, u| {
        states.push((lam, u.to_vec()))
    })?;
    let mut path = vec![[0.0, 0.0]];
    for (lam, u) in &states {
        path.push([disc.edge_rotation(far, u)? / gauge, lam * m_max]);
    }
    Ok(path)
}

/// One compared curve.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellRigRow {
    /// Test name: tensile_warp, tensile_weft, bending_warp, bending_weft.
    pub test: String,
    /// RMS difference from the measured loading branch, % of its range.
    pub rms_pct: f64,
    /// The largest strain (tensile) or curvature (1/m, bending) the rig reached.
    pub max_x: f64,
    /// The measured loading branch (SI).
    pub measured: Vec<[f64; 2]>,
    /// The shell's path (SI).
    pub simulated: Vec<[f64; 2]>,
}

/// The shell rigs of one fabric.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellRigReport {
    /// Fabric name.
    pub name: String,
    /// One row per measured curve the fabric has (tensile and bending, warp and weft).
    pub rows: Vec<ShellRigRow>,
}

impl ShellRigReport {
    /// The largest RMS (%) over the rows (0 without rows).
    pub fn worst(&self) -> f64 {
        self.rows.iter().map(|r| r.rms_pct).fold(0.0, f64::max)
    }
}

/// Runs the shell's tensile and bending rigs on every measured tensile and bending curve of a
/// fabric file, with the law built straight from its measurements (the cloth's
/// `MeasuredLaw`, unfitted: the shell needs no correction for a rig's discretisation) and the
/// lab's protocol (Fm, curvature amplitude). A fabric without measured curves gives no rows.
/// Errors name the fabric.
pub fn run_shell_rigs(spec: &FabricSpec, opts: &ShellRigOptions) -> Result<ShellRigReport, String> {
    let name = if spec.path.is_empty() {
        spec.name.clone()
    } else {
        spec.path.clone()
    };
    let model = LawModel::new(&measurements(spec)).map_err(|e| format!("{name}: {e}"))?;
    let law: Arc<dyn MaterialLaw> = Arc::new(model.law());
    let shell = FabricLaw::new(law.clone()).map_err(|e| format!("{name}: {e}"))?;
    let c = &spec.curves;
    let dirs = [Direction::Warp, Direction::Weft];
    let tests: [(&str, &Option<Curve>, usize, bool); 4] = [
        ("tensile_warp", &c.tensile_warp, 0, true),
        ("tensile_weft", &c.tensile_weft, 1, true),
        ("bending_warp", &c.bending_warp, 0, false),
        ("bending_weft", &c.bending_weft, 1, false),
    ];
    let mut rows = Vec::new();
    for (test, curve, d, tensile) in tests {
        let Some(curve) = curve else { continue };
        let run = if tensile {
            shell_tensile(
                &shell,
                spec.density,
                dirs[d],
                model.protocol.tensile_fm[d],
                opts,
            )
        } else {
            let m_max = law.bending(dirs[d], model.protocol.bending_amplitude[d]).0;
            shell_bending(&shell, spec.density, dirs[d], m_max, opts)
        };
        let simulated = run.map_err(|e| format!("{name}: {test} on the shell: {e}"))?;
        let rms = curve_rms_pct(&curve.loading, &simulated)
            .ok_or_else(|| format!("{name}: {test}: the shell's path covers no measured point"))?;
        rows.push(ShellRigRow {
            test: test.to_string(),
            rms_pct: rms,
            max_x: simulated.last().map_or(0.0, |p| p[0]),
            measured: curve.loading.clone(),
            simulated,
        });
    }
    Ok(ShellRigReport {
        name: spec.name.clone(),
        rows,
    })
}
