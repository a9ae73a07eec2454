//! Moments along an edge: a conservative couple per unit rest width m on the edge ξ^k = const,
//! whose potential is −λ m ∫ θ ds, θ the rotation of the deformed tangent a_k (across the edge)
//! from the rest tangent towards the rest normal, in the plane of the two:
//! θ = atan2(a_k·N, a_k·T), T = X,k/|X,k|, N the rest normal. The residual and the tangent are
//! its exact first and second derivatives through the MLS shape functions, so the Newton
//! tangent stays exact (and symmetric). The points are built by
//! [`super::discretisation::Discretisation::add_edge_moment`]. A pure-bending rig loads a strip with it: under a
//! uniform moment the strip's curvature is uniform.

use faer::sparse::Triplet;

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
    /// The edge (index into [`super::problem::EDGE_NAMES`]).
    pub edge: usize,
}

impl MomentPoint {
    /// (p, q) = (a·T, a·N) of the deformed tangent a at `u`.
    pub fn components(&self, u: &[f64]) -> (f64, f64) {
        let mut a = self.rest_tangent;
        for (&j, &s) in self.nodes.iter().zip(&self.slope) {
            a += V3::new(u[3 * j], u[3 * j + 1], u[3 * j + 2]) * s;
        }
        (a.dot(&self.t), a.dot(&self.n))
    }
}

/// The mean rotation θ (rad) over `points` (weighted by their line weights).
pub fn mean_rotation(points: &[MomentPoint], u: &[f64]) -> f64 {
    let (mut sum, mut len) = (0.0, 0.0);
    for m in points {
        let (p, q) = m.components(u);
        sum += m.line * q.atan2(p);
        len += m.line;
    }
    sum / len
}

/// Adds the edge moments' share of the residual at load factor `lambda`: −λ w ∂θ/∂u.
pub fn add_moment_residual(moments: &[MomentPoint], u: &[f64], lambda: f64, res: &mut [f64]) {
    for m in moments {
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
    moments: &[MomentPoint],
    u: &[f64],
    lambda: f64,
    trip: &mut Vec<Triplet<usize, usize, f64>>,
) {
    for m in moments {
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
