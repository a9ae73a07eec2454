//! Grading a pattern to a size: every piece scaled by a girth factor across (x) and a height
//! factor along (y, the pieces being drawn upright), with its corners, curve control points,
//! grain line and notches, and its placement on the body (the anchor's offset across by the
//! girth, the height offset by the height). Seam allowances stay (they are sewing, not size).
//! The matching mannequin is `body::Mannequin::graded`; guide: docs/sweeps.md (grading).
//!
//! With `girth == height` the grading is a similarity and seams that matched still match;
//! otherwise edges at different angles stretch differently, and the graded pattern is
//! validated again, so a seam whose two edges no longer match is an error that names it.

use super::pattern::{Pattern, P2};
use super::PatternError;
use crate::body::grading::check_grade;

impl Pattern {
    /// This pattern graded by `girth` across and `height` along every piece (see the module
    /// doc); the result is validated. An error names a factor outside
    /// `body::grading::GRADE_RANGE` or a seam the grading unmatched.
    pub fn graded(&self, girth: f64, height: f64) -> Result<Pattern, PatternError> {
        for (name, v) in [("girth", girth), ("height", height)] {
            check_grade(name, v).map_err(PatternError::Parameter)?;
        }
        let f = |p: P2| [p[0] * girth, p[1] * height];
        let mut g = self.clone();
        for piece in &mut g.pieces {
            for c in &mut piece.outline.corners {
                c.at = f(c.at);
                c.segment = c.segment.mapped(f);
            }
            piece.grain = [f(piece.grain[0]), f(piece.grain[1])];
            for n in &mut piece.notches {
                *n = f(*n);
            }
            if let Some(pl) = &mut piece.placement {
                pl.x *= girth;
                pl.dz *= height;
            }
        }
        g.validate()?;
        Ok(g)
    }
}
