//! `TriMesh`: a triangle mesh with 3D positions and 2D rest coordinates (the flat pattern,
//! metres, u along the warp and v along the weft).

use super::{GeometryError, Vec3};

/// A triangle mesh. `rest` holds, per vertex, the flat rest position in the fabric plane
/// (metres; u = warp direction, v = weft direction). Triangles index vertices counter-clockwise.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct TriMesh {
    /// World positions of the vertices (m).
    pub positions: Vec<Vec3>,
    /// Rest (pattern) coordinates of the vertices (m).
    pub rest: Vec<[f64; 2]>,
    /// Triangles as vertex index triples.
    pub triangles: Vec<[usize; 3]>,
}

impl TriMesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Checks sizes, indices, finiteness and non-degenerate rest triangles.
    pub fn validate(&self) -> Result<(), GeometryError> {
        let n = self.positions.len();
        if self.rest.len() != n {
            return Err(GeometryError::Invalid(format!(
                "{} positions but {} rest coordinates",
                n,
                self.rest.len()
            )));
        }
        if let Some(i) = self
            .positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(GeometryError::Invalid(format!(
                "vertex {i} has a non-finite position"
            )));
        }
        if let Some(i) = self
            .rest
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(GeometryError::Invalid(format!(
                "vertex {i} has a non-finite rest coordinate"
            )));
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri.iter().any(|&i| i >= n) {
                return Err(GeometryError::Invalid(format!(
                    "triangle {t} indexes a vertex out of range (mesh has {n} vertices)"
                )));
            }
            if self.rest_area(t) <= 0.0 {
                return Err(GeometryError::Invalid(format!(
                    "triangle {t} has zero rest area (degenerate or missing UVs)"
                )));
            }
        }
        Ok(())
    }

    /// Unsigned rest area of triangle `t` (m²).
    pub fn rest_area(&self, t: usize) -> f64 {
        let [a, b, c] = self.triangles[t];
        let (pa, pb, pc) = (self.rest[a], self.rest[b], self.rest[c]);
        0.5 * ((pb[0] - pa[0]) * (pc[1] - pa[1]) - (pc[0] - pa[0]) * (pb[1] - pa[1])).abs()
    }

    /// Per-vertex rest area: a third of each incident triangle's rest area (m²).
    pub fn vertex_rest_areas(&self) -> Vec<f64> {
        let mut area = vec![0.0; self.positions.len()];
        for t in 0..self.triangles.len() {
            let a = self.rest_area(t) / 3.0;
            for &i in &self.triangles[t] {
                area[i] += a;
            }
        }
        area
    }

    /// Area-weighted vertex normals of the current positions (unit length, or zero).
    pub fn vertex_normals(&self) -> Vec<Vec3> {
        vertex_normals(&self.positions, &self.triangles)
    }

    /// Axis-aligned bounds (min, max) of the current positions.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        bounds(&self.positions)
    }
}

/// Area-weighted vertex normals of `positions` over `triangles`.
pub fn vertex_normals(positions: &[Vec3], triangles: &[[usize; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::zeros(); positions.len()];
    for t in triangles {
        let fn_ = (positions[t[1]] - positions[t[0]]).cross(&(positions[t[2]] - positions[t[0]]));
        for &i in t {
            n[i] += fn_;
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

/// Axis-aligned bounds (min, max) of a point set; zeros when empty.
pub fn bounds(positions: &[Vec3]) -> (Vec3, Vec3) {
    if positions.is_empty() {
        return (Vec3::zeros(), Vec3::zeros());
    }
    let mut lo = positions[0];
    let mut hi = positions[0];
    for p in positions {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}
