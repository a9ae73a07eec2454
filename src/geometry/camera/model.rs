//! The pinhole camera model: intrinsics (focal lengths, principal point), two-term radial
//! distortion, pose (world→camera rotation and translation) and image size; projection of
//! world points to pixels and back. See the [camera module](super) for the model's equations.

use nalgebra::{Matrix3, Vector3};

/// A calibrated pinhole camera with radial distortion; see the [camera module](super) for the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Horizontal focal length, pixels.
    pub fx: f64,
    /// Vertical focal length, pixels.
    pub fy: f64,
    /// Principal point, x, pixels.
    pub cx: f64,
    /// Principal point, y, pixels.
    pub cy: f64,
    /// First radial distortion coefficient (of `r²`).
    pub k1: f64,
    /// Second radial distortion coefficient (of `r⁴`).
    pub k2: f64,
    /// World→camera rotation.
    pub rotation: Matrix3<f64>,
    /// World→camera translation: `pc = rotation · p + translation`.
    pub translation: Vector3<f64>,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

impl Camera {
    /// A camera without distortion from focal lengths, principal point, pose and image size.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        fx: f64,
        fy: f64,
        cx: f64,
        cy: f64,
        rotation: Matrix3<f64>,
        translation: Vector3<f64>,
        width: u32,
        height: u32,
    ) -> Self {
        Camera {
            fx,
            fy,
            cx,
            cy,
            k1: 0.0,
            k2: 0.0,
            rotation,
            translation,
            width,
            height,
        }
    }

    /// A camera without distortion at `eye` looking at `target`, the world's +y up in the image
    /// (image x towards +x when looking along −z), square pixels of focal length `focal`,
    /// principal point at the image centre.
    pub fn looking_at(
        eye: Vector3<f64>,
        target: Vector3<f64>,
        focal: f64,
        width: u32,
        height: u32,
    ) -> Camera {
        Camera::looking_at_up(eye, target, Vector3::y(), focal, width, height)
    }

    /// [`Camera::looking_at`] with `up` (a world direction, not along the view) up in the
    /// image: the z-up worlds of the tracking sequences pass +z.
    pub fn looking_at_up(
        eye: Vector3<f64>,
        target: Vector3<f64>,
        up: Vector3<f64>,
        focal: f64,
        width: u32,
        height: u32,
    ) -> Camera {
        let f = (target - eye).normalize();
        let right = f.cross(&up).normalize();
        let down = f.cross(&right);
        let rotation = Matrix3::from_rows(&[right.transpose(), down.transpose(), f.transpose()]);
        Camera::new(
            focal,
            focal,
            (width as f64 - 1.0) / 2.0,
            (height as f64 - 1.0) / 2.0,
            rotation,
            -(rotation * eye),
            width,
            height,
        )
    }

    /// The intrinsic matrix `K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]`.
    pub fn k_matrix(&self) -> Matrix3<f64> {
        Matrix3::new(self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0)
    }

    /// Camera centre in world coordinates, `−Rᵀ t`.
    pub fn center(&self) -> Vector3<f64> {
        -(self.rotation.transpose() * self.translation)
    }

    /// A world point in the camera frame, `R p + t`.
    pub fn to_camera_frame(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * p + self.translation
    }

    /// Applies the radial distortion to ideal normalised coordinates `(x, y)` (`X/Z, Y/Z`).
    pub fn distort(&self, xy: [f64; 2]) -> [f64; 2] {
        let r2 = xy[0] * xy[0] + xy[1] * xy[1];
        let f = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
        [xy[0] * f, xy[1] * f]
    }

    /// Inverts [`distort`](Self::distort): ideal normalised coordinates from distorted ones, by
    /// Newton iteration on the radius. Exact to ~1e-14 inside the region where the distortion is
    /// monotonic; outside it returns the best iterate found.
    pub fn undistort(&self, xy: [f64; 2]) -> [f64; 2] {
        let rd = (xy[0] * xy[0] + xy[1] * xy[1]).sqrt();
        if rd == 0.0 || (self.k1 == 0.0 && self.k2 == 0.0) {
            return xy;
        }
        // solve g(r) = r (1 + k1 r² + k2 r⁴) − rd = 0
        let mut r = rd;
        for _ in 0..50 {
            let r2 = r * r;
            let g = r * (1.0 + self.k1 * r2 + self.k2 * r2 * r2) - rd;
            let dg = 1.0 + 3.0 * self.k1 * r2 + 5.0 * self.k2 * r2 * r2;
            if dg.abs() < 1e-12 {
                break;
            }
            let step = g / dg;
            r -= step;
            if step.abs() <= 1e-15 * rd.max(1e-300) {
                break;
            }
        }
        let s = r / rd;
        [xy[0] * s, xy[1] * s]
    }

    /// Pixel → ideal normalised coordinates (`X/Z, Y/Z` in the camera frame), removing distortion.
    pub fn undistort_pixel_to_normalized(&self, uv: [f64; 2]) -> [f64; 2] {
        self.undistort([(uv[0] - self.cx) / self.fx, (uv[1] - self.cy) / self.fy])
    }

    /// The pixel where the point would appear with the same `K` but no distortion.
    pub fn undistorted_pixel(&self, uv: [f64; 2]) -> [f64; 2] {
        let n = self.undistort_pixel_to_normalized(uv);
        [self.fx * n[0] + self.cx, self.fy * n[1] + self.cy]
    }

    /// Projects a camera-frame point without checking that it is in front (divides by `z`).
    pub(crate) fn project_camera_frame_unchecked(&self, pc: &Vector3<f64>) -> [f64; 2] {
        let d = self.distort([pc.x / pc.z, pc.y / pc.z]);
        [self.fx * d[0] + self.cx, self.fy * d[1] + self.cy]
    }

    /// Projects a world point to pixels (distortion included); `None` when the point is not in
    /// front of the camera (`z ≤ 0` in the camera frame). Points outside the image are still
    /// projected: compare with [`width`](Self::width)/[`height`](Self::height) if that matters.
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        let pc = self.to_camera_frame(p);
        if pc.z.is_nan() || pc.z <= 0.0 {
            return None;
        }
        Some(self.project_camera_frame_unchecked(&pc))
    }

    /// The same camera for an image pyramid level shrunk by `factor` (2 = half size): focal
    /// lengths divided by `factor`, principal point `c' = (c + 0.5) / factor − 0.5` (pixel
    /// centres stay consistent), width and height divided and rounded (at least 1); distortion
    /// and pose unchanged.
    pub fn scaled(&self, factor: f64) -> Camera {
        let size = |n: u32| ((n as f64 / factor).round().max(1.0)) as u32;
        Camera {
            fx: self.fx / factor,
            fy: self.fy / factor,
            cx: (self.cx + 0.5) / factor - 0.5,
            cy: (self.cy + 0.5) / factor - 0.5,
            width: size(self.width),
            height: size(self.height),
            ..self.clone()
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A distorted 320×240 test camera, shared by the camera's tests.
    pub(crate) fn cam() -> Camera {
        Camera {
            k1: -0.08,
            k2: 0.02,
            ..Camera::new(
                400.0,
                401.0,
                162.0,
                118.0,
                Matrix3::identity(),
                Vector3::zeros(),
                320,
                240,
            )
        }
    }

    #[test]
    fn undistort_inverts_distort() {
        let c = cam();
        for &p in &[[0.0, 0.0], [0.3, -0.2], [-0.5, 0.4], [0.01, 0.0]] {
            let d = c.distort(p);
            let u = c.undistort(d);
            assert!(
                (u[0] - p[0]).abs() < 1e-13 && (u[1] - p[1]).abs() < 1e-13,
                "{p:?} {u:?}"
            );
        }
    }

    #[test]
    fn behind_camera_is_none_and_centre_projects_to_principal_point() {
        let c = cam();
        assert!(c.project(&Vector3::new(0.0, 0.0, -1.0)).is_none());
        assert!(c.project(&Vector3::new(0.0, 0.0, 0.0)).is_none());
        let uv = c.project(&Vector3::new(0.0, 0.0, 2.0)).expect("in front");
        assert_eq!(uv, [162.0, 118.0]);
        assert_eq!(c.center(), Vector3::zeros());
    }

    #[test]
    fn scaled_camera_maps_pixel_areas_consistently() {
        let c = cam();
        let h = c.scaled(2.0);
        assert_eq!((h.width, h.height), (160, 120));
        assert_eq!((h.fx, h.fy), (200.0, 200.5));
        assert_eq!((h.cx, h.cy), (80.75, 58.75));
        assert_eq!(
            (h.k1, h.k2, h.rotation, h.translation),
            (c.k1, c.k2, c.rotation, c.translation)
        );
        let p = Vector3::new(0.3, -0.2, 2.5);
        let (a, b) = (c.project(&p).expect("front"), h.project(&p).expect("front"));
        // a full-resolution pixel u covers [u − 0.5, u + 0.5]; at half size that is (u + 0.5) / 2 − 0.5
        for i in 0..2 {
            assert!(
                ((a[i] + 0.5) / 2.0 - 0.5 - b[i]).abs() < 1e-12,
                "{a:?} {b:?}"
            );
        }
        assert_eq!(c.scaled(1.0), c);
        assert_eq!(c.scaled(3.0).width, 107);
    }
}
