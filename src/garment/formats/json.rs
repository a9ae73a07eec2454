//! The JSON pattern format: a [`Pattern`] as serde writes it, in metres, y up.
//!
//! ```json
//! {
//!   "name": "tube skirt",
//!   "pieces": [
//!     {
//!       "name": "front",
//!       "outline": { "corners": [
//!         { "name": "hem_cf",   "at": [0.0, 0.0] },
//!         { "name": "hem_side", "at": [0.25, 0.0] },
//!         { "name": "hip_side", "at": [0.25, 0.45],
//!           "segment": { "type": "cubic", "c1": [0.25, 0.55], "c2": [0.22, 0.6] } },
//!         { "name": "waist_side", "at": [0.2, 0.62] },
//!         { "name": "waist_cf", "at": [0.0, 0.62] }
//!       ] },
//!       "grain": [[0.1, 0.1], [0.1, 0.5]],
//!       "seam_allowance": 0.01,
//!       "fold": "waist_cf",
//!       "placement": { "side": "front", "anchor": "waist_cf", "x": 0.0, "level": "waist", "dz": 0.0 }
//!     },
//!     { "name": "back", "copies": "pair", "outline": { "corners": [ … ] }, "grain": … }
//!   ],
//!   "seams": [
//!     { "name": "side_l",
//!       "a": { "piece": "front", "from": "hem_side", "to": "waist_side" },
//!       "b": { "piece": "back_l", "from": "waist_side", "to": "hem_side" } }
//!   ]
//! }
//! ```
//!
//! * `pieces[].outline.corners`: the corners in order, each with a unique `name`, its
//!   position `at` and the `segment` that leaves it towards the next corner: `{"type":"line"}`
//!   (the default when omitted) or `{"type":"cubic","c1":[x,y],"c2":[x,y]}`. The outline should
//!   run counter-clockwise; a clockwise one is turned round on reading (names are kept).
//! * `grain`: two points, the warp running from the first to the second.
//! * Optional: `seam_allowance` (m, default 0), `notches` (points), `fold` (the corner whose
//!   straight segment is the fold line), `copies` (`"one"` or `"pair"`), `placement` (where
//!   the piece goes on the mannequin: `side` `front`/`back`, `anchor` corner, `x` (m), `level`
//!   one of neck, shoulder, chest, waist, hip, crotch, knee, ankle, and `dz` (m)).
//! * `seams[]`: `name`, edges `a` and `b` (`piece`, `from`, `to`: the outline run
//!   counter-clockwise from corner `from` to corner `to`), optional `aligned` (default false:
//!   `a.from` meets `b.to`). Seams name pieces as they are after
//!   [expansion](Pattern::expanded): a pair `P` is `P_l` and `P_r`, and unfolded corners are
//!   `name'`.
//!
//! [`read_pattern_json`] checks the pattern ([`Pattern::validate`]) before returning it;
//! syntax errors give `file:line:column`.

use std::path::Path;

use crate::garment::error::PatternError;
use crate::garment::pattern::Pattern;

/// Reads a JSON pattern file, sets `source` to its path, turns clockwise outlines round and
/// validates the pattern.
pub fn read_pattern_json(path: impl AsRef<Path>) -> Result<Pattern, PatternError> {
    let path = path.as_ref();
    let text = crate::limits::read_to_string(path).map_err(|source| PatternError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let pattern = parse_pattern_json(&text, path)?;
    pattern.validate()?;
    Ok(pattern)
}

/// Parses the text of a JSON pattern (`path` is used for `source` and in errors), turns
/// clockwise outlines round, and does not validate.
pub fn parse_pattern_json(text: &str, path: &Path) -> Result<Pattern, PatternError> {
    let mut pattern: Pattern = serde_json::from_str(text).map_err(|e| json_error(path, &e))?;
    pattern.source = path.display().to_string();
    for piece in &mut pattern.pieces {
        piece.outline.make_ccw();
    }
    Ok(pattern)
}

/// Writes a pattern as pretty-printed JSON.
pub fn write_pattern_json(pattern: &Pattern, path: impl AsRef<Path>) -> Result<(), PatternError> {
    let path = path.as_ref();
    let text = serde_json::to_string_pretty(pattern).map_err(|e| PatternError::Parse {
        path: path.to_path_buf(),
        line: 0,
        message: format!("cannot serialise the pattern: {e}"),
    })?;
    std::fs::write(path, text + "\n").map_err(|source| PatternError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// A serde_json error as `file:line:column: message`.
pub(crate) fn json_error(path: &Path, e: &serde_json::Error) -> PatternError {
    let full = e.to_string();
    // serde_json appends " at line L column C"; the position goes in front instead.
    let message = match full.rfind(" at line ") {
        Some(i) => full[..i].to_string(),
        None => full,
    };
    PatternError::Syntax {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message,
    }
}
