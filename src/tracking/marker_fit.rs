//! The puppet fitted to a marker trial: body proportions and each marker's offset on its bone
//! over the whole trial, then per-frame inverse kinematics by Levenberg–Marquardt within the
//! puppet's joint limits, warm-started from the previous frame ([`fit_markers`]).
//!
//! A marker `m` on bone `b` sits at `T_b(p) · r_m`, `T_b` the bone's transform for pose
//! parameters `p` and `r_m` the marker's rest position. Calibration alternates, on every
//! `calibration_stride`-th frame: the pose of each frame (LM), then every marker's rest
//! position in closed form (the mean of `T_b⁻¹ x` over the frames where it is seen: rigid
//! transforms keep distances, so this is the least-squares point), then the segment lengths
//! (a coordinate search on [`Proportions`], the marker offsets carried by their bones).
//! Markers are read in the engine's frame ([`MarkerTrial::world`]), so a y-up file is turned
//! by the one convention of [`crate::geometry::export_frame`].

use nalgebra::{DMatrix, DVector, Point3};

use super::marker_set::MarkerSet;
use super::puppet::fit::PUPPET_DAMPING;
use super::puppet::{Proportions, Puppet, DRIVEN_BONES, PARAM_COUNT};
use crate::body::{Mannequin, MarkerTrial, Pose};
use crate::geometry::least_squares::{self, BoundedDifferences, LeastSquares, Schedule, Tries};
use crate::geometry::Vec3;

/// Pull (metres per radian, metres per metre) of every parameter toward its start: keeps
/// what no marker sees (hands, neck shares) still.
const PRIOR: f64 = 0.003;

/// Options of [`fit_markers`].
#[derive(Clone, Debug)]
pub struct MarkerFitOptions {
    /// Every this many frames take part in the calibration (segment lengths, offsets).
    pub calibration_stride: usize,
    /// Rounds of calibration (poses, offsets, lengths).
    pub rounds: usize,
    /// LM iterations per frame.
    pub iterations: usize,
}

impl Default for MarkerFitOptions {
    fn default() -> Self {
        MarkerFitOptions {
            calibration_stride: 8,
            rounds: 4,
            iterations: 40,
        }
    }
}

/// One fitted marker.
#[derive(Clone, Debug)]
pub struct FittedMarker {
    /// Its label.
    pub label: String,
    /// Its index in the trial.
    pub index: usize,
    /// The skeleton bone carrying it.
    pub bone: usize,
    /// Its rest position on the fitted puppet (metres, engine frame).
    pub rest: Vec3,
}

/// The result of [`fit_markers`].
#[derive(Clone, Debug)]
pub struct MarkerFit {
    /// The puppet with the fitted proportions.
    pub puppet: Puppet,
    /// The fitted markers.
    pub markers: Vec<FittedMarker>,
    /// Pose parameters per frame.
    pub params: Vec<Vec<f64>>,
    /// Distance (metres) from each fitted marker to its observation, per frame (`NaN` where
    /// the sample is invalid), frame-major.
    pub errors: Vec<f64>,
}

/// Per-marker residual statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct MarkerResidual {
    /// The marker's label.
    pub label: String,
    /// Valid samples.
    pub samples: usize,
    /// Root mean square distance, metres.
    pub rms: f64,
    /// Largest distance, metres.
    pub max: f64,
}

impl MarkerFit {
    /// Root mean square of the marker distances over all valid samples, metres.
    pub fn rms(&self) -> f64 {
        let (s, n) = self
            .errors
            .iter()
            .filter(|e| e.is_finite())
            .fold((0.0, 0usize), |(s, n), e| (s + e * e, n + 1));
        (s / n.max(1) as f64).sqrt()
    }

    /// Residual statistics per marker.
    pub fn per_marker(&self) -> Vec<MarkerResidual> {
        let m = self.markers.len();
        self.markers
            .iter()
            .enumerate()
            .map(|(k, mk)| {
                let e: Vec<f64> = self
                    .errors
                    .iter()
                    .skip(k)
                    .step_by(m)
                    .copied()
                    .filter(|e| e.is_finite())
                    .collect();
                let rms = (e.iter().map(|x| x * x).sum::<f64>() / e.len().max(1) as f64).sqrt();
                MarkerResidual {
                    label: mk.label.clone(),
                    samples: e.len(),
                    rms,
                    max: e.iter().fold(0.0, |a: f64, &b| a.max(b)),
                }
            })
            .collect()
    }

    /// The per-marker residuals as CSV: `marker,samples,rms_mm,max_mm`, then an `all` row.
    pub fn residual_csv(&self) -> String {
        let mut s = String::from("marker,samples,rms_mm,max_mm\n");
        for r in self.per_marker() {
            s += &format!(
                "{},{},{:.3},{:.3}\n",
                r.label,
                r.samples,
                r.rms * 1e3,
                r.max * 1e3
            );
        }
        let n = self.errors.iter().filter(|e| e.is_finite()).count();
        let max = self
            .errors
            .iter()
            .filter(|e| e.is_finite())
            .fold(0.0f64, |a, &b| a.max(b));
        s += &format!("all,{n},{:.3},{:.3}\n", self.rms() * 1e3, max * 1e3);
        s
    }

    /// The sixteen tracking joints of every frame (for BVH export and metrics).
    pub fn joints(&self) -> Vec<[Vec3; 16]> {
        let mut pose = Pose::identity(self.puppet.bone_count());
        self.params
            .iter()
            .map(|p| {
                self.puppet.pose_into(p, &mut pose);
                self.puppet.joints(&pose)
            })
            .collect()
    }
}

/// Observations of one frame: per fitted marker, its position (engine frame) if valid.
fn observed(trial: &MarkerTrial, markers: &[FittedMarker], frame: usize) -> Vec<Option<Vec3>> {
    markers
        .iter()
        .map(|m| trial.world(frame, m.index))
        .collect()
}

/// Fits `mannequin`'s puppet to `trial` through `set` (see the module docs). Markers of the set
/// absent from the trial are skipped; the error names a set that matches fewer than six.
pub fn fit_markers(
    mannequin: &Mannequin,
    trial: &MarkerTrial,
    set: &MarkerSet,
    options: &MarkerFitOptions,
) -> Result<MarkerFit, String> {
    if trial.frames == 0 {
        return Err(format!("{}: the trial has no frames", trial.source));
    }
    let base = Puppet::new(mannequin)?;
    let rough = set.resolve(mannequin, &base)?;
    let mut markers = Vec::new();
    for (spec, (bone, rest)) in set.markers.iter().zip(rough) {
        if let Some(index) = trial.marker(&spec.label) {
            markers.push(FittedMarker {
                label: spec.label.clone(),
                index,
                bone,
                rest,
            });
        }
    }
    if markers.len() < 6 {
        return Err(format!(
            "{}: only {} markers of the set are in the trial (6 needed)",
            trial.source,
            markers.len()
        ));
    }
    // uniform scale from the standing height: head top over the lowest marker, median frame
    let scale = height_ratio(trial, &markers).unwrap_or(1.0).clamp(0.6, 1.6);
    let mut prop = uniform(scale);
    let mut puppet = base.with_proportions(&prop)?;
    carry(&base, &puppet, &mut markers);
    let calib: Vec<usize> = (0..trial.frames)
        .step_by(options.calibration_stride.max(1))
        .collect();
    let obs: Vec<Vec<Option<Vec3>>> = calib
        .iter()
        .map(|&f| observed(trial, &markers, f))
        .collect();
    let mut params: Vec<Vec<f64>> = Vec::new();
    for round in 0..options.rounds {
        crate::limits::check_cancelled()?;
        // poses: sequential in the first round, then from the last round's pose of the frame
        let mut prev: Option<Vec<f64>> = None;
        for (k, o) in obs.iter().enumerate() {
            let start = if round == 0 {
                prev.take()
            } else {
                Some(params[k].clone())
            };
            let p = solve_frame(&puppet, &markers, o, start.as_deref(), options.iterations);
            if round == 0 {
                params.push(p.clone());
                prev = Some(p);
            } else {
                params[k] = p;
            }
        }
        refit_offsets(&puppet, &mut markers, &params, &obs);
        if round + 1 < options.rounds {
            let before = puppet.clone();
            prop = search_proportions(&base, prop, &markers, &before, &params, &obs)?;
            puppet = base.with_proportions(&prop)?;
            carry(&before, &puppet, &mut markers);
        }
    }
    // every frame, warm-started from the previous one
    let mut all = Vec::with_capacity(trial.frames);
    let mut errors = Vec::with_capacity(trial.frames * markers.len());
    let mut pose = Pose::identity(puppet.bone_count());
    let mut prev = params.first().cloned();
    for f in 0..trial.frames {
        if f % 64 == 0 {
            crate::limits::check_cancelled()?;
        }
        let o = observed(trial, &markers, f);
        let p = solve_frame(&puppet, &markers, &o, prev.as_deref(), options.iterations);
        puppet.pose_into(&p, &mut pose);
        for (m, x) in markers.iter().zip(&o) {
            errors.push(match x {
                Some(x) => (marker_at(&pose, m) - x).norm(),
                None => f64::NAN,
            });
        }
        prev = Some(p.clone());
        all.push(p);
    }
    Ok(MarkerFit {
        puppet,
        markers,
        params: all,
        errors,
    })
}

/// All length scales `s`, girth `s`.
fn uniform(s: f64) -> Proportions {
    Proportions {
        torso: s,
        neck: s,
        head: s,
        upper_arm: s,
        forearm: s,
        hand: s,
        thigh: s,
        shin: s,
        foot: s,
        girth: s,
    }
}

/// The trial's head-top height over its lowest body marker, over the rest set's.
fn height_ratio(trial: &MarkerTrial, markers: &[FittedMarker]) -> Option<f64> {
    let top = markers.iter().position(|m| m.label == "HeadTop")?;
    let rest_low = markers
        .iter()
        .map(|m| m.rest.z)
        .fold(f64::INFINITY, f64::min);
    let rest_h = markers[top].rest.z - rest_low;
    let mut h: Vec<f64> = (0..trial.frames)
        .filter_map(|f| {
            let o = observed(trial, markers, f);
            let t = o[top]?.z;
            let low = o
                .iter()
                .flatten()
                .map(|p| p.z)
                .fold(f64::INFINITY, f64::min);
            Some(t - low)
        })
        .collect();
    if h.is_empty() || rest_h <= 0.0 {
        return None;
    }
    h.sort_by(f64::total_cmp);
    Some(h[h.len() / 2] / rest_h)
}

/// Moves the markers' rest positions from puppet `from` to puppet `to` with their bones (the
/// offset from the bone head is kept).
fn carry(from: &Puppet, to: &Puppet, markers: &mut [FittedMarker]) {
    for m in markers {
        m.rest = to.rest_heads()[m.bone] + (m.rest - from.rest_heads()[m.bone]);
    }
}

/// A marker's posed position.
fn marker_at(pose: &Pose, m: &FittedMarker) -> Vec3 {
    (pose.transform(m.bone) * Point3::from(m.rest)).coords
}

/// The closed-form rest position of every marker given the poses of the calibration frames.
fn refit_offsets(
    puppet: &Puppet,
    markers: &mut [FittedMarker],
    params: &[Vec<f64>],
    obs: &[Vec<Option<Vec3>>],
) {
    let mut sums = vec![(Vec3::zeros(), 0usize); markers.len()];
    let mut pose = Pose::identity(puppet.bone_count());
    for (p, o) in params.iter().zip(obs) {
        puppet.pose_into(p, &mut pose);
        for (k, m) in markers.iter().enumerate() {
            if let Some(x) = o[k] {
                let local = pose.transform(m.bone).inverse() * Point3::from(x);
                sums[k].0 += local.coords;
                sums[k].1 += 1;
            }
        }
    }
    for (m, (s, n)) in markers.iter_mut().zip(sums) {
        if n > 0 {
            m.rest = s / n as f64;
        }
    }
}

/// Sum of squared marker distances over the calibration frames, each frame re-solved from
/// its current pose (a few iterations) on `puppet`.
fn calibration_cost(
    puppet: &Puppet,
    markers: &[FittedMarker],
    params: &[Vec<f64>],
    obs: &[Vec<Option<Vec3>>],
) -> f64 {
    let mut pose = Pose::identity(puppet.bone_count());
    let mut ms = markers.to_vec();
    let solved: Vec<Vec<f64>> = params
        .iter()
        .zip(obs)
        .map(|(p, o)| solve_frame(puppet, &ms, o, Some(p), 8))
        .collect();
    refit_offsets(puppet, &mut ms, &solved, obs);
    let mut cost = 0.0;
    for (p, o) in solved.iter().zip(obs) {
        puppet.pose_into(p, &mut pose);
        for (m, x) in ms.iter().zip(o) {
            if let Some(x) = x {
                cost += (marker_at(&pose, m) - x).norm_squared();
            }
        }
    }
    cost
}

/// One pass of a coordinate search over the segment scales (±4 %, then ±1.5 %).
fn search_proportions(
    base: &Puppet,
    start: Proportions,
    markers: &[FittedMarker],
    current: &Puppet,
    params: &[Vec<f64>],
    obs: &[Vec<Option<Vec3>>],
) -> Result<Proportions, String> {
    let eval = |p: &Proportions| -> Result<f64, String> {
        let pup = base.with_proportions(p)?;
        let mut ms = markers.to_vec();
        carry(current, &pup, &mut ms);
        Ok(calibration_cost(&pup, &ms, params, obs))
    };
    let mut best = start;
    let mut best_cost = eval(&best)?;
    for step in [0.04, 0.015] {
        for field in 0..10 {
            for sign in [1.0, -1.0] {
                let mut q = best;
                let v = field_mut(&mut q, field);
                *v *= 1.0 + sign * step;
                let c = eval(&q)?;
                if c < best_cost {
                    best = q;
                    best_cost = c;
                    break;
                }
            }
        }
    }
    Ok(best)
}

/// Field `k` of the proportions (torso, neck, head, upper arm, forearm, hand, thigh, shin,
/// foot, girth).
fn field_mut(p: &mut Proportions, k: usize) -> &mut f64 {
    match k {
        0 => &mut p.torso,
        1 => &mut p.neck,
        2 => &mut p.head,
        3 => &mut p.upper_arm,
        4 => &mut p.forearm,
        5 => &mut p.hand,
        6 => &mut p.thigh,
        7 => &mut p.shin,
        8 => &mut p.foot,
        _ => &mut p.girth,
    }
}

/// Inverse kinematics of one frame: the parameters within the limits that bring the markers
/// closest to `obs`, from `start` (or, without one, the root placed by a rigid fit of the
/// pelvis and chest markers).
fn solve_frame(
    puppet: &Puppet,
    markers: &[FittedMarker],
    obs: &[Option<Vec3>],
    start: Option<&[f64]>,
    iterations: usize,
) -> Vec<f64> {
    let mut p = match start {
        Some(s) => s.to_vec(),
        None => rigid_start(puppet, markers, obs),
    };
    p.resize(PARAM_COUNT, 0.0);
    puppet.clamp(&mut p);
    let seen: Vec<usize> = (0..markers.len()).filter(|&k| obs[k].is_some()).collect();
    if seen.is_empty() {
        return p;
    }
    let bones: Vec<usize> = markers.iter().map(|m| m.bone).collect();
    let subset = puppet.with_ancestors(&bones);
    let mut problem = MarkerIk {
        puppet,
        markers,
        obs,
        seen: &seen,
        prior: p.clone(),
        pose: Pose::identity(puppet.bone_count()),
        rows: 3 * seen.len() + PARAM_COUNT,
        active: active_params(puppet, &subset),
        subset,
    };
    let schedule = Schedule {
        iterations,
        damping: PUPPET_DAMPING,
        tries: Tries::Count(10),
        progress: |old, new| old - new > 1e-10 * old.max(1e-12),
    };
    least_squares::minimize(&mut problem, p, &schedule).state
}

/// Root translation and rotation from a rigid (Kabsch) fit of the pelvis and chest markers'
/// rest positions to their observations; the rest pose if fewer than three are seen.
fn rigid_start(puppet: &Puppet, markers: &[FittedMarker], obs: &[Option<Vec3>]) -> Vec<f64> {
    let mut p = vec![0.0; PARAM_COUNT];
    let groups = puppet.bone_groups();
    let pairs: Vec<(Vec3, Vec3)> = markers
        .iter()
        .zip(obs)
        .filter(|(m, _)| {
            matches!(
                groups[m.bone],
                super::puppet::PartGroup::Root | super::puppet::PartGroup::Torso
            )
        })
        .filter_map(|(m, o)| o.map(|x| (m.rest, x)))
        .collect();
    if let Some((r, t)) = super::puppet::kabsch(&pairs) {
        let root = puppet.rest_heads()[0];
        let d = t + r * root - root;
        p[0..3].copy_from_slice(d.as_slice());
        p[3..6].copy_from_slice(r.scaled_axis().as_slice());
    }
    p
}

/// Which parameters move a bone of `subset` (the marker bones and their ancestors): the root
/// and the chest and head (whose rotations the spine and neck bones share) always, a limb's
/// rotation when its bone is in the subset (it turns that bone and those below it only).
fn active_params(puppet: &Puppet, subset: &[usize]) -> [bool; PARAM_COUNT] {
    let mut active = [true; PARAM_COUNT];
    for k in 2..DRIVEN_BONES.len() {
        let used = puppet
            .driven_bone(k)
            .is_some_and(|b| subset.binary_search(&b).is_ok());
        active[6 + 3 * k..9 + 3 * k].fill(used);
    }
    active
}

/// Inverse kinematics of one frame as a least-squares problem.
struct MarkerIk<'a> {
    puppet: &'a Puppet,
    markers: &'a [FittedMarker],
    obs: &'a [Option<Vec3>],
    seen: &'a [usize],
    prior: Vec<f64>,
    pose: Pose,
    rows: usize,
    /// The marker bones and their ancestors: the only bones posed.
    subset: Vec<usize>,
    /// Parameters that move a marker; the others have only their prior row.
    active: [bool; PARAM_COUNT],
}

impl LeastSquares for MarkerIk<'_> {
    type State = Vec<f64>;

    fn parameter_count(&self) -> usize {
        PARAM_COUNT
    }

    fn residuals(&mut self, p: &Vec<f64>, out: &mut DVector<f64>) {
        if out.len() != self.rows {
            *out = DVector::zeros(self.rows);
        }
        self.puppet
            .pose_subset_into(p, &mut self.pose, &self.subset);
        for (r, &k) in self.seen.iter().enumerate() {
            let x = self.obs[k].unwrap_or_default();
            let e = marker_at(&self.pose, &self.markers[k]) - x;
            out.fixed_rows_mut::<3>(3 * r).copy_from(&e);
        }
        let o = 3 * self.seen.len();
        for i in 0..PARAM_COUNT {
            out[o + i] = PRIOR * (p[i] - self.prior[i]);
        }
    }

    fn jacobian(&mut self, p: &Vec<f64>, r: &DVector<f64>, jac: &mut DMatrix<f64>) {
        let mut differences = BoundedDifferences::new(self.rows);
        let o = 3 * self.seen.len();
        for i in 0..PARAM_COUNT {
            if !self.active[i] {
                jac.column_mut(i).fill(0.0);
                jac[(o + i, i)] = PRIOR;
                continue;
            }
            let hi = self.puppet.params()[i].hi;
            jac.set_column(
                i,
                differences.column(p, i, hi, r, |q, out| self.residuals(q, out)),
            );
        }
    }

    fn step(&mut self, p: &Vec<f64>, delta: &DVector<f64>) -> Vec<f64> {
        let mut q: Vec<f64> = p.iter().zip(delta.iter()).map(|(a, d)| a + d).collect();
        self.puppet.clamp(&mut q);
        q
    }
}
