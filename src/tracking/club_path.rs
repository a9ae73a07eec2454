//! The club's path through the frames (`smoothest_path`): each frame's refined shaft
//! hypotheses, chained by dynamic programming so the club's motion stays smooth where the
//! image evidence is weak (the smeared shaft at impact).

use nalgebra::UnitQuaternion;

use crate::geometry::Vec3;

/// One club hypothesis: grip point, unit shaft direction (grip → head), length.
#[derive(Clone, Copy, Debug)]
pub(super) struct Shaft {
    pub(super) grip: Vec3,
    pub(super) dir: Vec3,
    pub(super) length: f64,
}

/// How motion is weighed against evidence: the scale (radians) and weight of a shaft's
/// turn away from its predicted turn, and the scale (metres) and weight of the grip's
/// departure from constant velocity.
#[derive(Clone, Copy, Debug)]
pub(super) struct MotionWeights {
    pub(super) turn_sigma: f64,
    pub(super) turn_weight: f64,
    pub(super) motion_sigma: f64,
    pub(super) motion_weight: f64,
}

/// The path through the frames' hypotheses `(shaft, evidence)` that best trades evidence
/// against acceleration (dynamic programming over consecutive pairs): a shaft's turn from
/// the turn of the two frames before it, and the grip's departure from its constant
/// velocity, weighed as the forward search's motion priors. Index of the chosen hypothesis
/// per frame.
pub(super) fn smoothest_path(hyps: &[Vec<(Shaft, f64)>], o: &MotionWeights) -> Vec<usize> {
    let n = hyps.len();
    if n == 0 || hyps.iter().any(Vec::is_empty) {
        return vec![0; n];
    }
    let accel = |h: &Shaft, i: &Shaft, j: &Shaft| {
        let pred = UnitQuaternion::rotation_between(&h.dir, &i.dir).map_or(i.dir, |q| q * i.dir);
        let turn = pred.dot(&j.dir).clamp(-1.0, 1.0).acos() / o.turn_sigma;
        let slide = (j.grip - (2.0 * i.grip - h.grip)).norm() / o.motion_sigma;
        o.turn_weight * turn * turn + o.motion_weight * slide * slide
    };
    if n == 1 {
        let best = (0..hyps[0].len()).max_by(|&a, &b| hyps[0][a].1.total_cmp(&hyps[0][b].1));
        return vec![best.unwrap_or(0)];
    }
    // cost[(i, j)]: best cost of a path ending with hypothesis i at k − 1 and j at k
    let mut cost: Vec<Vec<f64>> = (hyps[0].iter())
        .map(|a| hyps[1].iter().map(|b| -a.1 - b.1).collect())
        .collect();
    let mut back: Vec<Vec<Vec<usize>>> = vec![Vec::new(), Vec::new()];
    for k in 2..n {
        let (prev, here) = (&hyps[k - 1], &hyps[k]);
        let mut next = vec![vec![f64::INFINITY; here.len()]; prev.len()];
        let mut from = vec![vec![0usize; here.len()]; prev.len()];
        for (i, pi) in prev.iter().enumerate() {
            for (j, hj) in here.iter().enumerate() {
                for (h, ph) in hyps[k - 2].iter().enumerate() {
                    let c = cost[h][i] + accel(&ph.0, &pi.0, &hj.0) - hj.1;
                    if c < next[i][j] {
                        (next[i][j], from[i][j]) = (c, h);
                    }
                }
            }
        }
        cost = next;
        back.push(from);
    }
    let (mut i, mut j) = (0, 0);
    for (a, row) in cost.iter().enumerate() {
        for (b, &c) in row.iter().enumerate() {
            if c < cost[i][j] {
                (i, j) = (a, b);
            }
        }
    }
    let mut path = vec![0; n];
    (path[n - 2], path[n - 1]) = (i, j);
    for k in (2..n).rev() {
        let h = back[k][path[k - 1]][path[k]];
        path[k - 2] = h;
    }
    path
}
