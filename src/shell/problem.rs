//! A shell problem: the rest surface over a rectangle of the parameter plane, the sample points,
//! the material, the boundary conditions per edge and at points, and the loads; with the
//! discretisation parameters ([`ShellParameters`]).

use super::material::ShellMaterial;
use super::mls::Basis;
use super::surface::Surface;

/// A direction a constraint acts along.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Direction {
    /// A fixed global direction (unit or not: it is normalised).
    Fixed([f64; 3]),
    /// The rest surface's normal at the boundary point.
    Normal,
}

/// An essential condition on an edge, enforced by a penalty.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Constraint {
    /// u·d = 0 (a support, a diaphragm, a symmetry plane's normal displacement).
    Value(Direction),
    /// (∂u/∂ν)·d = 0, ν the edge's outward normal in the surface (a clamp, a symmetry plane's
    /// rotation): with d = the normal, no rotation about the edge.
    Slope(Direction),
}

/// The edges of the parameter rectangle: ξ¹ = min, ξ¹ = max, ξ² = min, ξ² = max.
pub const EDGE_NAMES: [&str; 4] = ["xi1_min", "xi1_max", "xi2_min", "xi2_max"];

/// Everything that defines a static shell problem.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellProblem {
    /// The rest mid-surface.
    pub surface: Surface,
    /// The parameter rectangle [ξ¹ min, ξ¹ max, ξ² min, ξ² max].
    pub domain: [f64; 4],
    /// Sample points in the parameter plane (inside the rectangle, edges included).
    pub nodes: Vec<[f64; 2]>,
    /// The material.
    pub material: ShellMaterial,
    /// Conditions per edge, in the order of [`EDGE_NAMES`].
    pub edges: [Vec<Constraint>; 4],
    /// Point conditions u(ξ)·d = 0.
    pub pins: Vec<([f64; 2], [f64; 3])>,
    /// Dead load per unit rest area (N/m²), global.
    pub area_load: [f64; 3],
    /// Point forces (N), global, at parameter points.
    pub point_loads: Vec<([f64; 2], [f64; 3])>,
}

impl ShellProblem {
    /// A flat strip [0, `l`] × [0, `b`] of `material` on an `along` × `across` grid of points,
    /// clamped along ξ¹ = 0 (no displacement, no rotation about the edge), free elsewhere,
    /// unloaded (set `area_load` or `point_loads` after).
    pub fn clamped_strip(
        l: f64,
        b: f64,
        along: usize,
        across: usize,
        material: ShellMaterial,
    ) -> ShellProblem {
        let domain = [0.0, l, 0.0, b];
        let fixed = |v: [f64; 3]| Constraint::Value(Direction::Fixed(v));
        ShellProblem {
            surface: Surface::Plane,
            domain,
            nodes: grid_nodes(domain, along, across),
            material,
            edges: [
                vec![
                    fixed([1.0, 0.0, 0.0]),
                    fixed([0.0, 1.0, 0.0]),
                    fixed([0.0, 0.0, 1.0]),
                    Constraint::Slope(Direction::Normal),
                ],
                vec![],
                vec![],
                vec![],
            ],
            pins: vec![],
            area_load: [0.0; 3],
            point_loads: vec![],
        }
    }
}

/// How a problem is discretised and solved.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct ShellParameters {
    /// MLS basis.
    pub basis: Basis,
    /// Support radius of a node / its local spacing (nearest-neighbour distance).
    pub support_factor: f64,
    /// Background cells per side of the parameter rectangle's longer side, per sample point
    /// along it (1: one cell per spacing).
    pub cell_factor: f64,
    /// Gauss points per background cell side, and per edge segment (1 to 6).
    pub gauss: usize,
    /// Penalty factor: the penalty stiffness is this times the shell's own stiffness scale.
    pub penalty: f64,
    /// Load steps of the Newton solve.
    pub load_steps: usize,
    /// Newton stops when |residual| ≤ this × |load|.
    pub tolerance: f64,
    /// Most Newton iterations per load step.
    pub max_iterations: usize,
}

impl Default for ShellParameters {
    fn default() -> Self {
        ShellParameters {
            basis: Basis::Quadratic,
            support_factor: 3.5,
            cell_factor: 1.0,
            gauss: 4,
            penalty: 1e3,
            load_steps: 1,
            tolerance: 1e-9,
            max_iterations: 30,
        }
    }
}

impl ShellParameters {
    /// Checks every field against its range; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        let ranges: [(&str, f64, f64, f64); 4] = [
            ("support_factor", self.support_factor, 1.0, 10.0),
            ("cell_factor", self.cell_factor, 0.25, 8.0),
            ("penalty", self.penalty, 1.0, 1e12),
            ("tolerance", self.tolerance, 1e-15, 1e-2),
        ];
        for (name, v, lo, hi) in ranges {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(format!(
                    "shell parameter `{name}` must lie in [{lo}, {hi}], got {v}"
                ));
            }
        }
        let counts = [
            ("gauss", self.gauss, 1, 6),
            ("load_steps", self.load_steps, 1, 100_000),
            ("max_iterations", self.max_iterations, 1, 1000),
        ];
        for (name, v, lo, hi) in counts {
            if v < lo || v > hi {
                return Err(format!(
                    "shell parameter `{name}` must lie in [{lo}, {hi}], got {v}"
                ));
            }
        }
        Ok(())
    }
}

/// An `n1` × `n2` grid of sample points over the rectangle, edges included.
pub fn grid_nodes(domain: [f64; 4], n1: usize, n2: usize) -> Vec<[f64; 2]> {
    let mut out = Vec::with_capacity(n1 * n2);
    for j in 0..n2 {
        for i in 0..n1 {
            let s = i as f64 / (n1 - 1).max(1) as f64;
            let t = j as f64 / (n2 - 1).max(1) as f64;
            out.push([
                domain[0] + s * (domain[1] - domain[0]),
                domain[2] + t * (domain[3] - domain[2]),
            ]);
        }
    }
    out
}

/// Gauss–Legendre points and weights on [−1, 1], 1 to 6 points.
pub fn gauss_legendre(n: usize) -> (&'static [f64], &'static [f64]) {
    match n {
        1 => (&[0.0], &[2.0]),
        2 => (
            &[-0.577_350_269_189_625_8, 0.577_350_269_189_625_8],
            &[1.0, 1.0],
        ),
        3 => (
            &[-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4],
            &[
                0.555_555_555_555_555_6,
                0.888_888_888_888_888_8,
                0.555_555_555_555_555_6,
            ],
        ),
        4 => (
            &[
                -0.861_136_311_594_052_6,
                -0.339_981_043_584_856_3,
                0.339_981_043_584_856_3,
                0.861_136_311_594_052_6,
            ],
            &[
                0.347_854_845_137_453_9,
                0.652_145_154_862_546_1,
                0.652_145_154_862_546_1,
                0.347_854_845_137_453_9,
            ],
        ),
        5 => (
            &[
                -0.906_179_845_938_664,
                -0.538_469_310_105_683,
                0.0,
                0.538_469_310_105_683,
                0.906_179_845_938_664,
            ],
            &[
                0.236_926_885_056_189_1,
                0.478_628_670_499_366_5,
                0.568_888_888_888_888_9,
                0.478_628_670_499_366_5,
                0.236_926_885_056_189_1,
            ],
        ),
        _ => (
            &[
                -0.932_469_514_203_152,
                -0.661_209_386_466_264_5,
                -0.238_619_186_083_196_9,
                0.238_619_186_083_196_9,
                0.661_209_386_466_264_5,
                0.932_469_514_203_152,
            ],
            &[
                0.171_324_492_379_170_3,
                0.360_761_573_048_138_6,
                0.467_913_934_572_691,
                0.467_913_934_572_691,
                0.360_761_573_048_138_6,
                0.171_324_492_379_170_3,
            ],
        ),
    }
}
