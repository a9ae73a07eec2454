//! A golfer's address pose, made from the puppet's own rest joints and the textbook set-up
//! (not from any capture): the upper body tilted forward from the hips, the knees flexed
//! and forward, the arms hanging from the shoulders with the hands together in front of
//! the lead thigh. The automatic start on a golf sequence searches from it
//! ([`TrackerOptions::golf_address`](super::tracker::TrackerOptions::golf_address)), as a
//! silhouette alone does not tell a forward bend with hanging arms from a standing pose
//! under loose clothes.

use super::joints::{joint_index, JOINT_COUNT};
use super::puppet::Puppet;
use crate::geometry::Vec3;

/// Forward tilt of the upper body from the hips (radians; 30–45° in golf instruction).
pub const SPINE_TILT: f64 = 0.6;
/// Forward travel of the knees from their rest place (metres; a 15–25° knee flex).
const KNEE_FORWARD: f64 = 0.08;
/// How far the hips sit back and down as the knees flex and the trunk tilts (metres).
const HIPS_BACK: f64 = 0.06;
const HIPS_DOWN: f64 = 0.04;
/// The hands' place across the body, toward the lead (left, +x) side (metres).
const HANDS_LEAD: f64 = 0.05;

fn at(name: &str) -> usize {
    joint_index(name).unwrap_or(0)
}

/// The address joints of `puppet` (world metres, facing −y as the puppet at rest).
pub fn address_joints(puppet: &Puppet) -> [Vec3; JOINT_COUNT] {
    let rest = puppet.rest_joints();
    let mut j = rest;
    let hips = ["l_hip", "r_hip"].map(at);
    let centre = 0.5 * (rest[hips[0]] + rest[hips[1]]);
    let shift = Vec3::new(0.0, HIPS_BACK, -HIPS_DOWN);
    // the upper body turns forward (toward −y) about the hips' line
    let (s, c) = SPINE_TILT.sin_cos();
    let tilt = |p: Vec3| {
        let d = p - centre;
        centre + Vec3::new(d.x, c * d.y - s * d.z, s * d.y + c * d.z) + shift
    };
    for name in ["spine", "neck", "head", "l_shoulder", "r_shoulder"] {
        j[at(name)] = tilt(rest[at(name)]);
    }
    for name in ["pelvis", "l_hip", "r_hip"] {
        j[at(name)] = rest[at(name)] + shift;
    }
    for name in ["l_knee", "r_knee"] {
        j[at(name)] = rest[at(name)] + Vec3::new(0.0, -KNEE_FORWARD, -0.01);
    }
    // arms straight down from the shoulders to hands together below the chest
    let shoulders = [at("l_shoulder"), at("r_shoulder")];
    let mid = 0.5 * (j[shoulders[0]] + j[shoulders[1]]);
    for (side, (sh, el, wr)) in [
        ("l_shoulder", "l_elbow", "l_wrist"),
        ("r_shoulder", "r_elbow", "r_wrist"),
    ]
    .iter()
    .enumerate()
    {
        let (sh, el, wr) = (at(sh), at(el), at(wr));
        let reach = (rest[el] - rest[sh]).norm() + (rest[wr] - rest[el]).norm();
        let across = if side == 0 { 0.03 } else { -0.03 };
        let hand_x = centre.x + HANDS_LEAD + across;
        let horizontal = Vec3::new(hand_x - j[sh].x, mid.y - 0.05 - j[sh].y, 0.0);
        let drop = (0.95 * reach).powi(2) - horizontal.norm_squared();
        let wrist = j[sh] + horizontal - Vec3::new(0.0, 0.0, drop.max(0.0).sqrt());
        j[wr] = wrist;
        j[el] = 0.5 * (j[sh] + wrist) + Vec3::new(0.0, 0.02, 0.0);
    }
    j
}

/// The puppet's parameters closest to [`address_joints`] (its pre-positioning fit).
pub fn golf_address_pose(puppet: &Puppet) -> Vec<f64> {
    puppet.fit_to_joints(&address_joints(puppet), &puppet.rest_params())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::Mannequin;

    #[test]
    fn the_address_pose_bends_forward_with_the_hands_together_below_the_chest() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/data/bodies/makehuman");
        let Ok(m) = Mannequin::load_makehuman(&dir) else {
            eprintln!("skipped: no MakeHuman body under {}", dir.display());
            return;
        };
        let puppet = Puppet::new(&m).unwrap();
        let p = golf_address_pose(&puppet);
        let mut pose = crate::body::Pose::identity(0);
        puppet.pose_into(&p, &mut pose);
        let j = puppet.joints(&pose);
        let rest = puppet.rest_joints();
        // the head goes forward (−y) and down, the wrists meet below the shoulders
        assert!(
            j[at("head")].y < rest[at("head")].y - 0.3,
            "{:?}",
            j[at("head")]
        );
        assert!(j[at("head")].z < rest[at("head")].z - 0.15);
        let wrists = (j[at("l_wrist")] - j[at("r_wrist")]).norm();
        assert!(wrists < 0.15, "wrists {wrists} m apart");
        assert!(j[at("l_wrist")].z < j[at("l_shoulder")].z - 0.4);
        // the fit lands near its target joints (within the joint limits)
        let target = address_joints(&puppet);
        let worst = (0..JOINT_COUNT)
            .map(|k| (j[k] - target[k]).norm())
            .fold(0.0, f64::max);
        assert!(
            worst < 0.08,
            "worst joint {worst} m from the address joints"
        );
    }
}
