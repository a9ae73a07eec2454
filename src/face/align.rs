//! Similarity alignment of two point sets (Umeyama 1991): the scale, rotation and translation
//! that best map one set onto the other in least squares. Used to compare shapes whose scale
//! and placement are arbitrary (a face reconstructed from uncalibrated photos).

use nalgebra::{Matrix3, Rotation3, SVD};

use crate::geometry::Vec3;

/// `p ↦ scale · rotation · p + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Similarity {
    /// Scale factor.
    pub scale: f64,
    /// Rotation.
    pub rotation: Rotation3<f64>,
    /// Translation.
    pub translation: Vec3,
}

impl Similarity {
    /// Applies the transform to one point.
    pub fn apply(&self, p: &Vec3) -> Vec3 {
        self.scale * (self.rotation * p) + self.translation
    }
}

/// The similarity minimising `Σ |s R from[i] + t − to[i]|²` (no reflection). `None` for
/// fewer than 3 pairs, different lengths or a degenerate (collinear) set.
pub fn similarity_align(from: &[Vec3], to: &[Vec3]) -> Option<Similarity> {
    let n = from.len();
    if n < 3 || to.len() != n {
        return None;
    }
    let mf: Vec3 = from.iter().sum::<Vec3>() / n as f64;
    let mt: Vec3 = to.iter().sum::<Vec3>() / n as f64;
    let mut cov = Matrix3::zeros();
    let mut var = 0.0;
    for (a, b) in from.iter().zip(to) {
        let (da, db) = (a - mf, b - mt);
        cov += db * da.transpose();
        var += da.norm_squared();
    }
    cov /= n as f64;
    var /= n as f64;
    if var.is_nan() || var <= 0.0 {
        return None;
    }
    let svd = SVD::new(cov, true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut d = Matrix3::identity();
    if (u * vt).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let r = u * d * vt;
    let trace = (Matrix3::from_diagonal(&svd.singular_values) * d).trace();
    let scale = trace / var;
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    let rotation = Rotation3::from_matrix_unchecked(r);
    let translation = mt - scale * (rotation * mf);
    Some(Similarity {
        scale,
        rotation,
        translation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_known_similarity() {
        let pts: Vec<Vec3> = (0..20)
            .map(|i| {
                let t = i as f64;
                Vec3::new(t.sin(), (1.3 * t).cos(), 0.1 * t)
            })
            .collect();
        let truth = Similarity {
            scale: 1.7,
            rotation: Rotation3::new(Vec3::new(0.3, -0.2, 0.9)),
            translation: Vec3::new(1.0, -2.0, 0.5),
        };
        let moved: Vec<Vec3> = pts.iter().map(|p| truth.apply(p)).collect();
        let s = similarity_align(&pts, &moved).unwrap();
        assert!((s.scale - 1.7).abs() < 1e-12);
        // matrices compared entry by entry (the angle between two nearly equal rotations comes
        // from an arccos and is only good to ~1e-8)
        let d = (s.rotation.matrix() - truth.rotation.matrix()).abs().max();
        assert!(d < 1e-12, "rotation differs by {d}");
        assert!((s.translation - truth.translation).norm() < 1e-12);
        assert!(similarity_align(&pts[..2], &moved[..2]).is_none());
    }
}
