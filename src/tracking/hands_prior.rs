//! The two-handed grip prior: a golfer (or anyone swinging a bat or an axe) holds one object
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
}
