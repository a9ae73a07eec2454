//! [`LookAtCamera`]: a camera placed the way a person frames a picture (eye, target, up,
//! vertical field of view, image size), with automatic framing of a bounding box; what the
//! renderer and the scripts' `render` take. It describes the same pinhole model as
//! [`Camera`] (no distortion, square pixels, principal point at the image centre) and
//! converts to one ([`LookAtCamera::to_camera`]); the renderer projects through its own frame
//! ([`LookAtCamera::project`]: `R (p − eye)` and pixel corners at integers), the arithmetic its
//! pictures have always had.

use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

use super::Camera;
use crate::geometry::Vec3;

/// Distance (m) of the near clipping plane in front of the eye: closer points are not drawn.
pub const NEAR: f64 = 1e-3;
/// Largest image width or height (pixels) the renderer produces; larger sizes are clamped.
pub const MAX_SIZE: u32 = 16384;

/// The placement of a pinhole perspective camera looking from `eye` at `target`, with `up`
/// giving the image's upward direction (Z is up in the scene); [`to_camera`](Self::to_camera)
/// gives the [`Camera`]. Pixel (0, 0) is the top-left corner of the image;
/// pixel centres are at half-integer coordinates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LookAtCamera {
    /// Position of the eye (m).
    pub eye: Vec3,
    /// Point the camera looks at (m); it projects to the image centre.
    pub target: Vec3,
    /// Upward direction of the image (need not be unit or orthogonal to the view direction).
    pub up: Vec3,
    /// Vertical field of view (degrees, in (0, 180)).
    pub fov_y_deg: f64,
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
}

impl Default for LookAtCamera {
    /// An 800 × 600, 40° camera looking at the origin from +x, −y, above.
    fn default() -> Self {
        LookAtCamera {
            eye: Vec3::new(1.6, -2.4, 1.3),
            target: Vec3::zeros(),
            up: Vec3::z(),
            fov_y_deg: 40.0,
            width: 800,
            height: 600,
        }
    }
}

/// An orthonormal camera frame with the intrinsics, precomputed for projection.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    /// Eye position.
    pub eye: Vec3,
    /// Image right, image up, and viewing direction (unit, right-handed with `up × right`).
    pub right: Vec3,
    pub up: Vec3,
    pub forward: Vec3,
    /// Focal length and image centre in pixels.
    pub focal: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Frame {
    /// World point to camera coordinates (x right, y up, z forward, metres).
    pub fn camera_coords(&self, p: &Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(&self.right), d.dot(&self.up), d.dot(&self.forward))
    }

    /// World direction to camera coordinates.
    pub fn camera_dir(&self, d: &Vec3) -> Vec3 {
        Vec3::new(d.dot(&self.right), d.dot(&self.up), d.dot(&self.forward))
    }

    /// Camera coordinates to pixel coordinates (x right, y down) for a point with z > 0.
    pub fn pixel(&self, c: &Vec3) -> (f64, f64) {
        (
            self.cx + self.focal * c.x / c.z,
            self.cy - self.focal * c.y / c.z,
        )
    }
}

impl LookAtCamera {
    /// A default-sized camera (800 × 600, 40°, Z up) at `eye` looking at `target`.
    pub fn look_at(eye: Vec3, target: Vec3) -> LookAtCamera {
        LookAtCamera {
            eye,
            target,
            ..LookAtCamera::default()
        }
    }

    /// A `width` × `height`, 40° camera with a three-quarter view of the box
    /// `bounds_min`..`bounds_max` (from +x, −y and above, Z up), aimed so that the box's image
    /// is centred, from just far enough that the whole box fits with a 5 % margin on each side. Non-finite or
    /// inverted bounds frame a unit cube at the origin.
    pub fn framing(bounds_min: Vec3, bounds_max: Vec3, width: u32, height: u32) -> LookAtCamera {
        let ok = bounds_min
            .iter()
            .chain(bounds_max.iter())
            .all(|c| c.is_finite())
            && (0..3).all(|k| bounds_min[k] <= bounds_max[k]);
        let (lo, hi) = if ok {
            (bounds_min, bounds_max)
        } else {
            (Vec3::repeat(-0.5), Vec3::repeat(0.5))
        };
        let center = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo).norm()).max(1e-3);
        let mut cam = LookAtCamera {
            eye: center + Vec3::new(0.9, -1.4, 0.8).normalize(),
            target: center,
            up: Vec3::z(),
            fov_y_deg: 40.0,
            width,
            height,
        };
        let Some(f) = cam.frame() else { return cam };
        // Tangents of the half fields of view, shrunk by the margin.
        let ty = 0.9 * (0.5 * cam.fov_y_deg.to_radians()).tan();
        let tx = ty * f.cx.max(0.5) / f.cy.max(0.5);
        let corners: Vec<Vec3> = (0..8)
            .map(|k| {
                let pick = |bit: usize, a: f64, b: f64| if k & bit == 0 { a } else { b };
                Vec3::new(
                    pick(1, lo.x, hi.x),
                    pick(2, lo.y, hi.y),
                    pick(4, lo.z, hi.z),
                )
            })
            .collect();
        // Corners relative to `target` in the camera frame; the eye sits `dist` behind the
        // target, so a corner's depth is dist + z.
        let relative = |target: Vec3| corners.iter().map(move |c| f.camera_dir(&(c - target)));
        // Smallest distance that fits every corner around `target`.
        let fit = |target: Vec3| {
            relative(target).fold(radius * 0.1, |d: f64, c| {
                d.max(c.x.abs() / tx - c.z)
                    .max(c.y.abs() / ty - c.z)
                    .max(NEAR * 10.0 - c.z)
            })
        };
        // Centre the box's image: move the target within the image plane toward the middle of
        // the corners' image extents, a few times, then fit the distance.
        let mut target = center;
        for _ in 0..3 {
            let dist = fit(target);
            let (mut x, mut y) = (
                [f64::INFINITY, -f64::INFINITY],
                [f64::INFINITY, -f64::INFINITY],
            );
            for c in relative(target) {
                let (u, v) = (c.x / (dist + c.z), c.y / (dist + c.z));
                x = [x[0].min(u), x[1].max(u)];
                y = [y[0].min(v), y[1].max(v)];
            }
            target += (f.right * (x[0] + x[1]) + f.up * (y[0] + y[1])) * (0.5 * dist);
        }
        cam.target = target;
        cam.eye = target - f.forward * fit(target);
        cam
    }

    /// The camera's frame and intrinsics, or `None` when the camera is unusable (non-finite
    /// values, eye on the target, field of view outside (0°, 180°)). A zero or parallel `up`
    /// falls back to Z, or Y when looking along Z. Sizes are clamped to 1..=[`MAX_SIZE`].
    pub(crate) fn frame(&self) -> Option<Frame> {
        let finite = self
            .eye
            .iter()
            .chain(self.target.iter())
            .chain(self.up.iter())
            .all(|c| c.is_finite());
        if !(finite && self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return None;
        }
        let forward = (self.target - self.eye).try_normalize(1e-12)?;
        let mut right = None;
        for up in [self.up, Vec3::z(), Vec3::y()] {
            right = forward.cross(&up).try_normalize(1e-9);
            if right.is_some() {
                break;
            }
        }
        let right = right?;
        let (w, h) = self.size();
        let focal = 0.5 * f64::from(h) / (0.5 * self.fov_y_deg.to_radians()).tan();
        Some(Frame {
            eye: self.eye,
            right,
            up: right.cross(&forward),
            forward,
            focal,
            cx: 0.5 * f64::from(w),
            cy: 0.5 * f64::from(h),
        })
    }

    /// Image size actually rendered: width and height clamped to 1..=[`MAX_SIZE`].
    pub fn size(&self) -> (u32, u32) {
        (
            self.width.clamp(1, MAX_SIZE),
            self.height.clamp(1, MAX_SIZE),
        )
    }

    /// Projects world point `p` to `(x, y, depth)`: pixel coordinates (x right, y down, from the
    /// top-left corner of the image) and depth along the viewing direction (m). `None` when
    /// the point is non-finite, closer than [`NEAR`] or behind the eye, or the camera is
    /// unusable. Points outside the field of view still project (outside the image).
    pub fn project(&self, p: Vec3) -> Option<(f64, f64, f64)> {
        let f = self.frame()?;
        let c = f.camera_coords(&p);
        if c.z.is_nan() || c.z < NEAR || !c.x.is_finite() || !c.y.is_finite() {
            return None;
        }
        let (x, y) = f.pixel(&c);
        Some((x, y, c.z))
    }

    /// The same view as a pinhole [`Camera`] (`None` when unusable, see `frame`): rotation
    /// rows right, down, forward; `t = −R eye`; square pixels of the focal length the field
    /// of view gives; principal point at the image centre in the [`Camera`]'s pixel-centre
    /// convention (`(w − 1) / 2, (h − 1) / 2`); no distortion; the clamped image size. Its
    /// projection matches [`project`](Self::project) up to rounding, shifted by half a
    /// pixel (pixel centres at integers instead of half-integers).
    pub fn to_camera(&self) -> Option<Camera> {
        let f = self.frame()?;
        let down = -f.up;
        let rotation =
            Matrix3::from_rows(&[f.right.transpose(), down.transpose(), f.forward.transpose()]);
        let (w, h) = self.size();
        Some(Camera::new(
            f.focal,
            f.focal,
            f.cx - 0.5,
            f.cy - 0.5,
            rotation,
            -(rotation * f.eye),
            w,
            h,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn target_projects_to_centre_and_behind_is_none() {
        let cam = LookAtCamera::look_at(Vec3::new(3.0, -2.0, 1.0), Vec3::new(0.1, 0.2, 0.3));
        let (x, y, d) = cam.project(cam.target).unwrap();
        assert!((x - 400.0).abs() < 1e-9 && (y - 300.0).abs() < 1e-9);
        assert!((d - (cam.target - cam.eye).norm()).abs() < 1e-9);
        // Up in the world is up in the image (smaller y).
        let (_, y_up, _) = cam.project(cam.target + Vec3::z() * 0.1).unwrap();
        assert!(y_up < y);
        assert!(cam.project(cam.eye * 2.0 - cam.target).is_none());
        assert!(cam.project(Vec3::new(f64::NAN, 0.0, 0.0)).is_none());
        // Looking straight down still works (up falls back).
        let down = LookAtCamera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::zeros());
        assert!(down.project(Vec3::new(0.1, 0.0, 0.0)).is_some());
    }

    #[test]
    fn framing_keeps_the_box_in_view() {
        let (lo, hi) = (Vec3::new(-0.5, -0.25, -0.8), Vec3::new(0.5, 0.25, 0.0));
        let cam = LookAtCamera::framing(lo, hi, 640, 480);
        let mut ext = [f64::INFINITY, -f64::INFINITY, f64::INFINITY, -f64::INFINITY];
        for k in 0..8 {
            let c = Vec3::new(
                [lo.x, hi.x][k & 1],
                [lo.y, hi.y][(k >> 1) & 1],
                [lo.z, hi.z][k >> 2],
            );
            let (x, y, _) = cam.project(c).unwrap();
            assert!(
                (31.9..608.1).contains(&x) && (23.9..456.1).contains(&y),
                "{x} {y}"
            );
            ext = [ext[0].min(x), ext[1].max(x), ext[2].min(y), ext[3].max(y)];
        }
        // Centred, and tight along one axis.
        assert!(((ext[0] + ext[1]) / 2.0 - 320.0).abs() < 3.0, "{ext:?}");
        assert!(((ext[2] + ext[3]) / 2.0 - 240.0).abs() < 3.0, "{ext:?}");
        assert!(
            ext[1] - ext[0] > 560.0 || ext[3] - ext[2] > 420.0,
            "{ext:?}"
        );
        let json = serde_json::to_string(&cam).unwrap();
        assert_eq!(serde_json::from_str::<LookAtCamera>(&json).unwrap(), cam);
        let pinhole = cam.to_camera().unwrap();
        for k in 0..8 {
            let c = Vec3::new(
                [lo.x, hi.x][k & 1],
                [lo.y, hi.y][(k >> 1) & 1],
                [lo.z, hi.z][k >> 2],
            );
            let (x, y, _) = cam.project(c).unwrap();
            let uv = pinhole.project(&c).unwrap();
            assert!((uv[0] + 0.5 - x).abs() < 1e-9 && (uv[1] + 0.5 - y).abs() < 1e-9);
        }
        let bad = LookAtCamera::framing(Vec3::repeat(f64::NAN), Vec3::zeros(), 10, 10);
        assert!(bad.project(Vec3::zeros()).is_some());
    }
}
