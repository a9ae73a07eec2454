//! The MLPG discretisation of a shell problem, built once: support radii from the local
//! spacing, and for each node I its local sub-domain Ω_I (a circle of radius
//! `subdomain_factor` × spacing in the parameter plane, clipped by the rectangle) with its
//! quadrature points, the MLPG1 test function v_I (the weight bump on Ω_I) and the MLS shape
//! functions of the trial field at each point; the penalty terms of the essential conditions
//! on the parts of the edges inside Ω_I (a constant matrix: the conditions are homogeneous and
//! linear) and the load vector (dead loads).

use rayon::prelude::*;

use super::error::ShellError;
use super::kinematics::RestGeometry;
use super::mls::{bump, shape_functions, ShapeValues};
use super::neighbours::{local_spacing, PointGrid};
use super::problem::{gauss_legendre, Constraint, Direction, ShellParameters, ShellProblem};
use super::surface::V3;
use crate::limits;

/// One quadrature point of a sub-domain.
#[derive(Debug, Clone)]
pub struct QuadPoint {
    /// Quadrature weight × rest area element.
    pub weight: f64,
    /// The test function v_I and its derivatives `[v, v,1, v,2, v,11, v,12, v,22]`.
    pub test: [f64; 6],
    /// The rest geometry.
    pub rest: RestGeometry,
    /// Trial shape functions: global node ids, their slots in the node's column list, values.
    pub nodes: Vec<usize>,
    /// Slot of each node in [`NodeTerms::columns`].
    pub slots: Vec<usize>,
    /// `[φ, φ,1, φ,2, φ,11, φ,12, φ,22]` per node.
    pub values: Vec<[f64; 6]>,
}

/// Everything that node I's three equations need.
#[derive(Debug, Clone, Default)]
pub struct NodeTerms {
    /// The quadrature points of Ω_I.
    pub quad: Vec<QuadPoint>,
    /// The nodes these equations couple to, ascending.
    pub columns: Vec<usize>,
    /// Constant penalty blocks (3×3 row-major), one per column.
    pub penalty: Vec<[f64; 9]>,
    /// External load on these equations at load factor 1.
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
    /// Per node: its equations' terms.
    pub terms: Vec<NodeTerms>,
    grid: PointGrid,
    max_radius: f64,
}

fn resolve(d: Direction, normal: &V3) -> V3 {
    match d {
        Direction::Fixed(v) => V3::new(v[0], v[1], v[2]).normalize(),
        Direction::Normal => *normal,
    }
}

/// Distance from `x` along the unit direction `dir` to where the ray leaves the rectangle
/// `dom`, capped at `r`.
fn ray_reach(x: [f64; 2], dir: [f64; 2], r: f64, dom: [f64; 4]) -> f64 {
    let mut t = r;
    for k in 0..2 {
        if dir[k] > 1e-15 {
            t = t.min((dom[2 * k + 1] - x[k]) / dir[k]);
        } else if dir[k] < -1e-15 {
            t = t.min((dom[2 * k] - x[k]) / dir[k]);
        }
    }
    t.max(0.0)
}

/// Angles and weights of the angular quadrature of a circle of radius `r` about `x` clipped by
/// the rectangle `dom`: the breaks are where the circle crosses an edge line and the corners'
/// directions; a whole circle gets `n` equally spaced angles (exact for its trigonometric
/// integrands), each arc between breaks Gauss points (`gp`, `gw`) repeated over pieces of at
/// most 2π/n·gauss.
fn arc_quadrature(x: [f64; 2], r: f64, dom: [f64; 4], n: usize, gp: &[f64], gw: &[f64]) -> Vec<(f64, f64)> {
    use std::f64::consts::PI;
    let mut breaks = Vec::new();
    for k in 0..2 {
        for side in 0..2 {
            let d = dom[2 * k + side] - x[k];
            if d.abs() < r {
                let c = (d / r).clamp(-1.0, 1.0);
                let s = (1.0 - c * c).sqrt();
                // points x + r (cos θ, sin θ) with the k-th coordinate offset d
                let pts = if k == 0 { [[c, s], [c, -s]] } else { [[s, c], [-s, c]] };
                for p in pts {
                    breaks.push(p[1].atan2(p[0]));
                }
            }
        }
    }
    for cx in [dom[0], dom[1]] {
        for cy in [dom[2], dom[3]] {
            let (dx, dy) = (cx - x[0], cy - x[1]);
            if dx * dx + dy * dy < r * r && (dx != 0.0 || dy != 0.0) {
                breaks.push(dy.atan2(dx));
            }
        }
    }
    if breaks.is_empty() {
        return (0..n).map(|i| (2.0 * PI * i as f64 / n as f64, 2.0 * PI / n as f64)).collect();
    }
    for b in &mut breaks {
        if *b < 0.0 {
            *b += 2.0 * PI;
        }
    }
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let first = breaks[0];
    breaks.push(first + 2.0 * PI);
    let piece = 2.0 * PI / n as f64 * gp.len() as f64;
    let mut out = Vec::new();
    for w in breaks.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b - a < 1e-14 {
            continue;
        }
        let pieces = ((b - a) / piece).ceil().max(1.0) as usize;
        let h = (b - a) / pieces as f64;
        for m in 0..pieces {
            for (g, wg) in gp.iter().zip(gw) {
                out.push((a + h * (m as f64 + 0.5 * (g + 1.0)), wg * 0.5 * h));
            }
        }
    }
    out
}

fn add_block(cols: &mut Vec<(usize, [f64; 9])>, j: usize, s: f64, d: &V3) {
    let mut b = [0.0; 9];
    for r in 0..3 {
        for c in 0..3 {
            b[3 * r + c] = s * d[r] * d[c];
        }
    }
    cols.push((j, b));
}

impl Discretisation {
    /// Builds the discretisation: errors name the bad parameter, or the point whose shape
    /// functions cannot be built.
    pub fn new(problem: ShellProblem, params: ShellParameters) -> Result<Discretisation, ShellError> {
        params.validate().map_err(ShellError::Invalid)?;
        problem.surface.validate().map_err(ShellError::Invalid)?;
        let d = problem.domain;
        if !(d.iter().all(|v| v.is_finite()) && d[1] > d[0] && d[3] > d[2]) {
            return Err(ShellError::Invalid(format!(
                "parameter domain must be a finite rectangle [min1, max1, min2, max2], got {d:?}"
            )));
        }
        let n = problem.nodes.len();
        limits::check_count("shell sample points", n as u64, "max_particles", limits::get().max_particles)?;
        let tol = 1e-9 * (d[1] - d[0]).max(d[3] - d[2]);
        for (i, p) in problem.nodes.iter().enumerate() {
            if !(p[0] >= d[0] - tol && p[0] <= d[1] + tol && p[1] >= d[2] - tol && p[1] <= d[3] + tol) {
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
        let per_node = ((params.angular + 32) * params.gauss) as u64;
        limits::check_alloc("shell quadrature points", per_node * n as u64, 512)?;
        let mut disc = Discretisation {
            problem,
            params,
            spacing,
            radius,
            terms: Vec::new(),
            grid,
            max_radius,
        };
        let terms: Result<Vec<NodeTerms>, ShellError> =
            (0..n).into_par_iter().map(|i| disc.node_terms(i)).collect();
        disc.terms = terms?;
        Ok(disc)
    }

    /// Number of sample points.
    pub fn len(&self) -> usize {
        self.problem.nodes.len()
    }

    /// Whether there are no sample points.
    pub fn is_empty(&self) -> bool {
        self.problem.nodes.is_empty()
    }

    /// Total number of sub-domain quadrature points.
    pub fn quadrature_points(&self) -> usize {
        self.terms.iter().map(|t| t.quad.len()).sum()
    }

    /// The MLS shape functions at a parameter point (`what` names it in errors).
    pub fn shape_at(&self, x: [f64; 2], what: &dyn Fn() -> String) -> Result<ShapeValues, ShellError> {
        let mut cand = Vec::new();
        self.grid.within(x, self.max_radius, &mut cand);
        shape_functions(x, &self.problem.nodes, &self.radius, &cand, self.params.basis, what)
    }

    fn node_terms(&self, i: usize) -> Result<NodeTerms, ShellError> {
        let pr = &self.problem;
        let dom = pr.domain;
        let xi = pr.nodes[i];
        let h = self.spacing[i];
        let rs = self.params.subdomain_factor * h;
        let (gp, gw) = gauss_legendre(self.params.gauss);
        let m = 2;
        let (m_scale, b_scale) = pr.material.scales();
        let pen = self.params.penalty;
        let mut out = NodeTerms::default();
        let mut blocks: Vec<(usize, [f64; 9])> = Vec::new();
        let what = |kind: &str| {
            let s = format!("{kind} of node {i}");
            move || s.clone()
        };
        // sub-domain: the circle clipped by the rectangle, in polar (ray) quadrature about the
        // node: angular arcs split where the circle meets an edge or a corner lies inside it,
        // Gauss along each arc and along each ray up to where it leaves the sub-domain
        for (theta, w_theta) in arc_quadrature(xi, rs, dom, self.params.angular, gp, gw) {
            let dir = [theta.cos(), theta.sin()];
            let reach = ray_reach(xi, dir, rs, dom);
            if reach <= 0.0 {
                continue;
            }
            for (g, wr) in gp.iter().zip(gw) {
                let rho = 0.5 * reach * (g + 1.0);
                let p = [xi[0] + rho * dir[0], xi[1] + rho * dir[1]];
                let test = bump([p[0] - xi[0], p[1] - xi[1]], rs);
                if test[0] <= 0.0 {
                    continue;
                }
                let rest = RestGeometry::new(pr.surface.at(p)).ok_or_else(|| {
                    ShellError::Invalid(format!("degenerate rest surface at ({}, {})", p[0], p[1]))
                })?;
                let weight = w_theta * wr * 0.5 * reach * rho * rest.area;
                let s = self.shape_at(p, &what("a quadrature point"))?;
                for c in 0..3 {
                    out.load[c] += weight * test[0] * pr.area_load[c];
                }
                out.quad.push(QuadPoint {
                    weight,
                    test,
                    rest,
                    slots: vec![0; s.nodes.len()],
                    nodes: s.nodes,
                    values: s.values,
                });
            }
        }
        // essential conditions on the edges inside the sub-domain
        for (e, constraints) in pr.edges.iter().enumerate() {
            if constraints.is_empty() {
                continue;
            }
            let k = e / 2; // the parameter fixed on this edge
            let o = 1 - k;
            let value = dom[e];
            let sign = if e % 2 == 0 { -1.0 } else { 1.0 };
            let dist = (xi[k] - value).abs();
            if dist >= rs {
                continue;
            }
            let half = (rs * rs - dist * dist).sqrt();
            let (a, b) = ((xi[o] - half).max(dom[2 * o]), (xi[o] + half).min(dom[2 * o + 1]));
            if b <= a {
                continue;
            }
            let seg = (b - a) / m as f64;
            for c in 0..m {
                for (g, w) in gp.iter().zip(gw) {
                    let mut p = [0.0; 2];
                    p[k] = value;
                    p[o] = a + seg * (c as f64 + 0.5 * (g + 1.0));
                    let test = bump([p[0] - xi[0], p[1] - xi[1]], rs);
                    if test[0] <= 0.0 {
                        continue;
                    }
                    let sp = pr.surface.at(p);
                    let rest = RestGeometry::new(sp).ok_or_else(|| {
                        ShellError::Invalid(format!("degenerate rest surface at ({}, {})", p[0], p[1]))
                    })?;
                    let line = w * 0.5 * seg * sp.d1[o].norm();
                    let across = sp.d1[k].norm();
                    let s = self.shape_at(p, &what("an edge point"))?;
                    for con in constraints {
                        let (tv, deriv, dir, alpha) = match *con {
                            Constraint::Value(d) => (test[0], 0, d, pen * (m_scale / h).max(b_scale / h.powi(3))),
                            Constraint::Slope(d) => (sign * test[1 + k] / across, 1 + k, d, pen * b_scale / h),
                        };
                        let dv = resolve(dir, &rest.normal);
                        for (jj, &j) in s.nodes.iter().enumerate() {
                            let sj = if deriv == 0 { s.values[jj][0] } else { sign * s.values[jj][deriv] / across };
                            add_block(&mut blocks, j, alpha * line * tv * sj, &dv);
                        }
                    }
                }
            }
        }
        // pinned points and point loads inside the sub-domain
        for (p, d) in &pr.pins {
            let test = bump([p[0] - xi[0], p[1] - xi[1]], rs);
            if test[0] > 0.0 {
                let dv = V3::new(d[0], d[1], d[2]).normalize();
                let alpha = pen * m_scale.max(b_scale / (h * h));
                let s = self.shape_at(*p, &what("a pinned point"))?;
                for (jj, &j) in s.nodes.iter().enumerate() {
                    add_block(&mut blocks, j, alpha * test[0] * s.values[jj][0], &dv);
                }
            }
        }
        for (p, f) in &pr.point_loads {
            let test = bump([p[0] - xi[0], p[1] - xi[1]], rs);
            for c in 0..3 {
                out.load[c] += test[0] * f[c];
            }
        }
        // column list, slots, merged penalty blocks
        let mut cols: Vec<usize> = out.quad.iter().flat_map(|q| q.nodes.iter().copied()).collect();
        cols.extend(blocks.iter().map(|b| b.0));
        cols.push(i);
        cols.sort_unstable();
        cols.dedup();
        for q in &mut out.quad {
            for (s, j) in q.slots.iter_mut().zip(&q.nodes) {
                *s = cols.binary_search(j).unwrap_or(0);
            }
        }
        out.penalty = vec![[0.0; 9]; cols.len()];
        for (j, b) in blocks {
            let s = cols.binary_search(&j).unwrap_or(0);
            for t in 0..9 {
                out.penalty[s][t] += b[t];
            }
        }
        out.columns = cols;
        Ok(out)
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
