//! The body tracker, by analysis-by-synthesis (seed report §3.1, §5.1): the textured puppet is
//! rendered into every camera and its pose is searched so the renders match the images.
//!
//! * **Start**: the puppet is pre-positioned on frame 0 from approximate 3D joints (the
//!   sequence's `init_joints.csv`, or given) by a least-squares fit of its joint angles, then
//!   refined by annealing on the silhouette (background term only). Its colours are learnt by
//!   back-projection from all cameras, the pose is annealed again with colours, and the
//!   colours are learnt once more.
//! * **Each frame**: prediction from the two previous poses (damped constant velocity), then
//!   annealing in stages down the hierarchy: root and chest together, then the head, then each
//!   arm and each leg. Each stage moves only its own parameters; its layers go from a coarse
//!   pyramid level to the full image. Candidates of a layer are evaluated in parallel.
//! * The background model of each camera is its clean plate (the empty scene, shot before),
//!   or without one the per-pixel median of frames spread over the sequence (which keeps the
//!   parts of a person who hardly moves); each frame's lighting gain is measured against it.

use std::sync::Mutex;
use std::time::Instant;

use image::RgbImage;

use super::annealing::{anneal, AnnealScratch, AnnealSettings};
use super::cost::{pose_cost, Appearance, CostWorkspace, FrameViews, Robust};
use super::hands_prior::{hands_apart_penalty, lead_elbow_penalty};
use super::joints::JOINT_COUNT;
use super::puppet::{PartGroup, Puppet};
use super::puppet_mesh::TrackingMesh;
use super::pyramid::Level;
use super::restarts::{limb_restarts, trunk_restarts};
use super::sequence_files::SequenceError;
use super::stage_cost::{moving_bones, StageBase, MAX_MOVING_FRACTION};
use super::texture::learn_colours;
pub use super::tracker_options::TrackerOptions;
use crate::body::{Mannequin, Pose};
use crate::geometry::{SplitMix64, Vec3};

/// Errors of the tracker.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    /// Reading the sequence failed.
    #[error(transparent)]
    Sequence(#[from] SequenceError),
    /// The puppet could not be built.
    #[error("puppet: {0}")]
    Puppet(String),
    /// A setting or input is unusable.
    #[error("{0}")]
    Invalid(String),
}

/// Tracked motion and its diagnostics.
#[derive(Clone, Debug, Default)]
pub struct TrackResult {
    /// Tracked joints per frame (metres, world).
    pub joints: Vec<[Vec3; JOINT_COUNT]>,
    /// Puppet parameters per frame.
    pub params: Vec<Vec<f64>>,
    /// Final cost per frame.
    pub costs: Vec<f64>,
    /// Wall time per frame (seconds).
    pub frame_seconds: Vec<f64>,
    /// Total wall time per stage (seconds), in stage order.
    pub stage_seconds: Vec<(String, f64)>,
    /// Seconds spent reading images and building pyramids, in total.
    pub io_seconds: f64,
    /// Seconds of the start (background, pre-positioning, texture).
    pub start_seconds: f64,
    /// Cost evaluations in total.
    pub evaluations: usize,
    /// The sequence's frame of the first tracked frame (its start).
    pub first_frame: usize,
    /// Overlap of each tracked frame's pose with the foreground ([`Tracker::overlap`]).
    pub overlaps: Vec<f64>,
    /// What happened to each frame (tracked, lost, recovered).
    pub status: Vec<super::frame_status::FrameStatus>,
    /// Per-frame mean joint error against the ground truth (mm), when present.
    pub errors_mm: Option<Vec<f64>>,
    /// Per-frame, per-joint errors (mm), when the ground truth is present.
    pub joint_errors_mm: Option<Vec<[f64; JOINT_COUNT]>>,
    /// The puppet's proportions found by the body adaptation, when it ran.
    pub proportions: Option<super::puppet::Proportions>,
}

impl TrackResult {
    /// Mean per-joint position error over all frames (mm).
    pub fn mpjpe_mm(&self) -> Option<f64> {
        let e = self.errors_mm.as_ref()?;
        (!e.is_empty()).then(|| e.iter().sum::<f64>() / e.len() as f64)
    }

    /// Mean error of some joints over all frames (mm).
    pub fn joints_error_mm(&self, joints: &[usize]) -> Option<f64> {
        let e = self.joint_errors_mm.as_ref()?;
        let n = (e.len() * joints.len()) as f64;
        (n > 0.0).then(|| {
            e.iter()
                .map(|f| joints.iter().map(|&j| f[j]).sum::<f64>())
                .sum::<f64>()
                / n
        })
    }

    /// The sequence's frames (numbered as in the sequence) whose state is `status`.
    pub fn frames_with(&self, status: super::frame_status::FrameStatus) -> Vec<usize> {
        (self.status.iter().enumerate())
            .filter(|(_, s)| **s == status)
            .map(|(k, _)| self.first_frame + k)
            .collect()
    }

    /// Mean wall time per tracked frame (seconds), start excluded.
    pub fn seconds_per_frame(&self) -> f64 {
        if self.frame_seconds.is_empty() {
            0.0
        } else {
            self.frame_seconds.iter().sum::<f64>() / self.frame_seconds.len() as f64
        }
    }
}

/// One stage of the hierarchical search: a name and the parameter groups it moves.
pub(super) struct Stage {
    pub(super) name: &'static str,
    groups: &'static [PartGroup],
}

pub(super) const STAGES: &[Stage] = &[
    Stage {
        name: "torso",
        groups: &[PartGroup::Root, PartGroup::Torso],
    },
    Stage {
        name: "head",
        groups: &[PartGroup::Head],
    },
    Stage {
        name: "left arm",
        groups: &[PartGroup::LeftArm, PartGroup::LeftHand],
    },
    Stage {
        name: "right arm",
        groups: &[PartGroup::RightArm, PartGroup::RightHand],
    },
    Stage {
        name: "left leg",
        groups: &[PartGroup::LeftLeg, PartGroup::LeftFoot],
    },
    Stage {
        name: "right leg",
        groups: &[PartGroup::RightLeg, PartGroup::RightFoot],
    },
];

/// Initial move spread of parameter `k` (metres for the root translation, radians else;
/// `torso` for the pelvis and chest rotations).
fn move_sigma(k: usize, group: PartGroup, torso: f64) -> f64 {
    match group {
        PartGroup::Root if k < 3 => 0.03,
        PartGroup::Root | PartGroup::Torso => torso,
        PartGroup::Head => 0.15,
        PartGroup::LeftArm | PartGroup::RightArm => 0.25,
        PartGroup::LeftLeg | PartGroup::RightLeg => 0.2,
        _ => 0.2,
    }
}

/// The tracker's state between frames.
pub struct Tracker {
    pub(super) puppet: Puppet,
    /// The body model the puppet and its mesh are built on (kept to rebuild them with other
    /// proportions, [`super::body_adapt`]).
    pub(super) mannequin: Mannequin,
    pub(super) mesh: TrackingMesh,
    pub(super) colours: Option<Vec<[f32; 3]>>,
    pub(super) views: FrameViews,
    pub(super) workspaces: Vec<Mutex<CostWorkspace>>,
    pub(super) options: TrackerOptions,
    pub(super) rng: SplitMix64,
    pub(super) history: Vec<Vec<f64>>,
    scratch: AnnealScratch,
    pub(super) stage_seconds: Vec<f64>,
    pub(super) evaluations: usize,
    /// Further starting points of the limb stages (a pose library, during an automatic
    /// start or a recovery).
    pub(super) extra_seeds: Vec<Vec<f64>>,
    /// The still part of the puppet during a stage that moves one part of it.
    stage_base: StageBase,
}

impl Tracker {
    /// A tracker for `cameras` with their background models (full resolution).
    pub fn new(
        mannequin: &Mannequin,
        cameras: &[crate::geometry::Camera],
        backgrounds: &[Level],
        options: TrackerOptions,
    ) -> Result<Tracker, TrackError> {
        options.validate().map_err(TrackError::Invalid)?;
        if cameras.len() != backgrounds.len() || cameras.is_empty() {
            return Err(TrackError::Invalid(format!(
                "tracker: {} cameras but {} background images",
                cameras.len(),
                backgrounds.len()
            )));
        }
        let puppet = Puppet::new(mannequin).map_err(|e| TrackError::Puppet(e.to_string()))?;
        let mesh = TrackingMesh::build(mannequin, &puppet, options.mesh_cell);
        let levels = options.layers.iter().max().copied().unwrap_or(0) + 1;
        let views = FrameViews::new(
            cameras,
            backgrounds,
            levels,
            Robust {
                sigma: options.robust_sigma,
            },
        );
        let bones = mannequin.skeleton().len();
        let threads = rayon::current_num_threads() + 1;
        let workspaces = (0..threads)
            .map(|_| Mutex::new(CostWorkspace::new(&views, bones, mesh.rest.len())))
            .collect();
        Ok(Tracker {
            rng: SplitMix64::new(options.seed),
            puppet,
            mannequin: mannequin.clone(),
            mesh,
            colours: None,
            views,
            workspaces,
            options,
            history: Vec::new(),
            scratch: AnnealScratch::default(),
            stage_seconds: vec![0.0; STAGES.len()],
            evaluations: 0,
            extra_seeds: Vec::new(),
            stage_base: StageBase::default(),
        })
    }

    /// The puppet.
    pub fn puppet(&self) -> &Puppet {
        &self.puppet
    }

    /// Rebuilds the puppet, its mesh and the cost workspaces with body proportions `p`
    /// (relative to the mannequin); learnt colours are dropped (the mesh changes).
    pub fn set_proportions(&mut self, p: &super::puppet::Proportions) -> Result<(), TrackError> {
        let puppet = Puppet::new(&self.mannequin)
            .and_then(|b| b.with_proportions(p))
            .map_err(|e| TrackError::Puppet(e.to_string()))?;
        self.mesh = TrackingMesh::build(&self.mannequin, &puppet, self.options.mesh_cell);
        self.puppet = puppet;
        let bones = self.mannequin.skeleton().len();
        let n = self.mesh.rest.len();
        for w in &self.workspaces {
            let mut w = match w.lock() {
                Ok(g) => g,
                Err(poisoned) => poisoned.into_inner(),
            };
            *w = CostWorkspace::new(&self.views, bones, n);
        }
        self.colours = None;
        Ok(())
    }

    /// Runs the stages on the current frame from `start` (move spreads scaled by
    /// `sigma_scale`); returns the pose and its cost.
    pub fn search(&mut self, start: &[f64], sigma_scale: f64) -> (Vec<f64>, f64) {
        let centre = start.to_vec();
        self.search_with_prior(start, sigma_scale, &centre)
    }

    /// [`search`](Self::search) with the motion prior centred on `centre` (the prediction):
    /// `prior_weight · Σ ((p − centre) / spread)²` over the parameters a stage moves, added
    /// to the image cost, keeps what the images hardly see (an occluded leg) where the
    /// motion so far puts it.
    pub fn search_with_prior(
        &mut self,
        start: &[f64],
        sigma_scale: f64,
        centre: &[f64],
    ) -> (Vec<f64>, f64) {
        let prior_weight = self.options.prior_weight;
        let mut settings = AnnealSettings {
            particles: self.options.particles,
            levels: self.options.layers.clone(),
            ..Default::default()
        };
        let mut params = start.to_vec();
        let mut cost = f64::INFINITY;
        let infos = self.puppet.params();
        for (s, stage) in STAGES.iter().enumerate() {
            let t0 = Instant::now();
            let dofs: Vec<usize> = (0..infos.len())
                .filter(|&k| stage.groups.contains(&infos[k].group))
                .collect();
            if dofs.is_empty() {
                continue;
            }
            let spread: Vec<f64> = dofs
                .iter()
                .map(|&k| move_sigma(k, infos[k].group, self.options.torso_spread))
                .collect();
            // limbs move fastest and are the most often hidden: half as many particles again
            settings.particles = if s >= 2 {
                self.options.particles * 3 / 2
            } else {
                self.options.particles
            };
            let sigma: Vec<f64> = spread.iter().map(|s| sigma_scale * s).collect();
            settings.seeds.clear();
            if self.options.limb_restarts && s >= 2 && !self.history.is_empty() {
                limb_restarts(
                    infos,
                    &params,
                    &dofs,
                    &self.history[self.history.len() - 1],
                    &mut settings.seeds,
                );
            }
            if s >= 2 {
                settings.seeds.extend(self.extra_seeds.iter().cloned());
            }
            if s == 0 && self.options.anchor_limbs && !self.history.is_empty() {
                trunk_restarts(&params, &mut settings.seeds);
            }
            let app = Appearance {
                puppet: &self.puppet,
                mesh: &self.mesh,
                colours: self.colours.as_deref(),
                lbs: self.options.lbs,
            };
            // a stage that moves one part renders the rest once ([`super::stage_cost`])
            let by_difference = s >= 1 && {
                let moving = moving_bones(&self.puppet, &params, &dofs);
                let mut ws = match self.workspaces[0].lock() {
                    Ok(g) => g,
                    Err(poisoned) => poisoned.into_inner(),
                };
                let fraction = self.stage_base.rebuild(
                    &app,
                    &self.views,
                    &params,
                    &moving,
                    &settings.levels,
                    &mut ws,
                );
                fraction < MAX_MOVING_FRACTION
            };
            let base = by_difference.then_some(&self.stage_base);
            let views = &self.views;
            let workspaces = &self.workspaces;
            let puppet = &self.puppet;
            // the trunk stage may keep the limbs still in the world
            let anchor = (s == 0 && self.options.anchor_limbs).then(|| puppet.limb_anchor(&params));
            let scratch = std::cell::RefCell::new(Pose::identity(0));
            // the second arm searched (the right: a right-handed golfer's trail arm, the one
            // hidden behind the lead arm) keeps its wrist on the grip when asked; the first
            // arm follows the images alone, so it does not follow a lost second arm
            let hands_apart = self.options.hands_apart.filter(|_| s == 3);
            // and the left arm's stage keeps a golfer's lead arm from folding
            let lead_elbow = self.options.lead_elbow_min.filter(|_| s == 2);
            let r = anneal(
                &params,
                &dofs,
                &sigma,
                &settings,
                &mut self.rng,
                |p| {
                    if let Some(a) = &anchor {
                        puppet.keep_limbs(p, a, &mut scratch.borrow_mut());
                    }
                    puppet.clamp(p)
                },
                |p, level| {
                    let slot = rayon::current_thread_index().unwrap_or(workspaces.len() - 1);
                    let mut ws = match workspaces[slot.min(workspaces.len() - 1)].lock() {
                        Ok(g) => g,
                        Err(poisoned) => poisoned.into_inner(),
                    };
                    let prior: f64 = dofs
                        .iter()
                        .zip(&spread)
                        .map(|(&k, s)| ((p[k] - centre[k]) / s).powi(2))
                        .sum();
                    let image = match base.and_then(|b| b.cost(&app, views, level, p, &mut ws)) {
                        Some(c) => c,
                        None => pose_cost(&app, views, level, p, &mut ws),
                    };
                    let hands = if hands_apart.is_some() || lead_elbow.is_some() {
                        let j = puppet.joints(&ws.pose);
                        hands_apart.map_or(0.0, |m| hands_apart_penalty(&j, m))
                            + lead_elbow.map_or(0.0, |m| lead_elbow_penalty(&j, m))
                    } else {
                        0.0
                    };
                    image + prior_weight * prior + hands
                },
                &mut self.scratch,
            );
            self.evaluations += r.evaluations;
            params = r.params;
            cost = r.cost;
            self.stage_seconds[s] += t0.elapsed().as_secs_f64();
        }
        (params, cost)
    }

    /// Learns the colours from the current frame at pose `params` (full resolution).
    pub(super) fn learn(&mut self, params: &[f64]) -> usize {
        let app = Appearance {
            puppet: &self.puppet,
            mesh: &self.mesh,
            colours: None,
            lbs: self.options.lbs,
        };
        let mut ws = match self.workspaces[0].lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        ws.pose_mesh(&app, params);
        let views: Vec<_> = self
            .views
            .views
            .iter()
            .map(|v| (&v[0].camera, &v[0].image, Some(v[0].active.as_slice())))
            .collect();
        let (colours, seen) = learn_colours(&self.mesh, &ws.skinned, &views);
        drop(ws);
        self.colours = Some(colours);
        seen
    }

    /// Frame 0: pre-positioning from approximate joints, silhouette refinement, texture.
    pub fn start(
        &mut self,
        images: &[RgbImage],
        approx: &[Vec3; JOINT_COUNT],
    ) -> Result<Vec<f64>, TrackError> {
        if approx.iter().any(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(TrackError::Invalid(
                "approximate first-frame joints are not finite".into(),
            ));
        }
        self.views.set_frame(images);
        let rest = self.puppet.rest_params();
        let fitted = self.puppet.fit_to_joints(approx, &rest);
        Ok(self.refine_start(fitted))
    }

    /// The start's refinement from a first pose `fitted` (current frame loaded): alternately
    /// learns the colours and searches the pose, with narrowing moves.
    pub(super) fn refine_start(&mut self, fitted: Vec<f64>) -> Vec<f64> {
        self.colours = None;
        let mut pose = fitted.clone();
        for scale in [0.4, 0.3, 0.2, 0.15, 0.1] {
            self.learn(&pose);
            (pose, _) = self.search_with_prior(&pose, scale, &fitted);
        }
        self.learn(&pose);
        self.history = vec![pose.clone()];
        pose
    }

    /// Frame 0 from a known pose (no search): learns the colours there.
    pub fn start_at(
        &mut self,
        images: &[RgbImage],
        params: &[f64],
    ) -> Result<Vec<f64>, TrackError> {
        self.check_images(images)?;
        self.views.set_frame(images);
        let mut p = params.to_vec();
        self.puppet.clamp(&mut p);
        self.learn(&p);
        self.history = vec![p.clone()];
        Ok(p)
    }

    /// Loads the images of the next frame (pyramids, lighting gain) without searching.
    pub fn set_frame(&mut self, images: &[RgbImage]) -> Result<(), TrackError> {
        self.check_images(images)?;
        self.views.set_frame(images);
        Ok(())
    }

    /// Checks that there is one image per camera, each of its camera's size.
    fn check_images(&self, images: &[RgbImage]) -> Result<(), TrackError> {
        let views = &self.views.views;
        if images.len() != views.len() {
            return Err(TrackError::Invalid(format!(
                "{} images for {} cameras",
                images.len(),
                views.len()
            )));
        }
        for (c, (img, v)) in images.iter().zip(views).enumerate() {
            let (w, h) = (v[0].background.width, v[0].background.height);
            if (img.width() as usize, img.height() as usize) != (w, h) {
                return Err(TrackError::Invalid(format!(
                    "image of camera {c} is {}×{}, its camera is {w}×{h}",
                    img.width(),
                    img.height()
                )));
            }
        }
        Ok(())
    }

    /// Tracks one frame (after [`start`](Self::start)); returns the pose and its cost.
    pub fn track(&mut self, images: &[RgbImage]) -> Result<(Vec<f64>, f64), TrackError> {
        self.check_images(images)?;
        self.views.set_frame(images);
        if self.history.is_empty() {
            self.history.push(self.puppet.rest_params());
        }
        let n = self.history.len();
        let mut predicted = self.history[n - 1].clone();
        if n >= 2 {
            let f = self.options.prediction;
            for (k, p) in predicted.iter_mut().enumerate() {
                *p += f * (self.history[n - 1][k] - self.history[n - 2][k]);
            }
            self.puppet.clamp(&mut predicted);
        }
        let (mut params, mut cost) = (predicted.clone(), f64::INFINITY);
        for k in 0..self.options.passes.len() {
            (params, cost) = self.search_with_prior(&params, self.options.passes[k], &predicted);
        }
        self.history.push(params.clone());
        if self.history.len() > 2 {
            self.history.remove(0);
        }
        Ok((params, cost))
    }

    /// Forgets the motion so far: the next frame is predicted from `params` alone (after a
    /// recovery).
    pub fn restart_history(&mut self, params: &[f64]) {
        self.history = vec![params.to_vec()];
    }

    /// The tracking joints of pose `params`.
    pub fn joints(&self, params: &[f64]) -> [Vec3; JOINT_COUNT] {
        let mut ws = match self.workspaces[0].lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        self.puppet.pose_into(params, &mut ws.pose);
        self.puppet.joints(&ws.pose)
    }
}
