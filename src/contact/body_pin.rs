//! `BodyPin`: a cloth particle that follows a point of a (possibly animated) mesh body's
//! surface at a fixed offset turning with the surface normal (a waistband on a character).

use super::body::{Body, Shape};
use super::mesh_body::MeshBody;
use super::primitives::closest_point_triangle;
use super::ContactError;
use crate::geometry::Vec3;

/// A cloth particle held at a fixed offset from a mesh body's vertex, the offset turning with
/// the vertex normal, so that it follows the (animated) body: a waistband on a character.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPin {
    /// The body (a mesh).
    pub body: usize,
    /// The cloth particle.
    pub particle: usize,
    /// The body surface point it follows: a triangle's vertices and barycentric weights.
    pub vertices: [usize; 3],
    /// Barycentric weights of the point in that triangle.
    pub weights: [f64; 3],
    /// Offset from the surface point when pinned (m).
    pub offset: Vec3,
    /// The surface normal there when pinned.
    pub normal: Vec3,
    /// Optional snap onto the body: the offset eases to `gap` along the normal between
    /// times `from` and `to` (s): (gap, from, to).
    pub snap: Option<(f64, f64, f64)>,
}

impl BodyPin {
    /// The followed surface point and its unit normal (vertex normals interpolated) on `m`'s
    /// current surface.
    pub fn anchor(&self, m: &MeshBody) -> (Vec3, Vec3) {
        let (mut p, mut n) = (Vec3::zeros(), Vec3::zeros());
        for (&v, &w) in self.vertices.iter().zip(&self.weights) {
            p += m.positions()[v] * w;
            n += m.vertex_normal(v) * w;
        }
        (p, n / n.norm().max(1e-300))
    }

    /// Where the particle goes at time `t` when the surface point is at `p` with unit normal
    /// `n`.
    pub fn target(&self, p: &Vec3, n: &Vec3, t: f64) -> Vec3 {
        let turn = nalgebra::Rotation3::rotation_between(&self.normal, n)
            .unwrap_or_else(nalgebra::Rotation3::identity);
        let offset = match self.snap {
            Some((gap, from, to)) => {
                let s = if to > from {
                    ((t - from) / (to - from)).clamp(0.0, 1.0)
                } else if t >= to {
                    1.0
                } else {
                    0.0
                };
                let w = s * s * (3.0 - 2.0 * s);
                self.offset * (1.0 - w) + self.normal * (gap * w)
            }
            None => self.offset,
        };
        p + turn * offset
    }
}

impl BodyPin {
    /// The mesh of body `body` of `bodies`, which pins may follow, and its name, once `snap`
    /// (see `Collisions::pin_to_body`) is checked.
    pub fn mesh_of(
        bodies: &[Body],
        body: usize,
        snap: Option<(f64, f64, f64)>,
    ) -> Result<(&MeshBody, &str), ContactError> {
        if let Some((gap, from, to)) = snap {
            if !(gap.is_finite() && gap >= 0.0 && from.is_finite() && to.is_finite() && to >= from)
            {
                return Err(ContactError::Parameter(format!(
                    "pin_to_body: snap needs gap >= 0 and from <= to, got gap {gap}, from {from}, to {to}"
                )));
            }
        }
        let Some(b) = bodies.get(body) else {
            return Err(ContactError::Parameter(format!(
                "body {body} does not exist ({} bodies)",
                bodies.len()
            )));
        };
        let Shape::Mesh(m) = &b.shape else {
            return Err(ContactError::Parameter(format!(
                "body {body} (`{}`) is not a mesh: only mesh bodies carry pins",
                b.name
            )));
        };
        Ok((m, &b.name))
    }

    /// The pin of particle `p` (at `x[p]`) to mesh `m` (body `body`, named `name`): it follows
    /// the point of the surface nearest to it in the rest pose, keeping its present offset.
    pub fn new(
        (m, name): (&MeshBody, &str),
        body: usize,
        p: usize,
        x: &[Vec3],
        snap: Option<(f64, f64, f64)>,
    ) -> Result<BodyPin, ContactError> {
        let Some(xp) = x.get(p) else {
            return Err(ContactError::Parameter(format!(
                "particle {p} out of range (cloth has {})",
                x.len()
            )));
        };
        let rest = m.rest_positions();
        let (tri, weights, _) = m
            .triangles()
            .iter()
            .map(|t| {
                let (q, w) = closest_point_triangle(*xp, rest[t[0]], rest[t[1]], rest[t[2]]);
                (*t, w, (q - xp).norm_squared())
            })
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .ok_or_else(|| {
                ContactError::Parameter(format!("body {body} (`{name}`) has no triangles"))
            })?;
        let mut pin = BodyPin {
            body,
            particle: p,
            vertices: tri,
            weights,
            offset: Vec3::zeros(),
            normal: Vec3::zeros(),
            snap,
        };
        let (at, normal) = pin.anchor(m);
        pin.offset = xp - at;
        pin.normal = normal;
        Ok(pin)
    }
}
