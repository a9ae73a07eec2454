//! Limbs kept still in the world while the trunk moves ([`Puppet::keep_limbs`]): the
//! parameters of the upper arms and thighs rewritten so that their world rotation stays what
//! it was in a reference pose ([`LimbAnchor`]), whatever the pelvis and chest do. A child
//! module of [`super`] (declared there with a `path` attribute), so it reaches the puppet's
//! fields.
//!
//! The tracker's trunk stage moves the pelvis and chest with the limbs' parameters (relative
//! to their parents) fixed, so turning the pelvis swings planted legs with it and the legs'
//! misfit outweighs the trunk's better fit; with the limbs anchored, a trunk candidate is
//! judged on the trunk, and the limb stages that follow move the limbs.

use nalgebra::UnitQuaternion;

use super::{Drive, Puppet};
use crate::body::Pose;

/// Driven-bone indices of the limb roots: left upper arm, left thigh, right upper arm, right
/// thigh (`DRIVEN_BONES` order).
const LIMB_ROOTS: [usize; 4] = [2, 5, 8, 11];

/// World rotations of the limb roots in a reference pose, and the bones to pose to find
/// their parents' rotations.
#[derive(Clone, Debug)]
pub struct LimbAnchor {
    rotations: [UnitQuaternion<f64>; 4],
    parents: [Option<usize>; 4],
    subset: Vec<usize>,
}

impl Puppet {
    /// The anchor of the limbs at `params` (allocates; once per search, not per candidate).
    pub fn limb_anchor(&self, params: &[f64]) -> LimbAnchor {
        let mut pose = Pose::identity(self.heads.len());
        self.pose_into(params, &mut pose);
        let bones = LIMB_ROOTS.map(|k| self.driven[k]);
        let parents = bones.map(|b| self.base.parents[b]);
        let subset = self.with_ancestors(&parents.iter().flatten().copied().collect::<Vec<_>>());
        LimbAnchor {
            rotations: bones.map(|b| pose.transform(b).rotation),
            parents,
            subset,
        }
    }

    /// Rewrites the limb roots' parameters in `params` so their world rotations are the
    /// anchor's under the trunk of `params` (`scratch`: a pose reused between calls). Limits
    /// are not applied (see [`Puppet::clamp`]).
    pub fn keep_limbs(&self, params: &mut [f64], anchor: &LimbAnchor, scratch: &mut Pose) {
        self.pose_subset_into(params, scratch, &anchor.subset);
        for (i, &k) in LIMB_ROOTS.iter().enumerate() {
            debug_assert!(matches!(self.drives[self.driven[k]], Drive::Limb(_)));
            let parent = anchor.parents[i].map_or_else(
                || {
                    UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(
                        params[3], params[4], params[5],
                    ))
                },
                |q| scratch.transform(q).rotation,
            );
            let v =
                self.frames[k].transpose() * (parent.inverse() * anchor.rotations[i]).scaled_axis();
            params[6 + 3 * k..9 + 3 * k].copy_from_slice(v.as_slice());
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::body::{Mannequin, Pose};
    use crate::geometry::files::data_path;
    use crate::tracking::puppet::Puppet;

    #[test]
    fn a_turned_trunk_leaves_the_anchored_limbs_where_they_were() {
        let dir = data_path("bodies/makehuman");
        if !dir.is_dir() {
            eprintln!("skipped: {} is absent", dir.display());
            return;
        }
        let m = Mannequin::load_makehuman(&dir).unwrap();
        let puppet = Puppet::new(&m).unwrap();
        let mut p = puppet.rest_params();
        // a bent pose: arms raised and a knee bent
        for (i, v) in [(6 + 6, 0.6), (6 + 24, 0.8), (6 + 15, 0.4), (6 + 18, -0.9)] {
            p[i] = v;
        }
        let anchor = puppet.limb_anchor(&p);
        let mut q = p.clone();
        q[5] += 0.5; // the pelvis turned about z
        q[6 + 1] += 0.3; // the chest twisted
        let mut scratch = Pose::identity(0);
        puppet.keep_limbs(&mut q, &anchor, &mut scratch);
        let (mut a, mut b) = (Pose::identity(0), Pose::identity(0));
        puppet.pose_into(&p, &mut a);
        puppet.pose_into(&q, &mut b);
        for k in super::LIMB_ROOTS {
            let bone = puppet.driven[k];
            let d = a
                .transform(bone)
                .rotation
                .angle_to(&b.transform(bone).rotation);
            assert!(d < 1e-9, "limb {k}: turned by {d} rad");
        }
        // and the elbows and knees keep their bend: the forearm turns as the upper arm
        let fore = puppet.driven[3];
        let d = a
            .transform(fore)
            .rotation
            .angle_to(&b.transform(fore).rotation);
        assert!(d < 1e-9, "{d}");
    }
}
