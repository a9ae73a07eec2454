//! The meshless discretisation of a shell problem, built once: support radii from the local
//! spacing; the Galerkin weak form's quadrature on background cells (a uniform grid of cells
//! over the parameter rectangle, Gauss points in each) with the MLS shape functions at every
//! point; per node, the points in its support; the penalty terms of the essential conditions
//! along the edges (a constant symmetric matrix: the conditions are homogeneous and linear);
//! and the load vector (dead loads). Why Galerkin and not MLPG: `docs/shell.md`.

use rayon::prelude::*;

use super::error::ShellError;
use super::fabric_law::FabricLaw;
use super::kinematics::RestGeometry;
use super::mls::{shape_functions, ShapeValues};
use super::moment::{add_moment_residual, mean_rotation, MomentPoint};
use super::neighbours::{local_spacing, PointGrid};
use super::problem::{
    gauss_legendre, Constraint, Direction, ShellParameters, ShellProblem, EDGE_NAMES,
};
use super::surface::V3;
use crate::limits;

/// One quadrature point of the background cells.
#[derive(Debug, Clone)]
pub struct QuadPoint {
    /// Quadrature weight × rest area element.
    pub weight: f64,
    /// The rest geometry.
    pub rest: RestGeometry,
    /// Nodes whose support holds the point, ascending.
    pub nodes: Vec<usize>,
    /// `[φ, φ,1, φ,2, φ,11, φ,12, φ,22]` per node.
    pub values: Vec<[f64; 6]>,
}

/// Node J's rows: where its shape function lives and what couples to it.
#[derive(Debug, Clone, Default)]
pub struct NodeTerms {
    /// (quadrature point, position of J in its node list) for every point in J's support.
    pub quad: Vec<(usize, usize)>,
    /// The nodes these rows couple to, ascending.
    pub columns: Vec<usize>,
    /// Constant penalty blocks (3×3 row-major), one per column.
    pub penalty: Vec<[f64; 9]>,
    /// External load on these rows at load factor 1.
    pub load: [f64; 3],
}

/// The built discretisation.
#[derive(Debug, Clone)]
pub struct Discretisation {
    /// The problem.
    pub problem: ShellProblem,
    /// The parameters.
    pub params: ShellParameters,
    /// Local spacing per node.
    pub spacing: Vec<f64>,
    /// Support radius per node.
    pub radius: Vec<f64>,
    /// The background quadrature points.
    pub quad: Vec<QuadPoint>,
    /// Per node: its rows' terms.
    pub terms: Vec<NodeTerms>,
    /// A fabric's nonlinear law, used in place of `problem.material` for the strain energy
    /// when set ([`Discretisation::with_fabric_law`]).
    pub law: Option<FabricLaw>,
    /// Edge moments ([`Discretisation::add_edge_moment`]).
    pub moments: Vec<MomentPoint>,
    grid: PointGrid,
    max_radius: f64,
}

fn resolve(d: Direction, normal: &V3) -> V3 {
    match d {
        Direction::Fixed(v) => V3::new(v[0], v[1], v[2]).normalize(),
        Direction::Normal => *normal,
    }
}

/// A penalty term α ∫ (s_J u_J · d)(s_K δu_K · d): blocks for every pair of the point's nodes.
fn add_pairs(
    blocks: &mut [Vec<(usize, [f64; 9])>],
    nodes: &[usize],
    s: &[f64],
    scale: f64,
    d: &V3,
) {
    for (a, &j) in nodes.iter().enumerate() {
        for (b, &k) in nodes.iter().enumerate() {
            let c = scale * s[a] * s[b];
            if c == 0.0 {
                continue;
            }
            let mut blk = [0.0; 9];
            for r in 0..3 {
                for q in 0..3 {
                    blk[3 * r + q] = c * d[r] * d[q];
                }
            }
            blocks[j].push((k, blk));
        }
    }
}

impl Discretisation {
    /// Builds the discretisation: errors name the bad parameter, or the point whose shape
    /// functions cannot be built.
    pub fn new(
        problem: ShellProblem,
        params: ShellParameters,
    ) -> Result<Discretisation, ShellError> {
        params.validate().map_err(ShellError::Invalid)?;
        problem.surface.validate().map_err(ShellError::Invalid)?;
        let d = problem.domain;
        if !(d.iter().all(|v| v.is_finite()) && d[1] > d[0] && d[3] > d[2]) {
            return Err(ShellError::Invalid(format!(
                "parameter domain must be a finite rectangle [min1, max1, min2, max2], got {d:?}"
            )));
        }
        let n = problem.nodes.len();
        limits::check_count(
            "shell sample points",
            n as u64,
            "max_particles",
            limits::get().max_particles,
        )?;
        let tol = 1e-9 * (d[1] - d[0]).max(d[3] - d[2]);
        for (i, p) in problem.nodes.iter().enumerate() {
            if !(p[0] >= d[0] - tol
                && p[0] <= d[1] + tol
                && p[1] >= d[2] - tol
                && p[1] <= d[3] + tol)
            {
                return Err(ShellError::Invalid(format!(
                    "sample point {i} ({}, {}) lies outside the parameter rectangle {d:?}",
                    p[0], p[1]
                )));
            }
        }
        let guess = ((d[1] - d[0]) * (d[3] - d[2]) / n.max(1) as f64).sqrt();
        let spacing = local_spacing(&problem.nodes, guess)?;
        let radius: Vec<f64> = spacing.iter().map(|h| h * params.support_factor).collect();
        let max_radius = radius.iter().cloned().fold(0.0, f64::max);
        let grid = PointGrid::new(&problem.nodes, max_radius)?;
        // background cells: about `cell_factor` per mean spacing along each side
        let cells = [0, 1].map(|k| {
            (((d[2 * k + 1] - d[2 * k]) / guess * params.cell_factor).ceil() as usize).max(1)
        });
        let g = params.gauss;
        let count = (cells[0] * cells[1] * g * g) as u64;
        limits::check_alloc("shell quadrature points", count, 512)?;
        let mut disc = Discretisation {
            problem,
            params,
            spacing,
            radius,
            quad: Vec::new(),
            terms: Vec::new(),
            law: None,
            moments: Vec::new(),
            grid,
            max_radius,
        };
        disc.quad = disc.cell_points(cells)?;
        disc.terms = disc.node_terms(cells)?;
        Ok(disc)
    }

    /// Builds the discretisation of a shell of the fabric law `law`: the problem's material
    /// becomes the law's initial-slope linear shell (for the penalty scales; its areal density
    /// is kept) and the strain energy is the law's ([`FabricLaw`]).
    pub fn with_fabric_law(
        mut problem: ShellProblem,
        params: ShellParameters,
        law: FabricLaw,
    ) -> Result<Discretisation, ShellError> {
        problem.material = law
            .tangent_material(problem.material.density)
            .map_err(ShellError::Invalid)?;
        let mut disc = Discretisation::new(problem, params)?;
        disc.law = Some(law);
        Ok(disc)
    }

    fn cell_points(&self, cells: [usize; 2]) -> Result<Vec<QuadPoint>, ShellError> {
        let d = self.problem.domain;
        let (gp, gw) = gauss_legendre(self.params.gauss);
        let cw = [
            (d[1] - d[0]) / cells[0] as f64,
            (d[3] - d[2]) / cells[1] as f64,
        ];
        let per_cell = |c: usize| -> Result<Vec<QuadPoint>, ShellError> {
            let (cx, cy) = (c % cells[0], c / cells[0]);
            let mut out = Vec::with_capacity(gp.len() * gp.len());
            for (gy, wy) in gp.iter().zip(gw) {
                for (gx, wx) in gp.iter().zip(gw) {
                    let p = [
                        d[0] + cw[0] * (cx as f64 + 0.5 * (gx + 1.0)),
                        d[2] + cw[1] * (cy as f64 + 0.5 * (gy + 1.0)),
                    ];
                    let rest = RestGeometry::new(self.problem.surface.at(p)).ok_or_else(|| {
                        ShellError::Invalid(format!(
                            "degenerate rest surface at ({}, {})",
                            p[0], p[1]
                        ))
                    })?;
                    let s = self.shape_at(p, &|| format!("quadrature point of cell {cx}, {cy}"))?;
                    out.push(QuadPoint {
                        weight: wx * wy * 0.25 * cw[0] * cw[1] * rest.area,
                        rest,
                        nodes: s.nodes,
                        values: s.values,
                    });
                }
            }
            Ok(out)
        };
        // every cell's result kept, so that the error reported is the first cell's in order,
        // whichever thread failed first (a collect into Result stops at any error)
        let parts: Vec<Result<Vec<QuadPoint>, ShellError>> = (0..cells[0] * cells[1])
            .into_par_iter()
            .map(per_cell)
            .collect();
        let mut out = Vec::new();
        for part in parts {
            out.extend(part?);
        }
        Ok(out)
    }

    fn node_terms(&self, cells: [usize; 2]) -> Result<Vec<NodeTerms>, ShellError> {
        let pr = &self.problem;
        let n = self.len();
        let dom = pr.domain;
        let (gp, gw) = gauss_legendre(self.params.gauss);
        let (m_scale, b_scale) = pr.material.scales();
        let pen = self.params.penalty;
        let h = self.spacing.iter().sum::<f64>() / n as f64;
        let mut terms = vec![NodeTerms::default(); n];
        let mut blocks: Vec<Vec<(usize, [f64; 9])>> = vec![Vec::new(); n];
        for (qi, q) in self.quad.iter().enumerate() {
            for (a, &j) in q.nodes.iter().enumerate() {
                terms[j].quad.push((qi, a));
                for c in 0..3 {
                    terms[j].load[c] += q.weight * q.values[a][0] * pr.area_load[c];
                }
            }
        }
        // essential conditions along the edges: Gauss points on each cell's side
        for (e, constraints) in pr.edges.iter().enumerate() {
            if constraints.is_empty() {
                continue;
            }
            let k = e / 2; // the parameter fixed on this edge
            let o = 1 - k;
            let sign = if e % 2 == 0 { -1.0 } else { 1.0 };
            let segs = cells[o];
            let len = (dom[2 * o + 1] - dom[2 * o]) / segs as f64;
            for sgi in 0..segs {
                for (g, w) in gp.iter().zip(gw) {
                    let mut p = [0.0; 2];
                    p[k] = dom[e];
                    p[o] = dom[2 * o] + len * (sgi as f64 + 0.5 * (g + 1.0));
                    let sp = pr.surface.at(p);
                    let rest = RestGeometry::new(sp).ok_or_else(|| {
                        ShellError::Invalid(format!(
                            "degenerate rest surface at ({}, {})",
                            p[0], p[1]
                        ))
                    })?;
                    let line = w * 0.5 * len * sp.d1[o].norm();
                    let across = sp.d1[k].norm();
                    let s = self.shape_at(p, &|| {
                        format!("a point of edge {}", super::problem::EDGE_NAMES[e])
                    })?;
                    for con in constraints {
                        let (deriv, dir) = match *con {
                            Constraint::Value(d) => (0, d),
                            Constraint::Slope(d) => (1 + k, d),
                        };
                        let dv = resolve(dir, &rest.normal);
                        // the shell's own stiffness along d: bending for the normal part,
                        // membrane for the tangential part
                        let dn = dv.dot(&rest.normal).powi(2);
                        let alpha = match *con {
                            Constraint::Value(_) => {
                                pen * (m_scale / h * (1.0 - dn) + b_scale / h.powi(3) * dn)
                            }
                            Constraint::Slope(_) => pen * b_scale / h,
                        };
                        let sv: Vec<f64> = s
                            .values
                            .iter()
                            .map(|v| {
                                if deriv == 0 {
                                    v[0]
                                } else {
                                    sign * v[deriv] / across
                                }
                            })
                            .collect();
                        add_pairs(&mut blocks, &s.nodes, &sv, alpha * line, &dv);
                    }
                }
            }
        }
        for (p, d) in &pr.pins {
            let dv = V3::new(d[0], d[1], d[2]).normalize();
            let alpha = pen * m_scale.max(b_scale / (h * h));
            let s = self.shape_at(*p, &|| "a pinned point".to_string())?;
            let sv: Vec<f64> = s.values.iter().map(|v| v[0]).collect();
            add_pairs(&mut blocks, &s.nodes, &sv, alpha, &dv);
        }
        for (p, f) in &pr.point_loads {
            let s = self.shape_at(*p, &|| "a loaded point".to_string())?;
            for (a, &j) in s.nodes.iter().enumerate() {
                for c in 0..3 {
                    terms[j].load[c] += s.values[a][0] * f[c];
                }
            }
        }
        // column lists and merged penalty blocks
        for (j, t) in terms.iter_mut().enumerate() {
            let mut cols: Vec<usize> = t
                .quad
                .iter()
                .flat_map(|&(qi, _)| self.quad[qi].nodes.iter().copied())
                .collect();
            cols.extend(blocks[j].iter().map(|b| b.0));
            cols.push(j);
            cols.sort_unstable();
            cols.dedup();
            t.penalty = vec![[0.0; 9]; cols.len()];
            for (k, b) in &blocks[j] {
                let s = cols.binary_search(k).unwrap_or(0);
                for x in 0..9 {
                    t.penalty[s][x] += b[x];
                }
            }
            t.columns = cols;
        }
        Ok(terms)
    }

    /// Gauss points along `edge` (0 to 3, [`EDGE_NAMES`]) carrying `moment_per_width` (N·m/m
    /// at load factor 1).
    fn edge_points(
        &self,
        edge: usize,
        moment_per_width: f64,
    ) -> Result<Vec<MomentPoint>, ShellError> {
        if edge > 3 {
            return Err(ShellError::Invalid(format!(
                "edge index must be 0 to 3 ({EDGE_NAMES:?}), got {edge}"
            )));
        }
        if !moment_per_width.is_finite() {
            return Err(ShellError::Invalid(format!(
                "edge moment must be finite, got {moment_per_width}"
            )));
        }
        let dom = self.problem.domain;
        let (k, o) = (edge / 2, 1 - edge / 2);
        let h = self.spacing.iter().sum::<f64>() / self.len().max(1) as f64;
        let span = dom[2 * o + 1] - dom[2 * o];
        let segs = ((2.0 * span / h).ceil() as usize).clamp(1, 10_000);
        let len = span / segs as f64;
        let (gp, gw) = gauss_legendre(self.params.gauss);
        let mut out = Vec::with_capacity(segs * gp.len());
        for sgi in 0..segs {
            for (g, w) in gp.iter().zip(gw) {
                let mut p = [0.0; 2];
                p[k] = dom[edge];
                p[o] = dom[2 * o] + len * (sgi as f64 + 0.5 * (g + 1.0));
                let sp = self.problem.surface.at(p);
                let normal = sp.d1[0].cross(&sp.d1[1]).normalize();
                let line = w * 0.5 * len * sp.d1[o].norm();
                let s = self.shape_at(p, &|| format!("a point of edge {}", EDGE_NAMES[edge]))?;
                out.push(MomentPoint {
                    slope: s.values.iter().map(|v| v[1 + k]).collect(),
                    nodes: s.nodes,
                    rest_tangent: sp.d1[k],
                    t: sp.d1[k].normalize(),
                    n: normal,
                    weight: moment_per_width * line,
                    line,
                    edge,
                });
            }
        }
        Ok(out)
    }

    /// Adds a moment per unit rest width `moment_per_width` (N·m/m at load factor 1) along
    /// `edge` (0 to 3, [`EDGE_NAMES`]): positive turns the tangent across the edge (along ξ^k)
    /// towards the rest normal. It scales with the load factor like the other loads.
    pub fn add_edge_moment(
        &mut self,
        edge: usize,
        moment_per_width: f64,
    ) -> Result<(), ShellError> {
        let pts = self.edge_points(edge, moment_per_width)?;
        self.moments.extend(pts);
        Ok(())
    }

    /// The mean rotation θ (rad) along `edge` of the deformed tangent across it, towards the
    /// rest normal (the angle an edge moment works through).
    pub fn edge_rotation(&self, edge: usize, u: &[f64]) -> Result<f64, ShellError> {
        let pts = self.edge_points(edge, 0.0)?;
        Ok(mean_rotation(&pts, u))
    }

    /// The norm of the external load vector at load factor 1 (area and point loads and edge
    /// moments at rest): the scale of Newton's relative residual.
    pub fn external_load_norm(&self) -> f64 {
        let mut f: Vec<f64> = self.terms.iter().flat_map(|t| t.load).collect();
        let u = vec![0.0; f.len()];
        let mut r = vec![0.0; f.len()];
        add_moment_residual(&self.moments, &u, 1.0, &mut r);
        for (a, b) in f.iter_mut().zip(&r) {
            *a -= b;
        }
        f.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// Number of sample points.
    pub fn len(&self) -> usize {
        self.problem.nodes.len()
    }

    /// Whether there are no sample points.
    pub fn is_empty(&self) -> bool {
        self.problem.nodes.is_empty()
    }

    /// Number of background quadrature points.
    pub fn quadrature_points(&self) -> usize {
        self.quad.len()
    }

    /// The MLS shape functions at a parameter point (`what` names it in errors).
    pub fn shape_at(
        &self,
        x: [f64; 2],
        what: &dyn Fn() -> String,
    ) -> Result<ShapeValues, ShellError> {
        let mut cand = Vec::new();
        self.grid.within(x, self.max_radius, &mut cand);
        shape_functions(
            x,
            &self.problem.nodes,
            &self.radius,
            &cand,
            self.params.basis,
            what,
        )
    }

    /// The displacement at a parameter point from the nodal parameters `u` (3 per node).
    pub fn displacement_at(&self, x: [f64; 2], u: &[f64]) -> Result<V3, ShellError> {
        Ok(self.field_at(x, u)?[0])
    }

    /// The displacement and its first parameter derivatives at a point: `[u, u,1, u,2]`.
    pub fn field_at(&self, x: [f64; 2], u: &[f64]) -> Result<[V3; 3], ShellError> {
        let s = self.shape_at(x, &|| "an evaluation point".to_string())?;
        let mut out = [V3::zeros(); 3];
        for (k, &j) in s.nodes.iter().enumerate() {
            let uj = V3::new(u[3 * j], u[3 * j + 1], u[3 * j + 2]);
            for (d, o) in out.iter_mut().enumerate() {
                *o += uj * s.values[k][d];
            }
        }
        Ok(out)
    }
}
