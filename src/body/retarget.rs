//! Retargeting a BVH clip (iClone `CC_Base` rig) onto the MakeHuman mannequin, and sampling
//! the skinned body over time.
//!
//! The two rest poses differ (MakeHuman stands in an A-pose; the BVH rig's all-zero pose is
//! not a stance at all), so joint rotations are not copied. Only the clip's world joint
//! positions are used. For every frame:
//!
//! * three bones take a full orientation from the clip, each from a frame of two lines
//!   (`FRAMES`): the pelvis (`root`) from the hip line and the trunk axis, the chest
//!   (`spine02`) from the collar line and the upper back, the head from the eye line and the
//!   neck. The pelvis is placed so the hip centre follows the clip's hip centre scaled by the
//!   ratio of standing hip heights ([`Animation::scale`]); with
//!   [`RetargetOptions::in_place`] it is pinned horizontally and only bobs;
//! * the lumbar spine and the neck take shares of the rotation between the pelvis and the
//!   chest, and between the chest and the head (`BLENDS`), so bending and twist spread
//!   along them and the mannequin keeps its own spine curve;
//! * limbs are swung (`SWINGS`): down the hierarchy each bone first follows its parent
//!   rigidly (its head goes where the parent carries it, its twist is inherited), then a
//!   mapped bone turns by the smallest rotation that points it (or its chain: the two
//!   upper-leg bones as one thigh) along the matching BVH bone, joint to child joint;
//! * every other bone (fingers, toes, face, breasts, collar, twist helpers) follows its
//!   parent.
//!
//! Poses are computed once per frame; [`Animation::vertices_at`] interpolates between the
//! two nearest frames (rotations by slerp, joint positions linearly) and skins.

use std::sync::Mutex;

use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion};

use super::error::BodyError;
use super::skinning::Pose;
use super::{Mannequin, Motion};
use crate::geometry::Vec3;

/// How a clip is mapped onto the mannequin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RetargetOptions {
    /// Remove the root's horizontal travel (treadmill): the hip centre stays above its rest
    /// place, the vertical bob and all rotations are kept. Default `true`.
    pub in_place: bool,
    /// Clip time (seconds) that animation time 0 maps to. Default 0.
    pub start_time: f64,
    /// Extra outward tilt of the upper arms (degrees), for mannequins whose hips are wider than
    /// the captured actor's (the hands would otherwise brush through them). Default 0.
    pub arm_spread_deg: f64,
}

impl Default for RetargetOptions {
    fn default() -> Self {
        RetargetOptions {
            in_place: true,
            start_time: 0.0,
            arm_spread_deg: 0.0,
        }
    }
}

/// A mannequin bone swung to follow a BVH bone.
#[derive(Clone, Debug)]
pub struct SwingMap {
    /// Mannequin bone.
    pub bone: String,
    /// Mannequin joint its direction points to (its tail, or a joint further down).
    pub toward: String,
    /// BVH joint at the start of the matching BVH bone.
    pub bvh_from: String,
    /// BVH joint at the end of the matching BVH bone.
    pub bvh_to: String,
}

/// Limb mapping; `{s}` is the mannequin side (`L`/`R`), `{S}` the BVH's.
/// Entries: (mannequin bone, mannequin joint it points to, BVH from, BVH to). A mannequin
/// chain mapped onto one BVH bone is swung as a whole at its first bone (its direction is
/// first head → last tail), the others follow: swinging each bone of a curved chain onto the
/// same line would bend the skin at every joint of the chain.
const SWINGS: &[(&str, &str, &str, &str)] = &[
    (
        "upperarm01.{s}",
        "lowerarm01.{s}____head",
        "{S}_Upperarm",
        "{S}_Forearm",
    ),
    (
        "lowerarm01.{s}",
        "wrist.{s}____head",
        "{S}_Forearm",
        "{S}_Hand",
    ),
    ("wrist.{s}", "finger3-1.{s}____head", "{S}_Hand", "{S}_Mid1"),
    (
        "upperleg01.{s}",
        "lowerleg01.{s}____head",
        "{S}_Thigh",
        "{S}_Calf",
    ),
    ("lowerleg01.{s}", "foot.{s}____head", "{S}_Calf", "{S}_Foot"),
    ("foot.{s}", "toe3-1.{s}____head", "{S}_Foot", "{S}_ToeBase"),
];

/// Bones that take their full orientation from a frame of four joints (lateral line, then a
/// second line made orthogonal to it), mannequin and BVH: the pelvis from the hip line and
/// the trunk, the chest from the clavicle line and the upper back, the head from the eye line
/// and the neck. The second lines are chosen where the two rigs agree at rest (the trunk and
/// neck axes; their lower spine, collar and eye joints sit at different depths).
const FRAMES: &[(&str, [&str; 4], [&str; 4])] = &[
    (
        "root",
        [
            "upperleg01.R____head",
            "upperleg01.L____head",
            "upperleg01.R____head",
            "spine02____head",
        ],
        ["R_Thigh", "L_Thigh", "R_Thigh", "Spine02"],
    ),
    (
        "spine02",
        [
            "clavicle.R____head",
            "clavicle.L____head",
            "spine02____head",
            "neck01____head",
        ],
        ["R_Clavicle", "L_Clavicle", "Spine02", "NeckTwist01"],
    ),
    (
        "head",
        [
            "eye.R____head",
            "eye.L____head",
            "neck01____head",
            "neck03____tail",
        ],
        ["R_Eye", "L_Eye", "NeckTwist01", "Head"],
    ),
];

/// Bones between two frame-driven bones, with their share of the rotation from the lower to
/// the upper one: the lumbar spine between pelvis and chest, the neck between chest and head.
/// Spreading the rotation keeps the mannequin's own spine curve where the clip stands
/// straight, which swinging each vertebra onto the clip's (differently placed) spine joints
/// would not.
const BLENDS: &[(&str, &str, &str, f64)] = &[
    ("spine05", "root", "spine02", 0.25),
    ("spine04", "root", "spine02", 0.5),
    ("spine03", "root", "spine02", 0.75),
    ("neck01", "spine02", "head", 0.25),
    ("neck02", "spine02", "head", 0.5),
    ("neck03", "spine02", "head", 0.75),
];

/// Mannequin hip joints (right, left): their midpoint is the hip centre that follows the clip.
const HIP_JOINTS: [&str; 2] = ["upperleg01.R____head", "upperleg01.L____head"];

/// Prefix of the iClone joint names.
const BVH_PREFIX: &str = "CC_Base_";

/// An orientation frame of four points: lateral axis `a → b` and a second axis `c → d`, made
/// orthogonal to the first.
#[derive(Clone, Copy, Debug)]
struct Quad<T> {
    a: T,
    b: T,
    c: T,
    d: T,
}

fn frame_of(p: Quad<Vec3>) -> Option<Matrix3<f64>> {
    let x = (p.b - p.a).try_normalize(1e-12)?;
    let up = p.d - p.c;
    let y = (up - x * x.dot(&up)).try_normalize(1e-12)?;
    Some(Matrix3::from_columns(&[x, y, x.cross(&y)]))
}

/// The rotation taking frame `from` to frame `to` (both orthonormal, right-handed).
fn frame_rotation(from: &Matrix3<f64>, to: &Matrix3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(to * from.transpose()))
}

/// Smallest rotation turning unit vector `d` into unit vector `e` (any half turn if opposite).
fn swing(d: Vec3, e: Vec3) -> UnitQuaternion<f64> {
    UnitQuaternion::rotation_between(&d, &e).unwrap_or_else(|| {
        let helper = if d.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        let axis = nalgebra::Unit::new_normalize(d.cross(&helper));
        UnitQuaternion::from_axis_angle(&axis, std::f64::consts::PI)
    })
}

/// How one mannequin bone is driven, with resolved indices.
#[derive(Clone, Copy, Debug)]
enum Drive {
    /// Follows its parent rigidly.
    Follow,
    /// Swung from rest direction `dir` (unit) to BVH joints `from → to`, tilted outward by
    /// `spread` (tangent of the angle, signed by side) along the parent's lateral axis.
    Swing {
        dir: Vec3,
        from: usize,
        to: usize,
        spread: f64,
    },
    /// Full orientation from a frame of four points (rest frame of the mannequin, BVH joints).
    Frame {
        rest: Matrix3<f64>,
        bvh: Quad<usize>,
    },
    /// A share of the rotation from the orientation of frame-driven bone `lower` to that of
    /// frame-driven bone `upper` (bending and twist spread along the spine and neck).
    Blend {
        lower: usize,
        upper: usize,
        share: f64,
    },
}

/// A mannequin animated by a retargeted BVH clip.
#[derive(Debug)]
pub struct Animation {
    mannequin: Mannequin,
    motion: Motion,
    options: RetargetOptions,
    swings: Vec<SwingMap>,
    scale: f64,
    /// One pose per clip frame.
    poses: Vec<Pose>,
    scratch: Mutex<Pose>,
}

impl Animation {
    /// Retargets `motion` onto `mannequin`. Fails, naming the clip or the mannequin part, if a
    /// joint or bone of the mapping is missing or degenerate.
    pub fn new(
        mannequin: Mannequin,
        motion: Motion,
        options: RetargetOptions,
    ) -> Result<Animation, BodyError> {
        let clip = motion.name().to_string();
        let skel = mannequin.skeleton();
        let bvh = |n: &str| {
            let full = format!("{BVH_PREFIX}{n}");
            motion.joint_index(&full).ok_or_else(|| {
                BodyError::invalid(
                    &clip,
                    format!("joint '{full}' needed for retargeting is missing"),
                )
            })
        };
        let mh_bone = |n: &str| {
            skel.bone_index(n).ok_or_else(|| {
                BodyError::invalid(
                    "mannequin",
                    format!("bone '{n}' needed for retargeting is missing"),
                )
            })
        };
        let mh_joint = |n: &str| {
            skel.joint(n).map(|j| j.rest).ok_or_else(|| {
                BodyError::invalid(
                    "mannequin",
                    format!("joint '{n}' needed for retargeting is missing"),
                )
            })
        };
        let bones = skel.bones();
        let mut drives = vec![Drive::Follow; bones.len()];
        let mut swings = Vec::new();
        for side in ["L", "R"] {
            for &(bone, toward, from, to) in SWINGS {
                if side == "R" && !bone.contains("{s}") {
                    continue;
                }
                let sub = |s: &str| s.replace("{s}", side).replace("{S}", side);
                let b = mh_bone(&sub(bone))?;
                let dir = (mh_joint(&sub(toward))? - bones[b].head)
                    .try_normalize(1e-12)
                    .ok_or_else(|| {
                        BodyError::invalid(
                            "mannequin",
                            format!("bone '{}' has no length", sub(bone)),
                        )
                    })?;
                let sign = if side == "L" { 1.0 } else { -1.0 };
                let spread = if bone.starts_with("upperarm") {
                    sign * options.arm_spread_deg.to_radians().tan()
                } else {
                    0.0
                };
                drives[b] = Drive::Swing {
                    dir,
                    from: bvh(&sub(from))?,
                    to: bvh(&sub(to))?,
                    spread,
                };
                swings.push(SwingMap {
                    bone: sub(bone),
                    toward: sub(toward),
                    bvh_from: format!("{BVH_PREFIX}{}", sub(from)),
                    bvh_to: format!("{BVH_PREFIX}{}", sub(to)),
                });
            }
        }
        let root = bones
            .iter()
            .position(|b| b.parent.is_none())
            .ok_or_else(|| BodyError::invalid("mannequin", "the skeleton has no root"))?;
        for (bone, mh, bv) in FRAMES {
            let b = mh_bone(bone)?;
            let rest = frame_of(Quad {
                a: mh_joint(mh[0])?,
                b: mh_joint(mh[1])?,
                c: mh_joint(mh[2])?,
                d: mh_joint(mh[3])?,
            })
            .ok_or_else(|| {
                BodyError::invalid("mannequin", format!("degenerate frame for '{bone}'"))
            })?;
            let bvh = Quad {
                a: bvh(bv[0])?,
                b: bvh(bv[1])?,
                c: bvh(bv[2])?,
                d: bvh(bv[3])?,
            };
            drives[b] = Drive::Frame { rest, bvh };
        }
        for &(bone, lower, upper, share) in BLENDS {
            let (lower, upper) = (mh_bone(lower)?, mh_bone(upper)?);
            drives[mh_bone(bone)?] = Drive::Blend {
                lower,
                upper,
                share,
            };
        }
        if !matches!(drives[root], Drive::Frame { .. }) {
            return Err(BodyError::invalid(
                "mannequin",
                "the root bone is not the pelvis",
            ));
        }
        let hip_rest = 0.5 * (mh_joint(HIP_JOINTS[0])? + mh_joint(HIP_JOINTS[1])?);

        // all frames' joint positions, and the clip's standing hip height
        let frames: Vec<Vec<Vec3>> = (0..motion.frame_count())
            .map(|k| motion.joint_positions(k))
            .collect();
        let (lt, lc, lf) = (bvh("L_Thigh")?, bvh("L_Calf")?, bvh("L_Foot")?);
        let (rt, rc, rf) = (bvh("R_Thigh")?, bvh("R_Calf")?, bvh("R_Foot")?);
        let f0 = &frames[0];
        let leg = 0.5
            * ((f0[lt] - f0[lc]).norm()
                + (f0[lc] - f0[lf]).norm()
                + (f0[rt] - f0[rc]).norm()
                + (f0[rc] - f0[rf]).norm());
        let ankle = frames
            .iter()
            .map(|p| p[lf].z.min(p[rf].z))
            .fold(f64::INFINITY, f64::min);
        let scale = hip_rest.z / (leg + ankle);
        if !(scale.is_finite() && scale > 0.0) {
            return Err(BodyError::invalid(&clip, "cannot measure the hip height"));
        }
        let start = ((options.start_time / motion.frame_time()).floor().max(0.0) as usize)
            .min(motion.frame_count() - 1);
        let hip_start = 0.5 * (frames[start][lt] + frames[start][rt]);

        let poses = frames
            .iter()
            .map(|p| {
                let hip = 0.5 * (p[lt] + p[rt]);
                let mut target = hip_rest + (hip - hip_start) * scale;
                if options.in_place {
                    target.x = hip_rest.x;
                    target.y = hip_rest.y;
                }
                target.z = hip.z * scale;
                pose_for_frame(&mannequin, &drives, p, hip_rest, target)
            })
            .collect();
        let scratch = Mutex::new(mannequin.rest_pose());
        Ok(Animation {
            mannequin,
            motion,
            options,
            swings,
            scale,
            poses,
            scratch,
        })
    }

    /// The mannequin.
    pub fn mannequin(&self) -> &Mannequin {
        &self.mannequin
    }

    /// The clip.
    pub fn motion(&self) -> &Motion {
        &self.motion
    }

    /// The options the clip was retargeted with.
    pub fn options(&self) -> RetargetOptions {
        self.options
    }

    /// The limb mapping (mannequin bone ← BVH bone). The pelvis, chest and head are driven by
    /// frames (hip, collar and eye lines), the lumbar spine and neck by shares of the rotation
    /// between them, and every other bone follows its parent.
    pub fn swing_map(&self) -> &[SwingMap] {
        &self.swings
    }

    /// Scale applied to the clip's root translation (mannequin / clip standing hip height).
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Playable length (seconds): the clip's duration after [`RetargetOptions::start_time`].
    pub fn duration(&self) -> f64 {
        (self.motion.duration() - self.options.start_time).max(0.0)
    }

    /// The pose at frame `k` of the clip (clamped to the last frame).
    pub fn frame_pose(&self, k: usize) -> &Pose {
        &self.poses[k.min(self.poses.len() - 1)]
    }

    /// The pose at animation time `t` (seconds from the start time, clamped to the clip),
    /// interpolated between frames, into `pose` (which must have one transform per bone).
    pub fn pose_at_into(&self, t: f64, pose: &mut Pose) {
        let dt = self.motion.frame_time();
        let last = self.poses.len() - 1;
        let tc = (self.options.start_time + t).clamp(0.0, last as f64 * dt);
        let x = if tc.is_finite() { tc / dt } else { 0.0 };
        let k = (x.floor() as usize).min(last);
        let u = x - k as f64;
        let (p0, p1) = (&self.poses[k], &self.poses[(k + 1).min(last)]);
        for (b, bone) in self.mannequin.skeleton().bones().iter().enumerate() {
            let (t0, t1) = (p0.transform(b), p1.transform(b));
            if u <= 0.0 {
                pose.set(b, *t0);
                continue;
            }
            let rot = t0.rotation.slerp(&t1.rotation, u);
            let h = Point3::from(bone.head);
            let head = (t0 * h).coords.lerp(&(t1 * h).coords, u);
            pose.set(
                b,
                Isometry3::from_parts(Translation3::from(head - rot * bone.head), rot),
            );
        }
    }

    /// The pose at animation time `t` (see [`Animation::pose_at_into`]).
    pub fn pose_at(&self, t: f64) -> Pose {
        let mut pose = self.mannequin.rest_pose();
        self.pose_at_into(t, &mut pose);
        pose
    }

    /// Skinned skin vertices at animation time `t` (seconds; interpolated between frames,
    /// clamped to the clip), into `out` (resized and reused).
    pub fn vertices_at(&self, t: f64, out: &mut Vec<Vec3>) {
        let mut pose = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        self.pose_at_into(t, &mut pose);
        self.mannequin.skin(&pose, out);
    }
}

/// The mannequin pose for one frame of BVH joint positions `p` (world, metres, z up), with
/// the root's hip centre `hip_rest` placed at `target`.
fn pose_for_frame(
    mannequin: &Mannequin,
    drives: &[Drive],
    p: &[Vec3],
    hip_rest: Vec3,
    target: Vec3,
) -> Pose {
    let bones = mannequin.skeleton().bones();
    // full orientations first: the blended bones between them need both ends
    let framed: Vec<Option<UnitQuaternion<f64>>> = drives
        .iter()
        .map(|d| match *d {
            Drive::Frame { rest, bvh } => frame_of(Quad {
                a: p[bvh.a],
                b: p[bvh.b],
                c: p[bvh.c],
                d: p[bvh.d],
            })
            .map(|f| frame_rotation(&rest, &f)),
            _ => None,
        })
        .collect();
    let mut rot = vec![UnitQuaternion::identity(); bones.len()];
    let mut out = Vec::with_capacity(bones.len());
    for (b, bone) in bones.iter().enumerate() {
        // follow the parent: inherit its rotation, put the head where it carries it
        let (mut r, head, pivot) = match bone.parent {
            Some(q) => {
                let parent: &Isometry3<f64> = &out[q];
                (rot[q], (parent * Point3::from(bone.head)).coords, bone.head)
            }
            None => (UnitQuaternion::identity(), target, hip_rest),
        };
        match drives[b] {
            Drive::Follow => {}
            Drive::Swing {
                dir,
                from,
                to,
                spread,
            } => {
                let lateral = r * Vec3::x() * spread;
                if let Some(e) =
                    (p[to] - p[from] + lateral * (p[to] - p[from]).norm()).try_normalize(1e-12)
                {
                    r = swing(r * dir, e) * r;
                }
            }
            Drive::Frame { .. } => r = framed[b].unwrap_or(r),
            Drive::Blend {
                lower,
                upper,
                share,
            } => {
                if let (Some(lo), Some(up)) = (framed[lower], framed[upper]) {
                    r = lo * UnitQuaternion::identity().slerp(&(lo.inverse() * up), share);
                }
            }
        }
        rot[b] = r;
        out.push(Isometry3::from_parts(
            Translation3::from(head - r * pivot),
            r,
        ));
    }
    Pose::from_transforms(out)
}
