//! Moments along an edge: a conservative couple per unit rest width m on the edge ξ^k = const,
//! whose potential is −λ m ∫ θ ds, θ the rotation of the deformed tangent a_k (across the edge)
//! from the rest tangent towards the rest normal, in the plane of the two:
//! θ = atan2(a_k·N, a_k·T), T = X,k/|X,k|, N the rest normal. The residual and the tangent are
//! its exact first and second derivatives through the MLS shape functions, so the Newton
//! tangent stays exact (and symmetric). A pure-bending rig loads a strip with it: under a
//! uniform moment the strip's curvature is uniform.

use faer::sparse::Triplet;

use super::discretisation::Discretisation;
use super::error::ShellError;
use super::problem::{gauss_legendre, EDGE_NAMES};
use super::surface::V3;

/// One Gauss point of an edge moment.
#[derive(Debug, Clone, PartialEq)]
pub struct MomentPoint {
    /// Nodes whose support holds the point.
    pub nodes: Vec<usize>,
    /// φ_J,k of those nodes (derivative across the edge).
    pub slope: Vec<f64>,
    /// Rest tangent X,k.
    pub rest_tangent: V3,
    /// Unit rest tangent T.
    pub t: V3,
    /// Unit rest normal N.
    pub n: V3,
    /// Moment per width × line weight (N·m at load factor 1); 0 for a point that only reads.
    pub weight: f64,
    /// Line weight (m) of the point on its edge.
    pub line: f64,
    /// The edge (index into [`EDGE_NAMES`]).
    pub edge: usize,
}

impl MomentPoint {
    /// (p, q) = (a·T, a·N) of the deformed tangent a at `u`.
    fn components(&self, u: &[f64]) -> (f64, f64) {
        let mut a = self.rest_tangent;
        for (&j, &s) in self.nodes.iter().zip(&self.slope) {
            a += V3::new(u[3 * j], u[3 * j + 1], u[3 * j + 2]) * s;
        }
        (a.dot(&self.t), a.dot(&self.n))
    }
}

impl Discretisation {
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
        let (mut sum, mut len) = (0.0, 0.0);
        for m in &pts {
            let (p, q) = m.components(u);
            sum += m.line * q.atan2(p);
            len += m.line;
        }
        Ok(sum / len)
    }

    /// The norm of the external load vector at load factor 1 (area and point loads and edge
    /// moments at rest): the scale of Newton's relative residual.
    pub fn external_load_norm(&self) -> f64 {
        let mut f: Vec<f64> = self.terms.iter().flat_map(|t| t.load).collect();
        let u = vec![0.0; f.len()];
        let mut r = vec![0.0; f.len()];
        add_moment_residual(self, &u, 1.0, &mut r);
        for (a, b) in f.iter_mut().zip(&r) {
            *a -= b;
        }
        f.iter().map(|x| x * x).sum::<f64>().sqrt()
    }
}

/// Adds the edge moments' share of the residual at load factor `lambda`: −λ w ∂θ/∂u.
pub fn add_moment_residual(disc: &Discretisation, u: &[f64], lambda: f64, res: &mut [f64]) {
    for m in &disc.moments {
        let (p, q) = m.components(u);
        let rho2 = p * p + q * q;
        let g = (m.t * (-q) + m.n * p) / rho2;
        for (&j, &s) in m.nodes.iter().zip(&m.slope) {
            for c in 0..3 {
                res[3 * j + c] -= lambda * m.weight * s * g[c];
            }
        }
    }
}

/// Adds the edge moments' share of the tangent at load factor `lambda`: −λ w ∂²θ/∂u², as
/// triplets (the same entries on every call, so the sparsity pattern does not change).
pub fn add_moment_tangent(
    disc: &Discretisation,
    u: &[f64],
    lambda: f64,
    trip: &mut Vec<Triplet<usize, usize, f64>>,
) {
    for m in &disc.moments {
        let (p, q) = m.components(u);
        let rho4 = (p * p + q * q).powi(2);
        let (hpp, hpq, hqq) = (
            2.0 * p * q / rho4,
            (q * q - p * p) / rho4,
            -2.0 * p * q / rho4,
        );
        let (t, n) = (m.t, m.n);
        let mut h = [[0.0; 3]; 3];
        for (c, row) in h.iter_mut().enumerate() {
            for (d, v) in row.iter_mut().enumerate() {
                *v = hpp * t[c] * t[d] + hpq * (t[c] * n[d] + n[c] * t[d]) + hqq * n[c] * n[d];
            }
        }
        for (&j, &sj) in m.nodes.iter().zip(&m.slope) {
            for (&k, &sk) in m.nodes.iter().zip(&m.slope) {
                let f = -lambda * m.weight * sj * sk;
                for (c, row) in h.iter().enumerate() {
                    for (d, v) in row.iter().enumerate() {
                        trip.push(Triplet::new(3 * j + c, 3 * k + d, f * v));
                    }
                }
            }
        }
    }
}
