//! The rigid pose of a head: rotation about a pivot inside the head, then translation.
//!
//! A model point `p` goes to `R (p − c) + c + t`, with `c` the [pivot](head_pivot) (a point
//! about 9 cm behind the face, near the centre of the head, so yaw and pitch turn the face as
//! a neck does) and `t` the translation. Angles, as written in files: yaw about the vertical
//! axis y (positive turns the nose towards the subject's left, +x), pitch about x (positive
//! turns the nose down), roll about z (positive tilts the top of the head towards −x);
//! `R = R_y(yaw) · R_x(pitch) · R_z(roll)`.

use nalgebra::{Matrix3, Rotation3, Vector3};

use super::model::FaceMesh;
use crate::geometry::Vec3;

/// How far behind the face's mean point the pivot lies (m).
pub const PIVOT_DEPTH: f64 = 0.09;

/// The pivot of a face mesh: its centroid moved [`PIVOT_DEPTH`] along −z.
pub fn head_pivot(mesh: &FaceMesh) -> Vec3 {
    mesh.centroid() - Vec3::new(0.0, 0.0, PIVOT_DEPTH)
}

/// Rotation and translation of a head.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadPose {
    /// Rotation about the pivot.
    pub rotation: Rotation3<f64>,
    /// Translation after the rotation (m).
    pub translation: Vec3,
}

impl Default for HeadPose {
    fn default() -> Self {
        HeadPose {
            rotation: Rotation3::identity(),
            translation: Vec3::zeros(),
        }
    }
}

impl HeadPose {
    /// From yaw, pitch, roll (radians) and a translation.
    pub fn from_angles(yaw: f64, pitch: f64, roll: f64, translation: Vec3) -> HeadPose {
        let ry = Rotation3::from_axis_angle(&Vector3::y_axis(), yaw);
        let rx = Rotation3::from_axis_angle(&Vector3::x_axis(), pitch);
        let rz = Rotation3::from_axis_angle(&Vector3::z_axis(), roll);
        HeadPose {
            rotation: ry * rx * rz,
            translation,
        }
    }

    /// Yaw, pitch and roll (radians) of the rotation (inverse of [`from_angles`](Self::from_angles),
    /// pitch in `[−π/2, π/2]`).
    pub fn angles(&self) -> [f64; 3] {
        let m: &Matrix3<f64> = self.rotation.matrix();
        // R = Ry Rx Rz: m[(1,2)] = −sin(pitch); m[(0,2)] = sin(yaw) cos(pitch);
        // m[(2,2)] = cos(yaw) cos(pitch); m[(1,0)] = cos(pitch) sin(roll); m[(1,1)] = cos(pitch) cos(roll)
        let pitch = (-m[(1, 2)]).clamp(-1.0, 1.0).asin();
        let yaw = m[(0, 2)].atan2(m[(2, 2)]);
        let roll = m[(1, 0)].atan2(m[(1, 1)]);
        [yaw, pitch, roll]
    }

    /// Moves model points: `out[i] = R (p[i] − pivot) + pivot + t`. No allocation once `out`
    /// has its size.
    pub fn apply(&self, pivot: &Vec3, points: &[Vec3], out: &mut Vec<Vec3>) {
        out.clear();
        let r = self.rotation.matrix();
        let shift = pivot + self.translation;
        out.extend(points.iter().map(|p| r * (p - pivot) + shift));
    }

    /// One point.
    pub fn apply_one(&self, pivot: &Vec3, p: &Vec3) -> Vec3 {
        self.rotation * (p - pivot) + pivot + self.translation
    }

    /// The angle (radians) of the rotation taking this pose's rotation to `other`'s.
    pub fn angle_to(&self, other: &HeadPose) -> f64 {
        (self.rotation.inverse() * other.rotation).angle()
    }

    /// This pose with a small rotation `omega` (rotation vector, world axes, about the pivot)
    /// composed on the left and `dt` added to the translation.
    pub fn perturbed(&self, omega: &Vec3, dt: &Vec3) -> HeadPose {
        HeadPose {
            rotation: Rotation3::new(*omega) * self.rotation,
            translation: self.translation + dt,
        }
    }
}
