//! The figurines of pre-positioning: the front and back planes of the body on which each
//! piece is laid flat, grain vertical, its placement's anchor corner at a horizontal offset
//! and a landmark height. A [`Figurine`] maps a flat pattern point to `(X, height)` on its
//! side's plane; [`s_of`] turns that `X` into the left coordinate shared by both sides.

use super::silhouette::Landmarks;
use crate::garment::mesh::GarmentMesh;
use crate::garment::{Pattern, PatternError, Side, P2};

/// The figurine (front or back view) transform of a piece: flat point ↦ (X, height).
pub(super) struct Figurine {
    pub(super) side: Side,
    rot: [f64; 4],
    anchor: P2,
    pub(super) at: P2,
}

impl Figurine {
    /// The figurine point `(X, height)` of the flat pattern point `p`.
    pub(super) fn apply(&self, p: &P2) -> P2 {
        let (x, y) = (p[0] - self.anchor[0], p[1] - self.anchor[1]);
        let r = &self.rot;
        [
            self.at[0] + r[0] * x + r[1] * y,
            self.at[1] + r[2] * x + r[3] * y,
        ]
    }
}

/// Each piece's figurine transform from its placement.
pub(super) fn figurines(
    pattern: &Pattern,
    garment: &GarmentMesh,
    marks: &Landmarks,
) -> Result<Vec<Figurine>, PatternError> {
    garment
        .pieces
        .iter()
        .map(|pm| {
            let err = |message: String| PatternError::Piece {
                source_name: pattern.source.clone(),
                piece: pm.name.clone(),
                message,
            };
            let piece = pattern
                .pieces
                .iter()
                .find(|p| p.name == pm.name)
                .ok_or_else(|| err("not in the pattern".into()))?;
            let pl = piece
                .placement
                .as_ref()
                .ok_or_else(|| err("has no placement: pre-positioning needs one".into()))?;
            let level = marks.get(&pl.level).ok_or_else(|| {
                err(format!(
                    "placement level '{}' is not a landmark (neck, shoulder, chest, armpit, waist, hip, crotch, knee, ankle)",
                    pl.level
                ))
            })?;
            let anchor = pm
                .corners
                .iter()
                .find(|(name, _)| *name == pl.anchor)
                .map(|&(_, v)| garment.flat[v])
                .ok_or_else(|| err(format!("placement anchor corner '{}' not found", pl.anchor)))?;
            let g = [
                piece.grain[1][0] - piece.grain[0][0],
                piece.grain[1][1] - piece.grain[0][1],
            ];
            // the smallest turn that makes the grain vertical
            let mut phi = std::f64::consts::FRAC_PI_2 - g[1].atan2(g[0]);
            while phi > std::f64::consts::FRAC_PI_2 {
                phi -= std::f64::consts::PI;
            }
            while phi <= -std::f64::consts::FRAC_PI_2 {
                phi += std::f64::consts::PI;
            }
            let (c, s) = (phi.cos(), phi.sin());
            Ok(Figurine {
                side: pl.side,
                rot: [c, -s, s, c],
                anchor,
                at: [pl.x, level + pl.dz],
            })
        })
        .collect()
}

/// Left coordinate of a figurine X on a side.
#[inline]
pub(super) fn s_of(side: Side, x: f64) -> f64 {
    match side {
        Side::Front => x,
        Side::Back => -x,
    }
}
