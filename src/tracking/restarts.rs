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
}
