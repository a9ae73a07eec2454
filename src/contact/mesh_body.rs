//! Triangle-mesh bodies: a validated mesh (degenerate triangles dropped, non-manifold or
//! inconsistently wound meshes rejected with the edge named), wrapped in parry's BVH for
//! closest-point queries, with our own angle-weighted pseudo-normals for the inside test, and
//! optionally animated (vertices refitted each step, surface velocities from the last move).

use std::collections::HashMap;
use std::sync::Arc;

use parry3d_f64::math::Vector as PVec;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::{TriMesh as ParryMesh, TriMeshFlags, TrianglePointLocation};

use super::proximity::Proximity;
use super::ContactError;
use crate::geometry::Vec3;

/// Something that moves a mesh body's vertices over time (a skinned character, keyframes).
pub trait BodyAnimation: Send + Sync + std::fmt::Debug {
    /// Vertex positions at time `t` (s), as many as the mesh has, written into `out`.
    fn positions_at(&self, t: f64, out: &mut Vec<Vec3>);
}

/// A collision mesh.
#[derive(Debug, Clone)]
pub struct MeshBody {
    /// Name for messages (the file name for meshes read from disk).
    pub name: String,
    positions: Vec<Vec3>,
    rest: Vec<Vec3>,
    velocities: Vec<Vec3>,
    triangles: Vec<[usize; 3]>,
    /// For each triangle and each of its edges (ab, bc, ca) the triangle across, if any.
    across: Vec<[u32; 3]>,
    face_normals: Vec<Vec3>,
    vertex_normals: Vec<Vec3>,
    parry: ParryMesh,
    /// Bounds of `positions`, kept up to date (asked once per cloth vertex and step).
    aabb: (Vec3, Vec3),
    animation: Option<Arc<dyn BodyAnimation>>,
    scratch: Vec<Vec3>,
    /// Triangles dropped because they had no area.
    pub dropped_degenerate: usize,
    /// Whether the mesh is closed (every edge shared by two triangles).
    pub closed: bool,
}

const NONE: u32 = u32::MAX;

impl MeshBody {
    /// A mesh body from vertex positions and triangles. Degenerate triangles (a repeated index
    /// or no area) are dropped and counted; an index out of range, a non-finite vertex, an edge
    /// shared by more than two triangles (non-manifold) or two neighbours wound oppositely are
    /// errors naming the triangle or edge. A closed mesh wound inward is turned outward.
    pub fn new(
        name: &str,
        positions: Vec<Vec3>,
        triangles: &[[usize; 3]],
    ) -> Result<MeshBody, ContactError> {
        let err = |message: String| ContactError::Mesh {
            body: name.to_string(),
            message,
        };
        if let Some(i) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(err(format!("vertex {i} is not finite")));
        }
        let n = positions.len();
        let (lo, hi) = crate::geometry::mesh::bounds(&positions);
        let scale = (hi - lo).norm().max(1e-300);
        let mut tris = Vec::with_capacity(triangles.len());
        let mut dropped = 0;
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i >= n) {
                return Err(err(format!(
                    "triangle {t} uses vertex {i}, but the mesh has {n} vertices"
                )));
            }
            let [a, b, c] = tri.map(|i| positions[i]);
            let area2 = (b - a).cross(&(c - a)).norm();
            if tri[0] == tri[1]
                || tri[1] == tri[2]
                || tri[0] == tri[2]
                || area2 <= 1e-14 * scale * scale
            {
                dropped += 1;
                continue;
            }
            tris.push(*tri);
        }
        if tris.is_empty() {
            return Err(err("no triangle with a non-zero area".into()));
        }
        // edge → (triangle, local edge) of its first use, checking manifoldness and winding
        let mut first: HashMap<(usize, usize), (u32, u8, bool)> =
            HashMap::with_capacity(tris.len() * 2);
        let mut across = vec![[NONE; 3]; tris.len()];
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                match first.get_mut(&key) {
                    None => {
                        first.insert(key, (t as u32, k as u8, a < b));
                    }
                    Some(entry) => {
                        let (t0, k0, forward0) = *entry;
                        if t0 == NONE {
                            return Err(err(format!(
                                "non-manifold edge ({}, {}): shared by more than two triangles (triangle {t} among them)",
                                key.0, key.1
                            )));
                        }
                        if forward0 == (a < b) {
                            return Err(err(format!(
                                "inconsistent winding: triangles {t0} and {t} run edge ({}, {}) the same way; orient the mesh consistently",
                                key.0, key.1
                            )));
                        }
                        across[t][k] = t0;
                        across[t0 as usize][k0 as usize] = t as u32;
                        entry.0 = NONE;
                    }
                }
            }
        }
        let closed = across.iter().all(|a| a.iter().all(|&t| t != NONE));
        if closed && signed_volume(&positions, &tris) < 0.0 {
            for tri in &mut tris {
                tri.swap(1, 2);
            }
            for a in &mut across {
                // edges (ab, bc, ca) become (ac, cb, ba): ab↔ca swap, bc stays
                a.swap(0, 2);
            }
        }
        let parry = ParryMesh::with_flags(
            positions.iter().map(|p| PVec::from(*p)).collect(),
            tris.iter().map(|t| t.map(|i| i as u32)).collect(),
            TriMeshFlags::DEFORMABLE,
        )
        .map_err(|e| err(format!("cannot build its BVH: {e}")))?;
        let mut body = MeshBody {
            name: name.to_string(),
            velocities: vec![Vec3::zeros(); n],
            face_normals: vec![Vec3::zeros(); tris.len()],
            vertex_normals: vec![Vec3::zeros(); n],
            rest: positions.clone(),
            positions,
            triangles: tris,
            across,
            parry,
            aabb: (Vec3::zeros(), Vec3::zeros()),
            animation: None,
            scratch: Vec::new(),
            dropped_degenerate: dropped,
            closed,
        };
        body.update_normals();
        body.aabb = crate::geometry::mesh::bounds(&body.positions);
        Ok(body)
    }

    /// Drives the vertices by `animation` from now on; the mesh moves to its pose at time 0.
    pub fn animate(&mut self, animation: Arc<dyn BodyAnimation>) -> Result<(), ContactError> {
        let mut p = Vec::new();
        animation.positions_at(0.0, &mut p);
        if p.len() != self.positions.len() {
            return Err(ContactError::Mesh {
                body: self.name.clone(),
                message: format!(
                    "the animation gives {} vertices, the mesh has {}",
                    p.len(),
                    self.positions.len()
                ),
            });
        }
        self.animation = Some(animation);
        self.set_positions(&p, None);
        Ok(())
    }

    /// Current vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Vertex positions the mesh was built with (an animated character's rest pose).
    pub fn rest_positions(&self) -> &[Vec3] {
        &self.rest
    }

    /// Triangles (outward winding when the mesh is closed).
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// Moves the vertices to `positions`; with `dt`, surface velocities become the move over
    /// `dt`, otherwise zero. Refits the BVH.
    pub fn set_positions(&mut self, positions: &[Vec3], dt: Option<f64>) {
        for i in 0..self.positions.len() {
            self.velocities[i] = match dt {
                Some(dt) if dt > 0.0 => (positions[i] - self.positions[i]) / dt,
                _ => Vec3::zeros(),
            };
            self.positions[i] = positions[i];
        }
        let p = &self.positions;
        self.parry.update_vertices(|v| {
            for (dst, src) in v.iter_mut().zip(p) {
                *dst = PVec::from(*src);
            }
        });
        self.update_normals();
        self.aabb = crate::geometry::mesh::bounds(&self.positions);
    }

    /// Current surface velocities (of the last move).
    pub fn velocities(&self) -> &[Vec3] {
        &self.velocities
    }

    /// Puts the mesh back where a checkpoint found it: `positions` with surface velocities
    /// `velocities` (both one per vertex, else an error naming the body).
    pub fn restore(&mut self, positions: &[Vec3], velocities: &[Vec3]) -> Result<(), ContactError> {
        let n = self.positions.len();
        if positions.len() != n || velocities.len() != n {
            return Err(ContactError::Mesh {
                body: self.name.clone(),
                message: format!(
                    "the checkpoint has {} vertices, the mesh {n}",
                    positions.len()
                ),
            });
        }
        self.set_positions(positions, None);
        self.velocities.copy_from_slice(velocities);
        Ok(())
    }

    /// Moves an animated mesh to its pose at time `t`, the last move lasting `dt`.
    pub fn advance_to(&mut self, t: f64, dt: f64) {
        if let Some(anim) = self.animation.clone() {
            let mut p = std::mem::take(&mut self.scratch);
            anim.positions_at(t, &mut p);
            if p.len() == self.positions.len() {
                self.set_positions(&p, Some(dt));
            }
            self.scratch = p;
        }
    }

    /// Unit outward pseudo-normal (angle-weighted) at vertex `i`.
    pub fn vertex_normal(&self, i: usize) -> Vec3 {
        let n = self.vertex_normals[i];
        n / n.norm().max(1e-300)
    }

    /// Axis-aligned bounds of the current vertices.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.aabb
    }

    fn update_normals(&mut self) {
        self.vertex_normals.fill(Vec3::zeros());
        for (t, tri) in self.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| self.positions[i]);
            let n = (b - a).cross(&(c - a));
            let n = n / n.norm().max(1e-300);
            self.face_normals[t] = n;
            let corners = [(a, b, c), (b, c, a), (c, a, b)];
            for (k, (p, q, r)) in corners.iter().enumerate() {
                let (u, w) = (q - p, r - p);
                let angle = u.angle(&w);
                self.vertex_normals[tri[k]] += n * angle;
            }
        }
    }

    /// Signed distance (negative inside, by the pseudo-normal of the closest feature), outward
    /// normal and surface velocity at the closest point, when within `max_dist` (or inside).
    pub fn proximity(&self, p: &Vec3, max_dist: f64) -> Option<Proximity> {
        let (proj, (t, loc)) = self
            .parry
            .project_local_point_and_get_location_with_max_dist(PVec::from(*p), false, max_dist)?;
        let t = t as usize;
        let tri = self.triangles[t];
        let pseudo = match loc {
            TrianglePointLocation::OnVertex(i) => self.vertex_normals[tri[i as usize]],
            TrianglePointLocation::OnEdge(i, _) => {
                // parry's edge numbering: 0 = ab, 1 = bc, 2 = ac (= our edge 2, ca)
                let other = self.across[t][i as usize];
                let own = self.face_normals[t];
                if other == NONE {
                    own
                } else {
                    own + self.face_normals[other as usize]
                }
            }
            _ => self.face_normals[t],
        };
        let q: Vec3 = proj.point.into();
        let d = p - q;
        let dist = d.norm();
        let inside = d.dot(&pseudo) < 0.0;
        let distance = if inside { -dist } else { dist };
        let normal = if dist > 1e-12 {
            if inside {
                -d / dist
            } else {
                d / dist
            }
        } else {
            self.face_normals[t]
        };
        let w = barycentric(&q, &tri.map(|i| self.positions[i]));
        let velocity = self.velocities[tri[0]] * w[0]
            + self.velocities[tri[1]] * w[1]
            + self.velocities[tri[2]] * w[2];
        Some(Proximity {
            distance,
            normal,
            velocity,
        })
    }
}

/// Barycentric weights of `q` (on or near the triangle) in triangle `t`, clamped to ≥ 0.
fn barycentric(q: &Vec3, t: &[Vec3; 3]) -> [f64; 3] {
    let (e0, e1, e2) = (t[1] - t[0], t[2] - t[0], q - t[0]);
    let (d00, d01, d11) = (e0.dot(&e0), e0.dot(&e1), e1.dot(&e1));
    let (d20, d21) = (e2.dot(&e0), e2.dot(&e1));
    let den = d00 * d11 - d01 * d01;
    if den.abs() < 1e-300 {
        return [1.0, 0.0, 0.0];
    }
    let v = ((d11 * d20 - d01 * d21) / den).clamp(0.0, 1.0);
    let w = ((d00 * d21 - d01 * d20) / den).clamp(0.0, 1.0 - v);
    [1.0 - v - w, v, w]
}

fn signed_volume(p: &[Vec3], tris: &[[usize; 3]]) -> f64 {
    tris.iter()
        .map(|t| p[t[0]].dot(&p[t[1]].cross(&p[t[2]])))
        .sum::<f64>()
        / 6.0
}
