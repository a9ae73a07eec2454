//! The MLPG residual and its tangent. Node I's three equations are the local weak form on its
//! sub-domain with the test function v_I eᵢ:
//! R_I = ∫_{Ω_I} ∂W/∂(a_α, a_αβ) · (v_I,α eᵢ, v_I,αβ eᵢ) dA + (penalty terms) − λ f_I,
//! (internal virtual work of the local strain energy density W, see
//! [`super::kinematics`]), no boundary integral on the circle ∂Ω_I because v_I and its
//! derivatives vanish there; the tangent is the exact derivative (the Hessian of W through the
//! MLS trial functions). Rows are built per node in parallel and joined in node order
//! (deterministic).

use faer::sparse::{SparseColMat, Triplet};
use rayon::prelude::*;

use super::discretisation::{Discretisation, NodeTerms};
use super::error::ShellError;
use super::jet::NV;
use super::kinematics::{energy_density, rest_locals};

/// One node's residual (3) and, if asked, its row blocks (3×3 per column, row-major).
fn node_rows(
    t: &NodeTerms,
    disc: &Discretisation,
    u: &[f64],
    lambda: f64,
    tangent: bool,
) -> ([f64; 3], Vec<[f64; 9]>) {
    let mat = &disc.problem.material;
    let mut r = [0.0; 3];
    let mut k = if tangent { vec![[0.0; 9]; t.columns.len()] } else { Vec::new() };
    for q in &t.quad {
        let mut l = rest_locals(&q.rest);
        for (jj, &j) in q.nodes.iter().enumerate() {
            let phi = &q.values[jj];
            for slot in 0..5 {
                for c in 0..3 {
                    l[3 * slot + c] += phi[slot + 1] * u[3 * j + c];
                }
            }
        }
        let w = energy_density(&l, &q.rest, mat);
        for c in 0..3 {
            let mut s = 0.0;
            for p in 0..5 {
                s += q.test[p + 1] * w.g[3 * p + c];
            }
            r[c] += q.weight * s;
        }
        if tangent {
            // m[c][col] = weight Σ_p v_p H[3p + c][col]
            let mut m = [[0.0; NV]; 3];
            for c in 0..3 {
                for col in 0..NV {
                    let mut s = 0.0;
                    for p in 0..5 {
                        s += q.test[p + 1] * w.h[3 * p + c][col];
                    }
                    m[c][col] = q.weight * s;
                }
            }
            for (jj, &slot) in q.slots.iter().enumerate() {
                let phi = &q.values[jj];
                let b = &mut k[slot];
                for c in 0..3 {
                    for d in 0..3 {
                        let mut s = 0.0;
                        for qq in 0..5 {
                            s += phi[qq + 1] * m[c][3 * qq + d];
                        }
                        b[3 * c + d] += s;
                    }
                }
            }
        }
    }
    for (s, &j) in t.columns.iter().enumerate() {
        let p = &t.penalty[s];
        for c in 0..3 {
            for d in 0..3 {
                r[c] += p[3 * c + d] * u[3 * j + d];
            }
        }
        if tangent {
            for e in 0..9 {
                k[s][e] += p[e];
            }
        }
    }
    for c in 0..3 {
        r[c] -= lambda * t.load[c];
    }
    (r, k)
}

/// The residual at load factor `lambda` (length 3 × nodes).
pub fn residual(disc: &Discretisation, u: &[f64], lambda: f64) -> Vec<f64> {
    let rows: Vec<[f64; 3]> = disc
        .terms
        .par_iter()
        .map(|t| node_rows(t, disc, u, lambda, false).0)
        .collect();
    rows.concat()
}

/// The residual and the tangent matrix (sparse, column-compressed) at load factor `lambda`.
pub fn residual_and_tangent(
    disc: &Discretisation,
    u: &[f64],
    lambda: f64,
) -> Result<(Vec<f64>, SparseColMat<usize, f64>), ShellError> {
    let rows: Vec<([f64; 3], Vec<[f64; 9]>)> = disc
        .terms
        .par_iter()
        .map(|t| node_rows(t, disc, u, lambda, true))
        .collect();
    let n = 3 * disc.len();
    let nnz: usize = rows.iter().map(|r| r.1.len() * 9).sum();
    crate::limits::check_alloc("shell tangent entries", nnz as u64, 24)?;
    let mut trip = Vec::with_capacity(nnz);
    let mut res = Vec::with_capacity(n);
    for (i, (r, k)) in rows.iter().enumerate() {
        res.extend_from_slice(r);
        for (s, &j) in disc.terms[i].columns.iter().enumerate() {
            for c in 0..3 {
                for d in 0..3 {
                    trip.push(Triplet::new(3 * i + c, 3 * j + d, k[s][3 * c + d]));
                }
            }
        }
    }
    let mat = SparseColMat::try_new_from_triplets(n, n, &trip)
        .map_err(|e| ShellError::Solver(format!("tangent matrix: {e:?}")))?;
    Ok((res, mat))
}
