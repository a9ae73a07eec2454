//! The tracking mesh: a light version of the puppet's skin for fast rendering, made by vertex
//! clustering on a grid.
//!
//! Skin vertices falling in the same grid cell are merged only if their dominant bones belong
//! to the same body part ([`PartGroup`]), so arms never weld to the torso nor hands to hips.
//! A cluster's vertex is the mean of its members; triangles are remapped onto clusters (the
//! source winding, outward, is kept), and degenerate or duplicate ones dropped. Each vertex
//! keeps its dominant bone (rigid skinning, as the seed report's tracker does), up to four
//! LBS influences (summed over its members, renormalised), its part, and the skin vertex
//! nearest to it (to colour it from a skin texture or compare with the full skin).

use std::collections::{BTreeMap, HashSet};

use nalgebra::Point3;

use super::puppet::{PartGroup, Puppet};
use crate::body::{Mannequin, Pose};
use crate::geometry::Vec3;

/// Default grid cell (metres; hands use half of it): about 2,850 triangles on the MakeHuman
/// body. Splitting cells by part adds small clusters along part borders, so the cell is
/// larger than the triangle count alone would suggest.
pub const DEFAULT_CELL: f64 = 0.04;

/// Cell size of the hands relative to `cell`: fingers are thinner than a cell, and the
/// fingertips bound the body's width in the A-pose.
const HAND_CELL: f64 = 0.5;

/// The light skin of the tracking puppet (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct TrackingMesh {
    /// Rest positions (the puppet's rest skin, clustered).
    pub rest: Vec<Vec3>,
    /// Triangles, wound outward like the source skin.
    pub triangles: Vec<[u32; 3]>,
    /// Dominant bone of each vertex (rigid skinning).
    pub bone: Vec<u32>,
    /// Body part of each vertex (that of its dominant bone).
    pub part: Vec<PartGroup>,
    /// Index of the skin vertex nearest to each vertex at rest.
    pub source: Vec<u32>,
    /// Up to four LBS bones per vertex (unused slots repeat bone 0 with weight 0).
    pub lbs_bones: Vec<[u32; 4]>,
    /// LBS weights matching `lbs_bones`, summing to one.
    pub lbs_weights: Vec<[f64; 4]>,
}

/// Where bone `b` of `pose` carries `p` (at rest if the pose lacks the bone).
#[inline]
fn carry(pose: &Pose, b: u32, p: Vec3) -> Vec3 {
    match pose.transforms().get(b as usize) {
        Some(t) => (t * Point3::from(p)).coords,
        None => p,
    }
}

/// Where the weighted bones `bs` (weights `ws`, zero weights skipped) of `pose` carry `p`.
#[inline]
fn blend(pose: &Pose, p: Vec3, bs: &[u32; 4], ws: &[f64; 4]) -> Vec3 {
    (0..4)
        .filter(|&k| ws[k] > 0.0)
        .map(|k| carry(pose, bs[k], p) * ws[k])
        .sum()
}

impl TrackingMesh {
    /// Clusters `puppet`'s rest skin (the mannequin's skin re-proportioned; triangles from
    /// `mannequin`) on a grid of `cell` metres ([`DEFAULT_CELL`] if `cell` is not a positive
    /// finite number). Triangles referring past the puppet's skin are skipped.
    pub fn build(mannequin: &Mannequin, puppet: &Puppet, cell: f64) -> TrackingMesh {
        let cell = if cell.is_finite() && cell > 0.0 {
            cell
        } else {
            DEFAULT_CELL
        };
        let rest = puppet.rest_skin();
        let weights = puppet.weights();
        let groups = puppet.bone_groups();
        let n = rest.len().min(weights.len());
        // cluster of every skin vertex, clusters numbered in order of first member
        let mut cells: BTreeMap<(PartGroup, i64, i64, i64), u32> = BTreeMap::new();
        let mut cluster = vec![0u32; n];
        let mut members: Vec<Vec<usize>> = Vec::new();
        let mut parts: Vec<PartGroup> = Vec::new();
        for v in 0..n {
            let dominant = weights
                .influences(v)
                .fold(
                    (0, f64::NEG_INFINITY),
                    |a, (b, w)| if w > a.1 { (b, w) } else { a },
                )
                .0;
            let part = groups.get(dominant).copied().unwrap_or(PartGroup::Root);
            let size = match part {
                PartGroup::LeftHand | PartGroup::RightHand => cell * HAND_CELL,
                _ => cell,
            };
            let q = |x: f64| (x / size).floor() as i64;
            let key = (part, q(rest[v].x), q(rest[v].y), q(rest[v].z));
            let id = *cells.entry(key).or_insert_with(|| {
                members.push(Vec::new());
                parts.push(part);
                (members.len() - 1) as u32
            });
            members[id as usize].push(v);
            cluster[v] = id;
        }
        // triangles onto clusters; drop degenerate and duplicate ones
        let mut seen = HashSet::new();
        let mut tris = Vec::new();
        for t in mannequin.triangles() {
            if t.iter().any(|&v| v >= n) {
                continue;
            }
            let c = [cluster[t[0]], cluster[t[1]], cluster[t[2]]];
            if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
                continue;
            }
            let mut key = c;
            key.sort_unstable();
            if seen.insert(key) {
                tris.push(c);
            }
        }
        // keep the clusters that triangles use, renumbered in cluster order
        let mut used = vec![u32::MAX; members.len()];
        for t in &tris {
            for &c in t {
                used[c as usize] = 0;
            }
        }
        let mut mesh = TrackingMesh::default();
        for (c, m) in members.iter().enumerate() {
            if used[c] == u32::MAX {
                continue;
            }
            used[c] = mesh.rest.len() as u32;
            let mean = m.iter().map(|&v| rest[v]).sum::<Vec3>() / m.len() as f64;
            let mut acc: BTreeMap<usize, f64> = BTreeMap::new();
            for &v in m {
                for (b, w) in weights.influences(v) {
                    *acc.entry(b).or_insert(0.0) += w;
                }
            }
            let mut inf: Vec<(usize, f64)> = acc.into_iter().collect();
            inf.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            // the rigid bone: the heaviest bone of the cluster's own part
            let part = parts[c];
            let own = inf
                .iter()
                .position(|&(b, _)| groups.get(b) == Some(&part))
                .unwrap_or(0);
            if own > 0 {
                inf.swap(0, own);
                inf[1..].sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            }
            inf.truncate(4);
            let total: f64 = inf.iter().map(|x| x.1).sum();
            let mut bones = [inf.first().map_or(0, |x| x.0 as u32); 4];
            let mut ws = [0.0; 4];
            for (k, &(b, w)) in inf.iter().enumerate() {
                bones[k] = b as u32;
                ws[k] = if total > 0.0 { w / total } else { 0.0 };
            }
            if total <= 0.0 {
                ws[0] = 1.0;
            }
            let source = m
                .iter()
                .copied()
                .min_by(|&a, &b| (rest[a] - mean).norm().total_cmp(&(rest[b] - mean).norm()))
                .unwrap_or(0);
            mesh.rest.push(mean);
            mesh.bone.push(bones[0]);
            mesh.part.push(part);
            mesh.source.push(source as u32);
            mesh.lbs_bones.push(bones);
            mesh.lbs_weights.push(ws);
        }
        mesh.triangles = tris
            .iter()
            .map(|t| {
                [
                    used[t[0] as usize],
                    used[t[1] as usize],
                    used[t[2] as usize],
                ]
            })
            .collect();
        mesh
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.rest.len()
    }

    /// Whether the mesh has no vertex.
    pub fn is_empty(&self) -> bool {
        self.rest.is_empty()
    }

    /// Rigid skinning: each vertex carried by its dominant bone, into `out` (the first
    /// `min(out.len(), self.len())` vertices).
    pub fn skin_rigid_into(&self, pose: &Pose, out: &mut [Vec3]) {
        for ((o, &p), &b) in out.iter_mut().zip(&self.rest).zip(&self.bone) {
            *o = carry(pose, b, p);
        }
    }

    /// The vertices `subset` (indices, in range) skinned into `out` (cleared first), rigidly
    /// or by linear blend skinning, each as [`skin_rigid_into`](Self::skin_rigid_into) or
    /// [`skin_lbs_into`](Self::skin_lbs_into) would place it.
    pub fn skin_subset_into(&self, pose: &Pose, lbs: bool, subset: &[u32], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend(subset.iter().map(|&v| {
            let v = v as usize;
            if lbs {
                blend(pose, self.rest[v], &self.lbs_bones[v], &self.lbs_weights[v])
            } else {
                carry(pose, self.bone[v], self.rest[v])
            }
        }));
    }

    /// Linear blend skinning with the (up to four) kept influences, into `out` (the first
    /// `min(out.len(), self.len())` vertices).
    pub fn skin_lbs_into(&self, pose: &Pose, out: &mut [Vec3]) {
        let per_vertex = self.rest.iter().zip(&self.lbs_bones).zip(&self.lbs_weights);
        for (o, ((&p, bs), ws)) in out.iter_mut().zip(per_vertex) {
            *o = blend(pose, p, bs, ws);
        }
    }
}
