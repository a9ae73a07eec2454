//! Linear camera resection: the normalised Direct Linear Transform from 3D–2D correspondences
//! (Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., alg. 7.1) and the RQ
//! decomposition of the projection matrix into intrinsics and pose — the starting point that
//! [`super::calibration`] refines.

use nalgebra::{DMatrix, Matrix3, Matrix3x4, Matrix4, Vector3};

use super::correspondences::{check_inputs, check_spread, CalibrationError};

/// `(K, R, t)` from [`decompose_projection`].
pub type KRt = (Matrix3<f64>, Matrix3<f64>, Vector3<f64>);

/// Similarity normalising 2D points: centroid to the origin, mean distance √2.
fn normalize_2d(pixels: &[[f64; 2]]) -> Result<Matrix3<f64>, CalibrationError> {
    let n = pixels.len() as f64;
    let (mx, my) = pixels
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p[0] / n, b + p[1] / n));
    let mean_d = pixels
        .iter()
        .map(|p| ((p[0] - mx).powi(2) + (p[1] - my).powi(2)).sqrt())
        .sum::<f64>()
        / n;
    if !(mean_d > 0.0 && mean_d.is_finite()) {
        return Err(CalibrationError::Degenerate(
            "all pixel observations coincide".into(),
        ));
    }
    let s = std::f64::consts::SQRT_2 / mean_d;
    Ok(Matrix3::new(
        s,
        0.0,
        -s * mx,
        0.0,
        s,
        -s * my,
        0.0,
        0.0,
        1.0,
    ))
}

/// Similarity normalising 3D points: centroid to the origin, mean distance √3.
fn normalize_3d(points: &[Vector3<f64>]) -> Result<Matrix4<f64>, CalibrationError> {
    let n = points.len() as f64;
    let mean = points.iter().sum::<Vector3<f64>>() / n;
    let mean_d = points.iter().map(|p| (p - mean).norm()).sum::<f64>() / n;
    if !(mean_d > 0.0 && mean_d.is_finite()) {
        return Err(CalibrationError::DegeneratePoints {
            shape: "coincident",
            ratio_2: 0.0,
            ratio_3: 0.0,
        });
    }
    let s = 3f64.sqrt() / mean_d;
    let mut t = Matrix4::identity() * s;
    t[(3, 3)] = 1.0;
    for i in 0..3 {
        t[(i, 3)] = -s * mean[i];
    }
    Ok(t)
}

/// Normalised DLT (Hartley & Zisserman alg. 7.1): the 3×4 projection matrix mapping the points
/// to the pixels, up to scale, with unit Frobenius norm and the sign chosen so that the points
/// have positive depth. Distortion is ignored. Needs ≥ 6 finite, non-coplanar points.
pub fn dlt(
    points: &[Vector3<f64>],
    pixels: &[[f64; 2]],
) -> Result<Matrix3x4<f64>, CalibrationError> {
    check_inputs(points, pixels)?;
    check_spread(points)?;
    let t2 = normalize_2d(pixels)?;
    let t3 = normalize_3d(points)?;
    let n = points.len();
    let mut a = DMatrix::<f64>::zeros(2 * n, 12);
    for (i, (p, uv)) in points.iter().zip(pixels).enumerate() {
        let x = t3 * p.push(1.0);
        let u = t2 * Vector3::new(uv[0], uv[1], 1.0);
        let (uu, vv, ww) = (u.x, u.y, u.z);
        for j in 0..4 {
            // row 2i:   [0ᵀ, −w Xᵀ, v Xᵀ]
            a[(2 * i, 4 + j)] = -ww * x[j];
            a[(2 * i, 8 + j)] = vv * x[j];
            // row 2i+1: [w Xᵀ, 0ᵀ, −u Xᵀ]
            a[(2 * i + 1, j)] = ww * x[j];
            a[(2 * i + 1, 8 + j)] = -uu * x[j];
        }
    }
    let svd = a.svd(false, true);
    let v_t = svd
        .v_t
        .as_ref()
        .ok_or_else(|| CalibrationError::Degenerate("SVD of the DLT system failed".into()))?;
    let sv = &svd.singular_values;
    let (imin, _) = sv
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .ok_or_else(|| CalibrationError::Degenerate("empty DLT system".into()))?;
    // a second (near) null vector means the solution is not unique
    let smax = sv.max();
    let second = sv
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != imin)
        .map(|(_, v)| *v)
        .fold(f64::INFINITY, f64::min);
    if second.is_nan() || second <= 1e-10 * smax {
        return Err(CalibrationError::Degenerate(
            "the DLT system has more than one solution (critical configuration)".into(),
        ));
    }
    let h = v_t.row(imin);
    let pn = Matrix3x4::from_fn(|r, c| h[4 * r + c]);
    let t2_inv = t2
        .try_inverse()
        .ok_or_else(|| CalibrationError::Degenerate("pixel normalisation not invertible".into()))?;
    let mut p = t2_inv * pn * t3;
    let norm = p.norm();
    if !(norm > 0.0 && norm.is_finite()) {
        return Err(CalibrationError::Degenerate(
            "DLT gave a null projection matrix".into(),
        ));
    }
    p /= norm;
    // sign: points in front have w = P₃·X > 0
    let positive = points
        .iter()
        .filter(|x| (p.row(2) * x.push(1.0))[0] > 0.0)
        .count();
    if 2 * positive < n {
        p = -p;
    }
    Ok(p)
}

/// Splits a projection matrix into `(K, R, t)` with `P ∝ K [R | t]`, `K` upper triangular with
/// positive diagonal and `K[(2,2)] = 1`, `R` a proper rotation (re-orthonormalised), and the
/// overall scale chosen positive (so that points with `P₃·X > 0` are in front). `K` keeps its
/// skew entry `K[(0,1)]`.
pub fn decompose_projection(p: &Matrix3x4<f64>) -> Result<KRt, CalibrationError> {
    if !p.iter().all(|v| v.is_finite()) {
        return Err(CalibrationError::Degenerate(
            "projection matrix is not finite".into(),
        ));
    }
    let m: Matrix3<f64> = p.fixed_view::<3, 3>(0, 0).into_owned();
    let p4: Vector3<f64> = p.column(3).into_owned();
    // RQ through Cholesky: M Mᵀ = K Kᵀ; with J the exchange matrix, J K J is lower triangular
    // and is the Cholesky factor of J M Mᵀ J.
    let j = Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0);
    let mmt = j * m * m.transpose() * j;
    let chol = mmt.cholesky().ok_or_else(|| {
        CalibrationError::Degenerate("projection matrix has a singular 3×3 part".into())
    })?;
    let k_full = j * chol.l() * j;
    let lambda = k_full[(2, 2)];
    let k_inv = k_full
        .try_inverse()
        .ok_or_else(|| CalibrationError::Degenerate("intrinsic matrix not invertible".into()))?;
    let r_raw = k_inv * m;
    if r_raw.determinant() <= 0.0 {
        return Err(CalibrationError::Degenerate(
            "projection implies a reflection (det R < 0): points on both sides of the camera?"
                .into(),
        ));
    }
    // nearest rotation
    let svd = r_raw.svd(true, true);
    let (u, v_t) = match (svd.u, svd.v_t) {
        (Some(u), Some(v_t)) => (u, v_t),
        _ => {
            return Err(CalibrationError::Degenerate(
                "SVD of the rotation failed".into(),
            ))
        }
    };
    let r = u * v_t;
    let t = k_inv * p4;
    let k = k_full / lambda;
    Ok((k, r, t))
}
