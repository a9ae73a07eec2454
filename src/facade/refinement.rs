//! What stands round a facade's windows, as the tile refinement measures it
//! ([`Refinement`]: the windows' sides moved to their strongest split lines, the frame width
//! and the sill height), and its rules ([`framed_window`]): the window between strips of
//! casing, and a sill under it (wall leaves carrying the `wall_frame` and `wall_sill`
//! elements).

use std::collections::BTreeMap;

use super::grammar::{Body, Dir, Size};
use super::labels::Class;
use super::rect::Rect;

/// Where a facade's windows' sides lie, and the frame width and sill height round them
/// (pixels; 0: none).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Refinement {
    /// How far the windows' left, top, right and bottom sides move out (negative: in) to
    /// their strongest split line.
    pub sides: [i32; 4],
    /// Width of the frame on the left, right, top and bottom of each window.
    pub frame: u32,
    /// Height of the sill below the frame.
    pub sill: u32,
}

impl Refinement {
    /// The window `r` with its sides moved; `r` itself if that would leave nothing.
    pub fn window(&self, r: &Rect) -> Rect {
        let [l, t, rt, b] = self.sides.map(i64::from);
        let clamp = |v: i64| v.max(0) as u32;
        let moved = Rect {
            x0: clamp(r.x0 as i64 - l),
            y0: clamp(r.y0 as i64 - t),
            x1: clamp(r.x1 as i64 + rt),
            y1: clamp(r.y1 as i64 + b),
        };
        if moved.x1 > moved.x0 && moved.y1 > moved.y0 {
            moved
        } else {
            *r
        }
    }

    /// The window `r` (its sides already moved) with its frame and sill round it.
    pub fn unit(&self, r: &Rect) -> Rect {
        Rect {
            x0: r.x0.saturating_sub(self.frame),
            y0: r.y0.saturating_sub(self.frame),
            x1: r.x1 + self.frame,
            y1: r.y1 + self.frame + self.sill,
        }
    }

    /// Whether there is nothing round the windows (their sides may still move).
    pub fn is_none(&self) -> bool {
        self.frame == 0 && self.sill == 0
    }

    /// Without the frame and sill: the windows' sides only.
    pub fn bare(&self) -> Self {
        Refinement {
            sides: self.sides,
            ..Default::default()
        }
    }
}

/// The rule for a `w` × `h` window (facade units, its rule `window`) with `r`'s frame and sill
/// round it, added to `rules` (shared by windows of one size): `window` alone when there is
/// nothing round it;
/// else the window between strips of `Frame` (`split(x)` in a row `JambsN`, `split(y)` for the
/// head and the bottom) above a `Sill`, in a rule `FramedWindowN` whose scope is
/// [`Refinement::unit`].
pub fn framed_window(
    rules: &mut BTreeMap<String, Body>,
    r: Refinement,
    w: f64,
    h: f64,
    window: &str,
) -> String {
    if r.is_none() {
        return window.into();
    }
    let (f, s) = (r.frame as f64, r.sill as f64);
    let mut parts: Vec<(Size, String)> = Vec::new();
    let middle = if r.frame > 0 {
        rules.insert(
            "Frame".into(),
            Body::Insert {
                class: Class::Wall,
                element: "wall_frame".into(),
            },
        );
        parts.push((Size::Fixed(f), "Frame".into()));
        let row = Body::Split {
            dir: Dir::X,
            parts: vec![
                (Size::Fixed(f), "Frame".into()),
                (Size::Fixed(w), window.into()),
                (Size::Fixed(f), "Frame".into()),
            ],
        };
        named(rules, row, "Jambs")
    } else {
        window.into()
    };
    parts.push((Size::Fixed(h), middle));
    if r.frame > 0 {
        parts.push((Size::Fixed(f), "Frame".into()));
    }
    if r.sill > 0 {
        rules.insert(
            "Sill".into(),
            Body::Insert {
                class: Class::Wall,
                element: "wall_sill".into(),
            },
        );
        parts.push((Size::Fixed(s), "Sill".into()));
    }
    named(rules, Body::Split { dir: Dir::Y, parts }, "FramedWindow")
}

/// The name of `body` among the rules made so far (`base1`, `base2`, … by first use), adding
/// it when new.
pub(crate) fn named(rules: &mut BTreeMap<String, Body>, body: Body, base: &str) -> String {
    let numbered = |n: &str| {
        n.strip_prefix(base)
            .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
    };
    if let Some((n, _)) = rules.iter().find(|(n, b)| **b == body && numbered(n)) {
        return n.clone();
    }
    let k = rules.keys().filter(|n| numbered(n)).count() + 1;
    let n = format!("{base}{k}");
    rules.insert(n.clone(), body);
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facade::grammar::Grammar;
    use crate::facade::rasterize::rasterize;

    #[test]
    fn a_framed_window_fills_its_unit_and_paints_the_window_where_it_was() {
        let mut rules = BTreeMap::new();
        rules.insert("Window".to_string(), Body::Leaf(Class::Window));
        let r = Refinement {
            sides: [0; 4],
            frame: 2,
            sill: 3,
        };
        let name = framed_window(&mut rules, r, 20.0, 35.0, "Window");
        assert_eq!(
            framed_window(&mut rules, r, 20.0, 35.0, "Window"),
            name,
            "one rule per size"
        );
        let unit = r.unit(&Rect::new(2, 2, 22, 37));
        assert_eq!(unit, Rect::new(0, 0, 24, 42));
        rules.insert("Facade".to_string(), rules[&name].clone());
        let g = Grammar {
            rules,
            axiom: "Facade".into(),
            size: (24.0, 42.0),
        };
        let text = g.to_text();
        assert!(
            text.contains("Frame --> insert(wall, wall_frame)"),
            "{text}"
        );
        assert!(text.contains("Sill --> insert(wall, wall_sill)"), "{text}");
        assert_eq!(Grammar::parse(&text).expect("reads back"), g);
        let leaves = g.derive(24.0, 42.0).expect("derives");
        assert_eq!(
            rasterize(&leaves, 24, 42).windows,
            vec![Rect::new(2, 2, 22, 37)]
        );
        assert_eq!(
            g.elements(),
            vec!["wall_frame".to_string(), "wall_sill".to_string()]
        );
        // 4 strips of frame and a sill
        assert_eq!(leaves.iter().filter(|l| l.element.is_some()).count(), 5);
    }
}
