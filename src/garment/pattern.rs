//! Pattern pieces and seams: the designer's 2D input, in metres, y up, each piece drawn right
//! side up as seen from outside the garment.
//!
//! A [`Piece`] is a closed [`Outline`] of named corners, each owning the segment (straight or
//! cubic Bézier) that leaves it; a grain line (the warp direction); a seam allowance; notches;
//! how it is cut (once, on a fold, or as a mirrored pair) and where it goes on the body
//! ([`Placement`]). A [`Seam`] sews two piece edges ([`EdgeRef`]) together.
//!
//! Corners are referred to by name, so that seam tables stay readable: importers name the
//! corners of a piece `c0`, `c1`, … in outline order unless the file names them.

use serde::{Deserialize, Serialize};

/// A 2D point or vector (m).
pub type P2 = [f64; 2];

/// The segment that leaves a corner and ends at the next corner of the outline.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Segment {
    /// A straight line.
    #[default]
    Line,
    /// A cubic Bézier curve with control points `c1` and `c2` (m).
    Cubic {
        /// First control point.
        c1: P2,
        /// Second control point.
        c2: P2,
    },
}

/// A corner of an outline and the segment that leaves it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Corner {
    /// The corner's name, unique within its piece (`c0`, `c1`, … unless the file names it).
    pub name: String,
    /// Where the corner is (m).
    pub at: P2,
    /// The segment from this corner to the next one.
    #[serde(default)]
    pub segment: Segment,
}

/// A closed outline: corners in counter-clockwise order (y up), the last one's segment
/// returning to the first corner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Outline {
    /// The corners, counter-clockwise.
    pub corners: Vec<Corner>,
}

/// On which figurine (front or back view of the mannequin) a piece is placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The front view.
    #[default]
    Front,
    /// The back view (seen from behind, from outside the garment).
    Back,
}

/// How many times a piece is cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Copies {
    /// One piece, as drawn.
    #[default]
    One,
    /// A mirrored pair: `<name>_l` as drawn and `<name>_r` mirrored (its placement `x` negated).
    Pair,
}

/// Where a piece goes on the mannequin, for automatic pre-positioning: the corner `anchor`
/// is put at horizontal offset `x` from the body's centre line (m, to the viewer's right in
/// the view of `side`) and at the height of the body landmark `level` plus `dz` (m).
/// The grain line is put vertical.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    /// The figurine (front or back view) the piece lies on.
    pub side: Side,
    /// The corner that is placed.
    pub anchor: String,
    /// Horizontal offset of the anchor from the body's centre line (m).
    #[serde(default)]
    pub x: f64,
    /// The body landmark whose height the anchor takes: `neck`, `shoulder`, `chest`, `waist`,
    /// `hip`, `crotch`, `knee` or `ankle`.
    pub level: String,
    /// Offset above the landmark (m).
    #[serde(default)]
    pub dz: f64,
}

/// One pattern piece.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Piece {
    /// The piece's name, unique within the pattern.
    pub name: String,
    /// The sewing line (the outline the simulation uses).
    pub outline: Outline,
    /// The grain line: the warp runs from the first point towards the second (m).
    pub grain: [P2; 2],
    /// Seam allowance outside the sewing line (m); drawn on pattern sheets, not simulated.
    #[serde(default)]
    pub seam_allowance: f64,
    /// Notches on the outline (m).
    #[serde(default)]
    pub notches: Vec<P2>,
    /// Cut on the fold: the name of the corner whose (straight) segment is the fold line.
    /// The piece is mirrored about that line and the halves joined before meshing; the
    /// mirrored corners are named with a trailing `'` (`c3` → `c3'`).
    #[serde(default)]
    pub fold: Option<String>,
    /// Cut once or as a mirrored pair.
    #[serde(default)]
    pub copies: Copies,
    /// Where the piece goes on the body (needed for pre-positioning).
    #[serde(default)]
    pub placement: Option<Placement>,
}

/// A piece edge: the outline path that runs forward (counter-clockwise) from corner `from`
/// to corner `to` of piece `piece`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct EdgeRef {
    /// The piece (after expansion of pairs: `<name>_l`, `<name>_r`).
    pub piece: String,
    /// The corner where the edge starts.
    pub from: String,
    /// The corner where the edge ends.
    pub to: String,
}

/// A seam: edge `a` sewn to edge `b`. Two pieces seen from outside run in opposite directions
/// along a seam, so by default `a.from` meets `b.to` and `a.to` meets `b.from`; with
/// `aligned`, `a.from` meets `b.from`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Seam {
    /// The seam's name (numbers it on pattern sheets and in errors).
    pub name: String,
    /// The first edge.
    pub a: EdgeRef,
    /// The second edge.
    pub b: EdgeRef,
    /// Whether the two edges run the same way (`a.from` meets `b.from`).
    #[serde(default)]
    pub aligned: bool,
}

/// A sewing pattern: pieces and the seams between them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Pattern {
    /// The pattern's name.
    pub name: String,
    /// Where it came from (a file path), used in error messages.
    #[serde(default)]
    pub source: String,
    /// The pieces.
    pub pieces: Vec<Piece>,
    /// The seams.
    #[serde(default)]
    pub seams: Vec<Seam>,
}
