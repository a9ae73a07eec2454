//! The motion of a golf broadcast sequence, as the puppet's parameters over time
//! (`load_motion`): a GEARS capture (C3D: the puppet fitted to the body markers, the club
//! to its markers, [`super::marker_fit`], [`super::club`]) or any BVH clip (the mannequin
//! driven by the retargeted clip, the puppet fitted to its sixteen tracking joints frame by
//! frame, [`Puppet::fit_to_joints`]; no club). The sequence maker then reshapes the puppet
//! (`reshaped`) and plays the parameters (`Swing`).

use std::path::Path;

use super::club::{fit_club, ClubFit, GEARS_CLUB};
use super::joints::JointSet;
use super::marker_fit::{fit_markers, MarkerFitOptions};
use super::marker_set::MarkerSet;
use super::puppet::{Proportions, Puppet};
use super::sequence_files::SequenceError;
use crate::body::{read_c3d, Animation, Mannequin, Motion, Pose, RetargetOptions};
use crate::geometry::{SplitMix64, Vec3};

/// A motion fitted with the puppet.
pub(crate) struct MotionSource {
    /// The puppet with the fitted proportions (the mannequin's for a BVH clip).
    pub puppet: Puppet,
    /// Parameters per fitted frame.
    pub params: Vec<Vec<f64>>,
    /// Fitted frames per second.
    pub rate: f64,
    /// The club fitted to its markers (captures only).
    pub club: Option<ClubFit>,
    /// The fit's residual RMS (m): markers for a capture, joints for a clip.
    pub residual_rms: f64,
    /// Length of the motion (s).
    pub duration: f64,
}

/// Reads the motion at `path` (`.c3d`: a GEARS capture; `.bvh`: a clip) and fits the puppet
/// on every `every`-th frame (the marker fit with `fit`).
pub(crate) fn load_motion(
    mannequin: &Mannequin,
    path: &Path,
    every: usize,
    fit: &MarkerFitOptions,
) -> Result<MotionSource, SequenceError> {
    let fail = |m: String| SequenceError::Motion {
        path: path.to_path_buf(),
        message: m,
    };
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "c3d" => {
            let mut trial = read_c3d(path)?;
            trial.up = trial.infer_up();
            let sub = trial.every(every);
            let f = fit_markers(mannequin, &sub, &MarkerSet::gears(), fit)
                .map_err(|m| fail(format!("marker fit: {m}")))?;
            let (a, b, wrist) = GEARS_CLUB;
            let club = fit_club(&sub, &a, &b, wrist).map_err(fail)?;
            Ok(MotionSource {
                residual_rms: f.rms(),
                puppet: f.puppet,
                params: f.params,
                rate: sub.rate,
                club: Some(club),
                duration: trial.duration(),
            })
        }
        "bvh" => {
            let clip = Motion::load_bvh(path)?;
            let rate = 1.0 / (clip.frame_time() * every as f64);
            let anim = Animation::new(mannequin.clone(), clip, RetargetOptions::default())?;
            let joints = JointSet::new(mannequin).map_err(fail)?;
            let puppet = Puppet::new(mannequin).map_err(fail)?;
            let n = (anim.duration() * rate + 1e-9).floor() as usize + 1;
            let mut pose = anim.mannequin().rest_pose();
            let mut fitted = Pose::identity(puppet.bone_count());
            let mut params: Vec<Vec<f64>> = Vec::with_capacity(n);
            let (mut sum, mut count) = (0.0, 0usize);
            for k in 0..n {
                anim.pose_at_into(k as f64 / rate, &mut pose);
                let target = joints.positions(&pose);
                let start = params.last().cloned().unwrap_or_default();
                let p = puppet.fit_to_joints(&target, &start);
                puppet.pose_into(&p, &mut fitted);
                for (a, b) in puppet.joints(&fitted).iter().zip(&target) {
                    sum += (a - b).norm_squared();
                    count += 1;
                }
                params.push(p);
            }
            Ok(MotionSource {
                puppet,
                params,
                rate,
                club: None,
                residual_rms: (sum / count.max(1) as f64).sqrt(),
                duration: anim.duration(),
            })
        }
        _ => Err(fail(format!(
            "unknown motion format `.{ext}` (a GEARS capture .c3d or a clip .bvh)"
        ))),
    }
}

/// `p` with each field multiplied by a factor drawn uniformly in `[1 − r, 1 + r]` from `rng`.
pub(crate) fn reshaped(p: Proportions, r: f64, rng: &mut SplitMix64) -> Proportions {
    let mut f = || 1.0 + rng.range(-r, r);
    Proportions {
        torso: p.torso * f(),
        neck: p.neck * f(),
        head: p.head * f(),
        upper_arm: p.upper_arm * f(),
        forearm: p.forearm * f(),
        hand: p.hand * f(),
        thigh: p.thigh * f(),
        shin: p.shin * f(),
        foot: p.foot * f(),
        girth: p.girth * f(),
    }
}

/// The motion as a function of time: the fitted parameters and the club (if any) in the lead
/// hand's rest frame, sampled at `rate`, interpolated linearly.
#[derive(Clone)]
pub(crate) struct Swing {
    pub rate: f64,
    pub params: Vec<Vec<f64>>,
    /// Grip and head in the golfer's lead-hand rest frame, per fitted frame.
    pub club: Option<Vec<(Vec3, Vec3)>>,
    pub hand: usize,
}

impl Swing {
    /// Parameters, and grip and head (golfer's rest frame of the hand) at time `t`.
    pub fn at(&self, t: f64, params: &mut Vec<f64>) -> Option<(Vec3, Vec3)> {
        let n = self.params.len();
        let x = (t * self.rate).clamp(0.0, (n - 1) as f64);
        let i = (x.floor() as usize).min(n - 1);
        let j = (i + 1).min(n - 1);
        let w = x - i as f64;
        params.clear();
        params.extend(
            self.params[i]
                .iter()
                .zip(&self.params[j])
                .map(|(a, b)| a + (b - a) * w),
        );
        let club = self.club.as_ref()?;
        let (a, b) = (club[i], club[j]);
        Some((a.0 + (b.0 - a.0) * w, a.1 + (b.1 - a.1) * w))
    }
}

/// Club points per fitted frame in the fitted hand's rest frame, moved to the golfer's hand
/// (`shift`); frames without a club fit take the nearest frame's. The grip is then held at
/// its mean place in the hand (the capture's wrist marker slides on the club by a few
/// centimetres, which would show the club beside the hands), the shaft keeping each frame's
/// direction and length. Fails when no frame has a club fit.
pub(crate) fn club_in_hand(
    fit_puppet: &Puppet,
    params: &[Vec<f64>],
    club: &ClubFit,
    hand: usize,
    shift: Vec3,
) -> Result<Vec<(Vec3, Vec3)>, String> {
    let mut pose = Pose::identity(fit_puppet.bone_count());
    let local: Vec<Option<(Vec3, Vec3)>> = params
        .iter()
        .enumerate()
        .map(|(f, p)| {
            let (g, h) = (club.grip.get(f).copied()??, club.head.get(f).copied()??);
            fit_puppet.pose_into(p, &mut pose);
            let inv = pose.transform(hand).inverse();
            let to_rest = |x: Vec3| (inv * nalgebra::Point3::from(x)).coords + shift;
            Some((to_rest(g), to_rest(h)))
        })
        .collect();
    let seen: Vec<usize> = (0..local.len()).filter(|&f| local[f].is_some()).collect();
    if seen.is_empty() {
        return Err("no frame sees three club markers".into());
    }
    let filled: Vec<(Vec3, Vec3)> = (0..local.len())
        .map(|f| {
            let k = seen.partition_point(|&s| s < f);
            let near = match (k.checked_sub(1).map(|i| seen[i]), seen.get(k)) {
                (Some(a), Some(&b)) => {
                    if f - a <= b - f {
                        a
                    } else {
                        b
                    }
                }
                (Some(a), None) => a,
                (None, Some(&b)) => b,
                (None, None) => unreachable!("seen is not empty"),
            };
            local[f].unwrap_or_else(|| local[near].expect("a seen frame"))
        })
        .collect();
    // the grip held fixed in the hand (its mean place), the shaft turned as captured
    let grip = filled.iter().map(|x| x.0).sum::<Vec3>() / filled.len() as f64;
    Ok(filled
        .into_iter()
        .map(|(g, h)| (grip, grip + (h - g)))
        .collect())
}
