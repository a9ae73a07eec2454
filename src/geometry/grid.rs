//! Rectangular grid generator: the standard test cloth, flat in the XY plane.

use super::{GeometryError, TriMesh, Vec3};
use crate::limits;

/// Checks that an `a` × `b` lattice of vertices (`what` names the generator and its counts)
/// stays within the limit `max_particles`, before anything is allocated.
pub(crate) fn check_lattice(what: &str, a: usize, b: usize) -> Result<(), GeometryError> {
    let max = limits::get().max_particles;
    let n = (a as f64) * (b as f64);
    limits::check(
        &format!("{what} = {a} × {b} vertices"),
        n,
        "max_particles",
        max,
    )
    .map(|_| ())
    .map_err(|e| GeometryError::Invalid(e.to_string()))
}

/// A `width` × `height` metre rectangle of `nx` × `ny` vertices, flat in the XY plane at z = 0,
/// centred at the origin. Vertex `(i, j)` (row `i` along y, column `j` along x) has index
/// `i * nx + j`; rest coordinates are (x, y) with u = x (warp) and v = y (weft). Each quad is
/// split into two triangles along alternating diagonals, so the mesh has no preferred shear direction.
/// More than `limits::get().max_particles` vertices is an error.
pub fn grid_mesh(width: f64, height: f64, nx: usize, ny: usize) -> Result<TriMesh, GeometryError> {
    if !(width.is_finite() && width > 0.0 && height.is_finite() && height > 0.0) {
        return Err(GeometryError::Invalid(format!(
            "grid size must be positive and finite, got {width} × {height}"
        )));
    }
    if nx < 2 || ny < 2 {
        return Err(GeometryError::Invalid(format!(
            "grid needs at least 2 × 2 vertices, got {nx} × {ny}"
        )));
    }
    check_lattice("grid nx × ny", nx, ny)?;
    let mut positions = Vec::with_capacity(nx * ny);
    let mut rest = Vec::with_capacity(nx * ny);
    for i in 0..ny {
        for j in 0..nx {
            let x = -0.5 * width + width * j as f64 / (nx - 1) as f64;
            let y = -0.5 * height + height * i as f64 / (ny - 1) as f64;
            positions.push(Vec3::new(x, y, 0.0));
            rest.push([x + 0.5 * width, y + 0.5 * height]);
        }
    }
    let triangles = grid_triangles(nx, ny);
    Ok(TriMesh {
        positions,
        rest,
        triangles,
    })
}

/// Triangles of an `nx` × `ny` vertex grid (vertex `(i, j)` at `i * nx + j`), each quad split
/// along alternating diagonals so the mesh has no preferred shear direction.
pub fn grid_triangles(nx: usize, ny: usize) -> Vec<[usize; 3]> {
    let mut triangles = Vec::with_capacity(2 * (nx - 1) * (ny - 1));
    for i in 0..ny - 1 {
        for j in 0..nx - 1 {
            let a = i * nx + j;
            let (b, c, d) = (a + 1, a + 1 + nx, a + nx);
            if (i + j) % 2 == 0 {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    triangles
}
