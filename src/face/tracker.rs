//! Tracking of head pose and expression in a multi-camera image sequence (seed §5.2.2): the
//! model, pre-positioned on the first frame, is textured from the first frame's images; then
//! per frame the rigid pose is found by Gauss–Newton on the photometric error and the
//! expression (FAP values) by simulated annealing, warm-started from the previous frame.
//!
//! The photometric error is measured on [surface samples](super::samples): points fixed on the
//! mesh, one per cell of a grid over the texture layout, each with the grey level learnt for it
//! on frame 0 (a weighted mean over the cameras that see it, weighted by how frontally). For a
//! pose and FAP values, a sample's residual in a camera is `g · I(π(X)) − c`, with `I` the
//! frame's grey image, `π` the projection, `g` the camera's lighting gain (least squares, per
//! frame) and `c` the learnt grey; the cost is `Σ w ρ(r)`, `ρ` Geman–McClure of scale
//! `robust_sigma`, `w` the sample's visibility weight (z-buffer test and the cosine of the
//! viewing angle, updated each frame at the predicted pose). No rendering in the loop: the
//! Jacobian of the rigid step is analytic (image gradient × projection × rotation about the
//! pivot), the annealing cost only re-projects the samples that the tracked FAPs move.
//!
//! Per frame: prediction (damped constant velocity), Gauss–Newton with Levenberg damping on a
//! half-resolution image then at full resolution, annealing of the FAP values (coarse layers
//! first; FAPs whose zones overlap searched together), a few Gauss–Newton steps on all FAP
//! values (the rig is linear, so their Jacobian is the image gradient times the turned unit
//! fields), a last Gauss–Newton pass on the pose. Deterministic: one seeded generator per frame, costs
//! pure, reductions in a fixed order.

use std::cell::RefCell;

use nalgebra::{Matrix6, Vector6};

use super::fap::FapRig;
use super::head_pose::{head_pivot, HeadPose};
use super::model::FaceMesh;
use super::samples::SurfaceSamples;
use super::FaceError;
use crate::geometry::image::GradientImage;
use crate::geometry::least_squares::{Attempt, Damping, DampingUpdate, DiagonalDamping, Tries};
use crate::geometry::Camera;
use crate::geometry::{SplitMix64, Vec3};
use crate::render::raster::{draw_triangles, project_vertices, RasterTarget};
use crate::tracking::annealing::{anneal, AnnealScratch, AnnealSettings};
use image::RgbImage;

/// Settings of the face tracker.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct FaceTrackerOptions {
    /// Cells per side of the sample grid over the texture layout. Default 100 (about 6,500
    /// samples on the canonical face).
    pub sample_grid: usize,
    /// Gauss–Newton iterations at half resolution. Default 5.
    pub gn_coarse: usize,
    /// Gauss–Newton iterations at full resolution, before and after the FAP search. Default 4.
    pub gn_fine: usize,
    /// Particles of the FAP annealing. Default 24.
    pub particles: usize,
    /// Annealing layers (the first half at half resolution). Default 4.
    pub layers: usize,
    /// Initial annealing spread, as a fraction of each FAP's range. Default 0.12.
    pub fap_spread: f64,
    /// Gauss–Newton iterations polishing the FAP values after the annealing. Default 3.
    pub fap_refine: usize,
    /// Fraction of the last frame-to-frame motion added to the prediction. Default 0.7.
    pub prediction: f64,
    /// Scale of the robust error (grey levels). Default 20.
    pub robust_sigma: f64,
    /// Seed of the annealing.
    pub seed: u64,
}

impl Default for FaceTrackerOptions {
    fn default() -> Self {
        FaceTrackerOptions {
            sample_grid: 100,
            gn_coarse: 5,
            gn_fine: 4,
            particles: 24,
            layers: 4,
            fap_spread: 0.12,
            fap_refine: 3,
            prediction: 0.7,
            robust_sigma: 20.0,
            seed: 7,
        }
    }
}

impl FaceTrackerOptions {
    /// Checks the settings; the error names the parameter.
    pub fn validate(&self) -> Result<(), FaceError> {
        let p = FaceError::parameter;
        if !(16..=1024).contains(&self.sample_grid) {
            return Err(p(
                "sample_grid",
                format!("must be 16..=1024, got {}", self.sample_grid),
            ));
        }
        if self.fap_refine > 100 {
            return Err(p(
                "fap_refine",
                format!("must be 0..=100, got {}", self.fap_refine),
            ));
        }
        if self.gn_coarse + self.gn_fine == 0 || self.gn_coarse > 100 || self.gn_fine > 100 {
            return Err(p("gn_coarse/gn_fine", "0..=100 each, not both 0".into()));
        }
        if !(2..=4096).contains(&self.particles) || !(1..=32).contains(&self.layers) {
            return Err(p(
                "particles/layers",
                "particles 2..=4096, layers 1..=32".into(),
            ));
        }
        for (n, v) in [
            ("fap_spread", self.fap_spread),
            ("prediction", self.prediction),
            ("robust_sigma", self.robust_sigma),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(p(n, format!("must be finite and ≥ 0, got {v}")));
            }
        }
        if self.robust_sigma <= 0.0 || self.prediction > 1.5 {
            return Err(p(
                "robust_sigma/prediction",
                "robust_sigma > 0, prediction ≤ 1.5".into(),
            ));
        }
        Ok(())
    }
}

/// One camera's images and per-frame state.
struct View {
    cam: [Camera; 2],
    img: [GradientImage; 2],
    gain: f64,
    /// Visibility weight of each sample (0: not seen).
    vis: Vec<f32>,
}

/// Tracked FAPs whose zones overlap, and the samples they move.
#[derive(Clone, Debug)]
struct FapGroup {
    /// Indices into the tracked FAPs.
    members: Vec<usize>,
    /// Samples moved by any member.
    active: Vec<usize>,
}

/// The residual `g · I(π(p)) − c` of a sample at world point `p` in view `v` (pyramid
/// `level`), and the gradient of `g · I(π(p))` with respect to `p` in world axes (image
/// gradient × projection, distortion ignored); `None` behind the camera or off the image.
#[inline]
fn residual_and_gradient(v: &View, level: usize, p: &Vec3, c: f32) -> Option<(f64, Vec3)> {
    let cam = &v.cam[level];
    let pc = cam.to_camera_frame(p);
    if pc.z <= 0.0 {
        return None;
    }
    let (u, w) = (cam.fx * pc.x / pc.z + cam.cx, cam.fy * pc.y / pc.z + cam.cy);
    let (i, ix, iy) = v.img[level].sample(u, w)?;
    let g = v.gain;
    let r = g * i as f64 - c as f64;
    let (ix, iy, z) = (g * ix as f64, g * iy as f64, pc.z);
    let d_pc = Vec3::new(
        ix * cam.fx / z,
        iy * cam.fy / z,
        -(ix * cam.fx * pc.x + iy * cam.fy * pc.y) / (z * z),
    );
    Some((r, cam.rotation.transpose() * d_pc))
}

/// Per-thread buffers of the annealing cost.
#[derive(Default)]
struct CostScratch {
    values: Vec<f64>,
    deformed: Vec<Vec3>,
}

thread_local! {
    static COST_SCRATCH: RefCell<CostScratch> = RefCell::new(CostScratch::default());
}

/// The tracker's state between frames.
pub struct FaceTracker {
    options: FaceTrackerOptions,
    mesh: FaceMesh,
    rig: FapRig,
    /// Rig indices of the tracked FAPs.
    tracked: Vec<usize>,
    ranges: Vec<(f64, f64)>,
    samples: SurfaceSamples,
    /// Learnt grey of each sample at full and half resolution (NaN: never seen).
    colours: [Vec<f32>; 2],
    /// Groups of tracked FAPs searched together.
    groups: Vec<FapGroup>,
    /// Displacement of every vertex per unit of each tracked FAP (the rig is linear).
    unit_fields: Vec<Vec<Vec3>>,
    /// Samples moved by some tracked FAP.
    fap_active: Vec<usize>,
    pivot: Vec3,
    pose: HeadPose,
    faps: Vec<f64>,
    previous: Option<(HeadPose, Vec<f64>)>,
    views: Vec<View>,
    raster: RasterTarget,
    projected: Vec<[f32; 3]>,
    deformed: Vec<Vec3>,
    posed: Vec<Vec3>,
    sample_pos: Vec<Vec3>,
    sample_nrm: Vec<Vec3>,
    anneal_scratch: AnnealScratch,
    frame: usize,
    /// Seconds spent per stage over all frames: images, visibility, rigid, expression.
    stage_seconds: [f64; 4],
}

/// Names of the tracker's stages, in the order of [`FaceTracker::stage_seconds`].
pub const STAGES: [&str; 4] = ["images", "visibility", "pose", "expression"];

/// What the tracker found for one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceFrameResult {
    /// Head pose.
    pub pose: HeadPose,
    /// Tracked FAP values, in the order of the tracked FAP numbers.
    pub faps: Vec<f64>,
    /// Final photometric cost (mean robust error per visible sample, 0..1).
    pub cost: f64,
}

impl FaceTracker {
    /// A tracker for `mesh` (the neutral adapted model, MediaPipe vertex order) and `cameras`,
    /// tracking the FAPs numbered `faps` (their order is the order of the results), starting
    /// from `pose` and `fap_values` on the first frame.
    pub fn new(
        mesh: &FaceMesh,
        cameras: &[Camera],
        faps: &[u8],
        pose: HeadPose,
        fap_values: &[f64],
        options: &FaceTrackerOptions,
    ) -> Result<FaceTracker, FaceError> {
        options.validate()?;
        mesh.validate("model")?;
        if cameras.is_empty() {
            return Err(FaceError::parameter(
                "cameras",
                "at least one camera is needed",
            ));
        }
        let (w0, h0) = (cameras[0].width, cameras[0].height);
        if let Some(k) = cameras.iter().position(|c| (c.width, c.height) != (w0, h0)) {
            return Err(FaceError::parameter(
                "cameras",
                format!(
                    "camera {k} has images of {}×{}, camera 0 of {w0}×{h0}: all must be the same size",
                    cameras[k].width, cameras[k].height
                ),
            ));
        }
        if w0 < 16 || h0 < 16 {
            return Err(FaceError::parameter(
                "cameras",
                format!("images of {w0}×{h0} are too small to track in (at least 16×16)"),
            ));
        }
        if fap_values.len() != faps.len() {
            return Err(FaceError::parameter(
                "fap_values",
                format!("{} values for {} FAPs", fap_values.len(), faps.len()),
            ));
        }
        let rig = FapRig::new(mesh)?;
        let mut tracked = Vec::new();
        for &n in faps {
            tracked.push(rig.index_of(n).ok_or_else(|| {
                FaceError::parameter("faps", format!("FAP {n} is not in the rig"))
            })?);
        }
        let ranges: Vec<(f64, f64)> = tracked.iter().map(|&i| rig.faps[i].range).collect();
        let mut values = vec![0.0; rig.len()];
        for (&i, &v) in tracked.iter().zip(fap_values) {
            if !v.is_finite() {
                return Err(FaceError::parameter("fap_values", "not finite"));
            }
            values[i] = v;
        }
        let samples = SurfaceSamples::on_texture_grid(mesh, options.sample_grid);
        // FAPs whose zones overlap are searched together; each group's cost reads only the
        // samples its FAPs move
        let mut moves: Vec<Vec<bool>> = Vec::new();
        let mut unit_fields: Vec<Vec<Vec3>> = Vec::new();
        let mut probe = vec![0.0; rig.len()];
        let mut moved = Vec::new();
        for &i in &tracked {
            probe[i] = 1.0;
            rig.apply(&mesh.positions, &probe, &mut moved);
            probe[i] = 0.0;
            unit_fields.push(
                moved
                    .iter()
                    .zip(&mesh.positions)
                    .map(|(a, b)| a - b)
                    .collect(),
            );
            moves.push(
                moved
                    .iter()
                    .zip(&mesh.positions)
                    .map(|(a, b)| a != b)
                    .collect(),
            );
        }
        let mut group_of: Vec<usize> = (0..tracked.len()).collect();
        for a in 0..tracked.len() {
            for b in 0..a {
                if moves[a].iter().zip(&moves[b]).any(|(x, y)| *x && *y) {
                    let (ga, gb) = (group_of[a], group_of[b]);
                    for g in group_of.iter_mut() {
                        if *g == ga {
                            *g = gb;
                        }
                    }
                }
            }
        }
        let mut any_moving = vec![false; mesh.vertex_count()];
        for m in &moves {
            for (a, x) in any_moving.iter_mut().zip(m) {
                *a |= *x;
            }
        }
        let fap_active = samples.touching(&mesh.triangles, &any_moving);
        let mut groups = Vec::new();
        for g in 0..tracked.len() {
            let members: Vec<usize> = (0..tracked.len()).filter(|&k| group_of[k] == g).collect();
            if members.is_empty() {
                continue;
            }
            let mut moving = vec![false; mesh.vertex_count()];
            for &k in &members {
                for (m, x) in moving.iter_mut().zip(&moves[k]) {
                    *m |= *x;
                }
            }
            let active = samples.touching(&mesh.triangles, &moving);
            groups.push(FapGroup { members, active });
        }
        let (w, h) = (cameras[0].width as usize, cameras[0].height as usize);
        let views = cameras
            .iter()
            .map(|c| View {
                cam: [c.clone(), c.scaled(2.0)],
                img: [GradientImage::default(), GradientImage::default()],
                gain: 1.0,
                vis: Vec::new(),
            })
            .collect();
        Ok(FaceTracker {
            options: options.clone(),
            pivot: head_pivot(mesh),
            mesh: mesh.clone(),
            rig,
            tracked,
            ranges,
            colours: [Vec::new(), Vec::new()],
            groups,
            unit_fields,
            fap_active,
            samples,
            pose,
            faps: values,
            previous: None,
            views,
            raster: RasterTarget::new(w, h),
            projected: Vec::new(),
            deformed: Vec::new(),
            posed: Vec::new(),
            sample_pos: Vec::new(),
            sample_nrm: Vec::new(),
            anneal_scratch: AnnealScratch::default(),
            frame: 0,
            stage_seconds: [0.0; 4],
        })
    }

    /// Number of surface samples.
    pub fn sample_count(&self) -> usize {
        self.samples.len()
    }

    /// Fraction of samples seen by at least one camera on the first frame.
    pub fn seen_fraction(&self) -> f64 {
        let seen = self.colours[0].iter().filter(|c| c.is_finite()).count();
        seen as f64 / self.samples.len().max(1) as f64
    }

    fn load_images(&mut self, images: &[RgbImage]) -> Result<(), FaceError> {
        if images.len() != self.views.len() {
            return Err(FaceError::parameter(
                "images",
                format!("{} images for {} cameras", images.len(), self.views.len()),
            ));
        }
        for (k, (v, img)) in self.views.iter_mut().zip(images).enumerate() {
            if img.width() != v.cam[0].width || img.height() != v.cam[0].height {
                return Err(FaceError::parameter(
                    "images",
                    format!(
                        "camera {k}: image {}×{}, camera {}×{}",
                        img.width(),
                        img.height(),
                        v.cam[0].width,
                        v.cam[0].height
                    ),
                ));
            }
            let [fine, coarse] = &mut v.img;
            fine.set_from_rgb(img, 0.8);
            coarse.set_half_of(fine, 1.0);
        }
        Ok(())
    }

    /// Posed vertices and sample positions/normals for the current pose and FAPs.
    fn pose_samples(&mut self) {
        self.rig
            .apply(&self.mesh.positions, &self.faps, &mut self.deformed);
        self.pose
            .apply(&self.pivot, &self.deformed, &mut self.posed);
        self.samples
            .positions(&self.posed, &self.mesh.triangles, &mut self.sample_pos);
        self.samples
            .normals(&self.posed, &self.mesh.triangles, &mut self.sample_nrm);
    }

    /// Visibility weights of the samples in every view at the current pose.
    fn update_visibility(&mut self) {
        self.pose_samples();
        let dummy = vec![[0.0f32; 3]; self.posed.len()];
        for v in &mut self.views {
            let cam = &v.cam[0];
            self.raster.clear();
            project_vertices(cam, &self.posed, &mut self.projected);
            draw_triangles(
                &mut self.raster,
                &self.projected,
                &dummy,
                &self.mesh.triangles,
            );
            let centre = cam.center();
            v.vis.clear();
            for (p, n) in self.sample_pos.iter().zip(&self.sample_nrm) {
                let to_cam = centre - p;
                let cos = n.dot(&to_cam) / to_cam.norm();
                let mut w = 0.0;
                if cos > 0.2 {
                    if let Some(uv) = cam.project(p) {
                        let (x, y) = (uv[0].round(), uv[1].round());
                        if x >= 0.0
                            && y >= 0.0
                            && (x as usize) < self.raster.width
                            && (y as usize) < self.raster.height
                        {
                            let z = cam.to_camera_frame(p).z as f32;
                            let zb = self.raster.depth[y as usize * self.raster.width + x as usize];
                            if z <= zb + 0.004 {
                                w = cos as f32;
                            }
                        }
                    }
                }
                v.vis.push(w);
            }
        }
    }

    /// Learns the samples' grey levels from the current images at the current pose.
    fn learn_colours(&mut self) {
        self.update_visibility();
        for level in 0..2 {
            let mut c = vec![f32::NAN; self.samples.len()];
            for (s, out) in c.iter_mut().enumerate() {
                let (mut acc, mut wsum) = (0.0f64, 0.0f64);
                for v in &self.views {
                    let w = (v.vis[s] as f64).powi(2);
                    if w <= 0.0 {
                        continue;
                    }
                    if let Some(uv) = v.cam[level].project(&self.sample_pos[s]) {
                        if let Some(i) = v.img[level].value_at(uv[0], uv[1]) {
                            acc += w * i as f64;
                            wsum += w;
                        }
                    }
                }
                if wsum > 0.0 {
                    *out = (acc / wsum) as f32;
                }
            }
            self.colours[level] = c;
        }
    }

    /// Least-squares lighting gain of each view at the current pose.
    fn update_gains(&mut self, level: usize) {
        for v in &mut self.views {
            let (mut num, mut den) = (0.0, 0.0);
            for (s, p) in self.sample_pos.iter().enumerate() {
                let c = self.colours[level][s];
                if v.vis[s] <= 0.0 || !c.is_finite() {
                    continue;
                }
                if let Some(uv) = v.cam[level].project(p) {
                    if let Some(i) = v.img[level].value_at(uv[0], uv[1]) {
                        num += v.vis[s] as f64 * i as f64 * c as f64;
                        den += v.vis[s] as f64 * (i as f64).powi(2);
                    }
                }
            }
            v.gain = if den > 0.0 {
                (num / den).clamp(0.5, 2.0)
            } else {
                1.0
            };
        }
    }

    /// Robust cost of all samples at the current pose and FAPs, at `level`.
    fn rigid_cost(&self, level: usize) -> (f64, f64) {
        let s2 = self.options.robust_sigma.powi(2);
        let (mut cost, mut wsum) = (0.0, 0.0);
        for v in &self.views {
            for (s, p) in self.sample_pos.iter().enumerate() {
                let c = self.colours[level][s];
                let w = v.vis[s] as f64;
                if w <= 0.0 || !c.is_finite() {
                    continue;
                }
                if let Some(uv) = v.cam[level].project(p) {
                    let r = match v.img[level].value_at(uv[0], uv[1]) {
                        Some(i) => v.gain * i as f64 - c as f64,
                        None => 255.0,
                    };
                    cost += w * r * r / (s2 + r * r);
                    wsum += w;
                }
            }
        }
        (cost, wsum)
    }

    /// Gauss–Newton (Levenberg-damped) on the rigid pose at `level`.
    fn gauss_newton(&mut self, level: usize, iterations: usize) {
        let s2 = self.options.robust_sigma.powi(2);
        let mut damping = pose_damping(1e-9, 0.0);
        self.pose_samples();
        let mut current = self.rigid_cost(level).0;
        for _ in 0..iterations {
            let mut h = Matrix6::<f64>::zeros();
            let mut b = Vector6::<f64>::zeros();
            let centre = self.pivot + self.pose.translation;
            for v in &self.views {
                for (s, p) in self.sample_pos.iter().enumerate() {
                    let c = self.colours[level][s];
                    let wv = v.vis[s] as f64;
                    if wv <= 0.0 || !c.is_finite() {
                        continue;
                    }
                    let Some((r, a)) = residual_and_gradient(v, level, p, c) else {
                        continue;
                    };
                    let jw = (p - centre).cross(&a);
                    let j = Vector6::new(jw.x, jw.y, jw.z, a.x, a.y, a.z);
                    // IRLS weight of Geman–McClure
                    let q = s2 + r * r;
                    let wr = wv * s2 * s2 / (q * q);
                    h += wr * j * j.transpose();
                    b += wr * r * j;
                }
            }
            let saved = self.pose;
            let improved = damping.try_steps(&h, &b, Tries::Count(4), |delta| {
                self.pose = saved.perturbed(
                    &Vec3::new(delta[0], delta[1], delta[2]),
                    &Vec3::new(delta[3], delta[4], delta[5]),
                );
                self.pose_samples();
                let c = self.rigid_cost(level).0;
                if c < current {
                    current = c;
                    return Attempt::Accepted { gain_ratio: 1.0 };
                }
                self.pose = saved;
                Attempt::Rejected
            });
            if !improved {
                self.pose_samples();
                break;
            }
            self.update_gains(level);
        }
    }

    /// Gauss–Newton (Levenberg-damped) polish of the tracked FAP values after the annealing,
    /// all together, at `level`: the rig is linear, so a sample's motion per FAP unit is the
    /// barycentric mix of its triangle's unit fields, turned by the head rotation.
    fn refine_faps(&mut self, level: usize, iterations: usize) {
        let n = self.tracked.len();
        if n == 0 || iterations == 0 {
            return;
        }
        let s2 = self.options.robust_sigma.powi(2);
        let mut damping = pose_damping(1e-12, 1e-12);
        self.pose_samples();
        let mut current = self.rigid_cost(level).0;
        let mut h = nalgebra::DMatrix::<f64>::zeros(n, n);
        let mut b = nalgebra::DVector::<f64>::zeros(n);
        let mut j = nalgebra::DVector::<f64>::zeros(n);
        for _ in 0..iterations {
            h.fill(0.0);
            b.fill(0.0);
            let rot = *self.pose.rotation.matrix();
            for v in &self.views {
                for &s in &self.fap_active {
                    let c = self.colours[level][s];
                    let wv = v.vis[s] as f64;
                    if wv <= 0.0 || !c.is_finite() {
                        continue;
                    }
                    let Some((r, a)) = residual_and_gradient(v, level, &self.sample_pos[s], c)
                    else {
                        continue;
                    };
                    // the gradient in the head's (model) axes
                    let a = rot.transpose() * a;
                    let t = self.mesh.triangles[self.samples.triangle[s] as usize];
                    let bc = self.samples.bary[s];
                    for (k, field) in self.unit_fields.iter().enumerate() {
                        let d = field[t[0] as usize] * bc[0]
                            + field[t[1] as usize] * bc[1]
                            + field[t[2] as usize] * bc[2];
                        j[k] = a.dot(&d);
                    }
                    let q = s2 + r * r;
                    let wr = wv * s2 * s2 / (q * q);
                    h.ger(wr, &j, &j, 1.0);
                    b.axpy(wr * r, &j, 1.0);
                }
            }
            let saved: Vec<f64> = self.tracked.iter().map(|&i| self.faps[i]).collect();
            let improved = damping.try_steps(&h, &b, Tries::Count(4), |delta| {
                for (k, (&i, (lo, hi))) in self.tracked.iter().zip(&self.ranges).enumerate() {
                    self.faps[i] = (saved[k] + delta[k]).clamp(*lo, *hi);
                }
                self.pose_samples();
                let c = self.rigid_cost(level).0;
                if c < current {
                    current = c;
                    return Attempt::Accepted { gain_ratio: 1.0 };
                }
                for (k, &i) in self.tracked.iter().enumerate() {
                    self.faps[i] = saved[k];
                }
                Attempt::Rejected
            });
            if !improved {
                self.pose_samples();
                break;
            }
        }
    }

    /// Simulated annealing of the tracked FAP values, group after group.
    fn anneal_faps(&mut self, rng: &mut SplitMix64) {
        for g in 0..self.groups.len() {
            self.anneal_group(g, rng);
        }
    }

    /// Simulated annealing of one group of FAPs (the others fixed).
    fn anneal_group(&mut self, g: usize, rng: &mut SplitMix64) {
        let group = &self.groups[g];
        let members: Vec<usize> = group.members.iter().map(|&k| self.tracked[k]).collect();
        let start: Vec<f64> = members.iter().map(|&i| self.faps[i]).collect();
        let dofs: Vec<usize> = (0..start.len()).collect();
        let ranges: Vec<(f64, f64)> = group.members.iter().map(|&k| self.ranges[k]).collect();
        let sigma: Vec<f64> = ranges
            .iter()
            .map(|(lo, hi)| self.options.fap_spread * (hi - lo))
            .collect();
        let layers = self.options.layers;
        let settings = AnnealSettings {
            particles: self.options.particles * start.len().div_ceil(2).max(1),
            levels: (0..layers).map(|l| usize::from(l < layers / 2)).collect(),
            survival: 0.5,
            decay: 0.6,
            ..Default::default()
        };
        let clamp = |p: &mut [f64]| {
            for (x, (lo, hi)) in p.iter_mut().zip(&ranges) {
                *x = x.clamp(*lo, *hi);
            }
        };
        let s2 = self.options.robust_sigma.powi(2);
        let (rig, mesh, base, pose, pivot) =
            (&self.rig, &self.mesh, &self.faps, &self.pose, &self.pivot);
        let (samples, views, colours) = (&self.samples, &self.views, &self.colours);
        let active = &group.active;
        let members = &members;
        let cost = |p: &[f64], level: usize| -> f64 {
            COST_SCRATCH.with(|cell| {
                let mut s = cell.borrow_mut();
                let s = &mut *s;
                s.values.clear();
                s.values.extend_from_slice(base);
                for (&i, &v) in members.iter().zip(p) {
                    s.values[i] = v;
                }
                rig.apply(&mesh.positions, &s.values, &mut s.deformed);
                let rot = pose.rotation.matrix();
                let shift = pivot + pose.translation;
                let mut total = 0.0;
                for &k in active {
                    let c = colours[level][k];
                    if !c.is_finite() {
                        continue;
                    }
                    let t = mesh.triangles[samples.triangle[k] as usize];
                    let b = samples.bary[k];
                    let x = s.deformed[t[0] as usize] * b[0]
                        + s.deformed[t[1] as usize] * b[1]
                        + s.deformed[t[2] as usize] * b[2];
                    let x = rot * (x - pivot) + shift;
                    for v in views {
                        let w = v.vis[k] as f64;
                        if w <= 0.0 {
                            continue;
                        }
                        let r = match v.cam[level].project(&x) {
                            Some(uv) => match v.img[level].value_at(uv[0], uv[1]) {
                                Some(i) => v.gain * i as f64 - c as f64,
                                None => 255.0,
                            },
                            None => 255.0,
                        };
                        total += w * r * r / (s2 + r * r);
                    }
                }
                total
            })
        };
        let result = anneal(
            &start,
            &dofs,
            &sigma,
            &settings,
            rng,
            clamp,
            cost,
            &mut self.anneal_scratch,
        );
        for (&i, &v) in members.iter().zip(&result.params) {
            self.faps[i] = v;
        }
    }

    /// Tracks one frame: `images` one per camera, in the cameras' order. The first call
    /// learns the texture at the initial pose and returns that pose refined.
    pub fn track(&mut self, images: &[RgbImage]) -> Result<FaceFrameResult, FaceError> {
        let mut clock = std::time::Instant::now();
        let mut lap = |stage: usize, s: &mut [f64; 4]| {
            s[stage] += clock.elapsed().as_secs_f64();
            clock = std::time::Instant::now();
        };
        let mut times = [0.0; 4];
        self.load_images(images)?;
        lap(0, &mut times);
        let mut rng = SplitMix64::new(
            self.options.seed ^ (self.frame as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
        );
        if self.frame == 0 {
            self.learn_colours();
            for v in &mut self.views {
                v.gain = 1.0;
            }
            lap(1, &mut times);
        } else {
            // prediction
            let (pose0, faps0) = (self.pose, self.faps.clone());
            if let Some((prev, prev_faps)) = &self.previous {
                let a = self.options.prediction;
                let d = (self.pose.rotation * prev.rotation.inverse()).scaled_axis() * a;
                let dt = (self.pose.translation - prev.translation) * a;
                self.pose = self.pose.perturbed(&d, &dt);
                for (&i, (lo, hi)) in self.tracked.iter().zip(&self.ranges) {
                    let v = self.faps[i] + 0.5 * a * (self.faps[i] - prev_faps[i]);
                    self.faps[i] = v.clamp(*lo, *hi);
                }
            }
            self.previous = Some((pose0, faps0));
            self.update_visibility();
            self.update_gains(1);
            lap(1, &mut times);
            self.gauss_newton(1, self.options.gn_coarse);
            lap(2, &mut times);
            self.update_visibility();
            self.update_gains(0);
            lap(1, &mut times);
            self.gauss_newton(0, self.options.gn_fine);
            lap(2, &mut times);
            self.anneal_faps(&mut rng);
            self.refine_faps(0, self.options.fap_refine);
            lap(3, &mut times);
            self.update_visibility();
            lap(1, &mut times);
            self.gauss_newton(0, self.options.gn_fine);
            lap(2, &mut times);
        }
        for (a, b) in self.stage_seconds.iter_mut().zip(times) {
            *a += b;
        }
        self.pose_samples();
        let (c, w) = self.rigid_cost(0);
        self.frame += 1;
        Ok(FaceFrameResult {
            pose: self.pose,
            faps: self.tracked.iter().map(|&i| self.faps[i]).collect(),
            cost: if w > 0.0 { c / w } else { f64::NAN },
        })
    }

    /// The photometric cost (sum over cameras and samples of the weighted robust error) of the
    /// current frame at `pose` and tracked FAP values `faps`, at full resolution (`level` 0) or
    /// half (1), with the current visibility and gains. For diagnostics and tests.
    pub fn cost_at(&mut self, pose: &HeadPose, faps: &[f64], level: usize) -> f64 {
        let (saved_pose, saved_faps) = (self.pose, self.faps.clone());
        self.pose = *pose;
        for (&i, &v) in self.tracked.iter().zip(faps) {
            self.faps[i] = v;
        }
        self.pose_samples();
        let c = self.rigid_cost(level.min(1)).0;
        self.pose = saved_pose;
        self.faps = saved_faps;
        self.pose_samples();
        c
    }

    /// Seconds spent so far in each stage ([`STAGES`]), all frames together.
    pub fn stage_seconds(&self) -> [f64; 4] {
        self.stage_seconds
    }

    /// The posed, deformed vertices of the last tracked frame.
    pub fn posed_vertices(&self) -> &[Vec3] {
        &self.posed
    }
}

/// The damping of the tracker's Gauss–Newton passes: `λ max(H_kk, floor) + extra` on the
/// diagonal, `λ` from 1e-3, divided by 3 (not below 1e-6) after an accepted step, times 10
/// after a rejected one or a failed factorisation.
fn pose_damping(floor: f64, extra: f64) -> Damping {
    Damping::new(
        1e-3,
        DiagonalDamping::Clamped { floor, extra },
        DampingUpdate::Factors {
            down: 3.0,
            min: 1e-6,
            up: 10.0,
            singular: 10.0,
        },
    )
}
