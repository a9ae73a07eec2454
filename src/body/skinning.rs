//! Linear blend skinning: per-bone rigid transforms ([`Pose`]) and per-vertex bone weights
//! ([`SkinWeights`], read from a MakeHuman `.mhw` file), blended into vertex positions.
//!
//! A skinned vertex is `p' = Σᵢ wᵢ (Rᵢ p + tᵢ)` over the bones influencing it, with weights
//! normalised to sum to one. Weights are stored flat (compressed rows: one offset per
//! vertex), so skinning is one pass over the vertices without allocation; large meshes are
//! split over threads in chunks.

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Point3};
use rayon::prelude::*;
use serde::Deserialize;

use super::error::BodyError;
use super::skeleton::Skeleton;
use crate::geometry::Vec3;

/// One rigid transform per bone, in world space and relative to the rest pose: a rest point
/// `p` carried by bone `b` goes to `R_b p + t_b`. The identity pose is the rest pose.
#[derive(Clone, Debug)]
pub struct Pose {
    transforms: Vec<Isometry3<f64>>,
    /// Row-major `[R | t]` of each transform, kept in step with `transforms`.
    affine: Vec<[f64; 12]>,
}

fn to_affine(t: &Isometry3<f64>) -> [f64; 12] {
    let r = t.rotation.to_rotation_matrix();
    let m = r.matrix();
    let v = t.translation.vector;
    [
        m[(0, 0)],
        m[(0, 1)],
        m[(0, 2)],
        v.x,
        m[(1, 0)],
        m[(1, 1)],
        m[(1, 2)],
        v.y,
        m[(2, 0)],
        m[(2, 1)],
        m[(2, 2)],
        v.z,
    ]
}

impl Pose {
    /// The rest pose of a skeleton with `bones` bones (every transform the identity).
    pub fn identity(bones: usize) -> Pose {
        Pose {
            transforms: vec![Isometry3::identity(); bones],
            affine: vec![to_affine(&Isometry3::identity()); bones],
        }
    }

    /// A pose from one transform per bone.
    pub fn from_transforms(transforms: Vec<Isometry3<f64>>) -> Pose {
        let affine = transforms.iter().map(to_affine).collect();
        Pose { transforms, affine }
    }

    /// Number of bones.
    pub fn len(&self) -> usize {
        self.transforms.len()
    }

    /// Whether the pose has no bone.
    pub fn is_empty(&self) -> bool {
        self.transforms.is_empty()
    }

    /// All transforms, indexed like the skeleton's bones.
    pub fn transforms(&self) -> &[Isometry3<f64>] {
        &self.transforms
    }

    /// The transform of `bone` (panics if out of range, like slice indexing).
    pub fn transform(&self, bone: usize) -> &Isometry3<f64> {
        &self.transforms[bone]
    }

    /// Sets the transform of `bone` (panics if out of range, like slice indexing).
    pub fn set(&mut self, bone: usize, t: Isometry3<f64>) {
        self.affine[bone] = to_affine(&t);
        self.transforms[bone] = t;
    }

    /// Where bone `bone` carries the rest point `p`.
    pub fn apply(&self, bone: usize, p: Vec3) -> Vec3 {
        (self.transforms[bone] * Point3::from(p)).coords
    }
}

/// Bone weights of every vertex of a mesh, normalised per vertex.
#[derive(Clone, Debug, Default)]
pub struct SkinWeights {
    /// `offsets[v]..offsets[v + 1]` are the influences of vertex `v`.
    offsets: Vec<usize>,
    bones: Vec<u32>,
    weights: Vec<f64>,
}

#[derive(Deserialize)]
struct WeightsFile {
    weights: BTreeMap<String, Vec<(usize, f64)>>,
}

/// Vertices per parallel task when skinning.
const CHUNK: usize = 2048;

impl SkinWeights {
    /// Parses `.mhw` JSON (`weights`: bone name → `[[vertex, weight], ...]`) for a mesh of
    /// `vertex_count` vertices. Every vertex needs a positive total weight; weights are then
    /// normalised to sum to one. `file` names the text in errors.
    pub fn parse_mhw(
        text: &str,
        file: &str,
        skeleton: &Skeleton,
        vertex_count: usize,
    ) -> Result<SkinWeights, BodyError> {
        let def: WeightsFile = serde_json::from_str(text).map_err(|e| BodyError::json(file, &e))?;
        let mut triplets: Vec<(usize, u32, f64)> = Vec::new();
        for (bone, list) in &def.weights {
            let b = skeleton.bone_index(bone).ok_or_else(|| {
                BodyError::invalid(file, format!("weights for unknown bone '{bone}'"))
            })?;
            for &(v, w) in list {
                if v >= vertex_count {
                    return Err(BodyError::invalid(
                        file,
                        format!("bone '{bone}': vertex {v} out of range (mesh has {vertex_count})"),
                    ));
                }
                if !(w.is_finite() && w >= 0.0) {
                    return Err(BodyError::invalid(
                        file,
                        format!("bone '{bone}': vertex {v} has weight {w}"),
                    ));
                }
                if w > 0.0 {
                    triplets.push((v, b as u32, w));
                }
            }
        }
        triplets.sort_by_key(|t| (t.0, t.1));
        let mut offsets = Vec::with_capacity(vertex_count + 1);
        let mut bones = Vec::with_capacity(triplets.len());
        let mut weights = Vec::with_capacity(triplets.len());
        let mut t = 0;
        for v in 0..vertex_count {
            offsets.push(bones.len());
            let start = bones.len();
            while t < triplets.len() && triplets[t].0 == v {
                let (_, b, w) = triplets[t];
                if bones.len() > start && bones[bones.len() - 1] == b {
                    *weights.last_mut().expect("nonempty") += w;
                } else {
                    bones.push(b);
                    weights.push(w);
                }
                t += 1;
            }
            let sum: f64 = weights[start..].iter().sum();
            if sum <= 0.0 {
                return Err(BodyError::invalid(
                    file,
                    format!("vertex {v} has no bone weight"),
                ));
            }
            for w in &mut weights[start..] {
                *w /= sum;
            }
        }
        offsets.push(bones.len());
        Ok(SkinWeights {
            offsets,
            bones,
            weights,
        })
    }

    /// The weights of the listed vertices only, in that order (vertex `i` of the result is
    /// `vertices[i]` of `self`; panics on an out-of-range index).
    pub fn subset(&self, vertices: &[usize]) -> SkinWeights {
        let mut out = SkinWeights {
            offsets: Vec::with_capacity(vertices.len() + 1),
            ..Default::default()
        };
        for &v in vertices {
            out.offsets.push(out.bones.len());
            let r = self.offsets[v]..self.offsets[v + 1];
            out.bones.extend_from_slice(&self.bones[r.clone()]);
            out.weights.extend_from_slice(&self.weights[r]);
        }
        out.offsets.push(out.bones.len());
        out
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Whether there is no vertex.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `(bone, weight)` influences of vertex `v` (weights sum to one).
    pub fn influences(&self, v: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let r = self.offsets[v]..self.offsets[v + 1];
        self.bones[r.clone()]
            .iter()
            .zip(&self.weights[r])
            .map(|(&b, &w)| (b as usize, w))
    }

    /// Largest number of bones influencing one vertex.
    pub fn max_influences(&self) -> usize {
        self.offsets
            .windows(2)
            .map(|w| w[1] - w[0])
            .max()
            .unwrap_or(0)
    }

    /// Skins vertex `v`, whose rest position is `p`.
    #[inline]
    pub fn skin_vertex(&self, v: usize, p: Vec3, pose: &Pose) -> Vec3 {
        let (mut x, mut y, mut z) = (0.0, 0.0, 0.0);
        for k in self.offsets[v]..self.offsets[v + 1] {
            let m = &pose.affine[self.bones[k] as usize];
            let w = self.weights[k];
            x += w * (m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3]);
            y += w * (m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7]);
            z += w * (m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
        }
        Vec3::new(x, y, z)
    }

    /// Skins all vertices: `out[v]` is `rest[v]` carried by the blended bone transforms.
    /// `rest` must have [`SkinWeights::len`] entries; `out` is resized and reused.
    pub fn skin(&self, rest: &[Vec3], pose: &Pose, out: &mut Vec<Vec3>) {
        let n = self.len().min(rest.len());
        out.resize(n, Vec3::zeros());
        if n <= CHUNK {
            for (v, o) in out.iter_mut().enumerate() {
                *o = self.skin_vertex(v, rest[v], pose);
            }
            return;
        }
        out.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(c, chunk)| {
                let base = c * CHUNK;
                for (i, o) in chunk.iter_mut().enumerate() {
                    *o = self.skin_vertex(base + i, rest[base + i], pose);
                }
            });
    }
}
