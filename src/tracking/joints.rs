//! The tracking joints: the sixteen body points whose 3D positions the tracker reports and is
//! scored on (mean per-joint position error), defined on the MakeHuman skeleton.
//!
//! Each joint is one end of a MakeHuman bone and moves rigidly with that bone, so its
//! position under a [`Pose`] is `pose.apply(bone, rest end)`: exact, and the same for
//! the ground truth of a synthetic sequence and for the tracked puppet.

use crate::body::skinning::Pose;
use crate::body::Mannequin;
use crate::geometry::Vec3;

/// Number of tracking joints.
pub const JOINT_COUNT: usize = 16;

/// Which end of a bone a joint is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoneEnd {
    /// The bone's head (where it hangs from its parent).
    Head,
    /// The bone's tail.
    Tail,
}

/// One tracking joint: its name, the MakeHuman bone carrying it, which end, and its parent
/// tracking joint (for drawing the skeleton and writing BVH; `None` for the pelvis).
#[derive(Clone, Copy, Debug)]
pub struct TrackingJoint {
    /// Name used in files (CSV headers, BVH joints).
    pub name: &'static str,
    /// MakeHuman bone that carries the joint.
    pub bone: &'static str,
    /// End of that bone.
    pub end: BoneEnd,
    /// Index of the parent joint in [`TRACKING_JOINTS`].
    pub parent: Option<usize>,
}

const fn j(
    name: &'static str,
    bone: &'static str,
    end: BoneEnd,
    parent: Option<usize>,
) -> TrackingJoint {
    TrackingJoint {
        name,
        bone,
        end,
        parent,
    }
}

/// The tracking joints, parents before children. Sides are the body's own (`l_` = left,
/// which is +x in the engine's world).
pub const TRACKING_JOINTS: [TrackingJoint; JOINT_COUNT] = [
    j("pelvis", "root", BoneEnd::Head, None),
    j("spine", "spine02", BoneEnd::Head, Some(0)),
    j("neck", "neck01", BoneEnd::Head, Some(1)),
    j("head", "head", BoneEnd::Tail, Some(2)),
    j("l_shoulder", "upperarm01.L", BoneEnd::Head, Some(1)),
    j("l_elbow", "lowerarm01.L", BoneEnd::Head, Some(4)),
    j("l_wrist", "wrist.L", BoneEnd::Head, Some(5)),
    j("r_shoulder", "upperarm01.R", BoneEnd::Head, Some(1)),
    j("r_elbow", "lowerarm01.R", BoneEnd::Head, Some(7)),
    j("r_wrist", "wrist.R", BoneEnd::Head, Some(8)),
    j("l_hip", "upperleg01.L", BoneEnd::Head, Some(0)),
    j("l_knee", "lowerleg01.L", BoneEnd::Head, Some(10)),
    j("l_ankle", "foot.L", BoneEnd::Head, Some(11)),
    j("r_hip", "upperleg01.R", BoneEnd::Head, Some(0)),
    j("r_knee", "lowerleg01.R", BoneEnd::Head, Some(13)),
    j("r_ankle", "foot.R", BoneEnd::Head, Some(14)),
];

/// Index of a tracking joint by name.
pub fn joint_index(name: &str) -> Option<usize> {
    TRACKING_JOINTS.iter().position(|t| t.name == name)
}

/// The tracking joints resolved on one mannequin: bone indices and rest positions.
#[derive(Clone, Debug)]
pub struct JointSet {
    bones: [usize; JOINT_COUNT],
    rest: [Vec3; JOINT_COUNT],
}

impl JointSet {
    /// Resolves the joints on `mannequin`'s skeleton; the error names the first bone missing.
    pub fn new(mannequin: &Mannequin) -> Result<JointSet, String> {
        let sk = mannequin.skeleton();
        let mut bones = [0; JOINT_COUNT];
        let mut rest = [Vec3::zeros(); JOINT_COUNT];
        for (k, t) in TRACKING_JOINTS.iter().enumerate() {
            let b = sk.bone_index(t.bone).ok_or_else(|| {
                format!("the skeleton has no bone `{}` (joint {})", t.bone, t.name)
            })?;
            bones[k] = b;
            let bone = &sk.bones()[b];
            rest[k] = match t.end {
                BoneEnd::Head => bone.head,
                BoneEnd::Tail => bone.tail,
            };
        }
        Ok(JointSet { bones, rest })
    }

    /// Bone index carrying joint `k`.
    pub fn bone(&self, k: usize) -> usize {
        self.bones[k]
    }

    /// Rest position of joint `k`.
    pub fn rest(&self, k: usize) -> Vec3 {
        self.rest[k]
    }

    /// The joint positions under `pose` (one transform per mannequin bone).
    pub fn positions(&self, pose: &Pose) -> [Vec3; JOINT_COUNT] {
        std::array::from_fn(|k| pose.apply(self.bones[k], self.rest[k]))
    }
}

/// Mean per-joint position error between two joint sets (same units as the inputs).
pub fn mpjpe(a: &[Vec3; JOINT_COUNT], b: &[Vec3; JOINT_COUNT]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q).norm()).sum::<f64>() / JOINT_COUNT as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parents_come_first() {
        for (k, t) in TRACKING_JOINTS.iter().enumerate() {
            if let Some(p) = t.parent {
                assert!(p < k, "{}", t.name);
            }
        }
        assert_eq!(joint_index("r_wrist"), Some(9));
    }
}
