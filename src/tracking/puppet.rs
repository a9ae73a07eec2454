//! The tracking puppet: a 48-parameter pose space with joint limits that drives every bone of
//! the MakeHuman skeleton exactly as the retargeting of a BVH clip does
//! ([`crate::body::retarget`]), its own (re-proportionable) rest geometry, and the
//! pre-positioning fit of a pose to 3D tracking joints.
//!
//! Parameters ([`PARAM_COUNT`] values, see [`Puppet::params`] for names, limits and groups):
//! `[0..3]` root translation (world metres: displacement of the `root` bone head from rest),
//! `[3..6]` root rotation vector (world axes, about the root head), then one rotation vector
//! per bone of [`DRIVEN_BONES`], in that order, expressed in the bone's rest frame: `y` along
//! the bone (toward the joint it points to), `z` forward (for feet: up), `x = y × z` lateral.
//! So `x` is flexion, `y` twist about the bone and `z` the sideways bend (abduction); the
//! right side's frames are mirror images of the left's, so their `y` and `z` limits are the
//! left ones negated.
//!
//! World rotations compose as the retargeting does: a limb bone turns relative to its
//! skeleton parent, `R_b = R_parent · exp(F_b v_b)`; the chest (`spine02`) turns relative to
//! the pelvis and the head relative to the chest (their skeleton parents are the lumbar and
//! neck bones, which themselves take shares of those rotations: `spine05/04/03` get
//! `R_root · slerp(I, R_root⁻¹ R_chest, ¼, ½, ¾)`, `neck01/02/03` the same between chest and
//! head). Every other bone follows its parent; every bone's head goes where its parent
//! carries it. A retargeted pose is therefore reproduced exactly by
//! [`Puppet::pose_into`]`(`[`Puppet::params_from_pose`]`(pose))`.
//!
//! [`Proportions`] stretch segments along their axis (and all across by a girth factor); the
//! puppet then carries its own rest bone heads, tracking joints and rest skin
//! ([`Puppet::rest_skin`]), and poses are relative to that rest geometry.
//!
//! Two child files hold the rest: `puppet_rest.rs` (proportions and the rest geometry) and
//! `puppet_fit.rs` (the fit to joints, [`Puppet::fit_to_joints`]).

use nalgebra::{Isometry3, Matrix3, Point3, Translation3, UnitQuaternion};

use super::joints::{BoneEnd, JOINT_COUNT, TRACKING_JOINTS};
use crate::body::{Mannequin, Pose, SkinWeights};
use crate::geometry::Vec3;

#[path = "puppet_fit.rs"]
pub(crate) mod fit;
#[path = "puppet_limbs.rs"]
mod limbs;
#[path = "puppet_rest.rs"]
mod rest;

pub(crate) use fit::kabsch;
pub use limbs::LimbAnchor;
pub use rest::Proportions;
use rest::{right_of, Segment, KEYS};

/// Number of pose parameters.
pub const PARAM_COUNT: usize = 6 + 3 * DRIVEN_BONES.len();

/// Bones with their own rotation parameters, in parameter order (after the six root values),
/// with the joint their frame's `y` axis points to.
pub const DRIVEN_BONES: [(&str, &str); 14] = [
    ("spine02", "neck01____head"),
    ("head", "head____tail"),
    ("upperarm01.L", "lowerarm01.L____head"),
    ("lowerarm01.L", "wrist.L____head"),
    ("wrist.L", "finger3-1.L____head"),
    ("upperleg01.L", "lowerleg01.L____head"),
    ("lowerleg01.L", "foot.L____head"),
    ("foot.L", "toe3-1.L____head"),
    ("upperarm01.R", "lowerarm01.R____head"),
    ("lowerarm01.R", "wrist.R____head"),
    ("wrist.R", "finger3-1.R____head"),
    ("upperleg01.R", "lowerleg01.R____head"),
    ("lowerleg01.R", "foot.R____head"),
    ("foot.R", "toe3-1.R____head"),
];

/// Limits (degrees) of the left side's `[x flexion, y twist, z side]` components, by bone kind
/// (`DRIVEN_BONES` order without side); the right side negates `y` and `z`. Signs: positive
/// `x` bends the chest and head forward, raises the upper arm and thigh forward, bends the
/// elbow and lifts the toes; the knee bends with negative `x`; positive `z` abducts the upper
/// arm and thigh. Anatomical ranges, widened where the retargeting of the eight CMU clips goes
/// past them (checked on every frame by the test `tracking_puppet`): retargeting swings limbs
/// without twist, so an upper arm or thigh turned in or out shows up further down as a side
/// bend of the elbow, wrist, knee or ankle, and the A-pose rest shifts the shoulder's zero.
const LIMITS_DEG: [[(f64, f64); 3]; 8] = [
    // chest relative to pelvis (data: flex −14..13, twist −15..22, side −20..12)
    [(-35.0, 70.0), (-45.0, 45.0), (-35.0, 35.0)],
    // head relative to chest (data: −10..26, −32..44, −19..16)
    [(-60.0, 70.0), (-80.0, 80.0), (-45.0, 45.0)],
    // shoulder, from the A-pose (data: −57..92, 0, −47..56): extension widened to 90°
    [(-90.0, 180.0), (-100.0, 100.0), (-90.0, 150.0)],
    // elbow (data: −43..83, 0, −44..21): retargeting leaves the forearm up to 43° behind the
    // upper arm's frame and bent sideways (no upper-arm twist), so −50° and ±50°, not ~0/±20°
    [(-50.0, 160.0), (-90.0, 90.0), (-50.0, 50.0)],
    // wrist (data: −59..67, 0, −36..61): side widened from ~±35° (no forearm pronation)
    [(-85.0, 85.0), (-90.0, 90.0), (-50.0, 70.0)],
    // hip (data: −34..92, 0, −24..34)
    [(-40.0, 130.0), (-50.0, 50.0), (-35.0, 50.0)],
    // knee (data: −103..7, 0, −68..10): 7° past the rest's straight leg (the A-pose knee is
    // not quite straight) allowed as 12°; side widened to −75..20 (no thigh twist)
    [(-160.0, 12.0), (-40.0, 40.0), (-75.0, 20.0)],
    // ankle (data: −22..47, 0, −17..80): the foot's turn-out (leg twist, absent from the
    // retargeting) lands on the ankle's side axis, widened to 90°
    [(-60.0, 60.0), (-45.0, 45.0), (-30.0, 90.0)],
];

/// Shares of the lower→upper rotation taken by the lumbar spine (pelvis→chest) and the neck
/// (chest→head): the same table as `BLENDS` in `body/retarget.rs`, so poses agree exactly.
const BLENDS: [(&str, bool, f64); 6] = [
    ("spine05", false, 0.25),
    ("spine04", false, 0.5),
    ("spine03", false, 0.75),
    ("neck01", true, 0.25),
    ("neck02", true, 0.5),
    ("neck03", true, 0.75),
];

/// Root translation limit (metres, each axis) and root rotation-vector limit (radians, each
/// component: wider than π so a tracker can turn through a half turn continuously).
const ROOT_TRANSLATION: f64 = 5.0;
const ROOT_ROTATION: f64 = 2.0 * std::f64::consts::PI;

/// The body part a bone, a skin vertex or a parameter belongs to (sides are the body's own).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PartGroup {
    /// Pelvis (the root bone and what follows it rigidly); the root parameters.
    Root,
    /// Lumbar spine, chest, collar bones and shoulder blades; the chest parameters.
    Torso,
    /// Neck and head with the face; the head parameters.
    Head,
    /// Left upper arm and forearm.
    LeftArm,
    /// Right upper arm and forearm.
    RightArm,
    /// Left hand and fingers.
    LeftHand,
    /// Right hand and fingers.
    RightHand,
    /// Left thigh and shin.
    LeftLeg,
    /// Right thigh and shin.
    RightLeg,
    /// Left foot and toes.
    LeftFoot,
    /// Right foot and toes.
    RightFoot,
}

/// Name, limits and body part of one pose parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamInfo {
    /// `root.tx`, `root.rz`, `lowerarm01.L.flex`, `head.twist`, `foot.R.side`, ...
    pub name: String,
    /// Lower limit (metres or radians).
    pub lo: f64,
    /// Upper limit.
    pub hi: f64,
    /// Body part moved by the parameter.
    pub group: PartGroup,
}

/// How one bone's rotation is made.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Drive {
    Root,
    Follow,
    Chest,
    Head,
    /// Limb: parent rotation times the local rotation of driven bone `k`.
    Limb(usize),
    /// Share of the pelvis→chest (`false`) or chest→head (`true`) rotation.
    Blend(bool, f64),
}

/// The mannequin's rest data the puppet is built from (kept to re-proportion).
#[derive(Clone, Debug)]
struct Base {
    heads: Vec<Vec3>,
    parents: Vec<Option<usize>>,
    /// Per bone: its segment and the segment's rest axis.
    segment: Vec<(Segment, Vec3)>,
    groups: Vec<PartGroup>,
    /// Per driven bone: rest point its `y` axis points to.
    toward: [Vec3; 14],
    /// Tracking joints: carrying bone and rest point.
    joints: [(usize, Vec3); JOINT_COUNT],
    skin: Vec<Vec3>,
    weights: SkinWeights,
}

/// The tracking puppet (see the module docs).
#[derive(Clone, Debug)]
pub struct Puppet {
    base: Base,
    proportions: Proportions,
    drives: Vec<Drive>,
    driven: [usize; 14],
    root: usize,
    /// Rest bone heads of this puppet (after proportions).
    heads: Vec<Vec3>,
    /// Rest frames `[x y z]` of the driven bones.
    frames: [Matrix3<f64>; 14],
    joint_rest: [Vec3; JOINT_COUNT],
    rest_skin: Vec<Vec3>,
    params: Vec<ParamInfo>,
}

/// A finite number, or 0.
fn finite(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

impl Puppet {
    /// Builds the puppet on `mannequin`'s skeleton and skin; the error names the first bone or
    /// joint missing or degenerate.
    pub fn new(mannequin: &Mannequin) -> Result<Puppet, String> {
        let sk = mannequin.skeleton();
        let bones = sk.bones();
        let bone = |n: &str| {
            sk.bone_index(n)
                .ok_or_else(|| format!("the skeleton has no bone `{n}`"))
        };
        let joint = |n: &str| {
            sk.joint(n)
                .map(|j| j.rest)
                .ok_or_else(|| format!("the skeleton has no joint `{n}`"))
        };
        let root = bones
            .iter()
            .position(|b| b.parent.is_none())
            .ok_or("the skeleton has no root")?;
        if root != bone("root")? {
            return Err("the skeleton's root bone is not `root`".into());
        }
        let mut drives = vec![Drive::Follow; bones.len()];
        drives[root] = Drive::Root;
        drives[bone("spine02")?] = Drive::Chest;
        drives[bone("head")?] = Drive::Head;
        for (name, upper, share) in BLENDS {
            drives[bone(name)?] = Drive::Blend(upper, share);
        }
        let mut driven = [0; 14];
        let mut toward = [Vec3::zeros(); 14];
        for (k, (name, to)) in DRIVEN_BONES.iter().enumerate() {
            driven[k] = bone(name)?;
            toward[k] = joint(to)?;
            if k >= 2 {
                drives[driven[k]] = Drive::Limb(k);
            }
        }
        // segments and part groups: nearest key ancestor-or-self
        let mut key_of: Vec<Option<(Segment, PartGroup, Vec3)>> = vec![None; bones.len()];
        for (name, seg, group) in KEYS {
            for side in ["L", "R"] {
                let (full, group) = match name {
                    "root" | "spine05" | "neck01" | "head" if side == "R" => continue,
                    "root" | "spine05" | "neck01" | "head" => (name.to_string(), group),
                    _ if side == "L" => (format!("{name}.L"), group),
                    _ => (format!("{name}.R"), right_of(group)),
                };
                let b = bone(&full)?;
                let axis = match seg {
                    Segment::Torso | Segment::Head => Vec3::z(),
                    Segment::Neck => joint("head____head")? - bones[b].head,
                    _ => {
                        let k = driven.iter().position(|&d| d == b).ok_or("bad key")?;
                        toward[k] - bones[b].head
                    }
                };
                let axis = axis
                    .try_normalize(1e-9)
                    .ok_or_else(|| format!("bone `{full}` has no length"))?;
                key_of[b] = Some((seg, group, axis));
            }
        }
        let mut segment: Vec<(Segment, Vec3)> = Vec::with_capacity(bones.len());
        let mut groups = Vec::with_capacity(bones.len());
        for (b, bn) in bones.iter().enumerate() {
            let (seg, group, axis) = match (key_of[b], bn.parent) {
                (Some(k), _) => k,
                (None, Some(p)) => (segment[p].0, groups[p], segment[p].1),
                (None, None) => return Err("the root is not a key bone".into()),
            };
            segment.push((seg, axis));
            groups.push(group);
        }
        let mut joints = [(0, Vec3::zeros()); JOINT_COUNT];
        for (k, t) in TRACKING_JOINTS.iter().enumerate() {
            let b = bone(t.bone)?;
            joints[k] = (
                b,
                match t.end {
                    BoneEnd::Head => bones[b].head,
                    BoneEnd::Tail => bones[b].tail,
                },
            );
        }
        let base = Base {
            heads: bones.iter().map(|b| b.head).collect(),
            parents: bones.iter().map(|b| b.parent).collect(),
            segment,
            groups,
            toward,
            joints,
            skin: mannequin.rest_positions().to_vec(),
            weights: mannequin.weights().clone(),
        };
        Puppet::build(base, drives, driven, root, Proportions::default())
    }
}

/// Names, limits and groups of all parameters.
fn param_table(driven: &[usize; 14], groups: &[PartGroup]) -> Vec<ParamInfo> {
    let mut out = Vec::with_capacity(PARAM_COUNT);
    for (i, n) in ["tx", "ty", "tz", "rx", "ry", "rz"].iter().enumerate() {
        let l = if i < 3 {
            ROOT_TRANSLATION
        } else {
            ROOT_ROTATION
        };
        out.push(ParamInfo {
            name: format!("root.{n}"),
            lo: -l,
            hi: l,
            group: PartGroup::Root,
        });
    }
    for (k, (name, _)) in DRIVEN_BONES.iter().enumerate() {
        let (kind, right) = if k < 8 { (k, false) } else { (k - 6, true) };
        for (c, comp) in ["flex", "twist", "side"].iter().enumerate() {
            let (lo, hi) = LIMITS_DEG[kind][c];
            let (lo, hi) = if right && c > 0 { (-hi, -lo) } else { (lo, hi) };
            out.push(ParamInfo {
                name: format!("{name}.{comp}"),
                lo: lo.to_radians(),
                hi: hi.to_radians(),
                group: groups[driven[k]],
            });
        }
    }
    out
}

impl Puppet {
    /// Number of pose parameters ([`PARAM_COUNT`]).
    pub fn param_count(&self) -> usize {
        PARAM_COUNT
    }

    /// Name, limits and body part of every parameter, in parameter order.
    pub fn params(&self) -> &[ParamInfo] {
        &self.params
    }

    /// The rest pose's parameters (the mannequin's A-pose): all zeros.
    pub fn rest_params(&self) -> Vec<f64> {
        vec![0.0; PARAM_COUNT]
    }

    /// The proportions this puppet was built with.
    pub fn proportions(&self) -> Proportions {
        self.proportions
    }

    /// Number of skeleton bones (the length of the poses it makes).
    pub fn bone_count(&self) -> usize {
        self.heads.len()
    }

    /// Skeleton index of driven bone `k` ([`DRIVEN_BONES`] order; `None` past the end).
    pub fn driven_bone(&self, k: usize) -> Option<usize> {
        self.driven.get(k).copied()
    }

    /// Rest frame `[x flexion axis, y along the bone, z]` (world) of driven bone `k`.
    pub fn driven_frame(&self, k: usize) -> Option<Matrix3<f64>> {
        self.frames.get(k).copied()
    }

    /// Body part of every skeleton bone.
    pub fn bone_groups(&self) -> &[PartGroup] {
        &self.base.groups
    }

    /// Rest bone heads of this puppet (after proportions).
    pub fn rest_heads(&self) -> &[Vec3] {
        &self.heads
    }

    /// Rest positions of the tracking joints of this puppet, in `TRACKING_JOINTS` order.
    pub fn rest_joints(&self) -> [Vec3; JOINT_COUNT] {
        self.joint_rest
    }

    /// Rest skin of this puppet: the mannequin's skin vertices re-proportioned (each vertex
    /// carried by the weighted blend of its bones' segment stretches). Poses made by
    /// [`Puppet::pose_into`] apply to these points, not to the mannequin's.
    pub fn rest_skin(&self) -> &[Vec3] {
        &self.rest_skin
    }

    /// Skinning weights of [`Puppet::rest_skin`] (the mannequin's).
    pub fn weights(&self) -> &SkinWeights {
        &self.base.weights
    }

    /// Linear blend skinning of this puppet's rest skin under `pose`, into `out`.
    pub fn skin(&self, pose: &Pose, out: &mut Vec<Vec3>) {
        if pose.len() == self.heads.len() {
            self.base.weights.skin(&self.rest_skin, pose, out);
        } else {
            out.clear();
            out.extend_from_slice(&self.rest_skin);
        }
    }

    /// Forward kinematics: the transform of every skeleton bone for `params`, into `pose`
    /// (no allocation when `pose` has [`Puppet::bone_count`] bones; otherwise it is replaced).
    /// Missing or non-finite parameters count as 0; limits are not applied (see
    /// [`Puppet::clamp`]).
    pub fn pose_into(&self, params: &[f64], pose: &mut Pose) {
        self.pose_bones(params, pose, 0..self.heads.len());
    }

    /// The bones of `bones` with all their ancestors, ascending (parents first): the set
    /// [`Puppet::pose_subset_into`] needs to place `bones`.
    pub fn with_ancestors(&self, bones: &[usize]) -> Vec<usize> {
        let n = self.heads.len();
        let mut keep = vec![false; n];
        for &b in bones.iter().filter(|&&b| b < n) {
            let mut c = Some(b);
            while let Some(k) = c {
                if keep[k] {
                    break;
                }
                keep[k] = true;
                c = self.base.parents[k];
            }
        }
        (0..n).filter(|&b| keep[b]).collect()
    }

    /// [`Puppet::pose_into`] for the bones of `subset` only (ascending and closed under
    /// parents, as [`Puppet::with_ancestors`] gives); the other transforms are left as they
    /// were. For inverse kinematics that reads a few bones.
    pub fn pose_subset_into(&self, params: &[f64], pose: &mut Pose, subset: &[usize]) {
        self.pose_bones(params, pose, subset.iter().copied());
    }

    /// Forward kinematics over `bones` (parents before children).
    fn pose_bones(&self, params: &[f64], pose: &mut Pose, bones: impl Iterator<Item = usize>) {
        let n = self.heads.len();
        if pose.len() != n {
            *pose = Pose::identity(n);
        }
        let v = |i: usize| finite(params.get(i).copied().unwrap_or(0.0));
        let vec = |i: usize| Vec3::new(v(i), v(i + 1), v(i + 2));
        let local = |k: usize| UnitQuaternion::from_scaled_axis(self.frames[k] * vec(6 + 3 * k));
        let r_root = UnitQuaternion::from_scaled_axis(vec(3));
        let r_chest = r_root * local(0);
        let r_head = r_chest * local(1);
        for b in bones.filter(|&b| b < n) {
            let h = self.heads[b];
            let (head, r) = match (self.drives[b], self.base.parents[b]) {
                (Drive::Root, _) | (_, None) => (h + vec(0), r_root),
                (d, Some(q)) => {
                    let t = *pose.transform(q);
                    let r = match d {
                        Drive::Follow | Drive::Root => t.rotation,
                        Drive::Chest => r_chest,
                        Drive::Head => r_head,
                        Drive::Limb(k) => t.rotation * local(k),
                        Drive::Blend(upper, share) => {
                            let (lo, up) = if upper {
                                (r_chest, r_head)
                            } else {
                                (r_root, r_chest)
                            };
                            // as retarget.rs: lower · slerp(I, lower⁻¹ upper, share)
                            lo * UnitQuaternion::identity().slerp(&(lo.inverse() * up), share)
                        }
                    };
                    ((t * Point3::from(h)).coords, r)
                }
            };
            pose.set(
                b,
                Isometry3::from_parts(Translation3::from(head - r * h), r),
            );
        }
    }

    /// The parameters of `pose`: the inverse of [`Puppet::pose_into`], exact for any pose the
    /// retargeting makes and for parameters whose rotation vectors are shorter than π (each
    /// rotation comes back as its principal rotation vector). Bones missing from a short pose
    /// count as at rest.
    pub fn params_from_pose(&self, pose: &Pose) -> Vec<f64> {
        let tf = |b: usize| {
            pose.transforms()
                .get(b)
                .copied()
                .unwrap_or_else(Isometry3::identity)
        };
        let mut p = vec![0.0; PARAM_COUNT];
        let root = tf(self.root);
        let h = self.heads[self.root];
        let d = (root * Point3::from(h)).coords - h;
        let rv = root.rotation.scaled_axis();
        p[0..3].copy_from_slice(d.as_slice());
        p[3..6].copy_from_slice(rv.as_slice());
        for k in 0..14 {
            let b = self.driven[k];
            let base = match k {
                0 => root.rotation,
                1 => tf(self.driven[0]).rotation,
                _ => self.base.parents[b].map_or(root.rotation, |q| tf(q).rotation),
            };
            let v = self.frames[k].transpose() * (base.inverse() * tf(b).rotation).scaled_axis();
            p[6 + 3 * k..9 + 3 * k].copy_from_slice(v.as_slice());
        }
        p
    }

    /// The tracking joints under `pose`, in `TRACKING_JOINTS` order, from this puppet's rest
    /// geometry (bones missing from a short pose count as at rest).
    pub fn joints(&self, pose: &Pose) -> [Vec3; JOINT_COUNT] {
        std::array::from_fn(|k| {
            let b = self.base.joints[k].0;
            match pose.transforms().get(b) {
                Some(t) => (t * Point3::from(self.joint_rest[k])).coords,
                None => self.joint_rest[k],
            }
        })
    }

    /// Brings `params` inside the limits (non-finite values become 0, then are clamped).
    pub fn clamp(&self, params: &mut [f64]) {
        for (x, info) in params.iter_mut().zip(&self.params) {
            *x = finite(*x).clamp(info.lo, info.hi);
        }
    }
}
