//! A truncated cone of cloth cut from its exact flat pattern: a cone is developable, so it
//! unrolls into an annular sector, and the mesh's rest coordinates are that sector. Used for
//! A-line skirts and lampshade-like tubes.

use super::{GeometryError, TriMesh, Vec3};

/// A truncated cone around the vertical axis through `base` (the centre of its lower rim):
/// radius `r_bottom` at `base.z`, `r_top` at `base.z + height`, `n_around` × `n_down` vertices
/// (vertex `(i, j)` — row `i` from the bottom rim up, column `j` around — has index
/// `i * n_around + j`, so the last row is the top rim). The pattern is the annular sector that
/// rolls up exactly into this cone, minus a slit of `slit` (fraction of the circumference,
/// 0 ≤ slit < 1) at the back (+y); the front is at −y. More than
/// `limits::get().max_particles` vertices is an error.
pub fn cone_mesh(
    r_top: f64,
    r_bottom: f64,
    height: f64,
    n_around: usize,
    n_down: usize,
    base: Vec3,
    slit: f64,
) -> Result<TriMesh, GeometryError> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    if !(ok(r_top) && ok(r_bottom) && ok(height) && base.iter().all(|c| c.is_finite())) {
        return Err(GeometryError::Invalid(format!(
            "cone: radii and height must be positive and finite, got r_top {r_top}, r_bottom {r_bottom}, height {height}"
        )));
    }
    if !(0.0..1.0).contains(&slit) {
        return Err(GeometryError::Invalid(format!(
            "cone: slit must be in [0, 1), got {slit}"
        )));
    }
    if n_around < 3 || n_down < 2 {
        return Err(GeometryError::Invalid(format!(
            "cone needs at least 3 × 2 vertices, got {n_around} × {n_down}"
        )));
    }
    super::grid::check_lattice("cone n_around × n_down", n_around, n_down)?;
    let slant = ((r_bottom - r_top).powi(2) + height * height).sqrt();
    let mut positions = Vec::with_capacity(n_around * n_down);
    let mut rest = Vec::with_capacity(n_around * n_down);
    // a cylinder unrolls into a rectangle; a cone into a sector of radii rho_top..rho_bottom
    let flare = (r_bottom - r_top) / slant; // sin of the half-angle
    let span = 1.0 - slit;
    for i in 0..n_down {
        let s = i as f64 / (n_down - 1) as f64; // 0 at the bottom rim
        let r = r_bottom + (r_top - r_bottom) * s;
        let z = base.z + height * s;
        let along = slant * (1.0 - s); // slant distance from the top rim
        for j in 0..n_around {
            let u = (j as f64 / (n_around - 1) as f64 - 0.5) * span; // fraction of the turn
            let phi = 2.0 * std::f64::consts::PI * u;
            positions.push(Vec3::new(base.x + r * phi.sin(), base.y - r * phi.cos(), z));
            if flare.abs() < 1e-9 {
                // a cylinder: the rectangle
                rest.push([2.0 * std::f64::consts::PI * r_top * u, slant - along]);
            } else {
                let rho0 = r_top / flare; // apex to the top rim, along the slant
                let rho = rho0 + along;
                let theta = phi * flare;
                rest.push([rho * theta.sin(), -rho * theta.cos()]);
            }
        }
    }
    let triangles = super::grid::grid_triangles(n_around, n_down);
    Ok(TriMesh {
        positions,
        rest,
        triangles,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every edge's 3D length equals its pattern length: the cone is the rolled-up sector.
    #[test]
    fn pattern_rolls_up_without_stretch() {
        for (rt, rb) in [(0.16, 0.26), (0.2, 0.2), (0.3, 0.1)] {
            let m = cone_mesh(rt, rb, 0.5, 40, 12, Vec3::new(0.1, -0.2, 0.5), 0.07).unwrap();
            let mut worst: f64 = 0.0;
            for t in &m.triangles {
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let l3 = (m.positions[a] - m.positions[b]).norm();
                    let (p, q) = (m.rest[a], m.rest[b]);
                    let l2 = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
                    // chords of the same arc: equal up to the chord/arc difference per edge
                    worst = worst.max((l3 - l2).abs() / l2);
                }
            }
            assert!(worst < 2e-3, "cone {rt}/{rb}: edge length mismatch {worst}");
        }
    }
}
