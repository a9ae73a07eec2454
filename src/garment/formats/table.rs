//! Garment tables: a small JSON file that turns the parts of an SVG pattern (FreeSewing or
//! generic) into a garment: which parts are used, how each is cut and placed, and the seams.
//!
//! ```json
//! {
//!   "name": "aaron",
//!   "svg": "aaron.svg",
//!   "pieces": [
//!     { "part": "front", "fold": "c0", "copies": "one",
//!       "placement": { "side": "front", "anchor": "c0", "x": 0.0, "level": "neck", "dz": 0.0 } },
//!     { "part": "back", "placement": { "side": "back", "anchor": "c0", "level": "neck" } }
//!   ],
//!   "seams": [
//!     { "name": "side_left",
//!       "a": { "piece": "front", "from": "c2", "to": "c3" },
//!       "b": { "piece": "back", "from": "c2'", "to": "c3'" } }
//!   ]
//! }
//! ```
//!
//! * `svg`: the pattern file, relative to the table's folder; `svg_metres_per_unit`
//!   (optional) overrides its units.
//! * `pieces[]`: the parts used (others are left out), in this order. `part`: the SVG piece
//!   name (a FreeSewing part name, or a group id); `name` (optional) renames it. `fold`:
//!   absent = as the SVG marks it (FreeSewing's cut-on-fold marker), a corner name = that
//!   corner's segment is the fold, `null` = not cut on the fold. `copies`: `one` (default) or
//!   `pair`. `placement`: see [`Placement`]. `seam_allowance`
//!   (optional, m) overrides the one read from the SVG.
//! * `seams[]`: as in the JSON pattern format ([`super::json`]), naming pieces and corners
//!   after expansion (`P_l`/`P_r` for pairs, `c3'` for mirrored corners of a folded piece).
//!
//! Unknown fields are errors, so that a misspelt key does not pass silently.

use std::path::Path;

use serde::{Deserialize, Deserializer, Serialize};

use super::json::json_error;
use super::svg::{parse_pattern_svg, SvgOptions};
use crate::garment::error::PatternError;
use crate::garment::pattern::{Copies, Pattern, Placement, Seam};

/// One used part of the SVG.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartUse {
    /// The piece's name in the SVG.
    pub part: String,
    /// The piece's name in the garment (default: `part`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The fold: `None` (absent) as the SVG marks it, `Some(None)` not folded, `Some(Some(c))`
    /// folded along corner `c`'s segment.
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub fold: Option<Option<String>>,
    /// One piece or a mirrored pair.
    #[serde(default)]
    pub copies: Copies,
    /// Where the piece goes on the body.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<Placement>,
    /// Seam allowance (m), overriding the SVG's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seam_allowance: Option<f64>,
}

/// A garment table (see the module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GarmentTable {
    /// The garment's name.
    pub name: String,
    /// The SVG pattern, relative to the table's folder.
    pub svg: String,
    /// Metres per SVG user unit, overriding the file's own units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub svg_metres_per_unit: Option<f64>,
    /// The parts used.
    pub pieces: Vec<PartUse>,
    /// The seams, between expanded pieces.
    #[serde(default)]
    pub seams: Vec<Seam>,
}

/// Distinguishes a field that is present (even `null`) from an absent one.
fn present<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Option<String>>, D::Error> {
    Option::<String>::deserialize(d).map(Some)
}

/// Reads a garment table, loads the SVG it names, applies the table (parts, folds, copies,
/// placements, seams), validates, and returns the expanded pattern. Its `source` names the
/// table and the SVG.
pub fn read_garment(path: impl AsRef<Path>) -> Result<Pattern, PatternError> {
    let path = path.as_ref();
    let text = crate::limits::read_to_string(path).map_err(|source| PatternError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let table: GarmentTable = serde_json::from_str(&text).map_err(|e| json_error(path, &e))?;
    let svg_path = path.parent().unwrap_or(Path::new("")).join(&table.svg);
    let options = SvgOptions {
        metres_per_unit: table.svg_metres_per_unit,
        ..SvgOptions::default()
    };
    let svg_text = crate::limits::read_to_string(&svg_path).map_err(|source| PatternError::Io {
        path: svg_path.clone(),
        source,
    })?;
    let drawn = parse_pattern_svg(&svg_text, &svg_path, &options)?;
    let pattern = apply_table(
        &table,
        &drawn,
        &format!("{} (svg {})", path.display(), svg_path.display()),
    )?;
    pattern.validate()?;
    pattern.expanded()
}

/// Builds the garment from the parts of `drawn` that `table` uses; `source` names both files.
pub fn apply_table(
    table: &GarmentTable,
    drawn: &Pattern,
    source: &str,
) -> Result<Pattern, PatternError> {
    let mut pieces = Vec::with_capacity(table.pieces.len());
    for u in &table.pieces {
        let found = drawn
            .pieces
            .iter()
            .find(|p| p.name == u.part)
            .ok_or_else(|| {
                let parts: Vec<&str> = drawn.pieces.iter().map(|p| p.name.as_str()).collect();
                PatternError::Piece {
                    source_name: source.to_string(),
                    piece: u.part.clone(),
                    message: format!("no such part in the SVG (its parts: {})", parts.join(", ")),
                }
            })?;
        let mut piece = found.clone();
        if let Some(name) = &u.name {
            piece.name = name.clone();
        }
        if let Some(fold) = &u.fold {
            piece.fold = fold.clone();
        }
        piece.copies = u.copies;
        piece.placement = u.placement.clone();
        if let Some(sa) = u.seam_allowance {
            piece.seam_allowance = sa;
        }
        pieces.push(piece);
    }
    Ok(Pattern {
        name: table.name.clone(),
        source: source.to_string(),
        pieces,
        seams: table.seams.clone(),
    })
}
