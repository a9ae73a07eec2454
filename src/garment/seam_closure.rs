//! Crossings that pre-positioning leaves at a seam between the two pieces it joins: where both
//! pieces are wrapped onto the same shell and meet there (a skirt's side seam at fine meshes),
//! their seam lines lie within a millimetre of each other but shifted along the seam, and an
//! edge of one piece runs through a triangle of the other next to the seam. Sewing cannot
//! undo that: self-collision holds the crossing, and the seam stays open around it.
//!
//! The cure is to sew those stitches at once: the matched vertex pairs of the seam near the
//! crossing are moved to their midpoints (each pair is one weld class, so the pieces then fan
//! out from a common seam line, one to each side), in rounds with a growing reach until no
//! crossing between the two pieces of a seam is left. Seams joining two pieces laid on the
//! same side of the body (centre seams) are left to their own treatment in `dress`.

use super::mesh::GarmentMesh;
use crate::cloth::Simulation;
use crate::contact::SimulationContact;
use crate::geometry::Vec3;

/// Rounds of [`close_crossed_seams`].
const ROUNDS: usize = 8;

/// Sews shut, at pre-positioning, the stretches of the seams (other than those listed in
/// `skip`, by index) that pass by a crossing between the two pieces they join: every pair
/// with a vertex within `reach` of a crossing moves to its midpoint; the reach grows by half
/// each round while crossings are left, for up to [`ROUNDS`] rounds. Returns the crossings
/// between pieces joined by a closable seam that are left.
pub(super) fn close_crossed_seams(
    garment: &GarmentMesh,
    skip: &[usize],
    reach: f64,
    sim: &mut Simulation,
) -> usize {
    let n = sim.state.x.len();
    let mut piece = vec![usize::MAX; n];
    for (k, p) in garment.pieces.iter().enumerate() {
        for v in p.vertices.clone() {
            piece[v] = k;
        }
    }
    // the closable seams with the (unordered) pair of pieces each joins
    let seams: Vec<(usize, [usize; 2])> = garment
        .seams
        .iter()
        .enumerate()
        .filter(|(id, _)| !skip.contains(id))
        .filter_map(|(id, s)| {
            let &(a, b) = s.pairs.first()?;
            let (pa, pb) = (piece[a], piece[b]);
            (pa != pb).then_some((id, [pa.min(pb), pa.max(pb)]))
        })
        .collect();
    let mut reach = reach;
    let mut left = 0;
    for round in 0..=ROUNDS {
        let now = sim.state.x.clone();
        let sites: Vec<([usize; 2], Vec3)> = sim
            .contact_mut()
            .self_intersections(&now)
            .into_iter()
            .filter_map(|(e, t)| {
                let (pa, pb) = (piece[e[0] as usize], piece[t[0] as usize]);
                let key = [pa.min(pb), pa.max(pb)];
                let at = 0.5 * (now[e[0] as usize] + now[e[1] as usize]);
                (pa != pb && seams.iter().any(|s| s.1 == key)).then_some((key, at))
            })
            .collect();
        left = sites.len();
        if sites.is_empty() || round == ROUNDS {
            break;
        }
        let x = &mut sim.state.x;
        for &(id, key) in &seams {
            for &(a, b) in &garment.seams[id].pairs {
                let near = sites.iter().any(|(k, at)| {
                    *k == key && ((now[a] - at).norm() < reach || (now[b] - at).norm() < reach)
                });
                if near {
                    let m = 0.5 * (now[a] + now[b]);
                    x[a] = m;
                    x[b] = m;
                }
            }
        }
        reach *= 1.5;
    }
    left
}
