//! Alternative starting points for the annealing of a limb: where a limb can be when the
//! prediction from the last frames has led it astray.

use super::puppet::ParamInfo;

/// Elbow flexion of the half-bent restart (radians).
const BENT_ELBOW: f64 = 1.4;
/// Knee flexion of the half-bent restart (radians; the knee flexes negatively).
const BENT_KNEE: f64 = -1.2;

/// Alternative starting points of a limb stage searching `dofs` from `current`: the limb as
/// it was in the previous frame (`previous`, without the velocity prediction, which
/// overshoots when a limb stops), straight in the rest pose, half bent and straightened
/// (elbow or knee flexed, or at zero flexion, the rest as `current`). A limb that fell into a
/// wrong basin (a shin folded behind an occluder, a forearm hanging where it reaches forward)
/// has no path back through the small moves around the prediction; the annealing keeps
/// whichever start explains the images best.
pub fn limb_restarts(
    infos: &[ParamInfo],
    current: &[f64],
    dofs: &[usize],
    previous: &[f64],
    out: &mut Vec<Vec<f64>>,
) {
    out.push(previous.to_vec());
    out.push(vec![0.0; current.len()]);
    for straight in [false, true] {
        let mut limb = current.to_vec();
        for &k in dofs {
            let name = &infos[k].name;
            if name.ends_with(".flex") {
                let bent = if name.starts_with("lowerarm01") {
                    BENT_ELBOW
                } else if name.starts_with("lowerleg01") {
                    BENT_KNEE
                } else {
                    continue;
                };
                let flex = if straight { 0.0 } else { bent };
                limb[k] = flex.clamp(infos[k].lo, infos[k].hi);
            }
        }
        out.push(limb);
    }
}

/// Turns of the pelvis about the vertical tried by [`trunk_restarts`] (radians).
const TRUNK_TURNS: [f64; 6] = [-0.8, -0.4, -0.2, 0.2, 0.4, 0.8];
/// Chest twists tried by [`trunk_restarts`] (radians, added to the current twist).
const CHEST_TWISTS: [f64; 2] = [-0.35, 0.35];
/// Index of the chest's twist parameter (`spine02`, its `y` component).
const CHEST_TWIST: usize = 7;

/// Alternative starting points of the trunk stage: the pelvis turned about the vertical by
/// ±0.2, ±0.4 and ±0.8 rad, and the chest twisted by ±0.35 rad. A trunk that
/// turns fast (a golf downswing: the shoulders 15° a frame, reversing at the top) leaves the
/// prediction behind; with the limbs anchored in the world
/// ([`Puppet::keep_limbs`](super::puppet::Puppet::keep_limbs)) these starts let the
/// annealing reach it.
pub fn trunk_restarts(current: &[f64], out: &mut Vec<Vec<f64>>) {
    let root = nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(
        current[3], current[4], current[5],
    ));
    for turn in TRUNK_TURNS {
        let r = nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::z() * turn) * root;
        let mut p = current.to_vec();
        p[3..6].copy_from_slice(r.scaled_axis().as_slice());
        out.push(p);
    }
    for twist in CHEST_TWISTS {
        let mut p = current.to_vec();
        p[CHEST_TWIST] += twist;
        out.push(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tracking::puppet::PartGroup;

    fn info(name: &str, lo: f64, hi: f64) -> ParamInfo {
        ParamInfo {
            name: name.to_string(),
            lo,
            hi,
            group: PartGroup::LeftLeg,
        }
    }

    #[test]
    fn limb_restarts_are_the_previous_the_rest_the_half_bent_and_the_straightened_limb() {
        let infos = [
            info("upperleg01.L.flex", -0.7, 2.27),
            info("lowerleg01.L.flex", -2.79, 0.21),
            info("lowerleg01.L.side", -1.31, 0.35),
            info("lowerarm01.L.flex", -0.87, 2.79),
        ];
        let current = [0.4, -0.1, 0.2, 0.3];
        let previous = [0.5, -0.3, 0.1, 0.2];
        let mut out = Vec::new();
        // a leg stage: the knee bends, the elbow (not searched) keeps its value
        limb_restarts(&infos, &current, &[0, 1, 2], &previous, &mut out);
        assert_eq!(out.len(), 4);
        assert_eq!(out[0], previous);
        assert_eq!(out[1], vec![0.0; 4]);
        assert_eq!(out[2], vec![0.4, BENT_KNEE, 0.2, 0.3]);
        assert_eq!(out[3], vec![0.4, 0.0, 0.2, 0.3]);
        out.clear();
        limb_restarts(&infos, &current, &[3], &previous, &mut out);
        assert_eq!(out[2], vec![0.4, -0.1, 0.2, BENT_ELBOW]);
        assert_eq!(out[3], vec![0.4, -0.1, 0.2, 0.0]);
    }

    #[test]
    fn trunk_restarts_turn_the_pelvis_about_the_vertical_and_twist_the_chest() {
        let mut current = vec![0.0; 48];
        current[3..6].copy_from_slice(&[0.3, -0.2, 1.1]); // a tilted, turned pelvis
        current[CHEST_TWIST] = 0.1;
        let mut out = Vec::new();
        trunk_restarts(&current, &mut out);
        assert_eq!(out.len(), TRUNK_TURNS.len() + CHEST_TWISTS.len());
        let q = |p: &[f64]| {
            nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(p[3], p[4], p[5]))
        };
        for (p, turn) in out.iter().zip(TRUNK_TURNS) {
            // the seed's pelvis is the current one turned by `turn` about world z
            let d = q(p) * q(&current).inverse();
            let expected =
                nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::z() * turn);
            assert!(d.angle_to(&expected) < 1e-12, "{turn}");
            assert_eq!(p[CHEST_TWIST], 0.1);
        }
        for (p, twist) in out[TRUNK_TURNS.len()..].iter().zip(CHEST_TWISTS) {
            assert!((p[CHEST_TWIST] - 0.1 - twist).abs() < 1e-15);
            assert_eq!(p[3..6], current[3..6]);
        }
    }
}
