//! Rest geometry of the tracking puppet: body [`Proportions`], the segments they stretch, and
//! the rebuild of rest bone heads, bone frames, tracking joints and rest skin
//! ([`Puppet::with_proportions`]). A child module of [`super`] (declared there with a `path`
//! attribute), so it reaches the puppet's fields.
//!
//! Every bone belongs to the segment of its nearest key ancestor (or itself); a segment with
//! unit axis `a`, length scale `s` and girth `g` maps its bones' rest points by
//! `x ↦ head'_b + A (x − head_b)`, `A = g I + (s − g) a aᵀ` (the head: `A = s I`), each bone's
//! new head being carried by its parent's map. Lengths measured along a segment's axis, such
//! as elbow → wrist, therefore scale exactly by `s`. Skin vertices take the weighted blend of
//! their bones' maps, and the whole body is then lifted so the soles stay on the floor.

use nalgebra::Matrix3;

use super::{param_table, Base, Drive, PartGroup, Puppet, DRIVEN_BONES};
use crate::geometry::Vec3;

/// Body proportions: length scales per segment (along its axis) and a girth scale (across
/// every segment's axis). All 1 is the mannequin. Values are clamped to [0.5, 2]; a
/// non-finite value counts as 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proportions {
    /// Pelvis, spine and chest (vertical).
    pub torso: f64,
    /// Neck (neck base to head base).
    pub neck: f64,
    /// Head size (uniform).
    pub head: f64,
    /// Shoulder to elbow.
    pub upper_arm: f64,
    /// Elbow to wrist.
    pub forearm: f64,
    /// Wrist to the middle finger's tip.
    pub hand: f64,
    /// Hip to knee.
    pub thigh: f64,
    /// Knee to ankle.
    pub shin: f64,
    /// Ankle to toes.
    pub foot: f64,
    /// Scale across all segments (and of shoulder and hip width).
    pub girth: f64,
}

impl Default for Proportions {
    fn default() -> Self {
        Proportions {
            torso: 1.0,
            neck: 1.0,
            head: 1.0,
            upper_arm: 1.0,
            forearm: 1.0,
            hand: 1.0,
            thigh: 1.0,
            shin: 1.0,
            foot: 1.0,
            girth: 1.0,
        }
    }
}

impl Proportions {
    /// The ten values with their names, in field order (for files and scripts).
    pub fn named(&self) -> [(&'static str, f64); 10] {
        [
            ("torso", self.torso),
            ("neck", self.neck),
            ("head", self.head),
            ("upper_arm", self.upper_arm),
            ("forearm", self.forearm),
            ("hand", self.hand),
            ("thigh", self.thigh),
            ("shin", self.shin),
            ("foot", self.foot),
            ("girth", self.girth),
        ]
    }

    /// Proportions from the ten values of [`Proportions::named`], in its order; `None` for
    /// another count.
    pub fn from_values(v: &[f64]) -> Option<Proportions> {
        let &[torso, neck, head, upper_arm, forearm, hand, thigh, shin, foot, girth] = v else {
            return None;
        };
        Some(Proportions {
            torso,
            neck,
            head,
            upper_arm,
            forearm,
            hand,
            thigh,
            shin,
            foot,
            girth,
        })
    }

    /// As a JSON object of the named values.
    pub fn to_json(&self) -> serde_json::Value {
        self.named()
            .iter()
            .map(|(k, v)| (k.to_string(), serde_json::json!(v)))
            .collect::<serde_json::Map<_, _>>()
            .into()
    }
}

/// Segments scaled by [`Proportions`]; every bone belongs to the segment of its nearest
/// ancestor-or-self among the key bones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Segment {
    Torso,
    Neck,
    Head,
    UpperArm,
    Forearm,
    Hand,
    Thigh,
    Shin,
    Foot,
}

/// Key bones (without side): segment and part group (left side; right is mapped).
pub(super) const KEYS: [(&str, Segment, PartGroup); 10] = [
    ("root", Segment::Torso, PartGroup::Root),
    ("spine05", Segment::Torso, PartGroup::Torso),
    ("neck01", Segment::Neck, PartGroup::Head),
    ("head", Segment::Head, PartGroup::Head),
    ("upperarm01", Segment::UpperArm, PartGroup::LeftArm),
    ("lowerarm01", Segment::Forearm, PartGroup::LeftArm),
    ("wrist", Segment::Hand, PartGroup::LeftHand),
    ("upperleg01", Segment::Thigh, PartGroup::LeftLeg),
    ("lowerleg01", Segment::Shin, PartGroup::LeftLeg),
    ("foot", Segment::Foot, PartGroup::LeftFoot),
];

pub(super) fn right_of(g: PartGroup) -> PartGroup {
    match g {
        PartGroup::LeftArm => PartGroup::RightArm,
        PartGroup::LeftHand => PartGroup::RightHand,
        PartGroup::LeftLeg => PartGroup::RightLeg,
        PartGroup::LeftFoot => PartGroup::RightFoot,
        g => g,
    }
}

/// Rest frame `[x y z]` of a driven bone: `y` toward `toward`, `z` forward (feet: up).
fn frame_for(head: Vec3, toward: Vec3, foot: bool) -> Option<Matrix3<f64>> {
    let y = (toward - head).try_normalize(1e-9)?;
    let r = if foot { Vec3::z() } else { -Vec3::y() };
    let z = (r - y * y.dot(&r)).try_normalize(1e-6)?;
    Some(Matrix3::from_columns(&[y.cross(&z), y, z]))
}

impl Puppet {
    /// The same puppet with other body proportions (values clamped to [0.5, 2], non-finite
    /// ones taken as 1). Fails only if a segment degenerates.
    pub fn with_proportions(&self, p: &Proportions) -> Result<Puppet, String> {
        let c = |x: f64| {
            if x.is_finite() {
                x.clamp(0.5, 2.0)
            } else {
                1.0
            }
        };
        let p = Proportions {
            torso: c(p.torso),
            neck: c(p.neck),
            head: c(p.head),
            upper_arm: c(p.upper_arm),
            forearm: c(p.forearm),
            hand: c(p.hand),
            thigh: c(p.thigh),
            shin: c(p.shin),
            foot: c(p.foot),
            girth: c(p.girth),
        };
        Puppet::build(
            self.base.clone(),
            self.drives.clone(),
            self.driven,
            self.root,
            p,
        )
    }

    pub(super) fn build(
        base: Base,
        drives: Vec<Drive>,
        driven: [usize; 14],
        root: usize,
        proportions: Proportions,
    ) -> Result<Puppet, String> {
        let p = proportions;
        let maps: Vec<Matrix3<f64>> = base
            .segment
            .iter()
            .map(|&(seg, a)| {
                let s = match seg {
                    Segment::Torso => p.torso,
                    Segment::Neck => p.neck,
                    Segment::Head => return Matrix3::identity() * p.head,
                    Segment::UpperArm => p.upper_arm,
                    Segment::Forearm => p.forearm,
                    Segment::Hand => p.hand,
                    Segment::Thigh => p.thigh,
                    Segment::Shin => p.shin,
                    Segment::Foot => p.foot,
                };
                Matrix3::identity() * p.girth + a * a.transpose() * (s - p.girth)
            })
            .collect();
        // new heads: each carried by its parent's map x ↦ head'_p + A_p (x − head_p)
        let mut heads = base.heads.clone();
        for b in 0..heads.len() {
            if let Some(q) = base.parents[b] {
                heads[b] = heads[q] + maps[q] * (base.heads[b] - base.heads[q]);
            }
        }
        let map = |heads: &[Vec3], b: usize, x: Vec3| heads[b] + maps[b] * (x - base.heads[b]);
        let mut rest_skin: Vec<Vec3> = (0..base.skin.len())
            .map(|v| {
                base.weights
                    .influences(v)
                    .map(|(b, w)| map(&heads, b, base.skin[v]) * w)
                    .sum()
            })
            .collect();
        // keep the soles on the floor
        let low = |s: &[Vec3]| s.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        let lift = Vec3::new(0.0, 0.0, low(&base.skin) - low(&rest_skin));
        if lift.z.is_finite() {
            heads.iter_mut().for_each(|h| *h += lift);
            rest_skin.iter_mut().for_each(|v| *v += lift);
        }
        let mut frames = [Matrix3::identity(); 14];
        for k in 0..14 {
            let b = driven[k];
            frames[k] = frame_for(
                heads[b],
                map(&heads, b, base.toward[k]),
                DRIVEN_BONES[k].0.starts_with("foot"),
            )
            .ok_or_else(|| format!("bone `{}` has a degenerate frame", DRIVEN_BONES[k].0))?;
        }
        let joint_rest = std::array::from_fn(|k| {
            let (b, x) = base.joints[k];
            map(&heads, b, x)
        });
        let params = param_table(&driven, &base.groups);
        Ok(Puppet {
            base,
            proportions,
            drives,
            driven,
            root,
            heads,
            frames,
            joint_rest,
            rest_skin,
            params,
        })
    }
}
