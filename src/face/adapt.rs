//! Adaptation of the generic face mesh to a person from one or more photos with 68 landmarks
//! (seed report §5.2.1), with a backup of the model before every step and undo.
//!
//! This file owns the pipeline ([`FaceFit`], [`adapt`]) and its measure
//! ([`FaceFit::landmark_error_iod_pct`]); the steps' mathematics live in [`super::view_fit`]
//! (cameras and characteristic points), [`super::contour`] (silhouettes, sliding jaw points),
//! [`super::rbf`] and [`super::regions`] (the deformation).
//!
//! # Steps
//!
//! 1. [`FaceFit::calibrate_and_reconstruct`]: per-view cameras and the 3D characteristic points
//!    (bundle adjustment, [`super::view_fit::fit_views`]).
//! 2. [`FaceFit::adapt_contours`]: the mesh is deformed so that its characteristic landmarks go
//!    to the reconstructed points; then, ICP-like, in `contour_iterations` rounds: in every view
//!    the jaw landmarks are matched to the nearest point of the mesh's visible silhouette, each
//!    match gives a target — the landmark's line of sight at the matched point's depth — and
//!    (except after the last round, whose targets [`FaceFit::deform`] applies) the mesh is
//!    deformed again from the generic one with the characteristic and contour control points.
//!    Matches of several views (or landmarks) closer than `merge_radius` on the generic mesh are
//!    merged into one control point whose target minimises the summed squared distances to
//!    their lines of sight (plus a tiny pull to its current position), so a contour point only
//!    constrains the directions its views see.
//! 3. [`FaceFit::deform`]: the final RBF deformation of the whole generic mesh with all control
//!    points (region-separated, [`super::rbf::deform`]).
//! 4. [`FaceFit::refine_cameras`]: each camera refined on the deformed mesh's landmarks.
//!
//! Every step first pushes a snapshot (mesh, cameras, points, control points) on the history;
//! [`FaceFit::undo`] pops it. A step that fails leaves the state as it was, without a snapshot.

use nalgebra::Matrix3;

use super::contour::{match_jaw, silhouette};
use super::landmarks::{inter_ocular_distance, is_contour, landmark_positions, IBUG_POINTS};
use super::model::FaceMesh;
use super::rbf::{deform_smoothed, ControlPoint, DEFAULT_SUPPORT_FRACTION};
use super::regions::{landmark_region, FaceRegions, Region};
use super::view_fit::{
    fit_views, is_characteristic, landmark_normals, refine_cameras, validate_views, View,
    ViewFitOptions,
};
use super::FaceError;
use crate::geometry::Camera;
use crate::geometry::Vec3;

/// Settings of the adaptation.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptOptions {
    /// Settings of the camera and characteristic-point fit.
    pub view_fit: ViewFitOptions,
    /// RBF kernel support as a fraction of the generic face width
    /// ([`DEFAULT_SUPPORT_FRACTION`]).
    pub support_fraction: f64,
    /// RBF smoothing ([`super::rbf::Rbf::fit_smoothed`]): the reconstructed points carry noise
    /// and, with few views, depth errors; a little smoothing keeps the interpolant from
    /// overshooting between them (0 interpolates exactly; default 0.01, see [`super::rbf`]).
    pub rbf_smoothing: f64,
    /// Matching–deformation rounds of the contour step.
    pub contour_iterations: usize,
    /// A jaw landmark farther than this from the silhouette (as a fraction of the view's
    /// inter-ocular distance) is not matched in that round.
    pub contour_max_iod: f64,
    /// Contour matches closer than this on the generic mesh are merged (m).
    pub merge_radius: f64,
}

impl Default for AdaptOptions {
    fn default() -> Self {
        AdaptOptions {
            view_fit: ViewFitOptions::default(),
            support_fraction: DEFAULT_SUPPORT_FRACTION,
            rbf_smoothing: 0.01,
            contour_iterations: 5,
            contour_max_iod: 0.5,
            merge_radius: 0.004,
        }
    }
}

/// What a snapshot holds.
#[derive(Clone, Debug)]
struct Snapshot {
    step: &'static str,
    mesh: FaceMesh,
    cameras: Vec<Camera>,
    points: Vec<Vec3>,
    contour_controls: Vec<ControlPoint>,
    rms_px: Vec<f64>,
}

/// A face adaptation in progress: the generic mesh, the adapted one, the cameras and the
/// history of backups. Fields are public for reading; edit them only between steps.
#[derive(Clone, Debug)]
pub struct FaceFit {
    /// The generic mesh (never modified).
    pub generic: FaceMesh,
    /// The current adapted mesh.
    pub mesh: FaceMesh,
    /// The photos' landmarks.
    pub views: Vec<View>,
    /// One camera per view (empty before calibration).
    pub cameras: Vec<Camera>,
    /// The 68 reconstructed points (empty before calibration; contour ones are the generic's).
    pub points: Vec<Vec3>,
    /// The contour control points of the last contour round.
    pub contour_controls: Vec<ControlPoint>,
    /// Regions of the generic mesh's vertices.
    pub regions: FaceRegions,
    /// RMS reprojection error of the characteristic points per view after the last camera
    /// estimate (pixels).
    pub rms_px: Vec<f64>,
    /// The settings.
    pub options: AdaptOptions,
    history: Vec<Snapshot>,
}

impl FaceFit {
    /// Starts an adaptation: checks the views and the mesh (MediaPipe vertex order), labels the
    /// regions. The adapted mesh starts as the generic one.
    pub fn new(
        generic: &FaceMesh,
        views: &[View],
        options: &AdaptOptions,
    ) -> Result<FaceFit, FaceError> {
        validate_views(views)?;
        let regions = FaceRegions::mediapipe(generic)?;
        let positive = FaceError::require_positive;
        positive("support_fraction", options.support_fraction)?;
        positive("contour_max_iod", options.contour_max_iod)?;
        positive("merge_radius", options.merge_radius)?;
        if !(options.rbf_smoothing.is_finite() && options.rbf_smoothing >= 0.0) {
            return Err(FaceError::parameter(
                "rbf_smoothing",
                format!(
                    "must be finite and non-negative, got {}",
                    options.rbf_smoothing
                ),
            ));
        }
        Ok(FaceFit {
            generic: generic.clone(),
            mesh: generic.clone(),
            views: views.to_vec(),
            cameras: Vec::new(),
            points: Vec::new(),
            contour_controls: Vec::new(),
            regions,
            rms_px: Vec::new(),
            options: options.clone(),
            history: Vec::new(),
        })
    }

    fn snapshot(&self, step: &'static str) -> Snapshot {
        Snapshot {
            step,
            mesh: self.mesh.clone(),
            cameras: self.cameras.clone(),
            points: self.points.clone(),
            contour_controls: self.contour_controls.clone(),
            rms_px: self.rms_px.clone(),
        }
    }

    fn restore(&mut self, s: Snapshot) {
        self.mesh = s.mesh;
        self.cameras = s.cameras;
        self.points = s.points;
        self.contour_controls = s.contour_controls;
        self.rms_px = s.rms_px;
    }

    /// Runs `f` as a step: backup first, restore on error.
    fn step(
        &mut self,
        name: &'static str,
        f: impl FnOnce(&mut FaceFit) -> Result<(), FaceError>,
    ) -> Result<(), FaceError> {
        let backup = self.snapshot(name);
        match f(self) {
            Ok(()) => {
                self.history.push(backup);
                Ok(())
            }
            Err(e) => {
                self.restore(backup);
                Err(e)
            }
        }
    }

    /// Returns to the state before the last step; the name of the undone step, or an error
    /// when there is nothing to undo.
    pub fn undo(&mut self) -> Result<&'static str, FaceError> {
        let s = self.history.pop().ok_or_else(|| {
            FaceError::Failed("undo: nothing to undo (no adaptation step has been run)".into())
        })?;
        let step = s.step;
        self.restore(s);
        Ok(step)
    }

    /// Number of backups on the history (steps that can be undone).
    pub fn history_len(&self) -> usize {
        self.history.len()
    }

    /// Names of the steps on the history, oldest first.
    pub fn history_steps(&self) -> Vec<&'static str> {
        self.history.iter().map(|s| s.step).collect()
    }

    fn require_cameras(&self, step: &str) -> Result<(), FaceError> {
        validate_views(&self.views)?;
        if self.cameras.len() != self.views.len() || self.points.len() != IBUG_POINTS {
            return Err(FaceError::Failed(format!(
                "{step}: run calibrate_and_reconstruct first"
            )));
        }
        Ok(())
    }

    /// RBF support (m).
    fn support(&self) -> f64 {
        self.options.support_fraction * self.generic.width()
    }

    /// The generic mesh deformed by `controls` with the fit's regions and settings.
    fn deform_with(&self, controls: &[ControlPoint]) -> Result<FaceMesh, FaceError> {
        deform_smoothed(
            &self.generic,
            &self.regions,
            controls,
            self.support(),
            self.options.rbf_smoothing,
        )
    }

    /// Control points of the reconstructed characteristic points.
    pub fn characteristic_controls(&self) -> Vec<ControlPoint> {
        if self.points.len() != IBUG_POINTS {
            return Vec::new();
        }
        let g = landmark_positions(&self.generic);
        (0..IBUG_POINTS)
            .filter(|&i| is_characteristic(i))
            .map(|i| ControlPoint {
                position: g[i],
                displacement: self.points[i] - g[i],
                region: landmark_region(i),
            })
            .collect()
    }

    /// Step 1: cameras and 3D characteristic points ([`fit_views`]).
    pub fn calibrate_and_reconstruct(&mut self) -> Result<(), FaceError> {
        self.step("calibrate_and_reconstruct", |s| {
            let fit = fit_views(&s.generic, &s.views, &s.options.view_fit)?;
            s.cameras = fit.cameras;
            s.points = fit.points;
            s.rms_px = fit.rms_px;
            s.contour_controls.clear();
            Ok(())
        })
    }

    /// Step 2: contour adaptation (see the module docs).
    pub fn adapt_contours(&mut self) -> Result<(), FaceError> {
        self.require_cameras("adapt_contours")?;
        self.step("adapt_contours", |s| {
            let chars = s.characteristic_controls();
            s.mesh = s.deform_with(&chars)?;
            for round in 0..s.options.contour_iterations.max(1) {
                s.contour_controls = s.contour_targets();
                if round + 1 < s.options.contour_iterations {
                    let mut all = chars.clone();
                    all.extend(s.contour_controls.iter().cloned());
                    s.mesh = s.deform_with(&all)?;
                }
            }
            Ok(())
        })
    }

    /// Contour control points from the current mesh and cameras.
    fn contour_targets(&self) -> Vec<ControlPoint> {
        // (generic position, current position, target on the line of sight, ray direction)
        let mut matches: Vec<(Vec3, Vec3, Vec3, Vec3)> = Vec::new();
        for (view, cam) in self.views.iter().zip(&self.cameras) {
            let max_px = self.options.contour_max_iod * inter_ocular_distance(&view.landmarks);
            let found = match_jaw(&self.mesh, cam, &view.landmarks, max_px);
            let kinv = match cam.k_matrix().try_inverse() {
                Some(k) => k,
                None => continue,
            };
            for (i, m) in found.iter().enumerate() {
                let Some(m) = m else { continue };
                let p = m.position(&self.mesh);
                let depth = cam.to_camera_frame(&p).z;
                let l = view.landmarks[i];
                let ray_cam = kinv * Vec3::new(l[0], l[1], 1.0);
                let ray = cam.rotation.transpose() * ray_cam;
                let target = cam.center() + ray * depth;
                matches.push((m.position(&self.generic), p, target, ray.normalize()));
            }
        }
        // greedy merge of nearby matches
        let mut used = vec![false; matches.len()];
        let mut out = Vec::new();
        for k in 0..matches.len() {
            if used[k] {
                continue;
            }
            let group: Vec<usize> = (k..matches.len())
                .filter(|&j| {
                    !used[j] && (matches[j].0 - matches[k].0).norm() < self.options.merge_radius
                })
                .collect();
            let eps = 1e-3;
            let mut a = Matrix3::identity() * eps * group.len() as f64;
            let mut b = Vec3::zeros();
            let (mut gpos, mut cur) = (Vec3::zeros(), Vec3::zeros());
            for &j in &group {
                used[j] = true;
                let (g, p, t, d) = matches[j];
                let proj = Matrix3::identity() - d * d.transpose();
                a += proj;
                b += proj * t + p * eps;
                gpos += g;
                cur += p;
            }
            let n = group.len() as f64;
            gpos /= n;
            let q = a.lu().solve(&b).unwrap_or(cur / n);
            out.push(ControlPoint {
                position: gpos,
                displacement: q - gpos,
                region: Region::Other,
            });
        }
        out
    }

    /// Step 3: RBF deformation of the whole generic mesh with the characteristic and contour
    /// control points.
    pub fn deform(&mut self) -> Result<(), FaceError> {
        self.require_cameras("deform")?;
        self.step("deform", |s| {
            let mut all = s.characteristic_controls();
            all.extend(s.contour_controls.iter().cloned());
            s.mesh = s.deform_with(&all)?;
            Ok(())
        })
    }

    /// Step 4: refines every camera (pose, focal length) on the adapted mesh's landmarks.
    pub fn refine_cameras(&mut self) -> Result<(), FaceError> {
        self.require_cameras("refine_cameras")?;
        self.step("refine_cameras", |s| {
            let pts = landmark_positions(&s.mesh);
            let normals = landmark_normals(&s.mesh);
            s.rms_px = refine_cameras(
                &pts,
                &normals,
                &s.views,
                &mut s.cameras,
                &s.options.view_fit,
            )?;
            Ok(())
        })
    }

    /// Mean distance between view `view`'s landmarks and the adapted mesh's projected
    /// landmarks — a jaw landmark is measured to the projected silhouette — as a percentage of
    /// the inter-ocular distance (outer corners 36–45) of the given landmarks. NaN before
    /// calibration, for a view index out of range or a view without 68 landmarks.
    pub fn landmark_error_iod_pct(&self, view: usize) -> f64 {
        let (Some(v), Some(cam)) = (self.views.get(view), self.cameras.get(view)) else {
            return f64::NAN;
        };
        if v.landmarks.len() != IBUG_POINTS {
            return f64::NAN;
        }
        let iod = inter_ocular_distance(&v.landmarks);
        if iod.is_nan() || iod <= 0.0 {
            return f64::NAN;
        }
        let pts = landmark_positions(&self.mesh);
        let sil = silhouette(&self.mesh, cam);
        let mut sum = 0.0;
        for (i, l) in v.landmarks.iter().enumerate() {
            sum += if is_contour(i) {
                sil.distance(*l)
            } else {
                match cam.project(&pts[i]) {
                    Some(p) => ((p[0] - l[0]).powi(2) + (p[1] - l[1]).powi(2)).sqrt(),
                    None => f64::INFINITY,
                }
            };
        }
        100.0 * sum / v.landmarks.len() as f64 / iod
    }
}

/// The whole adaptation in one call: cameras and characteristic points, contour adaptation,
/// RBF deformation, camera refinement (each step undoable on the returned [`FaceFit`]).
pub fn adapt(
    generic: &FaceMesh,
    views: &[View],
    options: &AdaptOptions,
) -> Result<FaceFit, FaceError> {
    let mut fit = FaceFit::new(generic, views, options)?;
    fit.calibrate_and_reconstruct()?;
    fit.adapt_contours()?;
    fit.deform()?;
    fit.refine_cameras()?;
    Ok(fit)
}
