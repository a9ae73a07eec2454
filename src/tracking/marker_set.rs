//! Marker sets: which bone of the puppet's skeleton carries each labelled marker, and where the
//! marker roughly sits on the mannequin at rest (the starting point of the fit, which then finds
//! each marker's own offset). [`MarkerSet::gears`] is written for the GEARS golf capture set
//! (`../shared/data/motion/golf/`).

use super::puppet::Puppet;
use crate::body::Mannequin;
use crate::geometry::Vec3;

/// One marker: its label, its bone and a rough rest position.
#[derive(Clone, Debug, PartialEq)]
pub struct MarkerSpec {
    /// The label in the trial.
    pub label: String,
    /// The skeleton bone that carries it (MakeHuman name).
    pub bone: String,
    /// Rough rest position: between tracking joints `a` and `b` (indices of
    /// [`super::joints::TRACKING_JOINTS`]) at fraction `t`, plus `offset` (metres, engine axes:
    /// +x the body's left, −y its front, +z up).
    pub a: usize,
    /// Second joint of the interpolation.
    pub b: usize,
    /// Fraction from `a` to `b`.
    pub t: f64,
    /// Offset from the interpolated point.
    pub offset: Vec3,
}

/// A set of markers (see [`MarkerSpec`]).
#[derive(Clone, Debug, PartialEq)]
pub struct MarkerSet {
    /// The markers, in no particular order.
    pub markers: Vec<MarkerSpec>,
}

// tracking joints (TRACKING_JOINTS order)
const SPINE: usize = 1;
const NECK: usize = 2;
const HEAD: usize = 3;
const SHOULDER: usize = 4;
const ELBOW: usize = 5;
const WRIST: usize = 6;
const HIP: usize = 10;
const KNEE: usize = 11;
const ANKLE: usize = 12;
/// Index step from a left tracking joint to the right one.
const ARM_RIGHT: usize = 3;

/// Left-side (or midline) entries: label, right label (None on the midline), bone (`.L`
/// for sided bones), a, b, t, offset.
type Entry = (
    &'static str,
    Option<&'static str>,
    &'static str,
    usize,
    usize,
    f64,
    [f64; 3],
);

#[rustfmt::skip]
const GEARS: [Entry; 16] = [
    ("WaistLeft", Some("WaistRight"), "root", HIP, HIP, 0.0, [0.03, -0.08, 0.08]),
    ("WaistLBack", Some("WaistRBack"), "root", HIP, HIP, 0.0, [0.0, 0.12, 0.10]),
    ("BackTop", None, "spine02", NECK, NECK, 0.0, [0.0, 0.08, -0.03]),
    ("BackLeft", Some("BackRight"), "spine02", SPINE, NECK, 0.5, [0.07, 0.12, 0.0]),
    ("HeadTop", None, "head", HEAD, HEAD, 0.0, [0.0, 0.0, 0.0]),
    ("HeadFront", None, "head", NECK, HEAD, 0.6, [0.0, -0.1, 0.0]),
    ("HeadSide", None, "head", NECK, HEAD, 0.6, [0.08, 0.0, 0.0]),
    ("LShoulderTop", Some("RShoulderTop"), "upperarm01.L", SHOULDER, SHOULDER, 0.0, [0.0, 0.0, 0.05]),
    ("LShoulderBack", Some("RShoulderBack"), "spine02", SHOULDER, SHOULDER, 0.0, [-0.03, 0.08, 0.0]),
    ("LUArmHigh", Some("RUArmHigh"), "upperarm01.L", SHOULDER, ELBOW, 0.35, [0.05, 0.0, 0.0]),
    ("LElbowOut", Some("RElbowOut"), "upperarm01.L", ELBOW, ELBOW, 0.0, [0.04, 0.0, 0.0]),
    ("LWristTop", Some("RWristTop"), "lowerarm01.L", WRIST, WRIST, 0.0, [0.02, 0.0, 0.02]),
    ("LKneeOut", Some("RKneeOut"), "upperleg01.L", KNEE, KNEE, 0.0, [0.05, 0.0, 0.0]),
    ("LAnkleOut", Some("RAnkleOut"), "lowerleg01.L", ANKLE, ANKLE, 0.0, [0.04, 0.0, 0.0]),
    ("LToeIn", Some("RToeIn"), "foot.L", ANKLE, ANKLE, 0.0, [-0.02, -0.13, -0.05]),
    ("LToeOut", Some("RToeOut"), "foot.L", ANKLE, ANKLE, 0.0, [0.04, -0.11, -0.05]),
];

/// The right joint of a left tracking joint (midline joints are their own).
fn right_joint(k: usize) -> usize {
    match k {
        SHOULDER..=WRIST => k + ARM_RIGHT,
        HIP..=ANKLE => k + ARM_RIGHT,
        _ => k,
    }
}

impl MarkerSet {
    /// The GEARS golf set: waist (four, on the pelvis), back (three, on the chest), head
    /// (three), and per side shoulder top (upper arm) and back (chest), upper arm, elbow
    /// (upper arm), wrist (forearm), knee (thigh), ankle (shin) and two toe markers (foot).
    pub fn gears() -> MarkerSet {
        let mut markers = Vec::new();
        for (label, right, bone, a, b, t, o) in GEARS {
            let offset = Vec3::new(o[0], o[1], o[2]);
            markers.push(MarkerSpec {
                label: label.into(),
                bone: bone.into(),
                a,
                b,
                t,
                offset,
            });
            if let Some(r) = right {
                markers.push(MarkerSpec {
                    label: r.into(),
                    bone: bone.replace(".L", ".R"),
                    a: right_joint(a),
                    b: right_joint(b),
                    t,
                    offset: Vec3::new(-o[0], o[1], o[2]),
                });
            }
        }
        MarkerSet { markers }
    }

    /// Rough rest positions on `puppet` and skeleton bone indices (from `mannequin`'s
    /// skeleton, which the puppet shares), in set order; the error names an unknown bone.
    pub fn resolve(
        &self,
        mannequin: &Mannequin,
        puppet: &Puppet,
    ) -> Result<Vec<(usize, Vec3)>, String> {
        let joints = puppet.rest_joints();
        self.markers
            .iter()
            .map(|m| {
                let bone = mannequin
                    .skeleton()
                    .bone_index(&m.bone)
                    .ok_or_else(|| format!("marker `{}`: no bone `{}`", m.label, m.bone))?;
                let (a, b) = (joints[m.a.min(15)], joints[m.b.min(15)]);
                Ok((bone, a + (b - a) * m.t + m.offset))
            })
            .collect()
    }
}
