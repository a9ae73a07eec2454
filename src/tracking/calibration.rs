//! Camera calibration from 3D–2D correspondences.
//!
//! [`calibrate`] runs three stages:
//! 1. [`dlt`] (in [`super::dlt`]): the normalised Direct Linear Transform (Hartley & Zisserman, *Multiple View
//!    Geometry*, 2nd ed., alg. 7.1) gives the 3×4 projection matrix `P` from at least six
//!    non-coplanar points, ignoring distortion;
//! 2. [`decompose_projection`]: an RQ decomposition `P = λ K [R | t]` with positive focal lengths
//!    and `det R = +1` (the skew of `K` is dropped, the camera model has none);
//! 3. a Levenberg–Marquardt refinement (the damping of [`crate::geometry::least_squares`]) of `fx, fy, cx, cy, k1, k2`, the rotation
//!    (as an axis-angle increment composed on the left of the current rotation) and the
//!    translation, minimising the squared pixel reprojection error with a central-difference
//!    Jacobian and Nielsen's damping update.
//!
//! Bad input gives a [`CalibrationError`], never a panic.

use nalgebra::{DMatrix, Matrix3, Rotation3, SMatrix, SVector, Vector3};

pub use super::correspondences::{CalibrationError, MIN_POINTS};
pub use super::dlt::{decompose_projection, dlt, KRt};
use crate::geometry::least_squares::{Damping, DampingUpdate, DiagonalDamping};
use crate::geometry::Camera;

/// Number of refined parameters: fx, fy, cx, cy, k1, k2, ω (3), t (3).
const NPARAM: usize = 12;
type Params = SVector<f64, NPARAM>;
type Normal = SMatrix<f64, NPARAM, NPARAM>;

/// Options of [`calibrate_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationOptions {
    /// Most Levenberg–Marquardt iterations (accepted or rejected steps).
    pub max_iterations: usize,
    /// Refine `k1, k2`; when false they stay 0.
    pub estimate_distortion: bool,
    /// Stop when the step is below this, relative to the parameter size.
    pub step_tolerance: f64,
    /// Stop when the largest gradient entry (of ½‖r‖², scaled by the parameter size) is below this.
    pub gradient_tolerance: f64,
}

impl Default for CalibrationOptions {
    fn default() -> Self {
        CalibrationOptions {
            max_iterations: 200,
            estimate_distortion: true,
            step_tolerance: 1e-12,
            gradient_tolerance: 1e-12,
        }
    }
}

/// The result of [`calibrate`].
#[derive(Debug, Clone, PartialEq)]
pub struct Calibration {
    /// The refined camera; `width`/`height` are those given.
    pub camera: Camera,
    /// Root mean square reprojection error per point (Euclidean pixel distance), in pixels.
    pub rms_px: f64,
    /// Levenberg–Marquardt iterations done (each one Jacobian evaluation).
    pub iterations: usize,
    /// Whether a stopping test (small step or gradient) was met before `max_iterations`.
    pub converged: bool,
}

/// Unpacks the refinement parameters onto a camera whose rotation is `base`.
fn apply(template: &Camera, base: &Matrix3<f64>, x: &Params) -> Camera {
    let omega = Vector3::new(x[6], x[7], x[8]);
    let rot = Rotation3::from_scaled_axis(omega).into_inner() * base;
    Camera {
        fx: x[0],
        fy: x[1],
        cx: x[2],
        cy: x[3],
        k1: x[4],
        k2: x[5],
        rotation: rot,
        translation: Vector3::new(x[9], x[10], x[11]),
        width: template.width,
        height: template.height,
    }
}

fn pack(c: &Camera) -> Params {
    let mut x = Params::zeros();
    x[0] = c.fx;
    x[1] = c.fy;
    x[2] = c.cx;
    x[3] = c.cy;
    x[4] = c.k1;
    x[5] = c.k2;
    x[9] = c.translation.x;
    x[10] = c.translation.y;
    x[11] = c.translation.z;
    x
}

/// Residuals (pixel differences, 2 per point); `None` if a point falls behind the camera.
fn residuals(cam: &Camera, points: &[Vector3<f64>], pixels: &[[f64; 2]], out: &mut [f64]) -> bool {
    for (i, (p, uv)) in points.iter().zip(pixels).enumerate() {
        let pc = cam.to_camera_frame(p);
        if pc.z.is_nan() || pc.z <= 0.0 {
            return false;
        }
        let q = cam.project_camera_frame_unchecked(&pc);
        out[2 * i] = q[0] - uv[0];
        out[2 * i + 1] = q[1] - uv[1];
    }
    true
}

/// Root mean square Euclidean reprojection error of a camera on correspondences, in pixels;
/// infinite if a point is behind the camera.
pub fn rms_reprojection_error(cam: &Camera, points: &[Vector3<f64>], pixels: &[[f64; 2]]) -> f64 {
    let mut r = vec![0.0; 2 * points.len()];
    if points.is_empty() || !residuals(cam, points, pixels, &mut r) {
        return f64::INFINITY;
    }
    (r.iter().map(|v| v * v).sum::<f64>() / points.len() as f64).sqrt()
}

/// [`calibrate_with`] with default options.
pub fn calibrate(
    points: &[Vector3<f64>],
    pixels: &[[f64; 2]],
    width: u32,
    height: u32,
) -> Result<Calibration, CalibrationError> {
    calibrate_with(
        points,
        pixels,
        width,
        height,
        &CalibrationOptions::default(),
    )
}

/// Calibrates a camera from ≥ 6 non-coplanar 3D points and their observed pixels in an image of
/// `width × height`: DLT, RQ decomposition, then Levenberg–Marquardt refinement (see the
/// [module docs](self)).
pub fn calibrate_with(
    points: &[Vector3<f64>],
    pixels: &[[f64; 2]],
    width: u32,
    height: u32,
    options: &CalibrationOptions,
) -> Result<Calibration, CalibrationError> {
    let p = dlt(points, pixels)?;
    let (k, r, t) = decompose_projection(&p)?;
    let initial = Camera {
        fx: k[(0, 0)],
        fy: k[(1, 1)],
        cx: k[(0, 2)],
        cy: k[(1, 2)],
        k1: 0.0,
        k2: 0.0,
        rotation: r,
        translation: t,
        width,
        height,
    };
    let n = points.len();
    let mut base = initial.rotation;
    let mut x = pack(&initial);
    let mut res = vec![0.0; 2 * n];
    if !residuals(&initial, points, pixels, &mut res) {
        return Err(CalibrationError::Degenerate(
            "the linear estimate puts some points behind the camera".into(),
        ));
    }
    let mut cost = 0.5 * res.iter().map(|v| v * v).sum::<f64>();
    let active: Vec<usize> = (0..NPARAM)
        .filter(|&i| options.estimate_distortion || !(i == 4 || i == 5))
        .collect();

    // Nielsen's damping; λ set from the first Jacobian
    let mut damping = Damping::new(
        -1.0,
        DiagonalDamping::Clamped {
            floor: 1e-12,
            extra: 0.0,
        },
        DampingUpdate::Nielsen,
    );
    let mut iterations = 0;
    let mut converged = false;
    let mut jac = DMatrix::<f64>::zeros(2 * n, NPARAM);
    let mut rp = vec![0.0; 2 * n];
    let mut rm = vec![0.0; 2 * n];
    let mut need_jacobian = true;
    let mut jtj = Normal::zeros();
    let mut g = Params::zeros();
    while iterations < options.max_iterations {
        iterations += 1;
        if need_jacobian {
            // central differences; the rotation increment is at 0 after every accepted step
            for &c in &active {
                let h = 1e-6
                    * x[c]
                        .abs()
                        .max(if (6..=8).contains(&c) { 1.0 } else { 1e-2 });
                let (mut xp, mut xm) = (x, x);
                xp[c] += h;
                xm[c] -= h;
                let (cp, cm) = (apply(&initial, &base, &xp), apply(&initial, &base, &xm));
                for (i, (pt, uv)) in points.iter().zip(pixels).enumerate() {
                    let qp = cp.project_camera_frame_unchecked(&cp.to_camera_frame(pt));
                    let qm = cm.project_camera_frame_unchecked(&cm.to_camera_frame(pt));
                    rp[2 * i] = qp[0] - uv[0];
                    rp[2 * i + 1] = qp[1] - uv[1];
                    rm[2 * i] = qm[0] - uv[0];
                    rm[2 * i + 1] = qm[1] - uv[1];
                }
                for i in 0..2 * n {
                    jac[(i, c)] = (rp[i] - rm[i]) / (2.0 * h);
                }
            }
            let jt = jac.transpose();
            let jtj_d = &jt * &jac;
            jtj = Normal::from_fn(|a, b| jtj_d[(a, b)]);
            let r_vec = nalgebra::DVector::from_column_slice(&res);
            let g_d = jt * r_vec;
            g = Params::from_fn(|a, _| g_d[a]);
            need_jacobian = false;
            let scale = |c: usize| x[c].abs().max(1.0);
            let gmax = active
                .iter()
                .map(|&c| (g[c] * scale(c)).abs())
                .fold(0.0, f64::max);
            if gmax <= options.gradient_tolerance * (2.0 * cost).max(1e-300).sqrt().max(1.0) {
                converged = true;
                break;
            }
            if damping.lambda < 0.0 {
                damping.lambda = 1e-3 * active.iter().map(|&c| jtj[(c, c)]).fold(0.0, f64::max);
            }
        }
        // damped normal equations on the active parameters (Marquardt scaling, floor 1e-12)
        let m = active.len();
        let mut a = DMatrix::<f64>::zeros(m, m);
        let mut b = nalgebra::DVector::<f64>::zeros(m);
        for (ia, &ca) in active.iter().enumerate() {
            for (ib, &cb) in active.iter().enumerate() {
                a[(ia, ib)] = jtj[(ca, cb)];
            }
            b[ia] = g[ca];
        }
        let Some(step) = damping.solve(&a, &b) else {
            continue;
        };
        let mut delta = Params::zeros();
        for (ia, &ca) in active.iter().enumerate() {
            delta[ca] = step[ia];
        }
        let xnorm = active.iter().map(|&c| x[c] * x[c]).sum::<f64>().sqrt();
        if delta.norm() <= options.step_tolerance * (xnorm + options.step_tolerance) {
            converged = true;
            break;
        }
        let x_new = x + delta;
        let cam_new = apply(&initial, &base, &x_new);
        let mut res_new = vec![0.0; 2 * n];
        let ok = residuals(&cam_new, points, pixels, &mut res_new);
        let cost_new = if ok {
            0.5 * res_new.iter().map(|v| v * v).sum::<f64>()
        } else {
            f64::INFINITY
        };
        // predicted reduction of the linear model: −δᵀg − ½ δᵀ JᵀJ δ
        let predicted = -(delta.dot(&g)) - 0.5 * delta.dot(&(jtj * delta));
        let rho = if predicted > 0.0 {
            (cost - cost_new) / predicted
        } else {
            -1.0
        };
        if cost_new.is_finite() && rho > 0.0 {
            // accept: fold the rotation increment into the base rotation
            base = cam_new.rotation;
            x = x_new;
            x[6] = 0.0;
            x[7] = 0.0;
            x[8] = 0.0;
            let rel = (cost - cost_new) / cost.max(1e-300);
            res = res_new;
            cost = cost_new;
            damping.accept(rho);
            need_jacobian = true;
            if cost == 0.0 || rel < 1e-15 && delta.norm() <= 1e-9 * (xnorm + 1e-9) {
                converged = true;
                break;
            }
        } else {
            damping.reject();
            if !damping.lambda.is_finite() {
                break;
            }
        }
    }
    let camera = apply(&initial, &base, &x);
    let rms_px = (2.0 * cost / n as f64).sqrt();
    Ok(Calibration {
        camera,
        rms_px,
        iterations,
        converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        let rot = Rotation3::from_euler_angles(0.1, -0.2, 0.05).into_inner();
        Camera::new(
            500.0,
            480.0,
            320.0,
            240.0,
            rot,
            Vector3::new(0.1, -0.2, 3.0),
            640,
            480,
        )
    }

    fn grid_points() -> Vec<Vector3<f64>> {
        let mut v = Vec::new();
        for i in 0..3 {
            for j in 0..3 {
                for k in 0..3 {
                    v.push(Vector3::new(
                        i as f64 * 0.4 - 0.4,
                        j as f64 * 0.3 - 0.3,
                        k as f64 * 0.5 - 0.5,
                    ));
                }
            }
        }
        v
    }

    #[test]
    fn dlt_and_decomposition_recover_exact_camera() {
        let cam = camera();
        let pts = grid_points();
        let px: Vec<[f64; 2]> = pts
            .iter()
            .map(|p| cam.project(p).expect("in front"))
            .collect();
        let p = dlt(&pts, &px).expect("dlt");
        let (k, r, t) = decompose_projection(&p).expect("rq");
        assert!((k[(0, 0)] - 500.0).abs() < 1e-6, "{k}");
        assert!((k[(1, 1)] - 480.0).abs() < 1e-6, "{k}");
        assert!(
            (k[(0, 2)] - 320.0).abs() < 1e-6 && (k[(1, 2)] - 240.0).abs() < 1e-6,
            "{k}"
        );
        assert!(k[(0, 1)].abs() < 1e-6);
        assert!((r - cam.rotation).abs().max() < 1e-9, "{r}");
        assert!((t - cam.translation).norm() < 1e-9, "{t}");
        assert!((r.determinant() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn mismatched_lengths_and_nan_are_errors() {
        let pts = grid_points();
        let px = vec![[0.0, 0.0]; 5];
        assert!(matches!(
            dlt(&pts, &px),
            Err(CalibrationError::LengthMismatch { .. })
        ));
        let mut px: Vec<[f64; 2]> = pts
            .iter()
            .map(|p| camera().project(p).expect("front"))
            .collect();
        px[3][1] = f64::NAN;
        assert_eq!(
            calibrate(&pts, &px, 640, 480).expect_err("nan"),
            CalibrationError::NonFinite {
                what: "pixel",
                index: 3
            }
        );
    }
}
