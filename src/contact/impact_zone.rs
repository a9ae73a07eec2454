//! Bridson's rigid impact zones: vertices of pairs that still collide are merged (union–find)
//! into zones, each moved rigidly with its momentum and angular momentum; a rigid motion of an
//! intersection-free set cannot make it tangle itself.

use nalgebra::Rotation3;

use crate::geometry::{Mat3, Vec3};

/// Largest rotation (rad) of an impact zone in one step.
pub const MAX_TURN: f64 = 0.2;

/// Replaces the displacements `d` of the vertices of `zone` by the zone's rigid motion with the
/// same momentum and angular momentum (a zone holding prescribed vertices follows their mean
/// displacement), turning by at most [`MAX_TURN`] in the step.
pub fn rigid_motion(d: &mut [Vec3], zone: &[usize], x0: &[Vec3], inv_mass: &[f64]) {
    let pinned: Vec<usize> = zone
        .iter()
        .copied()
        .filter(|&i| inv_mass[i] == 0.0)
        .collect();
    if !pinned.is_empty() {
        // a zone holding prescribed vertices follows their mean displacement
        let mean = pinned.iter().map(|&i| d[i]).sum::<Vec3>() / pinned.len() as f64;
        for &i in zone {
            if inv_mass[i] != 0.0 {
                d[i] = mean;
            }
        }
        return;
    }
    let mass = |i: usize| 1.0 / inv_mass[i];
    let m: f64 = zone.iter().map(|&i| mass(i)).sum();
    let c = zone.iter().map(|&i| x0[i] * mass(i)).sum::<Vec3>() / m;
    let dc = zone.iter().map(|&i| d[i] * mass(i)).sum::<Vec3>() / m;
    let mut l = Vec3::zeros();
    let mut inertia = Mat3::zeros();
    for &i in zone {
        let r = x0[i] - c;
        l += (r.cross(&(d[i] - dc))) * mass(i);
        inertia += (Mat3::identity() * r.norm_squared() - r * r.transpose()) * mass(i);
    }
    // a nearly collinear zone has a nearly singular inertia: solve in the least-squares
    // sense, and never turn a zone by more than MAX_TURN in one step
    let omega = inertia
        .pseudo_inverse(1e-9 * inertia.norm())
        .map_or(Vec3::zeros(), |inv| inv * l);
    // nor so far that a vertex moves more, relative to the zone's centre, than the fastest
    // one did: a large zone (a whole garment piece) turned by MAX_TURN would swing its far
    // ends by decimetres in one step
    let (r_max, rel_max) = zone.iter().fold((0.0f64, 0.0f64), |(r, m), &i| {
        (r.max((x0[i] - c).norm()), m.max((d[i] - dc).norm()))
    });
    let limit = if r_max > 0.0 {
        MAX_TURN.min(rel_max / r_max)
    } else {
        MAX_TURN
    };
    let omega = if omega.norm() > limit {
        omega * (limit / omega.norm())
    } else {
        omega
    };
    let rot = Rotation3::new(omega);
    for &i in zone {
        let r = x0[i] - c;
        d[i] = dc + rot * r - r;
    }
}

/// Root of `i`'s class (with path compression).
pub fn find(parent: &mut [u32], i: usize) -> u32 {
    let mut r = i as u32;
    while parent[r as usize] != r {
        r = parent[r as usize];
    }
    let mut k = i as u32;
    while parent[k as usize] != r {
        let next = parent[k as usize];
        parent[k as usize] = r;
        k = next;
    }
    r
}

/// Merges the classes of `a` and `b`; the smaller root index wins (deterministic).
pub fn union(parent: &mut [u32], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        // the smaller index is the root: deterministic
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        parent[hi as usize] = lo;
    }
}
