//! Automatic pre-positioning of the puppet from the images alone (no approximate joints):
//! the person is found as the visual hull of the cameras' silhouettes
//! ([`super::visual_hull`]), the puppet is stood at its centre with its feet on its lowest
//! point, turned to each of [`HEADINGS`] headings and raised or lowered (an occluder over
//! the legs in two cameras carves the feet off the hull), and the best-fitting headings are
//! refined (at the height the silhouettes chose and, where that differs, with the feet on
//! the hull's lowest point) by the tracker's own annealing from coarse to fine, every limb stage also
//! starting from a small library of limb poses ([`limb_library`]). The same search, seeded
//! by the last good pose and scored with the learnt colours, finds the body again after a
//! loss ([`super::loss`]).

use nalgebra::{UnitQuaternion, Vector3};

use super::address_pose::golf_address_pose;
use super::cost::{pose_cost, Appearance};
use super::puppet::Puppet;
use super::tracker::{TrackError, Tracker};
use super::visual_hull::{
    foreground_fractions, search_box, visual_hull, Hull, FOREGROUND_RHO, MIN_PERSON_VOLUME,
};
use crate::geometry::Vec3;

/// Pyramid level the hull is carved at.
const HULL_LEVEL: usize = 1;
/// Edge of a hull cell (metres), unless the search box needs coarser cells.
const HULL_CELL: f64 = 0.05;
/// Most cells sampled over the search box.
const MAX_CELLS: f64 = 4.0e6;
/// Headings tried, evenly around the vertical.
pub const HEADINGS: usize = 16;
/// Headings refined by annealing (the best of the coarse scores, at least 60° apart).
const REFINED: usize = 4;
/// Spread factors of the annealing passes that refine a heading (wide, then narrower).
const PASSES: [f64; 4] = [3.0, 1.5, 0.7, 0.35];

/// Where the person is, from the visual hull.
#[derive(Clone, Copy, Debug)]
pub struct Found {
    /// Centroid of the hull's largest piece (metres, world).
    pub centre: Vec3,
    /// Height of its lowest point (metres).
    pub lowest: f64,
    /// Its volume (m³).
    pub volume: f64,
}

/// Limb poses tried by every limb stage of the search: upper arm raised back, not, forward
/// and up, in the body plane or abducted either way, elbow straight or bent; thigh back,
/// back, forward or high, not abducted (an abducted pair of legs turned a quarter turn
/// mimics a stride), knee straight or bent. Each vector sets both sides
/// the same (the right side's limits mirror the left's, so `side` values of both signs
/// cover both); only the searched stage's entries are used.
pub fn limb_library(puppet: &Puppet) -> Vec<Vec<f64>> {
    let infos = puppet.params();
    let index = |name: &str| infos.iter().position(|p| p.name.ends_with(name));
    let set = |p: &mut Vec<f64>, bone: &str, comp: &str, v: f64| {
        for side in ["L", "R"] {
            if let Some(k) = index(&format!("{bone}.{side}.{comp}")) {
                p[k] = v;
            }
        }
    };
    let mut out = Vec::new();
    let mut i = 0;
    for flex in [-0.8, 0.0, 1.2, 2.4] {
        for side in [-0.9, 0.0, 0.9] {
            for bent in [0.0, 1.3] {
                let mut p = puppet.rest_params();
                set(&mut p, "upperarm01", "flex", flex);
                set(&mut p, "upperarm01", "side", side);
                set(&mut p, "lowerarm01", "flex", bent);
                // legs: the same count of combinations, enumerated alongside
                let (thigh, abduct, knee) = (
                    [
                        -0.5, -0.35, -0.2, 0.0, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9, 1.2, 1.5,
                    ][i / 2],
                    0.0,
                    [0.0, -1.2][i % 2],
                );
                set(&mut p, "upperleg01", "flex", thigh);
                set(&mut p, "upperleg01", "side", abduct);
                set(&mut p, "lowerleg01", "flex", knee);
                puppet.clamp(&mut p);
                out.push(p);
                i += 1;
            }
        }
    }
    out
}

/// The heading (rotation about the vertical, radians) of a pose: the angle of its pelvis's
/// forward axis (rest forward is −y) in the ground plane.
pub fn heading(params: &[f64]) -> f64 {
    let r = UnitQuaternion::from_scaled_axis(Vector3::new(params[3], params[4], params[5]));
    let f = r * Vector3::new(0.0, -1.0, 0.0);
    f.x.atan2(-f.y)
}

impl Tracker {
    /// Finds the person in the current frame: the visual hull of all cameras. An error when
    /// its volume is below [`MIN_PERSON_VOLUME`] (nobody, or nobody the cameras agree on).
    pub fn find_person(&self) -> Result<Found, TrackError> {
        let (lo, hi) = search_box(&self.views);
        let size = hi - lo;
        let cell = HULL_CELL.max((size.x * size.y * size.z / MAX_CELLS).cbrt());
        let hull: Hull = visual_hull(&self.views, HULL_LEVEL, lo, hi, cell).largest_component();
        let volume = hull.volume();
        match (hull.centroid(), hull.lowest()) {
            (Some(centre), Some(lowest)) if volume >= MIN_PERSON_VOLUME => Ok(Found {
                centre,
                lowest: lowest - 0.5 * cell,
                volume,
            }),
            _ => {
                let fg: Vec<String> = foreground_fractions(&self.views, HULL_LEVEL)
                    .iter()
                    .map(|f| format!("{:.1} %", 100.0 * f))
                    .collect();
                Err(TrackError::Invalid(format!(
                    "no person found: the silhouettes of the {} cameras meet in {:.3} m³ \
                     (a person needs at least {MIN_PERSON_VOLUME} m³); foreground (ρ > \
                     {FOREGROUND_RHO} against the background) in {} of each camera's pixels",
                    self.views.views.len(),
                    volume,
                    fg.join(", ")
                )))
            }
        }
    }

    /// The image cost of `params` at pyramid `level` (with the colours once learnt, the
    /// silhouette before), without the motion prior.
    pub fn image_cost(&self, params: &[f64], level: usize) -> f64 {
        let app = Appearance {
            puppet: self.puppet(),
            mesh: &self.mesh,
            colours: self.colours.as_deref(),
            lbs: self.options.lbs,
        };
        let mut ws = match self.workspaces[0].lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        pose_cost(
            &app,
            &self.views,
            level.min(self.views.levels() - 1),
            params,
            &mut ws,
        )
    }

    /// `pose` turned by `turn` about the vertical through its pelvis and moved so the pelvis
    /// stands over `found.centre` with the lowest point of the skin on `found.lowest`.
    fn placed(&self, pose: &[f64], turn: f64, found: &Found) -> Vec<f64> {
        let mut p = pose.to_vec();
        let r = UnitQuaternion::from_scaled_axis(Vector3::new(p[3], p[4], p[5]));
        let r = UnitQuaternion::from_scaled_axis(Vector3::z() * turn) * r;
        p[3..6].copy_from_slice(r.scaled_axis().as_slice());
        let rest_pelvis = self.puppet().rest_joints()[0];
        p[0] = found.centre.x - rest_pelvis.x;
        p[1] = found.centre.y - rest_pelvis.y;
        p[2] = 0.0;
        self.puppet().clamp(&mut p);
        let app = Appearance {
            puppet: self.puppet(),
            mesh: &self.mesh,
            colours: None,
            lbs: self.options.lbs,
        };
        let low = {
            let mut ws = match self.workspaces[0].lock() {
                Ok(g) => g,
                Err(e) => e.into_inner(),
            };
            ws.pose_mesh(&app, &p);
            ws.skinned.iter().map(|v| v.z).fold(f64::INFINITY, f64::min)
        };
        if low.is_finite() {
            p[2] = found.lowest - low;
        }
        self.puppet().clamp(&mut p);
        p
    }

    /// The pose search of the current frame: the person found, the puppet (`hint`'s pose,
    /// or the rest pose) placed there at [`HEADINGS`] headings, the best refined by
    /// annealing with the limb library. Returns the pose and its image cost (full
    /// resolution).
    pub fn auto_pose(&mut self, hint: Option<&[f64]>) -> Result<(Vec<f64>, f64), TrackError> {
        let found = self.find_person()?;
        let base = hint.map_or_else(|| self.puppet().rest_params(), <[f64]>::to_vec);
        let mut scored: Vec<(f64, f64, Vec<f64>)> = (0..HEADINGS)
            .map(|h| {
                let turn = h as f64 * std::f64::consts::TAU / HEADINGS as f64;
                let placed = self.placed(&base, turn, &found);
                // the hull's lowest point is the feet's only where no occluder hides
                // them from two cameras; the silhouettes decide the height
                (-12..=4)
                    .map(|i| {
                        let mut p = placed.clone();
                        p[2] += 0.05 * i as f64;
                        self.puppet().clamp(&mut p);
                        (self.image_cost(&p, 1), turn, p)
                    })
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .unwrap_or((f64::INFINITY, turn, placed))
            })
            .collect();
        scored.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut picked: Vec<Vec<f64>> = Vec::new();
        let mut turns: Vec<f64> = Vec::new();
        for (_, turn, p) in &scored {
            let apart = |t: &f64| {
                let d = (turn - t).rem_euclid(std::f64::consts::TAU);
                d.min(std::f64::consts::TAU - d) >= 60f64.to_radians() - 1e-9
            };
            if turns.len() < REFINED && turns.iter().all(apart) {
                picked.push(p.clone());
                // the rest pose's silhouette may prefer the puppet sunk into the floor (its
                // spread arms then cover the clothed body); the feet on the hull's lowest
                // point are refined too, and the refined fits decide
                let floor = self.placed(&base, *turn, &found);
                if (floor[2] - p[2]).abs() > 0.07 {
                    picked.push(floor);
                }
                turns.push(*turn);
            }
        }
        // each pass's motion prior is centred on where the pass starts: large limb moves
        // must buy their cost in the images
        self.extra_seeds = limb_library(self.puppet());
        let mut best = (Vec::new(), f64::INFINITY);
        for start in picked {
            let mut pose = start;
            for scale in PASSES {
                pose = self.search(&pose, scale).0;
            }
            let cost = self.image_cost(&pose, 0);
            if cost < best.1 {
                best = (pose, cost);
            }
        }
        self.extra_seeds.clear();
        Ok(best)
    }

    /// The automatic start on `images` (the first frame): the pose search (from the rest
    /// pose, or a golfer's address with [`TrackerOptions::golf_address`](super::tracker::TrackerOptions::golf_address)) without colours
    /// (a silhouette fit), then the start's refinement (colours learnt, pose searched with
    /// them, in turn). `init_joints.csv` plays no part.
    pub fn start_auto(&mut self, images: &[image::RgbImage]) -> Result<Vec<f64>, TrackError> {
        self.set_frame(images)?;
        self.colours = None;
        let stance = self
            .options
            .golf_address
            .then(|| golf_address_pose(self.puppet()));
        let (pose, _) = self.auto_pose(stance.as_deref())?;
        Ok(self.refine_start(pose))
    }
}
