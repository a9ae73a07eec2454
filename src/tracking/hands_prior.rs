//! The golf grip priors. The two-handed grip: a golfer (or anyone swinging a bat or an axe) holds one object
//! with both hands, so the wrists stay within a grip's length of each other. Where one arm is
//! hidden or smeared by the shutter (the trail arm behind the lead one in the downswing), the
//! images alone let it wander; this prior keeps it on the grip. The tracker's right-arm stage
//! (searched after the left arm) adds it to the image cost when [`TrackerOptions::hands_apart`](super::tracker::TrackerOptions::hands_apart) is set.

use super::joints::{joint_index, JOINT_COUNT};
use crate::geometry::Vec3;

/// Distance over which the penalty grows by its weight (metres): a wrist this far beyond the
/// allowed separation costs [`HANDS_WEIGHT`].
pub const HANDS_SCALE: f64 = 0.05;

/// Weight of the prior in the tracker's cost units (about a thousand pixels' worth of image
/// misfit, the order of one forearm seen by four cameras).
pub const HANDS_WEIGHT: f64 = 0.1;

/// The penalty of joints whose wrists are more than `max_apart` metres apart:
/// `HANDS_WEIGHT · ((d − max_apart) / HANDS_SCALE)²`, zero within.
pub fn hands_apart_penalty(joints: &[Vec3; JOINT_COUNT], max_apart: f64) -> f64 {
    let (Some(l), Some(r)) = (joint_index("l_wrist"), joint_index("r_wrist")) else {
        return 0.0;
    };
    let excess = (joints[l] - joints[r]).norm() - max_apart;
    if excess > 0.0 {
        HANDS_WEIGHT * (excess / HANDS_SCALE).powi(2)
    } else {
        0.0
    }
}

/// Scale of the lead-elbow penalty (radians): an elbow this far past the allowed bend costs
/// [`HANDS_WEIGHT`].
pub const ELBOW_SCALE: f64 = 0.35;

/// The penalty of joints whose left elbow angle (between the upper arm and the forearm,
/// π = straight) is below `min_angle` radians: `HANDS_WEIGHT · ((min_angle − angle) /
/// ELBOW_SCALE)²`, zero above.
pub fn lead_elbow_penalty(joints: &[Vec3; JOINT_COUNT], min_angle: f64) -> f64 {
    let (Some(s), Some(e), Some(w)) = (
        joint_index("l_shoulder"),
        joint_index("l_elbow"),
        joint_index("l_wrist"),
    ) else {
        return 0.0;
    };
    let (a, b) = (joints[s] - joints[e], joints[w] - joints[e]);
    let (na, nb) = (a.norm(), b.norm());
    if na < 1e-9 || nb < 1e-9 {
        return 0.0;
    }
    let angle = (a.dot(&b) / (na * nb)).clamp(-1.0, 1.0).acos();
    let short = min_angle - angle;
    if short > 0.0 {
        HANDS_WEIGHT * (short / ELBOW_SCALE).powi(2)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with_wrists(l: Vec3, r: Vec3) -> [Vec3; JOINT_COUNT] {
        let mut j = [Vec3::zeros(); JOINT_COUNT];
        j[joint_index("l_wrist").unwrap()] = l;
        j[joint_index("r_wrist").unwrap()] = r;
        j
    }

    #[test]
    fn wrists_on_one_grip_pay_nothing_and_apart_pay_quadratically() {
        let near = with_wrists(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.1, 0.0, 1.0));
        assert_eq!(hands_apart_penalty(&near, 0.18), 0.0);
        let far = with_wrists(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.28, 0.0, 1.0));
        let p1 = hands_apart_penalty(&far, 0.18);
        assert!((p1 - HANDS_WEIGHT * 4.0).abs() < 1e-9, "{p1}");
        let farther = with_wrists(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.38, 0.0, 1.0));
        assert!((hands_apart_penalty(&farther, 0.18) - 4.0 * p1).abs() < 1e-9);
    }

    #[test]
    fn a_straight_lead_arm_pays_nothing_and_a_folded_one_pays() {
        let mut j = [Vec3::zeros(); JOINT_COUNT];
        j[joint_index("l_shoulder").unwrap()] = Vec3::new(0.0, 0.0, 1.4);
        j[joint_index("l_elbow").unwrap()] = Vec3::new(0.0, 0.0, 1.1);
        j[joint_index("l_wrist").unwrap()] = Vec3::new(0.0, 0.0, 0.85);
        let min = 100f64.to_radians();
        assert_eq!(lead_elbow_penalty(&j, min), 0.0);
        // folded to 60°: 40° short of the allowed bend
        let e = j[joint_index("l_elbow").unwrap()];
        let dir = Vec3::new(60f64.to_radians().sin(), 0.0, 60f64.to_radians().cos());
        j[joint_index("l_wrist").unwrap()] = e + 0.25 * dir;
        let p = lead_elbow_penalty(&j, min);
        let want = HANDS_WEIGHT * (40f64.to_radians() / ELBOW_SCALE).powi(2);
        assert!((p - want).abs() < 1e-9, "{p} against {want}");
    }
}
