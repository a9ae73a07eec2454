//! The residual and its tangent of the Galerkin weak form: node J's three rows are
//! R_J = ∫ ∂W/∂(a_α, a_αβ) · (φ_J,α eᵢ, φ_J,αβ eᵢ) dA + (penalty terms) − λ f_J, the internal
//! virtual work of the strain energy density W ([`super::kinematics`]) through the MLS shape
//! functions, and the tangent is its exact derivative (the Hessian of W, symmetric). The energy
//! jets are computed once per background point in parallel; rows are built per node in
//! parallel and joined in node order (deterministic).

use faer::sparse::{SparseColMat, Triplet};
use rayon::prelude::*;

use super::discretisation::{Discretisation, NodeTerms};
use super::error::ShellError;
use super::jet::NV;
use super::kinematics::{energy_density_law, rest_locals};
use super::moment::{add_moment_residual, add_moment_tangent};

/// One entry of the tangent (row, column, value).
pub type Entry = Triplet<usize, usize, f64>;

/// The weighted gradient and Hessian of the energy at one background point.
type PointJet = ([f64; NV], Box<[[f64; NV]; NV]>);

/// Weighted gradient and Hessian of the energy at every background point.
fn point_jets(disc: &Discretisation, u: &[f64], tangent: bool) -> Vec<PointJet> {
    let mat = &disc.problem.material;
    let law = disc.law.as_ref();
    disc.quad
        .par_iter()
        .map(|q| {
            let mut l = rest_locals(&q.rest);
            for (jj, &j) in q.nodes.iter().enumerate() {
                let phi = &q.values[jj];
                for slot in 0..5 {
                    for c in 0..3 {
                        l[3 * slot + c] += phi[slot + 1] * u[3 * j + c];
                    }
                }
            }
            let w = energy_density_law(&l, &q.rest, mat, law);
            let g = w.g.map(|x| x * q.weight);
            let mut h = Box::new([[0.0; NV]; NV]);
            if tangent {
                for a in 0..NV {
                    for b in 0..NV {
                        h[a][b] = w.h[a][b] * q.weight;
                    }
                }
            }
            (g, h)
        })
        .collect()
}

/// One node's residual (3) and, if asked, its row blocks (3×3 per column, row-major).
fn node_rows(
    t: &NodeTerms,
    disc: &Discretisation,
    jets: &[PointJet],
    u: &[f64],
    lambda: f64,
    tangent: bool,
) -> ([f64; 3], Vec<[f64; 9]>) {
    let mut r = [0.0; 3];
    let mut k = if tangent {
        vec![[0.0; 9]; t.columns.len()]
    } else {
        Vec::new()
    };
    for &(qi, a) in &t.quad {
        let q = &disc.quad[qi];
        let test = &q.values[a];
        let (g, h) = &jets[qi];
        for c in 0..3 {
            let mut s = 0.0;
            for p in 0..5 {
                s += test[p + 1] * g[3 * p + c];
            }
            r[c] += s;
        }
        if tangent {
            // m[c][col] = Σ_p φ_J,p H[3p + c][col]
            let mut m = [[0.0; NV]; 3];
            for c in 0..3 {
                for col in 0..NV {
                    let mut s = 0.0;
                    for p in 0..5 {
                        s += test[p + 1] * h[3 * p + c][col];
                    }
                    m[c][col] = s;
                }
            }
            let mut slot = 0;
            for (jj, &j) in q.nodes.iter().enumerate() {
                while t.columns[slot] < j {
                    slot += 1;
                }
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
    let jets = point_jets(disc, u, false);
    let rows: Vec<[f64; 3]> = disc
        .terms
        .par_iter()
        .map(|t| node_rows(t, disc, &jets, u, lambda, false).0)
        .collect();
    let mut res = rows.concat();
    add_moment_residual(&disc.moments, u, lambda, &mut res);
    res
}

/// The residual and the tangent matrix (sparse, column-compressed) at load factor `lambda`.
pub fn residual_and_tangent(
    disc: &Discretisation,
    u: &[f64],
    lambda: f64,
) -> Result<(Vec<f64>, SparseColMat<usize, f64>), ShellError> {
    let (res, trip) = residual_and_triplets(disc, u, lambda)?;
    Ok((res, tangent_matrix(disc, &trip)?))
}

/// The residual and the tangent's entries (duplicates summed by [`tangent_matrix`]), for
/// callers that add terms of their own (contact, inertia) before the matrix is built. Every
/// node's columns appear, zeros included, so the pattern does not depend on `u`.
pub fn residual_and_triplets(
    disc: &Discretisation,
    u: &[f64],
    lambda: f64,
) -> Result<(Vec<f64>, Vec<Entry>), ShellError> {
    let jets = point_jets(disc, u, true);
    let rows: Vec<([f64; 3], Vec<[f64; 9]>)> = disc
        .terms
        .par_iter()
        .map(|t| node_rows(t, disc, &jets, u, lambda, true))
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
    add_moment_residual(&disc.moments, u, lambda, &mut res);
    add_moment_tangent(&disc.moments, u, lambda, &mut trip);
    Ok((res, trip))
}

/// The tangent matrix from its entries (duplicates summed).
pub fn tangent_matrix(
    disc: &Discretisation,
    trip: &[Entry],
) -> Result<SparseColMat<usize, f64>, ShellError> {
    let n = 3 * disc.len();
    SparseColMat::try_new_from_triplets(n, n, trip)
        .map_err(|e| ShellError::Solver(format!("tangent matrix: {e:?}")))
}
