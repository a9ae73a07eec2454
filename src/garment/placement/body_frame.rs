//! `BodyFrame`: a mannequin's own coordinate frame, found from its inertia matrix (seed report
//! §5.4.1.1): the centroid, the up axis (largest spread), the left–right axis (normal of the
//! symmetry plane) and the front axis (smallest spread). Signs come from the body's shape: the
//! lowest slab holds two feet and the highest one head; the toes point forward of the shins.

use crate::garment::PatternError;
use crate::geometry::{Mat3, Vec3};

/// An orthonormal frame attached to a standing body, with `left = up × front`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyFrame {
    /// Area-weighted centroid of the skin (m).
    pub origin: Vec3,
    /// The body's left (normal of the symmetry plane).
    pub left: Vec3,
    /// Up, from the feet to the head.
    pub up: Vec3,
    /// Front, the way the body faces.
    pub front: Vec3,
    /// Height of the lowest skin point in the frame (m, negative).
    pub floor: f64,
    /// Height of the highest skin point in the frame (m).
    pub top: f64,
}

impl BodyFrame {
    /// The frame of a skin mesh.
    pub fn of(positions: &[Vec3], triangles: &[[usize; 3]]) -> Result<BodyFrame, PatternError> {
        if triangles.is_empty() {
            return Err(PatternError::Parameter("body mesh has no triangles".into()));
        }
        // area-weighted surface moments: each triangle's own second moment included
        let (mut area, mut c) = (0.0, Vec3::zeros());
        for t in triangles {
            let (a, b, d) = (positions[t[0]], positions[t[1]], positions[t[2]]);
            let w = 0.5 * (b - a).cross(&(d - a)).norm();
            area += w;
            c += (a + b + d) * (w / 3.0);
        }
        if !(area > 0.0 && c.iter().all(|v| v.is_finite())) {
            return Err(PatternError::Parameter(
                "body mesh has no area or non-finite vertices".into(),
            ));
        }
        let c = c / area;
        let mut cov = Mat3::zeros();
        for t in triangles {
            let (a, b, d) = (
                positions[t[0]] - c,
                positions[t[1]] - c,
                positions[t[2]] - c,
            );
            let w = 0.5 * (b - a).cross(&(d - a)).norm();
            // ∫ x xᵀ over a triangle = A/12 (Σ vᵢvᵢᵀ + (Σvᵢ)(Σvᵢ)ᵀ)
            let s = a + b + d;
            cov += (a * a.transpose() + b * b.transpose() + d * d.transpose() + s * s.transpose())
                * (w / 12.0);
        }
        let eig = nalgebra::SymmetricEigen::new(cov);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
        let axis = |k: usize| eig.eigenvectors.column(order[k]).into_owned();
        let (mut up, mut front) = (axis(0), axis(2));
        let depth = |p: &Vec3, ax: &Vec3| (p - c).dot(ax);
        // up: the low end holds two feet (two clusters across), the high end one head
        let ends = |u: &Vec3| {
            let hs: Vec<f64> = positions.iter().map(|p| depth(p, u)).collect();
            let (lo, hi) = hs
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
            (lo, hi, hs)
        };
        let lateral = axis(1);
        let clusters = |hs: &[f64], from: f64, to: f64| -> usize {
            let mut xs: Vec<f64> = positions
                .iter()
                .zip(hs)
                .filter(|(_, &h)| h >= from && h <= to)
                .map(|(p, _)| depth(p, &lateral))
                .collect();
            xs.sort_by(f64::total_cmp);
            if xs.is_empty() {
                return 0;
            }
            1 + xs.windows(2).filter(|w| w[1] - w[0] > 0.03).count()
        };
        let (lo, hi, hs) = ends(&up);
        let slab = 0.04 * (hi - lo);
        let (low_n, high_n) = (clusters(&hs, lo, lo + slab), clusters(&hs, hi - slab, hi));
        if high_n > low_n {
            up = -up;
        }
        let (lo, hi, hs) = ends(&up);
        // front: the feet (lowest 4 %) reach further forward than the shins (8–14 %)
        let mean_depth = |from: f64, to: f64| {
            let (mut s, mut n) = (0.0, 0usize);
            for (p, &h) in positions.iter().zip(&hs) {
                if h >= lo + from * (hi - lo) && h <= lo + to * (hi - lo) {
                    s += depth(p, &front);
                    n += 1;
                }
            }
            if n == 0 {
                0.0
            } else {
                s / n as f64
            }
        };
        if mean_depth(0.0, 0.04) < mean_depth(0.08, 0.14) {
            front = -front;
        }
        let left = up.cross(&front).normalize();
        let front = left.cross(&up).normalize();
        Ok(BodyFrame {
            origin: c,
            left,
            up: up.normalize(),
            front,
            floor: lo,
            top: hi,
        })
    }

    /// Body coordinates `(s, h, d)` (left, up, front) of a world point.
    #[inline]
    pub fn to_body(&self, p: &Vec3) -> [f64; 3] {
        let q = p - self.origin;
        [q.dot(&self.left), q.dot(&self.up), q.dot(&self.front)]
    }

    /// The world point of body coordinates `(s, h, d)`.
    #[inline]
    pub fn to_world(&self, s: f64, h: f64, d: f64) -> Vec3 {
        self.origin + self.left * s + self.up * h + self.front * d
    }
}
