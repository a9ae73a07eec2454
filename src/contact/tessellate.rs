//! Triangle meshes of bodies for pictures: spheres as UV spheres, boxes as 12 triangles,
//! planes as a square patch around the region of interest, meshes as themselves.

use super::body::{Body, Shape};
use crate::geometry::Vec3;

/// Triangles and vertices of a body drawn in a scene whose interesting part lies in the box
/// `(lo, hi)` (used to size planes).
pub fn body_mesh(body: &Body, lo: &Vec3, hi: &Vec3) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    match &body.shape {
        Shape::Sphere { center, radius } => uv_sphere(center, *radius, 48, 24),
        Shape::Cuboid { center, half } => cuboid(center, half),
        Shape::Plane { point, normal } => plane(point, normal, lo, hi),
        Shape::Mesh(m) => (m.positions().to_vec(), m.triangles().to_vec()),
    }
}

fn uv_sphere(c: &Vec3, r: f64, nu: usize, nv: usize) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    use std::f64::consts::PI;
    let mut p = Vec::with_capacity(nu * (nv + 1));
    for j in 0..=nv {
        let th = PI * j as f64 / nv as f64;
        for i in 0..nu {
            let ph = 2.0 * PI * i as f64 / nu as f64;
            p.push(c + Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * r);
        }
    }
    let mut t = Vec::with_capacity(2 * nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let (a, b) = (j * nu + i, j * nu + (i + 1) % nu);
            t.push([a, a + nu, b]);
            t.push([b, a + nu, b + nu]);
        }
    }
    (p, t)
}

fn cuboid(c: &Vec3, h: &Vec3) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let p: Vec<Vec3> = (0..8)
        .map(|k| {
            let s = |b: usize| if k & b != 0 { 1.0 } else { -1.0 };
            c + Vec3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (p, t)
}

fn plane(point: &Vec3, n: &Vec3, lo: &Vec3, hi: &Vec3) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let size = (hi - lo).norm().clamp(0.5, 1e3) * 1.5;
    let centre = (lo + hi) * 0.5;
    let c = centre - n * (centre - point).dot(n);
    let helper = if n.z.abs() < 0.9 {
        Vec3::z()
    } else {
        Vec3::x()
    };
    let u = n.cross(&helper).normalize() * size;
    let v = n.cross(&u);
    let p = vec![c - u - v, c + u - v, c + u + v, c - u + v];
    (p, vec![[0, 1, 2], [0, 2, 3]])
}
