//! Cloth–cloth collisions (Bridson, Fedkiw & Anderson 2002, after Provot 1997), applied to the
//! step's displacements `d = x1 − x0` from a state `x0` free of intersections:
//! 1. **repulsion**: vertex–triangle and edge–edge pairs closer than the thickness at the start
//!    and approaching lose their approach (inelastic impulse, a small push apart, Coulomb friction);
//! 2. **continuous detection**: the cubic coplanarity test on every candidate pair's linear
//!    motion; each hit gets an impulse leaving the pair a quarter thickness apart; repeated;
//! 3. **impact zones**: if hits remain, the vertices of colliding pairs are merged into zones
//!    moved rigidly (momentum and angular momentum kept), which cannot tangle themselves;
//!    zones grow until nothing crosses; as a last resort the zones' vertices stop, then those
//!    of the pairs still hitting, round by round, until nothing hits or only stopped and
//!    prescribed vertices do.
//!
//! Velocities change by the displacement corrections over dt. Candidate pairs come from a
//! spatial hash of swept boxes (see [`SpatialHash`]); pairs sharing a vertex are skipped.

mod broad_phase;
mod intersections;
mod response;

use rayon::prelude::*;

use super::ccd::{edge_edge_ccd, vertex_face_ccd, CcdHit};
use super::impact_zone::{find, rigid_motion};
use super::primitives::{closest_point_triangle, closest_points_segments};
use super::spatial_hash::{Aabb, SpatialHash};
use crate::geometry::Vec3;

/// Repeated continuous-detection passes before impact zones take over.
const CCD_PASSES: usize = 6;
/// Impact-zone rounds before the last-resort stop.
const ZONE_ROUNDS: usize = 24;
/// Rounds of the last resort that stop the free vertices of the pairs still hitting, before
/// every free vertex stops.
const STOP_ROUNDS: usize = 16;
/// Pairs are left this fraction of the thickness apart after a continuous hit.
const SEPARATION: f64 = 0.25;
/// Fraction of the overlap recovered per step by the repulsion push.
const PUSH: f64 = 0.2;

/// A candidate closer than the thickness: (candidate, distance, Bridson weights, unit normal).
type ClosePair = (usize, f64, [f64; 4], Vec3);

/// What one call of [`SelfCollision::respond`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SelfCollisionReport {
    /// Pairs closer than the thickness at the start of the step.
    pub proximities: usize,
    /// Continuous-detection hits over all passes.
    pub ccd_hits: usize,
    /// Continuous-detection passes run.
    pub passes: usize,
    /// Impact-zone rounds run.
    pub zone_rounds: usize,
    /// Vertices stopped by the last resort.
    pub stopped: usize,
    /// Crossing pairs left unresolved (the start of the step was already tangled).
    pub unresolved: usize,
}

/// Self-collision topology and workspaces of one cloth.
#[derive(Debug, Clone)]
pub struct SelfCollision {
    triangles: Vec<[u32; 3]>,
    edges: Vec<[u32; 2]>,
    cell: f64,
    tri_boxes: Vec<Aabb>,
    edge_boxes: Vec<Aabb>,
    tri_hash: SpatialHash,
    edge_hash: SpatialHash,
    vf: Vec<(u32, u32)>,
    ee: Vec<(u32, u32)>,
    d: Vec<Vec3>,
    d_in: Vec<Vec3>,
    d_bp: Vec<Vec3>,
    moved: Vec<bool>,
    parent: Vec<u32>,
    /// Vertices sewn together.
    welds: Welds,
    /// Pass-through zones (0: none): a vertex never collides with a triangle or edge whose
    /// vertices all lie in its own zone (empty: no zones).
    pub(super) zone: Vec<u32>,
}

/// Vertices sewn together: each vertex's weld class (`rep`, its representative; empty: none
/// welded), the classes' members (CSR by representative: `members[start[r]..start[r + 1]]`)
/// and, per step, each vertex's class inverse mass and whether its class is sewn shut (its
/// members within the thickness of each other) and so moves as one. An impulse on a vertex of
/// a sewn-shut class moves the whole class: moving one side of a seam alone opened the seam (a
/// panel's vertex repelled from the other panel's triangle at the seam pushed that triangle's
/// seam vertex away from its partner). A class still being sewn does not: its members may lie
/// on either side of the body.
#[derive(Debug, Clone, Default)]
struct Welds {
    rep: Vec<u32>,
    start: Vec<u32>,
    members: Vec<u32>,
    inv: Vec<f64>,
    joined: Vec<bool>,
}

impl Welds {
    /// Adds `step` to the displacement of `i` and of every vertex sewn to it.
    #[inline]
    fn add(&self, d: &mut [Vec3], i: usize, step: Vec3) {
        if self.rep.is_empty() || !self.joined[i] {
            d[i] += step;
        } else {
            let r = self.rep[i] as usize;
            for &m in &self.members[self.start[r] as usize..self.start[r + 1] as usize] {
                d[m as usize] += step;
            }
        }
    }
}

impl SelfCollision {
    /// Self-collision for the triangles of a cloth whose rest positions are `rest` (the grid's
    /// cell size follows the mean edge length).
    pub fn new(triangles: &[[usize; 3]], rest: &[Vec3]) -> SelfCollision {
        let mut edges: Vec<[u32; 2]> = triangles
            .iter()
            .flat_map(|t| {
                (0..3).map(move |k| {
                    let (a, b) = (t[k] as u32, t[(k + 1) % 3] as u32);
                    [a.min(b), a.max(b)]
                })
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let mean = edges
            .iter()
            .map(|e| (rest[e[0] as usize] - rest[e[1] as usize]).norm())
            .sum::<f64>()
            / edges.len().max(1) as f64;
        SelfCollision {
            triangles: triangles.iter().map(|t| t.map(|i| i as u32)).collect(),
            edges,
            cell: (2.0 * mean).max(1e-4),
            tri_boxes: Vec::new(),
            edge_boxes: Vec::new(),
            tri_hash: SpatialHash::default(),
            edge_hash: SpatialHash::default(),
            vf: Vec::new(),
            ee: Vec::new(),
            d: Vec::new(),
            d_in: Vec::new(),
            d_bp: Vec::new(),
            moved: Vec::new(),
            parent: Vec::new(),
            welds: Welds::default(),
            zone: Vec::new(),
        }
    }

    /// Sets the pass-through zones, one id per vertex (0: in none); an empty slice clears
    /// them. Pieces being sewn along a seam may pass through each other near it.
    pub fn set_zones(&mut self, zone: &[u32]) {
        self.zone.clear();
        self.zone.extend_from_slice(zone);
    }

    /// Declares pairs of vertices sewn together (seams): a welded vertex counts as shared with
    /// its partner, so the pair is never pushed apart nor counted as an intersection.
    pub fn set_welds(&mut self, n: usize, pairs: &[(usize, usize)]) {
        let mut rep: Vec<u32> = (0..n as u32).collect();
        fn root(r: &mut [u32], mut a: u32) -> u32 {
            while r[a as usize] != a {
                r[a as usize] = r[r[a as usize] as usize];
                a = r[a as usize];
            }
            a
        }
        for &(a, b) in pairs {
            if a < n && b < n {
                let (ra, rb) = (root(&mut rep, a as u32), root(&mut rep, b as u32));
                rep[ra.max(rb) as usize] = ra.min(rb);
            }
        }
        for i in 0..n as u32 {
            rep[i as usize] = root(&mut rep, i);
        }
        self.welds.rep = if pairs.is_empty() { Vec::new() } else { rep };
        self.welds.start.clear();
        self.welds.members.clear();
        if !self.welds.rep.is_empty() {
            let mut count = vec![0u32; n + 1];
            for &r in &self.welds.rep {
                count[r as usize + 1] += 1;
            }
            for i in 0..n {
                count[i + 1] += count[i];
            }
            let mut fill = count.clone();
            self.welds.members.resize(n, 0);
            for (i, &r) in self.welds.rep.iter().enumerate() {
                self.welds.members[fill[r as usize] as usize] = i as u32;
                fill[r as usize] += 1;
            }
            self.welds.start = count;
        }
    }

    /// Which vertices the last [`SelfCollision::respond`] moved.
    pub fn moved(&self) -> &[bool] {
        &self.moved
    }

    /// Whether the last [`SelfCollision::respond`] moved any vertex.
    pub fn moved_any(&self) -> bool {
        self.moved.iter().any(|&m| m)
    }

    /// Unique undirected edges of the cloth.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// The continuous hits of the current displacements, the candidates found again first if
    /// some displacement moved more than `margin` since they were.
    fn refresh_hits(
        &mut self,
        x0: &[Vec3],
        thickness: f64,
        margin: f64,
        hits: &mut Vec<(usize, CcdHit)>,
    ) {
        if self.stale(margin) {
            self.broad_phase(x0, thickness + margin);
        }
        self.find_hits(x0, thickness, hits);
    }

    /// Whether some displacement moved more than `margin` since the candidates were found.
    fn stale(&self, margin: f64) -> bool {
        let m2 = margin * margin;
        self.d
            .iter()
            .zip(&self.d_bp)
            .any(|(a, b)| (a - b).norm_squared() > m2)
    }

    /// Distance, Bridson weights and unit normal (pointing toward the first primitive) of
    /// candidate `k` at positions `x`.
    fn proximity(&self, k: usize, x: &[Vec3], vs: &[usize; 4]) -> Option<(f64, [f64; 4], Vec3)> {
        let p = vs.map(|i| x[i]);
        let (gap, w) = if k < self.vf.len() {
            let (q, b) = closest_point_triangle(p[0], p[1], p[2], p[3]);
            (p[0] - q, [1.0, -b[0], -b[1], -b[2]])
        } else {
            let (s, t, a, b) = closest_points_segments(p[0], p[1], p[2], p[3]);
            (a - b, [1.0 - s, s, -(1.0 - t), -t])
        };
        let dist = gap.norm();
        let nrm = if dist > 1e-12 {
            gap / dist
        } else if k < self.vf.len() {
            let nt = (p[2] - p[1]).cross(&(p[3] - p[1]));
            nt.try_normalize(1e-300)?
        } else {
            let ne = (p[1] - p[0]).cross(&(p[3] - p[2]));
            ne.try_normalize(1e-300)?
        };
        Some((dist, w, nrm))
    }

    /// Continuous hits of all candidates on the motion `x0 → x0 + d`, in candidate order.
    fn find_hits(&self, x0: &[Vec3], thickness: f64, hits: &mut Vec<(usize, CcdHit)>) {
        let d = &self.d;
        let nvf = self.vf.len();
        let total = nvf + self.ee.len();
        let chunk = 1024;
        let found: Vec<Vec<(usize, CcdHit)>> = (0..total.div_ceil(chunk))
            .into_par_iter()
            .map(|c| {
                let mut out = Vec::new();
                for k in c * chunk..((c + 1) * chunk).min(total) {
                    let vs = self.pair_vertices(k);
                    let xs = vs.map(|i| x0[i]);
                    let ds = vs.map(|i| d[i]);
                    if swept_apart(&xs, &ds, k < nvf, 0.1 * thickness) {
                        continue;
                    }
                    let hit = if k < nvf {
                        vertex_face_ccd(xs, ds, thickness * 0.1)
                    } else {
                        edge_edge_ccd(xs, ds, thickness * 0.1)
                    };
                    if let Some(h) = hit {
                        out.push((k, h));
                    }
                }
                out
            })
            .collect();
        hits.clear();
        hits.extend(found.into_iter().flatten());
    }

    /// (root, vertex) for every vertex of an impact zone (a union–find class of more than one
    /// vertex), sorted.
    fn zone_members(&mut self) -> Vec<(u32, u32)> {
        let n = self.parent.len();
        let roots: Vec<u32> = (0..n).map(|i| find(&mut self.parent, i)).collect();
        let mut size = vec![0u32; n];
        for r in &roots {
            size[*r as usize] += 1;
        }
        let mut m: Vec<(u32, u32)> = (0..n)
            .filter(|&i| size[roots[i] as usize] > 1)
            .map(|i| (roots[i], i as u32))
            .collect();
        m.sort_unstable();
        m
    }

    /// Replaces the displacements of every impact zone by the zone's rigid motion with the
    /// same momentum and angular momentum.
    fn rigidify_zones(&mut self, x0: &[Vec3], inv_mass: &[f64]) {
        let members = self.zone_members();
        let mut start = 0;
        while start < members.len() {
            let root = members[start].0;
            let mut end = start;
            while end < members.len() && members[end].0 == root {
                end += 1;
            }
            let zone: Vec<usize> = members[start..end].iter().map(|m| m.1 as usize).collect();
            rigid_motion(&mut self.d, &zone, x0, inv_mass);
            start = end;
        }
    }
}

/// Whether the boxes swept by the two primitives of a candidate over the step (from `x` by
/// `d`) are more than `gap` apart along some axis (then their motions cannot meet).
#[inline]
fn swept_apart(x: &[Vec3; 4], d: &[Vec3; 4], vertex_face: bool, gap: f64) -> bool {
    let split = if vertex_face { 1 } else { 2 };
    (0..3).any(|a| {
        let (mut lo0, mut hi0, mut lo1, mut hi1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for m in 0..4 {
            let (p, q) = (x[m][a], x[m][a] + d[m][a]);
            if m < split {
                lo0 = lo0.min(p.min(q));
                hi0 = hi0.max(p.max(q));
            } else {
                lo1 = lo1.min(p.min(q));
                hi1 = hi1.max(p.max(q));
            }
        }
        lo0 > hi1 + gap || lo1 > hi0 + gap
    })
}

#[cfg(test)]
mod tests;
