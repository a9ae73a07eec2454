//! Expansion of a [`Pattern`] into the pieces that are actually cut: pieces cut on the fold
//! are unfolded, mirrored pairs become two pieces.
//!
//! * **Fold.** A piece whose `fold` names corner `F` is mirrored about the straight segment
//!   `F → F+1` and the two halves are joined: the outline runs through the original corners up
//!   to `F`, then through the mirrored corners (named with a trailing `'`, in reverse order),
//!   and comes back to `F+1`; `F` and `F+1`, on the fold line, keep their names. The outline
//!   stays counter-clockwise, corner 0 stays first, the grain line is kept, notches off the
//!   fold line are mirrored too, and `fold` is cleared.
//! * **Pair.** A `Copies::Pair` piece `P` becomes `P_l` (as drawn) and `P_r`, mirrored about
//!   the vertical axis x = 0 (corner names unchanged, corner 0 first, outline re-ordered to stay
//!   counter-clockwise, placement `x` negated). Both get `copies: one`. Mirroring reverses
//!   the direction of travel: the edge `a → b` of `P_l` is the edge `b → a` of `P_r`.
//!
//! Seams of the file already refer to the expanded names; they are copied unchanged.

use super::error::PatternError;
use super::pattern::{Copies, Corner, Outline, Pattern, Piece, Segment, P2};

/// Distance under which a notch counts as lying on the fold line (m).
const ON_FOLD: f64 = 1e-6;

impl Pattern {
    /// The pattern with folds unfolded and pairs split (see the module doc). Errors name the
    /// piece whose fold corner is missing or whose fold segment is not a straight line.
    pub fn expanded(&self) -> Result<Pattern, PatternError> {
        let mut pieces = Vec::with_capacity(self.pieces.len());
        for piece in &self.pieces {
            let unfolded = match &piece.fold {
                Some(fold) => unfold(piece, fold, &self.source_name())?,
                None => piece.clone(),
            };
            match unfolded.copies {
                Copies::One => pieces.push(unfolded),
                Copies::Pair => {
                    let (l, r) = split_pair(&unfolded);
                    pieces.push(l);
                    pieces.push(r);
                }
            }
        }
        Ok(Pattern {
            name: self.name.clone(),
            source: self.source.clone(),
            pieces,
            seams: self.seams.clone(),
        })
    }
}

/// Reflection of `p` about the line through `a` and `b`.
fn reflect(p: P2, a: P2, b: P2) -> P2 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let t = ((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2;
    let foot = [a[0] + t * d[0], a[1] + t * d[1]];
    [2.0 * foot[0] - p[0], 2.0 * foot[1] - p[1]]
}

fn unfold(piece: &Piece, fold: &str, source: &str) -> Result<Piece, PatternError> {
    let err = |message: String| PatternError::Piece {
        source_name: source.to_string(),
        piece: piece.name.clone(),
        message,
    };
    let corners = &piece.outline.corners;
    let n = corners.len();
    let f = piece
        .outline
        .corner_index(fold)
        .ok_or_else(|| err(format!("fold corner '{fold}' does not exist")))?;
    if n < 3 {
        return Err(err(format!("cannot unfold an outline of {n} corners")));
    }
    if corners[f].segment != Segment::Line {
        return Err(err(format!(
            "fold edge {}→{} is not a straight line",
            corners[f].name,
            corners[(f + 1) % n].name
        )));
    }
    let (a, b) = (corners[f].at, corners[(f + 1) % n].at);
    if a == b {
        return Err(err(format!(
            "fold edge {}→{} has zero length",
            corners[f].name,
            corners[(f + 1) % n].name
        )));
    }
    let m = |p: P2| reflect(p, a, b);
    let mirrored_name = |i: usize| format!("{}'", corners[i].name);
    let mut out: Vec<Corner> = Vec::with_capacity(2 * n - 2);
    out.extend(corners[..f].iter().cloned());
    // F now leads into the mirrored half: the mirror of segment F-1 → F, run backwards.
    let back = |k: usize| corners[(k + n - 1) % n].segment.reversed().mapped(m);
    out.push(Corner {
        name: corners[f].name.clone(),
        at: a,
        segment: back(f),
    });
    // Mirrored corners F-1, F-2, …, F+2 (indices mod n), each leading to the next one down.
    let mut k = (f + n - 1) % n;
    while k != (f + 1) % n {
        out.push(Corner {
            name: mirrored_name(k),
            at: m(corners[k].at),
            segment: back(k),
        });
        k = (k + n - 1) % n;
    }
    // Back on the fold line at F+1, then the original corners after it (if F+1 is not 0).
    if f + 1 < n {
        out.extend(corners[f + 1..].iter().cloned());
    }
    let mut notches = piece.notches.clone();
    for p in &piece.notches {
        let q = m(*p);
        if (q[0] - p[0]).hypot(q[1] - p[1]) > 2.0 * ON_FOLD {
            notches.push(q);
        }
    }
    Ok(Piece {
        outline: Outline { corners: out },
        notches,
        fold: None,
        ..piece.clone()
    })
}

fn split_pair(piece: &Piece) -> (Piece, Piece) {
    let mut l = piece.clone();
    l.name = format!("{}_l", piece.name);
    l.copies = Copies::One;
    let flip = |p: P2| [-p[0], p[1]];
    let mut r = l.clone();
    r.name = format!("{}_r", piece.name);
    let mirrored = Outline {
        corners: piece
            .outline
            .corners
            .iter()
            .map(|c| Corner {
                name: c.name.clone(),
                at: flip(c.at),
                segment: c.segment.mapped(flip),
            })
            .collect(),
    };
    // Mirroring turns the outline clockwise; run it the other way (corner 0 stays first).
    r.outline = mirrored.reversed();
    r.grain = [flip(piece.grain[0]), flip(piece.grain[1])];
    r.notches = piece.notches.iter().map(|&p| flip(p)).collect();
    if let Some(pl) = &mut r.placement {
        pl.x = -pl.x;
    }
    (l, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corner(name: &str, at: P2) -> Corner {
        Corner {
            name: name.into(),
            at,
            segment: Segment::Line,
        }
    }

    fn half() -> Piece {
        // A half-front: fold along x = 0 from (0, 1) down to (0, 0) (corner "top" → "bottom").
        Piece {
            name: "front".into(),
            outline: Outline {
                corners: vec![
                    corner("bottom", [0.0, 0.0]),
                    corner("hem", [0.4, 0.0]),
                    Corner {
                        name: "side".into(),
                        at: [0.5, 1.0],
                        segment: Segment::Cubic {
                            c1: [0.3, 1.1],
                            c2: [0.1, 1.0],
                        },
                    },
                    corner("top", [0.0, 1.0]),
                ],
            },
            grain: [[0.2, 0.2], [0.2, 0.8]],
            seam_allowance: 0.01,
            notches: vec![[0.0, 0.5], [0.45, 0.5]],
            fold: Some("top".into()),
            copies: Copies::One,
            placement: None,
        }
    }

    #[test]
    fn unfolding_doubles_the_area_and_names_mirrored_corners() {
        let p = half();
        let u = unfold(&p, "top", "test").unwrap();
        let names: Vec<&str> = u.outline.corners.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["bottom", "hem", "side", "top", "side'", "hem'"]);
        assert!((u.outline.area() - 2.0 * p.outline.area()).abs() < 1e-12);
        assert_eq!(u.outline.corners[4].at, [-0.5, 1.0]);
        assert_eq!(u.notches.len(), 3);
        // The edge top → side' is the mirror of side → top.
        let top = u.outline.corner_index("top").unwrap();
        assert!((u.outline.edge_length(top, top + 1) - p.outline.segment_length(2)).abs() < 1e-12);
        assert!(u.fold.is_none());
    }

    #[test]
    fn pairs_are_mirrored_and_stay_counter_clockwise() {
        let mut p = half();
        p.fold = None;
        p.copies = Copies::Pair;
        let (l, r) = split_pair(&p);
        assert_eq!((l.name.as_str(), r.name.as_str()), ("front_l", "front_r"));
        assert!(r.outline.area() > 0.0);
        assert!((r.outline.area() - l.outline.area()).abs() < 1e-12);
        assert_eq!(r.outline.corners[0].name, "bottom");
        assert_eq!(r.outline.corners[1].name, "top");
        let (i, j) = (
            r.outline.corner_index("side").unwrap(),
            r.outline.corner_index("hem").unwrap(),
        );
        // Mirroring reverses edges: hem → side on the left is side → hem on the right.
        assert!((r.outline.edge_length(i, j) - l.outline.edge_length(1, 2)).abs() < 1e-9);
    }
}
