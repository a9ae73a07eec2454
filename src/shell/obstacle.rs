//! Contact of the shell with a rigid sphere by a penalty on the background quadrature points:
//! the energy ∫ ½ k ⟨r + δ − |x − c|⟩₊² dA over the rest surface, x = X + Σ φ_J u_J the deformed
//! mid-surface, so the contact pressure k·gap is integrated like any other load and does not
//! depend on where the sample points lie. No friction. Residual and exact tangent (the normal
//! stiffness k n nᵀ and the geometric term −k g/d (I − n nᵀ)) are added in place; the tangent's
//! blocks fall on node pairs that share a quadrature point, which the discretisation's sparsity
//! pattern already holds.

use faer::sparse::Triplet;
use rayon::prelude::*;

use super::assembly::Entry;
use super::discretisation::{Discretisation, QuadPoint};
use super::error::ShellError;
use super::surface::V3;

/// A rigid sphere the shell cannot enter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereObstacle {
    /// Centre (m).
    pub centre: [f64; 3],
    /// Radius (m).
    pub radius: f64,
    /// Contact distance δ kept from the surface (m): the cloth's half thickness.
    pub distance: f64,
    /// Penalty stiffness k per unit area (N/m³).
    pub stiffness: f64,
}

impl SphereObstacle {
    /// Checks the fields (finite; radius, stiffness > 0; distance ≥ 0); the message names the
    /// field.
    pub fn validate(&self) -> Result<(), ShellError> {
        let ok = self.centre.iter().all(|c| c.is_finite())
            && self.radius.is_finite()
            && self.radius > 0.0
            && self.distance.is_finite()
            && self.distance >= 0.0
            && self.stiffness.is_finite()
            && self.stiffness > 0.0;
        if ok {
            Ok(())
        } else {
            Err(ShellError::Invalid(format!(
                "sphere obstacle needs a finite centre, radius > 0, distance >= 0 and stiffness > 0, got {self:?}"
            )))
        }
    }

    /// The deformed position of a quadrature point.
    fn position(q: &QuadPoint, u: &[f64]) -> V3 {
        let mut x = q.rest.point.x;
        for (jj, &j) in q.nodes.iter().enumerate() {
            let phi = q.values[jj][0];
            x += V3::new(u[3 * j], u[3 * j + 1], u[3 * j + 2]) * phi;
        }
        x
    }

    /// (gap g > 0 when inside, unit normal n, distance d from the centre) at a point, or None
    /// when it is clear of the sphere.
    fn penetration(&self, x: &V3) -> Option<(f64, V3, f64)> {
        let c = V3::new(self.centre[0], self.centre[1], self.centre[2]);
        let r = x - c;
        let d = r.norm();
        let g = self.radius + self.distance - d;
        (g > 0.0 && d > 1e-12 * self.radius).then(|| (g, r / d, d))
    }

    /// Adds the penalty's residual to `res` (3 per node) and, with `trip`, its tangent: one
    /// 3×3 block per node pair that shares a point in contact, summed per node row (in
    /// parallel, joined in node order) so that a cloth lying on the sphere does not produce
    /// a triplet per point and pair.
    pub fn add_terms(
        &self,
        disc: &Discretisation,
        u: &[f64],
        res: &mut [f64],
        trip: Option<&mut Vec<Entry>>,
    ) {
        // per quadrature point: the weighted force gradient ∂E/∂x and Hessian ∂²E/∂x², where
        // in contact
        let local: Vec<Option<(V3, [f64; 9])>> = disc
            .quad
            .par_iter()
            .map(|q| {
                let (g, n, d) = self.penetration(&Self::position(q, u))?;
                let k = self.stiffness * q.weight;
                // ∂²E/∂x² = k n nᵀ − k g/d (I − n nᵀ)
                let geo = k * g / d;
                let mut h = [0.0; 9];
                for a in 0..3 {
                    for b in 0..3 {
                        let eye = if a == b { 1.0 } else { 0.0 };
                        h[3 * a + b] = k * n[a] * n[b] - geo * (eye - n[a] * n[b]);
                    }
                }
                Some((n * (-k * g), h))
            })
            .collect();
        for (q, l) in disc.quad.iter().zip(&local) {
            let Some((grad, _)) = l else { continue };
            for (jj, &j) in q.nodes.iter().enumerate() {
                let phi = q.values[jj][0];
                for c in 0..3 {
                    res[3 * j + c] += phi * grad[c];
                }
            }
        }
        let Some(trip) = trip else { return };
        let rows: Vec<Vec<Entry>> = disc
            .terms
            .par_iter()
            .enumerate()
            .map(|(j, t)| {
                let mut blocks: Vec<Option<[f64; 9]>> = vec![None; t.columns.len()];
                for &(qi, a) in &t.quad {
                    let Some((_, h)) = &local[qi] else { continue };
                    let q = &disc.quad[qi];
                    let pj = q.values[a][0];
                    let mut slot = 0;
                    for (kb, &l) in q.nodes.iter().enumerate() {
                        while t.columns[slot] < l {
                            slot += 1;
                        }
                        let s = pj * q.values[kb][0];
                        let b = blocks[slot].get_or_insert([0.0; 9]);
                        for e in 0..9 {
                            b[e] += s * h[e];
                        }
                    }
                }
                let mut out = Vec::new();
                for (slot, b) in blocks.iter().enumerate() {
                    let Some(b) = b else { continue };
                    let l = t.columns[slot];
                    for a in 0..3 {
                        for c in 0..3 {
                            out.push(Triplet::new(3 * j + a, 3 * l + c, b[3 * a + c]));
                        }
                    }
                }
                out
            })
            .collect();
        for r in rows {
            trip.extend(r);
        }
    }

    /// The largest penetration of the deformed quadrature points into the sphere grown by the
    /// contact distance (m; 0 when none is inside).
    pub fn max_penetration(&self, disc: &Discretisation, u: &[f64]) -> f64 {
        disc.quad
            .iter()
            .filter_map(|q| self.penetration(&Self::position(q, u)).map(|p| p.0))
            .fold(0.0, f64::max)
    }
}
