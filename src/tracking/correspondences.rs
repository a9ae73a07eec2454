//! 3D–2D correspondences for camera resection and calibration: their checks (equal lengths,
//! enough points, finite coordinates, non-coplanar 3D points) and [`CalibrationError`], the
//! error of the linear stage ([`super::dlt`]) and of the refinement ([`super::calibration`]).

use nalgebra::{Matrix3, Vector3};

/// Fewest correspondences accepted (the DLT needs 5½).
pub const MIN_POINTS: usize = 6;

/// Why a calibration could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// Fewer than [`MIN_POINTS`] correspondences.
    #[error("too few points for calibration: got {got}, need at least {needed}")]
    TooFewPoints {
        /// Number of correspondences given.
        got: usize,
        /// Minimum required.
        needed: usize,
    },
    /// The 3D and 2D lists differ in length.
    #[error("mismatched inputs: {points} 3D points but {pixels} pixel observations")]
    LengthMismatch {
        /// Number of 3D points.
        points: usize,
        /// Number of 2D observations.
        pixels: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("non-finite input: {what} {index} has a NaN or infinite coordinate")]
    NonFinite {
        /// `"3D point"` or `"pixel"`.
        what: &'static str,
        /// Index of the offending correspondence.
        index: usize,
    },
    /// The 3D points lie on a plane, a line or a point: the DLT is then undetermined.
    #[error(
        "degenerate 3D points: they are {shape} (spread ratios {ratio_2:.2e}, {ratio_3:.2e}); \
         the DLT needs non-coplanar points"
    )]
    DegeneratePoints {
        /// `"coplanar"`, `"collinear"` or `"coincident"`.
        shape: &'static str,
        /// √(λ₂/λ₁) of the point covariance.
        ratio_2: f64,
        /// √(λ₃/λ₁) of the point covariance.
        ratio_3: f64,
    },
    /// The linear or decomposition stage found no valid camera (e.g. coincident pixels,
    /// points on both sides of the camera, or a reflection).
    #[error("degenerate configuration: {0}")]
    Degenerate(String),
}

/// Checks lengths, counts and finiteness of the correspondences.
pub(crate) fn check_inputs(
    points: &[Vector3<f64>],
    pixels: &[[f64; 2]],
) -> Result<(), CalibrationError> {
    if points.len() != pixels.len() {
        return Err(CalibrationError::LengthMismatch {
            points: points.len(),
            pixels: pixels.len(),
        });
    }
    if points.len() < MIN_POINTS {
        return Err(CalibrationError::TooFewPoints {
            got: points.len(),
            needed: MIN_POINTS,
        });
    }
    if let Some(index) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        return Err(CalibrationError::NonFinite {
            what: "3D point",
            index,
        });
    }
    if let Some(index) = pixels
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(CalibrationError::NonFinite {
            what: "pixel",
            index,
        });
    }
    Ok(())
}

/// Rejects coplanar, collinear and coincident 3D point sets (relative spread below 1e-6).
pub(crate) fn check_spread(points: &[Vector3<f64>]) -> Result<(), CalibrationError> {
    let n = points.len() as f64;
    let mean = points.iter().sum::<Vector3<f64>>() / n;
    let mut cov = Matrix3::zeros();
    for p in points {
        let d = p - mean;
        cov += d * d.transpose();
    }
    cov /= n;
    let mut ev: Vec<f64> = cov
        .symmetric_eigenvalues()
        .iter()
        .map(|v| v.max(0.0))
        .collect();
    ev.sort_by(|a, b| b.total_cmp(a));
    let (l1, l2, l3) = (ev[0], ev[1], ev[2]);
    let ratio_2 = if l1 > 0.0 { (l2 / l1).sqrt() } else { 0.0 };
    let ratio_3 = if l1 > 0.0 { (l3 / l1).sqrt() } else { 0.0 };
    const TOL: f64 = 1e-6;
    let shape = if l1 <= 0.0 {
        Some("coincident")
    } else if ratio_2 < TOL {
        Some("collinear")
    } else if ratio_3 < TOL {
        Some("coplanar")
    } else {
        None
    };
    match shape {
        Some(shape) => Err(CalibrationError::DegeneratePoints {
            shape,
            ratio_2,
            ratio_3,
        }),
        None => Ok(()),
    }
}
