//! The generic face mesh: the MediaPipe canonical face (468 vertices, 898 triangles, UVs),
//! read from its landmark-order OBJ and converted from centimetres to metres.
//!
//! Axes as the file: y up, +z out of the face (towards a frontal viewer), +x towards the
//! subject's left. Vertex `i` is MediaPipe FaceMesh landmark `i`, so landmark tables index the
//! mesh directly. Any other OBJ with texture coordinates can be read too
//! ([`FaceMesh::load_obj`]); landmark tables then need their own vertex indices.

use std::path::{Path, PathBuf};

use super::FaceError;
use crate::geometry::files::data_dir;
use crate::geometry::{read_obj, Vec3};

/// Number of vertices of the MediaPipe canonical mesh.
pub const MEDIAPIPE_VERTICES: usize = 468;

/// File name of the canonical mesh in landmark order, under `faces/mediapipe_canonical/`.
pub const MEDIAPIPE_OBJ: &str = "mediapipe_canonical_face_468_landmark_order.obj";

/// Landmark of the outer corner of the subject's right eye (iBUG 36).
pub const RIGHT_EYE_OUTER: usize = 33;
/// Landmark of the outer corner of the subject's left eye (iBUG 45).
pub const LEFT_EYE_OUTER: usize = 263;
/// Landmark of the nose tip.
pub const NOSE_TIP: usize = 4;
/// Landmark of the chin (lowest point).
pub const CHIN: usize = 152;
/// Landmark of the top of the forehead.
pub const FOREHEAD: usize = 10;

/// The path of the MediaPipe canonical mesh under [`data_dir`].
pub fn mediapipe_path() -> PathBuf {
    data_dir()
        .join("faces")
        .join("mediapipe_canonical")
        .join(MEDIAPIPE_OBJ)
}

/// A textured triangle mesh of a face, in metres.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceMesh {
    /// Vertex positions (m).
    pub positions: Vec<Vec3>,
    /// Texture coordinates per vertex, `u` right, `v` up (OBJ convention), in `[0, 1]`.
    pub uvs: Vec<[f64; 2]>,
    /// Triangles, counter-clockwise seen from outside the face.
    pub triangles: Vec<[u32; 3]>,
}

impl FaceMesh {
    /// The MediaPipe canonical face from the shared data folder.
    pub fn mediapipe() -> Result<FaceMesh, FaceError> {
        let mesh = FaceMesh::load_obj(&mediapipe_path(), 0.01)?;
        if mesh.positions.len() != MEDIAPIPE_VERTICES {
            return Err(FaceError::Parse {
                path: mediapipe_path(),
                line: 0,
                message: format!(
                    "expected {MEDIAPIPE_VERTICES} vertices (FaceMesh landmark order), found {}",
                    mesh.positions.len()
                ),
            });
        }
        Ok(mesh)
    }

    /// Reads an OBJ with one texture coordinate per vertex, positions multiplied by `scale`
    /// (0.01 for centimetres). Errors name the file and line.
    pub fn load_obj(path: &Path, scale: f64) -> Result<FaceMesh, FaceError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(FaceError::parameter(
                "scale",
                format!("must be finite and positive, got {scale}"),
            ));
        }
        let mesh = read_obj(path).map_err(|e| match e {
            crate::geometry::GeometryError::Parse {
                path,
                line,
                message,
            } => FaceError::Parse {
                path,
                line,
                message,
            },
            other => FaceError::io(path, other),
        })?;
        Ok(FaceMesh {
            positions: mesh.positions.iter().map(|p| p * scale).collect(),
            uvs: mesh.rest.clone(),
            triangles: mesh
                .triangles
                .iter()
                .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32])
                .collect(),
        })
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Area-weighted vertex normals, unit length (zero for unused vertices).
    pub fn vertex_normals(&self) -> Vec<Vec3> {
        let mut n = vec![Vec3::zeros(); self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let f = (b - a).cross(&(c - a));
            for &i in t {
                n[i as usize] += f;
            }
        }
        for v in &mut n {
            let l = v.norm();
            if l > 0.0 {
                *v /= l;
            }
        }
        n
    }

    /// Axis-aligned bounds `(min, max)` of the vertices.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for p in &self.positions {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (lo, hi)
    }

    /// Face width: the x extent of the vertices (m). For the canonical mesh about 0.15 m.
    pub fn width(&self) -> f64 {
        let (lo, hi) = self.bounds();
        hi.x - lo.x
    }

    /// Mean of the vertices.
    pub fn centroid(&self) -> Vec3 {
        let s: Vec3 = self.positions.iter().sum();
        s / self.positions.len().max(1) as f64
    }

    /// For each vertex, the vertex nearest its mirror image in the plane `x = 0` (itself for
    /// vertices on the plane). Exact pairs on the symmetric canonical mesh.
    pub fn mirror_map(&self) -> Vec<usize> {
        self.positions
            .iter()
            .map(|p| {
                let m = Vec3::new(-p.x, p.y, p.z);
                let mut best = (f64::INFINITY, 0);
                for (j, q) in self.positions.iter().enumerate() {
                    let d = (q - m).norm_squared();
                    if d < best.0 {
                        best = (d, j);
                    }
                }
                best.1
            })
            .collect()
    }

    /// Vertex neighbours (sorted, no duplicates) from the triangles.
    pub fn neighbours(&self) -> Vec<Vec<usize>> {
        let mut nb = vec![Vec::new(); self.positions.len()];
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                nb[a].push(b);
                nb[b].push(a);
            }
        }
        for v in &mut nb {
            v.sort_unstable();
            v.dedup();
        }
        nb
    }

    /// The edges of the triangles, each once, as `(low, high)` vertex pairs, sorted.
    pub fn edges(&self) -> Vec<(usize, usize)> {
        let mut e: Vec<(usize, usize)> = self
            .triangles
            .iter()
            .flat_map(|t| {
                (0..3).map(move |k| {
                    let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                    (a.min(b), a.max(b))
                })
            })
            .collect();
        e.sort_unstable();
        e.dedup();
        e
    }

    /// Boundary edges (used by one triangle only), as `(a, b)` in the triangle's winding.
    pub fn boundary_edges(&self) -> Vec<(usize, usize)> {
        let mut count = std::collections::BTreeMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                *count.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
            }
        }
        let mut out = Vec::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                if count[&(a.min(b), a.max(b))] == 1 {
                    out.push((a, b));
                }
            }
        }
        out
    }

    /// Checks sizes, index ranges and finiteness; `source` names the mesh in the error.
    pub fn validate(&self, source: &str) -> Result<(), FaceError> {
        let n = self.positions.len();
        if self.uvs.len() != n {
            return Err(FaceError::Failed(format!(
                "{source}: {} texture coordinates for {n} vertices",
                self.uvs.len()
            )));
        }
        if let Some(i) = self
            .positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(FaceError::Failed(format!(
                "{source}: vertex {i} is not finite"
            )));
        }
        if let Some(t) = self
            .triangles
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(FaceError::Failed(format!(
                "{source}: triangle {t} refers to a vertex past {n}"
            )));
        }
        Ok(())
    }
}
