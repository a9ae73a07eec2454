//! The broad phase of cloth–cloth collisions: candidate vertex–triangle and edge–edge pairs
//! from a spatial hash of the boxes the primitives sweep over the step.

use rayon::prelude::*;

use super::super::spatial_hash::Aabb;
use super::SelfCollision;
use crate::geometry::Vec3;

impl SelfCollision {
    /// Candidate pairs whose boxes, swept from `x0` to `x0 + d`, come closer than `pad`.
    pub(super) fn broad_phase(&mut self, x0: &[Vec3], pad: f64) {
        self.d_bp.clear();
        self.d_bp.extend_from_slice(&self.d);
        let d = &self.d;
        let swept = |ids: &[u32], pad: f64| {
            let mut b = Aabb::empty();
            for &i in ids {
                let i = i as usize;
                b.grow(&x0[i]);
                b.grow(&(x0[i] + d[i]));
            }
            b.inflated(pad)
        };
        self.tri_boxes.clear();
        self.tri_boxes
            .extend(self.triangles.iter().map(|t| swept(t, pad)));
        self.edge_boxes.clear();
        self.edge_boxes
            .extend(self.edges.iter().map(|e| swept(e, 0.5 * pad)));
        self.tri_hash.build(&self.tri_boxes, self.cell);
        self.edge_hash.build(&self.edge_boxes, self.cell);
        let (tris, edges) = (&self.triangles, &self.edges);
        let (tri_hash, edge_hash, edge_boxes) = (&self.tri_hash, &self.edge_hash, &self.edge_boxes);
        let rep = &self.welds.rep;
        let r = |i: u32| if rep.is_empty() { i } else { rep[i as usize] };
        let zone = &self.zone;
        let z = |i: u32| if zone.is_empty() { 0 } else { zone[i as usize] };
        let n = x0.len();
        let chunk = 512;
        let vf: Vec<Vec<(u32, u32)>> = (0..n.div_ceil(chunk))
            .into_par_iter()
            .map(|c| {
                let (mut out, mut buf) = (Vec::new(), Vec::new());
                for i in c * chunk..((c + 1) * chunk).min(n) {
                    let mut b = Aabb::empty();
                    b.grow(&x0[i]);
                    b.grow(&(x0[i] + d[i]));
                    tri_hash.query(&b, &mut buf);
                    let iu = i as u32;
                    let ri = r(iu);
                    let zi = z(iu);
                    out.extend(
                        buf.iter()
                            .filter(|&&t| {
                                let t = &tris[t as usize];
                                let shared = t.iter().any(|&k| r(k) == ri);
                                let zoned = zi != 0 && t.iter().all(|&k| z(k) == zi);
                                !(shared || zoned)
                            })
                            .map(|&t| (iu, t)),
                    );
                }
                out
            })
            .collect();
        let ne = edges.len();
        let ee: Vec<Vec<(u32, u32)>> = (0..ne.div_ceil(chunk))
            .into_par_iter()
            .map(|c| {
                let (mut out, mut buf) = (Vec::new(), Vec::new());
                for e in c * chunk..((c + 1) * chunk).min(ne) {
                    edge_hash.query(&edge_boxes[e], &mut buf);
                    let [a, b] = edges[e];
                    let za = if z(a) != 0 && z(a) == z(b) { z(a) } else { 0 };
                    let (a, b) = (r(a), r(b));
                    out.extend(
                        buf.iter()
                            .filter(|&&f| {
                                let [p, q] = edges[f as usize];
                                let zoned = za != 0 && z(p) == za && z(q) == za;
                                let (p, q) = (r(p), r(q));
                                f as usize > e && p != a && p != b && q != a && q != b && !zoned
                            })
                            .map(|&f| (e as u32, f)),
                    );
                }
                out
            })
            .collect();
        self.vf.clear();
        self.vf.extend(vf.into_iter().flatten());
        self.ee.clear();
        self.ee.extend(ee.into_iter().flatten());
    }

    /// The four vertices of candidate `k` (vertex–face pairs first, then edge–edge).
    #[inline]
    pub(super) fn pair_vertices(&self, k: usize) -> [usize; 4] {
        if k < self.vf.len() {
            let (i, t) = self.vf[k];
            let t = self.triangles[t as usize];
            [i as usize, t[0] as usize, t[1] as usize, t[2] as usize]
        } else {
            let (e, f) = self.ee[k - self.vf.len()];
            let (e, f) = (self.edges[e as usize], self.edges[f as usize]);
            [e[0] as usize, e[1] as usize, f[0] as usize, f[1] as usize]
        }
    }
}
