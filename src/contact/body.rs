//! Collision bodies: analytic sphere, axis-aligned box and plane, and triangle meshes (static or
//! animated), each with its own static and kinetic friction. A body answers one question: how
//! far is a point from its surface (signed, negative inside), along which outward normal, and
//! how fast the surface moves there.

use serde::{Deserialize, Serialize};

use super::mesh_body::MeshBody;
use super::proximity::Proximity;
use super::ContactError;
use crate::geometry::Vec3;

/// Coulomb friction coefficients of a surface.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrictionCoefficients {
    /// Static coefficient μs: a sliding contact sticks when the tangential impulse needed to
    /// stop it is at most μs times the normal impulse (`mu_static` in files and scripts).
    #[serde(rename = "mu_static")]
    pub static_: f64,
    /// Kinetic coefficient μk: a sliding contact loses μk times the normal impulse
    /// (`mu_kinetic` in files and scripts).
    #[serde(rename = "mu_kinetic")]
    pub kinetic: f64,
}

impl Default for FrictionCoefficients {
    fn default() -> Self {
        FrictionCoefficients {
            static_: 0.5,
            kinetic: 0.4,
        }
    }
}

impl FrictionCoefficients {
    /// Checks both coefficients are finite and ≥ 0, naming `what` in the error.
    pub fn validate(&self, what: &str) -> Result<(), ContactError> {
        for (name, v) in [("static", self.static_), ("kinetic", self.kinetic)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ContactError::Parameter(format!(
                    "{what}: {name} friction coefficient must be finite and >= 0, got {v}"
                )));
            }
        }
        Ok(())
    }

    /// The coefficients of a contact between two surfaces: the mean of each (as PhysX's
    /// default "average" combine rule).
    pub fn combine(&self, other: &FrictionCoefficients) -> FrictionCoefficients {
        FrictionCoefficients {
            static_: 0.5 * (self.static_ + other.static_),
            kinetic: 0.5 * (self.kinetic + other.kinetic),
        }
    }
}

/// The geometry of a body.
#[derive(Debug, Clone)]
pub enum Shape {
    /// A solid ball.
    Sphere {
        /// Centre (m).
        center: Vec3,
        /// Radius (m).
        radius: f64,
    },
    /// A solid axis-aligned box.
    Cuboid {
        /// Centre (m).
        center: Vec3,
        /// Half extents along x, y, z (m).
        half: Vec3,
    },
    /// The half-space below a plane: solid where (p − point)·normal < 0.
    Plane {
        /// A point of the plane (m).
        point: Vec3,
        /// Outward unit normal.
        normal: Vec3,
    },
    /// A triangle mesh (closed meshes have an inside; open ones a front and a back).
    Mesh(Box<MeshBody>),
}

/// A collision body: a shape with friction and a name for messages.
#[derive(Debug, Clone)]
pub struct Body {
    /// Name used in messages and statistics.
    pub name: String,
    /// Geometry.
    pub shape: Shape,
    /// Friction of its surface.
    pub friction: FrictionCoefficients,
}

impl Body {
    /// A solid sphere.
    pub fn sphere(center: Vec3, radius: f64) -> Result<Body, ContactError> {
        if !(radius.is_finite() && radius > 0.0 && finite(&center)) {
            return Err(ContactError::Parameter(format!(
                "sphere: radius must be > 0 and the centre finite, got radius {radius}, centre {:?}",
                center.as_slice()
            )));
        }
        Ok(Body::new("sphere", Shape::Sphere { center, radius }))
    }

    /// A solid axis-aligned box from its centre and full size.
    pub fn cuboid(center: Vec3, size: Vec3) -> Result<Body, ContactError> {
        if !finite(&center) || !size.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(ContactError::Parameter(format!(
                "box: size must be > 0 and finite, centre finite; got size {:?}, centre {:?}",
                size.as_slice(),
                center.as_slice()
            )));
        }
        Ok(Body::new(
            "box",
            Shape::Cuboid {
                center,
                half: size * 0.5,
            },
        ))
    }

    /// The solid half-space below the plane through `point` with outward `normal`.
    pub fn plane(point: Vec3, normal: Vec3) -> Result<Body, ContactError> {
        let n = normal.norm();
        if !(finite(&point) && n.is_finite() && n > 1e-12) {
            return Err(ContactError::Parameter(format!(
                "plane: the point must be finite and the normal finite and non-zero, got point {:?}, normal {:?}",
                point.as_slice(),
                normal.as_slice()
            )));
        }
        Ok(Body::new(
            "plane",
            Shape::Plane {
                point,
                normal: normal / n,
            },
        ))
    }

    /// A solid closed cylinder of `radius` and `length` centred at `center` along `axis`,
    /// as a triangle mesh of `segments` facets around (flat caps).
    pub fn cylinder(
        center: Vec3,
        axis: Vec3,
        radius: f64,
        length: f64,
        segments: usize,
    ) -> Result<Body, ContactError> {
        let a = axis.norm();
        if !(finite(&center)
            && a.is_finite()
            && a > 1e-12
            && radius.is_finite()
            && radius > 0.0
            && length.is_finite()
            && length > 0.0
            && segments >= 3)
        {
            return Err(ContactError::Parameter(format!(
                "cylinder: radius and length must be > 0, the axis non-zero, the centre finite and at least 3 segments; got radius {radius}, length {length}, axis {:?}, centre {:?}, {segments} segments",
                axis.as_slice(),
                center.as_slice()
            )));
        }
        let w = axis / a;
        let u = if w.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        let u = (u - w * w.dot(&u)).normalize();
        let v = w.cross(&u);
        let mut p = Vec::with_capacity(2 * segments + 2);
        for end in [-0.5, 0.5] {
            for k in 0..segments {
                let t = std::f64::consts::TAU * k as f64 / segments as f64;
                p.push(center + w * (end * length) + (u * t.cos() + v * t.sin()) * radius);
            }
        }
        let (c0, c1) = (p.len(), p.len() + 1);
        p.push(center - w * (0.5 * length));
        p.push(center + w * (0.5 * length));
        let mut t = Vec::with_capacity(4 * segments);
        for k in 0..segments {
            let k1 = (k + 1) % segments;
            // outward: counter-clockwise seen from outside
            t.push([k, k1, segments + k1]);
            t.push([k, segments + k1, segments + k]);
            t.push([c0, k1, k]);
            t.push([c1, segments + k, segments + k1]);
        }
        Ok(Body::mesh(MeshBody::new("cylinder", p, &t)?))
    }

    /// A body of a triangle mesh.
    pub fn mesh(mesh: MeshBody) -> Body {
        let name = mesh.name.clone();
        Body::new(&name, Shape::Mesh(Box::new(mesh)))
    }

    fn new(name: &str, shape: Shape) -> Body {
        Body {
            name: name.to_string(),
            shape,
            friction: FrictionCoefficients::default(),
        }
    }

    /// Moves an animated body to time `t` (its surface velocity becomes the mean over the
    /// last move of length `dt`). Static bodies ignore it.
    pub fn advance_to(&mut self, t: f64, dt: f64) {
        if let Shape::Mesh(m) = &mut self.shape {
            m.advance_to(t, dt);
        }
    }

    /// The axis-aligned bounds of the body (infinite for a plane).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match &self.shape {
            Shape::Sphere { center, radius } => {
                let r = Vec3::repeat(*radius);
                (center - r, center + r)
            }
            Shape::Cuboid { center, half } => (center - half, center + half),
            Shape::Plane { .. } => (Vec3::repeat(f64::NEG_INFINITY), Vec3::repeat(f64::INFINITY)),
            Shape::Mesh(m) => m.bounds(),
        }
    }

    /// Signed distance, normal and surface velocity at the point of the surface closest to
    /// `p`, when `p` is inside the body or less than `max_dist` from it; `None` otherwise.
    pub fn proximity(&self, p: &Vec3, max_dist: f64) -> Option<Proximity> {
        let still = |distance: f64, normal: Vec3| {
            (distance < max_dist).then_some(Proximity {
                distance,
                normal,
                velocity: Vec3::zeros(),
            })
        };
        match &self.shape {
            Shape::Sphere { center, radius } => {
                let d = p - center;
                let r = d.norm();
                let n = if r > 1e-300 { d / r } else { Vec3::z() };
                still(r - radius, n)
            }
            Shape::Plane { point, normal } => still((p - point).dot(normal), *normal),
            Shape::Cuboid { center, half } => {
                let (distance, normal) = box_distance(&(p - center), half);
                still(distance, normal)
            }
            Shape::Mesh(m) => m.proximity(p, max_dist),
        }
    }

    /// Signed distance from `p` to the surface, exact for every shape (negative inside).
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.proximity(p, f64::INFINITY)
            .map_or(f64::INFINITY, |q| q.distance)
    }
}

/// Signed distance and outward normal of point `q` (relative to the centre) to an
/// axis-aligned box of half extents `h`.
fn box_distance(q: &Vec3, h: &Vec3) -> (f64, Vec3) {
    let d = q.abs() - h;
    let outside = Vec3::new(d.x.max(0.0), d.y.max(0.0), d.z.max(0.0));
    let out_len = outside.norm();
    if out_len > 0.0 {
        let n = Vec3::new(
            outside.x * q.x.signum(),
            outside.y * q.y.signum(),
            outside.z * q.z.signum(),
        ) / out_len;
        return (out_len, n);
    }
    // inside: the nearest face
    let k = if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    };
    let mut n = Vec3::zeros();
    n[k] = if q[k] >= 0.0 { 1.0 } else { -1.0 };
    (d[k], n)
}

fn finite(v: &Vec3) -> bool {
    v.iter().all(|c| c.is_finite())
}
