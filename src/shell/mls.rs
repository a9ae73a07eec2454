//! Moving-least-squares (MLS) shape functions on scattered points of the rest parameter plane,
//! with their first and second derivatives (full derivatives, not the "diffuse" ones): the C¹
//! approximation Kirchhoff–Love bending needs.
//!
//! At a point x the approximation is u(x) = Σ_I φ_I(x) u_I with φ_I(x) = w_I(x) p(x)ᵀ A(x)⁻¹ p(x_I),
//! A(x) = Σ_I w_I(x) p(x_I) p(x_I)ᵀ, p the polynomial basis (quadratic: 6 terms, cubic: 10) taken
//! about x and scaled by the support radius (the same space, so the same φ, but a well-scaled A),
//! and w_I(x) = (1 − |x − x_I|²/R_I²)⁴ inside the support radius R_I of node I, 0 outside: a
//! compactly supported weight that is C³ at the edge of its support and smooth inside.
//! Derivatives: γ = A⁻¹p, γ,ₓ = A⁻¹(p,ₓ − A,ₓγ), γ,ₓᵧ = A⁻¹(p,ₓᵧ − A,ₓγ,ᵧ − A,ᵧγ,ₓ − A,ₓᵧγ).

use nalgebra::{DMatrix, DVector};

use super::error::ShellError;

/// The polynomial basis of the MLS fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Basis {
    /// 1, x, y, x², xy, y² (reproduces quadratic fields).
    Quadratic,
    /// The quadratic terms and x³, x²y, xy², y³ (reproduces cubic fields).
    Cubic,
}

impl Basis {
    /// Number of terms.
    pub fn size(self) -> usize {
        match self {
            Basis::Quadratic => 6,
            Basis::Cubic => 10,
        }
    }

    /// The basis at the (scaled) offset (u, v).
    fn eval(self, u: f64, v: f64, out: &mut [f64]) {
        out[0] = 1.0;
        out[1] = u;
        out[2] = v;
        out[3] = u * u;
        out[4] = u * v;
        out[5] = v * v;
        if self == Basis::Cubic {
            out[6] = u * u * u;
            out[7] = u * u * v;
            out[8] = u * v * v;
            out[9] = v * v * v;
        }
    }
}

/// The weight (1 − q)⁴, q = |d|²/R², and its derivatives with respect to the evaluation point x
/// (d = x − x_I): `[w, w,x, w,y, w,xx, w,xy, w,yy]`; all zero outside the support.
pub fn bump(d: [f64; 2], r: f64) -> [f64; 6] {
    let r2 = r * r;
    let q = (d[0] * d[0] + d[1] * d[1]) / r2;
    if q >= 1.0 {
        return [0.0; 6];
    }
    let m = 1.0 - q;
    let (m2, m3) = (m * m, m * m * m);
    let qx = 2.0 * d[0] / r2;
    let qy = 2.0 * d[1] / r2;
    let qxx = 2.0 / r2;
    [
        m2 * m2,
        -4.0 * m3 * qx,
        -4.0 * m3 * qy,
        12.0 * m2 * qx * qx - 4.0 * m3 * qxx,
        12.0 * m2 * qx * qy,
        12.0 * m2 * qy * qy - 4.0 * m3 * qxx,
    ]
}

/// Shape functions at one point: the neighbours and, for each, `[φ, φ,x, φ,y, φ,xx, φ,xy, φ,yy]`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ShapeValues {
    /// Node ids whose support holds the point, ascending.
    pub nodes: Vec<usize>,
    /// Value and derivatives per node, in the order of `nodes`.
    pub values: Vec<[f64; 6]>,
}

/// Evaluates the MLS shape functions at `x` over the candidate `nodes` (ids into `points`, with
/// support radii `radius`): those whose support holds `x` are kept. `what` names the point in
/// errors (too few neighbours for the basis, a singular moment matrix).
pub fn shape_functions(
    x: [f64; 2],
    points: &[[f64; 2]],
    radius: &[f64],
    nodes: &[usize],
    basis: Basis,
    what: &dyn Fn() -> String,
) -> Result<ShapeValues, ShellError> {
    let m = basis.size();
    let fail = |reason: String| ShellError::ShapeFunctions {
        what: what(),
        x: x[0],
        y: x[1],
        reason,
    };
    let mut kept = Vec::with_capacity(nodes.len());
    let mut weights = Vec::with_capacity(nodes.len());
    let mut scale = 0.0f64;
    for &i in nodes {
        let d = [x[0] - points[i][0], x[1] - points[i][1]];
        let w = bump(d, radius[i]);
        if w[0] > 0.0 {
            kept.push(i);
            weights.push(w);
            scale = scale.max(radius[i]);
        }
    }
    if kept.len() < m {
        return Err(fail(format!(
            "{} neighbours within their supports, the {:?} basis needs at least {m} (raise the support factor or sample more densely)",
            kept.len(),
            basis
        )));
    }
    // A and its derivatives, basis about x scaled by `scale`
    let mut a = [
        DMatrix::zeros(m, m),
        DMatrix::zeros(m, m),
        DMatrix::zeros(m, m),
    ];
    let mut a2 = [
        DMatrix::zeros(m, m),
        DMatrix::zeros(m, m),
        DMatrix::zeros(m, m),
    ];
    let mut ps = Vec::with_capacity(kept.len());
    let mut p = vec![0.0; m];
    for (k, &i) in kept.iter().enumerate() {
        basis.eval(
            (points[i][0] - x[0]) / scale,
            (points[i][1] - x[1]) / scale,
            &mut p,
        );
        let pp = DVector::from_column_slice(&p);
        let outer = &pp * pp.transpose();
        let w = weights[k];
        a[0] += &outer * w[0];
        a[1] += &outer * w[1];
        a[2] += &outer * w[2];
        a2[0] += &outer * w[3];
        a2[1] += &outer * w[4];
        a2[2] += &outer * w[5];
        ps.push(pp);
    }
    let eig = a[0].clone().symmetric_eigen();
    let (lo, hi) = eig
        .eigenvalues
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &e| {
            (l.min(e), h.max(e.abs()))
        });
    if lo.is_nan() || hi.is_nan() || lo <= 1e-12 * hi {
        return Err(fail(format!(
            "singular moment matrix (eigenvalue ratio {:.3e}; {} neighbours, likely on a line or too few for the {:?} basis)",
            lo / hi.max(f64::MIN_POSITIVE),
            kept.len(),
            basis
        )));
    }
    let chol = a[0]
        .clone()
        .cholesky()
        .ok_or_else(|| fail("moment matrix not positive definite".into()))?;
    let mut px = DVector::zeros(m);
    let mut py = DVector::zeros(m);
    let mut pxx = DVector::zeros(m);
    let mut pxy = DVector::zeros(m);
    let mut pyy = DVector::zeros(m);
    let mut p0 = DVector::zeros(m);
    p0[0] = 1.0;
    px[1] = 1.0 / scale;
    py[2] = 1.0 / scale;
    pxx[3] = 2.0 / (scale * scale);
    pxy[4] = 1.0 / (scale * scale);
    pyy[5] = 2.0 / (scale * scale);
    let g = chol.solve(&p0);
    let gx = chol.solve(&(&px - &a[1] * &g));
    let gy = chol.solve(&(&py - &a[2] * &g));
    let gxx = chol.solve(&(&pxx - &a[1] * &gx * 2.0 - &a2[0] * &g));
    let gyy = chol.solve(&(&pyy - &a[2] * &gy * 2.0 - &a2[2] * &g));
    let gxy = chol.solve(&(&pxy - &a[1] * &gy - &a[2] * &gx - &a2[1] * &g));
    let mut values = Vec::with_capacity(kept.len());
    for (k, pi) in ps.iter().enumerate() {
        let w = weights[k];
        let (c, cx, cy) = (g.dot(pi), gx.dot(pi), gy.dot(pi));
        let (cxx, cxy, cyy) = (gxx.dot(pi), gxy.dot(pi), gyy.dot(pi));
        values.push([
            w[0] * c,
            w[1] * c + w[0] * cx,
            w[2] * c + w[0] * cy,
            w[3] * c + 2.0 * w[1] * cx + w[0] * cxx,
            w[4] * c + w[1] * cy + w[2] * cx + w[0] * cxy,
            w[5] * c + 2.0 * w[2] * cy + w[0] * cyy,
        ]);
    }
    Ok(ShapeValues {
        nodes: kept,
        values,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scattered(n: usize) -> (Vec<[f64; 2]>, Vec<f64>) {
        // a jittered grid on [0, 1]², deterministic
        let h = 1.0 / (n - 1) as f64;
        let mut pts = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let jx = ((i * 7 + j * 13) % 11) as f64 / 11.0 - 0.5;
                let jy = ((i * 5 + j * 3) % 7) as f64 / 7.0 - 0.5;
                pts.push([i as f64 * h + 0.3 * h * jx, j as f64 * h + 0.3 * h * jy]);
            }
        }
        let r = vec![3.2 * h; pts.len()];
        (pts, r)
    }

    fn check_reproduction(basis: Basis, f: &dyn Fn(f64, f64) -> [f64; 6]) {
        let (pts, r) = scattered(9);
        let all: Vec<usize> = (0..pts.len()).collect();
        for x in [[0.5, 0.5], [0.13, 0.71], [0.0, 0.0], [0.97, 0.41]] {
            let s = shape_functions(x, &pts, &r, &all, basis, &|| "test".into()).unwrap();
            let mut sum = [0.0; 6];
            for (k, &i) in s.nodes.iter().enumerate() {
                let fi = f(pts[i][0], pts[i][1])[0];
                for d in 0..6 {
                    sum[d] += s.values[k][d] * fi;
                }
            }
            let exact = f(x[0], x[1]);
            for d in 0..6 {
                assert!(
                    (sum[d] - exact[d]).abs() < 1e-9,
                    "{basis:?} at {x:?}, derivative {d}: {} vs {}",
                    sum[d],
                    exact[d]
                );
            }
        }
    }

    #[test]
    fn quadratic_basis_reproduces_quadratic_fields_and_derivatives() {
        // f = 1 + 2x − 3y + 0.5x² − 1.5xy + 2.5y², with its derivatives
        check_reproduction(Basis::Quadratic, &|x, y| {
            [
                1.0 + 2.0 * x - 3.0 * y + 0.5 * x * x - 1.5 * x * y + 2.5 * y * y,
                2.0 + x - 1.5 * y,
                -3.0 - 1.5 * x + 5.0 * y,
                1.0,
                -1.5,
                5.0,
            ]
        });
    }

    #[test]
    fn cubic_basis_reproduces_cubic_fields_and_derivatives() {
        check_reproduction(Basis::Cubic, &|x, y| {
            [
                x * x * x - 2.0 * x * x * y + 0.5 * y * y * y + x,
                3.0 * x * x - 4.0 * x * y + 1.0,
                -2.0 * x * x + 1.5 * y * y,
                6.0 * x - 4.0 * y,
                -4.0 * x,
                3.0 * y,
            ]
        });
    }

    #[test]
    fn too_few_neighbours_is_an_error_naming_the_point() {
        let pts = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let r = vec![2.0; 3];
        let e = shape_functions([0.2, 0.2], &pts, &r, &[0, 1, 2], Basis::Quadratic, &|| {
            "node 7".into()
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("node 7") && e.contains("3 neighbours"), "{e}");
    }

    #[test]
    fn collinear_points_give_a_singular_moment_matrix_error() {
        let pts: Vec<[f64; 2]> = (0..10).map(|i| [i as f64 * 0.1, 0.0]).collect();
        let r = vec![1.0; 10];
        let all: Vec<usize> = (0..10).collect();
        let e = shape_functions([0.45, 0.0], &pts, &r, &all, Basis::Quadratic, &|| {
            "node 3".into()
        })
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("singular moment matrix") && e.contains("node 3"),
            "{e}"
        );
    }
}
