//! Grading a mannequin to a size: the MakeHuman body scaled by a girth factor across (x and y,
//! about the vertical axis through the skin's mean point) and a height factor up (z, from the
//! floor, so the feet stay on z = 0). Skin, helper vertices and skeleton move together, so the
//! skinning weights and motions still fit. The matching pattern is graded by
//! `garment::Pattern::graded`; guide: docs/sweeps.md (grading).

use super::{BodyError, Mannequin};
use crate::geometry::Vec3;

/// The smallest and largest grading factor accepted (a size, not a different body).
pub const GRADE_RANGE: [f64; 2] = [0.5, 2.0];

/// Checks a grading factor: finite and within [`GRADE_RANGE`].
pub fn check_grade(name: &str, value: f64) -> Result<(), String> {
    if value.is_finite() && (GRADE_RANGE[0]..=GRADE_RANGE[1]).contains(&value) {
        Ok(())
    } else {
        Err(format!(
            "grading factor `{name}` = {value} is not within {} to {}",
            GRADE_RANGE[0], GRADE_RANGE[1]
        ))
    }
}

impl Mannequin {
    /// This mannequin graded to another size: x and y scaled by `girth` about the vertical
    /// axis through the skin's mean point, z by `height` from the floor. An error names a
    /// factor outside [`GRADE_RANGE`] (or NaN).
    pub fn graded(&self, girth: f64, height: f64) -> Result<Mannequin, BodyError> {
        for (name, v) in [("girth", girth), ("height", height)] {
            check_grade(name, v).map_err(|m| BodyError::invalid("mannequin grading", m))?;
        }
        let n = self.rest.len().max(1) as f64;
        let centre = self.rest.iter().fold(Vec3::zeros(), |a, p| a + p) / n;
        let map = |p: Vec3| {
            Vec3::new(
                centre.x + (p.x - centre.x) * girth,
                centre.y + (p.y - centre.y) * girth,
                p.z * height,
            )
        };
        let mut m = self.clone();
        for p in m.rest.iter_mut().chain(m.base_rest.iter_mut()) {
            *p = map(*p);
        }
        m.skeleton.map_points(map);
        Ok(m)
    }

    /// This mannequin with its skin at `rest` instead (another person's rest skin, one
    /// position per skin vertex, e.g. a reshaped puppet's), the skeleton and helper vertices
    /// kept: a body to dress at rest, not to animate with this mannequin's skeleton. An error
    /// names a wrong vertex count or a non-finite position.
    pub fn with_rest_skin(&self, rest: &[Vec3]) -> Result<Mannequin, BodyError> {
        if rest.len() != self.rest.len() {
            return Err(BodyError::invalid(
                "mannequin skin",
                format!(
                    "{} positions given, the skin has {}",
                    rest.len(),
                    self.rest.len()
                ),
            ));
        }
        if let Some(i) = rest.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(BodyError::invalid(
                "mannequin skin",
                format!("position {i} is not finite"),
            ));
        }
        let mut m = self.clone();
        m.rest.copy_from_slice(rest);
        Ok(m)
    }
}
