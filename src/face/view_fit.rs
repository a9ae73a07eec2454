//! Per-view camera estimation (pose and focal length) jointly with the 3D characteristic points,
//! from the 68 iBUG landmarks of one or more photos (seed report §5.2.1, first step).
//!
//! This file owns the input of the adaptation ([`View`] and its checks), the camera
//! initialisation ([`init_camera`]), the bundle adjustment ([`fit_views`]), the camera-only
//! refinement ([`refine_cameras`]) and the small Levenberg–Marquardt solver they share.
//!
//! # Method
//!
//! The unknowns are, per view, a camera with `fx = fy = f`, principal point at the image centre
//! and no distortion (rotation, translation, `f`), and the 3D positions of the *characteristic*
//! points: the 51 non-contour landmarks. The jaw points 0..=16 slide on the silhouette and are
//! left to [`super::contour`]. The world frame is the generic mesh's.
//!
//! 1. Each camera starts from a scaled-orthographic fit of the generic landmarks to the view's
//!    points (affine least squares, rows made orthonormal), with `f = initial_focal_factor ×
//!    max(width, height)` (or the known `focal`), then a Levenberg–Marquardt refinement of its
//!    pose and focal length, the latter under a weak log-normal prior around the start value;
//! 2. Bundle adjustment of all cameras and points minimises, in one least-squares sum,
//!    - the reprojection errors `(π_v(Xᵢ) − lᵢᵥ)/σ_px`, each weighted by `wᵢᵥ = clamp(nᵢ · eᵥ,
//!      min_view_weight, 1)`, the cosine between the generic normal at the point and the
//!      direction to camera `v`: a view that sees a point frontally has priority over one that
//!      sees it grazing;
//!    - a prior `(Xᵢ − Gᵢ)/σ_prior` pulling each point towards the generic landmark `Gᵢ`. It
//!      fixes the seven-parameter gauge (the reconstruction is the similarity-aligned one: the
//!      world scale is free, so this is the same as a prior towards the generic shape at the
//!      points' own scale) and, with a single view, a point's depth along its line of sight,
//!      which stays the generic one;
//!    - a soft symmetry tie `(Xᵢ − mirror(X_m))/σ_sym` for mirror pairs;
//!    - a prior `asin(a_y)/σ_pitch` on each camera's pitch, `a` being its optical axis in the
//!      generic face's frame (`y` up): photos are taken about at face level
//!      ([`ViewFitOptions::pitch_sigma_deg`], 10°). With one view, head pitch and the vertical
//!      proportions of the face are ambiguous — a longer nose and a lower mouth look like a
//!      head bent forward — and the shape prior alone resolves it by tilting the camera (by 17°
//!      on the synthetic test face of `tests/face_adapt.rs`: about 3 % vertex error, against 2.3 %
//!      with this prior and 1.3 % with the true camera); several views fix the pitch by
//!      themselves and make this prior negligible.
//!
//!    Central points (on the symmetry plane) have `x = 0` exactly: only `y, z` are unknowns.
//!
//! Jacobians are forward differences; the damping is Marquardt's (scaled diagonal). Nothing
//! panics on bad input: [`validate_views`] names the view and the point at fault.

use nalgebra::{Matrix3, Rotation3, SMatrix, Vector2};

use super::landmarks::{
    is_central, is_contour, landmark_positions, IBUG68_MIRROR, IBUG68_TO_MEDIAPIPE, IBUG_POINTS,
};
use super::model::{FaceMesh, MEDIAPIPE_VERTICES};
use super::FaceError;
use crate::geometry::least_squares::{
    self, DampingUpdate, DiagonalDamping, ForwardDifferences, Schedule, Tries,
};
use crate::geometry::Camera;
use crate::geometry::Vec3;

/// One photo of the face: its 68 iBUG landmarks in crate pixel coordinates (top-left pixel
/// centre at `(0, 0)`; subtract [`super::landmarks::PTS_PIXEL_ORIGIN`] from `.pts` values)
/// and its size.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    /// Name used in error messages (a file name, "frontal", …).
    pub name: String,
    /// The 68 landmarks (pixels).
    pub landmarks: Vec<[f64; 2]>,
    /// Image width (pixels).
    pub width: u32,
    /// Image height (pixels).
    pub height: u32,
}

impl View {
    /// A view from its parts.
    pub fn new(name: impl Into<String>, landmarks: Vec<[f64; 2]>, width: u32, height: u32) -> View {
        View {
            name: name.into(),
            landmarks,
            width,
            height,
        }
    }

    /// Checks the image size, the landmark count, finiteness, that every point is inside
    /// the image (one pixel of margin) and that the points can be a face
    /// ([`check_geometry`](super::landmarks::check_geometry): not piled up nor on a line).
    /// Errors name the view.
    pub fn validate(&self) -> Result<(), FaceError> {
        let err = |message: String| FaceError::Landmarks {
            source_name: format!("view `{}`", self.name),
            message,
        };
        if self.width == 0 || self.height == 0 {
            return Err(err(format!(
                "image size {}×{} is empty",
                self.width, self.height
            )));
        }
        if self.landmarks.len() != IBUG_POINTS {
            return Err(err(format!(
                "expected {IBUG_POINTS} landmarks (iBUG scheme), got {}",
                self.landmarks.len()
            )));
        }
        if let Some(i) = self
            .landmarks
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(err(format!("landmark {i} is not finite")));
        }
        // inside the image, one pixel of margin (crate coordinates: pixel centres 0..size-1)
        let (w, h) = (self.width as f64, self.height as f64);
        if let Some((i, p)) = self
            .landmarks
            .iter()
            .enumerate()
            .find(|(_, p)| !(p[0] >= -1.0 && p[0] <= w && p[1] >= -1.0 && p[1] <= h))
        {
            return Err(err(format!(
                "point {i} at ({:.1}, {:.1}) is outside the {}×{} image",
                p[0], p[1], self.width, self.height
            )));
        }
        super::landmarks::check_geometry(&self.landmarks, &format!("view `{}`", self.name))
    }
}

/// Checks a set of views: at least one, each valid ([`View::validate`]).
pub fn validate_views(views: &[View]) -> Result<(), FaceError> {
    if views.is_empty() {
        return Err(FaceError::parameter(
            "views",
            "no views: the adaptation needs at least one photo with landmarks",
        ));
    }
    views.iter().try_for_each(View::validate)
}

/// Settings of [`fit_views`] and [`refine_cameras`].
#[derive(Clone, Debug, PartialEq)]
pub struct ViewFitOptions {
    /// Landmark noise (pixels): the unit of the reprojection residuals.
    pub pixel_sigma: f64,
    /// Spread allowed to a characteristic point around the generic one (m).
    pub prior_sigma: f64,
    /// Spread allowed to the asymmetry of a mirror pair (m).
    pub symmetry_sigma: f64,
    /// Smallest weight of a residual seen grazing (the weight is the cosine of the angle
    /// between the generic normal and the direction to the camera).
    pub min_view_weight: f64,
    /// Levenberg–Marquardt iterations at most.
    pub iterations: usize,
    /// Starting focal length as a multiple of `max(width, height)`.
    pub initial_focal_factor: f64,
    /// Spread of the prior on `ln f` around the starting focal length: it keeps the focal
    /// length of a view with little perspective from running away (towards an orthographic
    /// camera at infinity), while several views still move it where they disagree.
    pub focal_log_sigma: f64,
    /// A known focal length (pixels, e.g. from the photo's EXIF data), kept fixed; `None`
    /// estimates it per view.
    pub focal: Option<f64>,
    /// Spread (degrees) of a prior on each camera's pitch — the elevation of its optical axis
    /// in the generic face's frame — around 0, a camera at face level (see the module docs);
    /// `None`: no prior. Not used by [`refine_cameras`], where the shape is fixed.
    pub pitch_sigma_deg: Option<f64>,
}

impl Default for ViewFitOptions {
    fn default() -> Self {
        ViewFitOptions {
            pixel_sigma: 1.0,
            prior_sigma: 0.01,
            symmetry_sigma: 0.003,
            min_view_weight: 0.15,
            iterations: 60,
            initial_focal_factor: 1.2,
            focal_log_sigma: 0.5,
            focal: None,
            pitch_sigma_deg: Some(10.0),
        }
    }
}

/// Result of [`fit_views`].
#[derive(Clone, Debug, PartialEq)]
pub struct ViewFit {
    /// One camera per view.
    pub cameras: Vec<Camera>,
    /// The 68 points in the generic mesh's frame: reconstructed for the characteristic points,
    /// the generic landmark for the contour points 0..=16 (left to the contour step).
    pub points: Vec<Vec3>,
    /// Root-mean-square reprojection error of the characteristic points, per view (pixels).
    pub rms_px: Vec<f64>,
    /// Bundle-adjustment iterations done.
    pub iterations: usize,
}

/// The starting (and prior) focal length of a view: the known one, or
/// `initial_focal_factor × max(width, height)`.
pub fn default_focal(view: &View, options: &ViewFitOptions) -> f64 {
    options
        .focal
        .unwrap_or(options.initial_focal_factor * view.width.max(view.height) as f64)
}

/// Whether iBUG point `i` is a characteristic point (reconstructed by [`fit_views`]).
pub fn is_characteristic(i: usize) -> bool {
    !is_contour(i)
}

/// Pinhole projection with the camera's `fx, fy, cx, cy` (no distortion; a point behind the
/// camera is pushed just in front so residuals stay finite).
fn project(c: &Camera, p: &Vec3) -> [f64; 2] {
    let q = c.rotation * p + c.translation;
    let z = q.z.max(1e-6);
    [c.fx * q.x / z + c.cx, c.fy * q.y / z + c.cy]
}

/// Weight of each (view, point): cosine between the normal and the direction to the camera.
fn view_weights(normals: &[Vec3], points: &[Vec3], camera: &Camera, min: f64) -> Vec<f64> {
    let c = camera.center();
    points
        .iter()
        .zip(normals)
        .map(|(p, n)| {
            let e = (c - p).normalize();
            n.dot(&e).clamp(min.clamp(1e-3, 1.0), 1.0)
        })
        .collect()
}

/// Generic normals at the 68 landmarks (mean of the pair's vertex normals).
pub fn landmark_normals(mesh: &FaceMesh) -> Vec<Vec3> {
    let n = mesh.vertex_normals();
    IBUG68_TO_MEDIAPIPE
        .iter()
        .map(|[a, b]| {
            let v = n[*a] + n[*b];
            v.try_normalize(1e-12).unwrap_or(Vec3::z())
        })
        .collect()
}

/// Dense Levenberg–Marquardt ([`least_squares::minimize`]) on a state `S` moved by
/// `apply(state, delta)`, with a forward-difference Jacobian of step `steps[k]` per parameter;
/// Marquardt's damping shifted by 1e-9 of the largest diagonal entry, `λ` from 1e-3, divided
/// by 3 (not below 1e-12) after an accepted step, times 4 after a rejected one, times 10 when
/// the damped system is not positive definite, tried while below 1e12; stops when a step
/// gains less than 1e-10 of the cost. Returns the state, its cost (half the squared residual
/// norm) and the iterations done.
pub(crate) fn levenberg_marquardt<S: Clone>(
    start: S,
    steps: &[f64],
    apply: &dyn Fn(&S, &[f64]) -> S,
    residual: &dyn Fn(&S) -> Vec<f64>,
    iterations: usize,
) -> (S, f64, usize) {
    let mut problem = ForwardDifferences {
        steps,
        apply,
        residual,
    };
    let schedule = Schedule {
        iterations,
        damping: (
            1e-3,
            DiagonalDamping::ShiftedRelative { relative: 1e-9 },
            DampingUpdate::Factors {
                down: 3.0,
                min: 1e-12,
                up: 4.0,
                singular: 10.0,
            },
        ),
        tries: Tries::WhileBelow(1e12),
        progress: |old, new| (old - new) / old.max(1e-300) > 1e-10,
    };
    let m = least_squares::minimize(&mut problem, start, &schedule);
    (m.state, m.cost, m.iterations)
}

/// Moves a camera by `(ω, δt, δf)`: rotation `exp(ω) R`, translation `t + δt`, `f + δf`.
fn move_camera(c: &Camera, d: &[f64], fix_focal: bool) -> Camera {
    let w = Vec3::new(d[0], d[1], d[2]);
    let mut out = c.clone();
    out.rotation = Rotation3::from_scaled_axis(w).matrix() * c.rotation;
    out.translation += Vec3::new(d[3], d[4], d[5]);
    if !fix_focal {
        out.fx = (c.fx + d[6]).max(1e-3);
    }
    out.fy = out.fx;
    out
}

/// Parameter steps of one camera for the numeric Jacobian.
fn camera_steps(c: &Camera) -> [f64; 7] {
    let h = 1e-6;
    [h, h, h, h, h, h, 1e-6 * c.fx.max(1.0)]
}

/// Scaled-orthographic start of a camera from 3D points and their images (the `used` ones),
/// focal length `focal`, principal point at the image centre; then a Levenberg–Marquardt
/// refinement of the pose and, unless `focal_log_sigma` is `None` (focal length fixed), of the
/// focal length under a prior `ln f ~ N(ln focal, focal_log_sigma²)`.
pub fn init_camera(
    points: &[Vec3],
    image: &[[f64; 2]],
    used: &[bool],
    width: u32,
    height: u32,
    focal: f64,
    focal_log_sigma: Option<f64>,
) -> Result<Camera, FaceError> {
    let fix_focal = focal_log_sigma.is_none();
    let idx: Vec<usize> = (0..points.len().min(image.len()))
        .filter(|&i| used.get(i).copied().unwrap_or(false))
        .collect();
    if idx.len() < 4 {
        return Err(FaceError::Failed(format!(
            "camera initialisation needs at least 4 points, got {}",
            idx.len()
        )));
    }
    let mean: Vec3 = idx.iter().map(|&i| points[i]).sum::<Vec3>() / idx.len() as f64;
    let mut mu = [0.0; 2];
    for &i in &idx {
        mu[0] += image[i][0] / idx.len() as f64;
        mu[1] += image[i][1] / idx.len() as f64;
    }
    let mut m = Matrix3::zeros();
    let mut rhs = SMatrix::<f64, 3, 2>::zeros();
    for &i in &idx {
        let d = points[i] - mean;
        m += d * d.transpose();
        for k in 0..2 {
            let col = d * (image[i][k] - mu[k]);
            rhs.set_column(k, &(rhs.column(k) + col));
        }
    }
    let inv = m
        .try_inverse()
        .ok_or_else(|| FaceError::Failed("camera initialisation: 3D points are coplanar".into()))?;
    let a = (inv * rhs).transpose(); // 2×3
    let svd = a.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return Err(FaceError::Failed(
            "camera initialisation: SVD failed".into(),
        ));
    };
    let s = 0.5 * (svd.singular_values[0] + svd.singular_values[1]);
    if !(s.is_finite() && s > 0.0) {
        return Err(FaceError::Failed(
            "camera initialisation: landmarks have no extent".into(),
        ));
    }
    let rows = u * vt; // 2×3 with orthonormal rows
    let r1: Vec3 = rows.row(0).transpose();
    let r2: Vec3 = rows.row(1).transpose();
    let rot = Matrix3::from_rows(&[r1.transpose(), r2.transpose(), r1.cross(&r2).transpose()]);
    let (cx, cy) = ((width as f64 - 1.0) * 0.5, (height as f64 - 1.0) * 0.5);
    let z0 = focal / s;
    let centre_cam = Vec3::new((mu[0] - cx) * z0 / focal, (mu[1] - cy) * z0 / focal, z0);
    let t = centre_cam - rot * mean;
    let cam = Camera::new(focal, focal, cx, cy, rot, t, width, height);
    let steps = camera_steps(&cam);
    let residual = |c: &Camera| -> Vec<f64> {
        let mut r: Vec<f64> = idx
            .iter()
            .flat_map(|&i| {
                let p = project(c, &points[i]);
                [p[0] - image[i][0], p[1] - image[i][1]]
            })
            .collect();
        if let Some(sigma) = focal_log_sigma {
            r.push((c.fx / focal).ln() / sigma);
        }
        r
    };
    let (cam, _, _) = levenberg_marquardt(
        cam,
        &steps,
        &|c, d| move_camera(c, d, fix_focal),
        &residual,
        100,
    );
    Ok(cam)
}

/// Refines each camera's pose and focal length with the 3D points fixed (the characteristic
/// ones of `points`, 68 in iBUG order), weighting residuals as [`fit_views`]; returns the RMS
/// reprojection error per view (pixels).
pub fn refine_cameras(
    points: &[Vec3],
    normals: &[Vec3],
    views: &[View],
    cameras: &mut [Camera],
    options: &ViewFitOptions,
) -> Result<Vec<f64>, FaceError> {
    validate_views(views)?;
    if cameras.len() != views.len() || points.len() != IBUG_POINTS || normals.len() != IBUG_POINTS {
        return Err(FaceError::parameter(
            "cameras",
            "one camera per view and 68 points with normals are needed",
        ));
    }
    let mut rms = Vec::new();
    for (view, cam) in views.iter().zip(cameras.iter_mut()) {
        let w = view_weights(normals, points, cam, options.min_view_weight);
        let steps = camera_steps(cam);
        let f0 = default_focal(view, options);
        let residual = |c: &Camera| -> Vec<f64> {
            let mut r: Vec<f64> = (0..IBUG_POINTS)
                .filter(|&i| is_characteristic(i))
                .flat_map(|i| {
                    let p = project(c, &points[i]);
                    let s = w[i].sqrt() / options.pixel_sigma;
                    [
                        (p[0] - view.landmarks[i][0]) * s,
                        (p[1] - view.landmarks[i][1]) * s,
                    ]
                })
                .collect();
            if options.focal.is_none() {
                r.push((c.fx / f0).ln() / options.focal_log_sigma);
            }
            r
        };
        let (c, _, _) = levenberg_marquardt(
            cam.clone(),
            &steps,
            &|c, d| move_camera(c, d, options.focal.is_some()),
            &residual,
            options.iterations,
        );
        *cam = c;
        rms.push(reprojection_rms(points, view, cam));
    }
    Ok(rms)
}

/// RMS distance (pixels) between a view's characteristic landmarks and the projected points.
pub fn reprojection_rms(points: &[Vec3], view: &View, camera: &Camera) -> f64 {
    let mut s = 0.0;
    let mut n = 0;
    for i in (0..IBUG_POINTS).filter(|&i| is_characteristic(i)) {
        let p = project(camera, &points[i]);
        s += (Vector2::new(p[0], p[1]) - Vector2::new(view.landmarks[i][0], view.landmarks[i][1]))
            .norm_squared();
        n += 1;
    }
    (s / n.max(1) as f64).sqrt()
}

/// State of the bundle adjustment.
#[derive(Clone)]
struct BaState {
    cameras: Vec<Camera>,
    points: Vec<Vec3>,
}

/// Estimates every view's camera and the 3D characteristic points jointly, starting from the
/// generic mesh (MediaPipe vertex order) — see the module docs.
pub fn fit_views(
    generic: &FaceMesh,
    views: &[View],
    options: &ViewFitOptions,
) -> Result<ViewFit, FaceError> {
    validate_views(views)?;
    if generic.positions.len() != MEDIAPIPE_VERTICES {
        return Err(FaceError::parameter(
            "generic",
            format!(
                "the landmark table needs the MediaPipe mesh ({MEDIAPIPE_VERTICES} vertices), \
                 got {}",
                generic.positions.len()
            ),
        ));
    }
    generic.validate("generic mesh")?;
    let positive = FaceError::require_positive;
    positive("pixel_sigma", options.pixel_sigma)?;
    positive("prior_sigma", options.prior_sigma)?;
    positive("symmetry_sigma", options.symmetry_sigma)?;
    positive("initial_focal_factor", options.initial_focal_factor)?;
    positive("focal_log_sigma", options.focal_log_sigma)?;
    if let Some(f) = options.focal {
        positive("focal", f)?;
    }
    if let Some(p) = options.pitch_sigma_deg {
        positive("pitch_sigma_deg", p)?;
    }
    let g = landmark_positions(generic);
    let normals = landmark_normals(generic);
    let used: Vec<bool> = (0..IBUG_POINTS).map(is_characteristic).collect();
    let mut cameras = Vec::with_capacity(views.len());
    for v in views {
        let f0 = default_focal(v, options);
        let prior = options.focal.is_none().then_some(options.focal_log_sigma);
        let cam = init_camera(&g, &v.landmarks, &used, v.width, v.height, f0, prior)
            .map_err(|e| FaceError::Failed(format!("view `{}`: {e}", v.name)))?;
        cameras.push(cam);
    }
    let focal0: Vec<f64> = views.iter().map(|v| default_focal(v, options)).collect();
    let weights: Vec<Vec<f64>> = cameras
        .iter()
        .map(|c| view_weights(&normals, &g, c, options.min_view_weight))
        .collect();
    // parameter layout: 7 per camera, then (x,)y,z per characteristic point
    let mut layout: Vec<(usize, usize)> = Vec::new(); // (point, coordinate)
    for i in (0..IBUG_POINTS).filter(|&i| is_characteristic(i)) {
        for k in 0..3 {
            if k == 0 && is_central(i) {
                continue;
            }
            layout.push((i, k));
        }
    }
    let nc = 7 * views.len();
    let mut steps: Vec<f64> = cameras.iter().flat_map(camera_steps).collect();
    steps.extend(std::iter::repeat_n(1e-6, layout.len()));
    let mut start_points = g.clone();
    for i in 0..IBUG_POINTS {
        if is_central(i) {
            start_points[i].x = 0.0;
        }
    }
    let start = BaState {
        cameras,
        points: start_points,
    };
    let apply = |s: &BaState, d: &[f64]| -> BaState {
        let mut out = s.clone();
        for (v, c) in out.cameras.iter_mut().enumerate() {
            if d[7 * v..7 * v + 7].iter().any(|x| *x != 0.0) {
                *c = move_camera(&s.cameras[v], &d[7 * v..7 * v + 7], options.focal.is_some());
            }
        }
        for (k, &(i, j)) in layout.iter().enumerate() {
            out.points[i][j] += d[nc + k];
        }
        out
    };
    let pairs: Vec<(usize, usize)> = (0..IBUG_POINTS)
        .filter(|&i| is_characteristic(i) && !is_central(i) && i < IBUG68_MIRROR[i])
        .map(|i| (i, IBUG68_MIRROR[i]))
        .collect();
    let residual = |s: &BaState| -> Vec<f64> {
        let mut r = Vec::new();
        for (v, view) in views.iter().enumerate() {
            for i in (0..IBUG_POINTS).filter(|&i| is_characteristic(i)) {
                let p = project(&s.cameras[v], &s.points[i]);
                let w = weights[v][i].sqrt() / options.pixel_sigma;
                r.push((p[0] - view.landmarks[i][0]) * w);
                r.push((p[1] - view.landmarks[i][1]) * w);
            }
        }
        for i in (0..IBUG_POINTS).filter(|&i| is_characteristic(i)) {
            let d = (s.points[i] - g[i]) / options.prior_sigma;
            r.extend_from_slice(d.as_slice());
        }
        if options.focal.is_none() {
            for (c, f0) in s.cameras.iter().zip(&focal0) {
                r.push((c.fx / f0).ln() / options.focal_log_sigma);
            }
        }
        if let Some(sp) = options.pitch_sigma_deg {
            for c in &s.cameras {
                r.push(c.rotation[(2, 1)].clamp(-1.0, 1.0).asin() / sp.to_radians());
            }
        }
        for &(i, m) in &pairs {
            let (a, b) = (s.points[i], s.points[m]);
            let d = Vec3::new(a.x + b.x, a.y - b.y, a.z - b.z) / options.symmetry_sigma;
            r.extend_from_slice(d.as_slice());
        }
        r
    };
    let (state, _, iterations) =
        levenberg_marquardt(start, &steps, &apply, &residual, options.iterations);
    let rms_px = views
        .iter()
        .zip(&state.cameras)
        .map(|(v, c)| reprojection_rms(&state.points, v, c))
        .collect();
    Ok(ViewFit {
        cameras: state.cameras,
        points: state.points,
        rms_px,
        iterations,
    })
}
