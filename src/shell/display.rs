//! The shell's triangulated display surface: the deformed mid-surface x = X + u evaluated on a
//! regular grid of the parameter rectangle (independent of where the sample points lie), two
//! triangles per grid cell. It is what renders, exports and measures (shadow areas) see.

use super::discretisation::Discretisation;
use super::error::ShellError;

/// Positions and triangles of a display surface.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DisplaySurface {
    /// Grid points, ξ¹ fastest (m).
    pub positions: Vec<[f64; 3]>,
    /// Triangles (indices into `positions`), counter-clockwise seen from the rest normal.
    pub triangles: Vec<[usize; 3]>,
    /// Grid points per side (along ξ¹, along ξ²).
    pub size: [usize; 2],
}

impl DisplaySurface {
    /// The deformed surface of `u` on `m1` × `m2` grid points (2 to 4096 each).
    pub fn new(
        disc: &Discretisation,
        u: &[f64],
        m1: usize,
        m2: usize,
    ) -> Result<DisplaySurface, ShellError> {
        if !(2..=4096).contains(&m1) || !(2..=4096).contains(&m2) {
            return Err(ShellError::Invalid(format!(
                "display grid needs 2 to 4096 points per side, got {m1} × {m2}"
            )));
        }
        if u.len() != 3 * disc.len() {
            return Err(ShellError::Invalid(format!(
                "displacements: expected {} values (3 per sample point), got {}",
                3 * disc.len(),
                u.len()
            )));
        }
        let d = disc.problem.domain;
        let mut positions = Vec::with_capacity(m1 * m2);
        for j in 0..m2 {
            for i in 0..m1 {
                let xi = [
                    d[0] + (d[1] - d[0]) * i as f64 / (m1 - 1) as f64,
                    d[2] + (d[3] - d[2]) * j as f64 / (m2 - 1) as f64,
                ];
                let x = disc.problem.surface.at(xi).x + disc.displacement_at(xi, u)?;
                positions.push([x.x, x.y, x.z]);
            }
        }
        let mut triangles = Vec::with_capacity(2 * (m1 - 1) * (m2 - 1));
        for j in 0..m2 - 1 {
            for i in 0..m1 - 1 {
                let a = j * m1 + i;
                triangles.push([a, a + 1, a + m1 + 1]);
                triangles.push([a, a + m1 + 1, a + m1]);
            }
        }
        Ok(DisplaySurface {
            positions,
            triangles,
            size: [m1, m2],
        })
    }
}
