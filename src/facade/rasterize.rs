//! Derived grammars back as pixels: the per-pixel parse of a derivation's leaves (for scoring
//! and overlays), and the round trip of a grammar through its rule file.

use super::grammar::{Grammar, Leaf};
use super::labels::{Class, LabelMap};
use super::rect::Rect;
use super::report::FacadeParse;

/// The pixel parse of derived leaves on a `width` × `height` grid: each pixel takes the class
/// of the leaf containing its centre; windows are the window leaves' pixel rectangles.
pub fn rasterize(leaves: &[Leaf], width: u32, height: u32) -> FacadeParse {
    let mut labels = LabelMap::filled(width, height, Class::Wall);
    let mut windows = Vec::new();
    let px = |v: f64, n: u32| (v - 0.5).ceil().clamp(0.0, n as f64) as u32;
    for l in leaves {
        let r = Rect {
            x0: px(l.scope.x0, width),
            y0: px(l.scope.y0, height),
            x1: px(l.scope.x1, width),
            y1: px(l.scope.y1, height),
        };
        labels.paint(&r, l.class);
        if l.class == Class::Window && r.area() > 0 {
            windows.push(r);
        }
    }
    FacadeParse { labels, windows }
}

/// The round trip of a grammar: its rule file read back and derived at `width` × `height`,
/// rasterised, against the grammar's own rasterised derivation: the share of pixels that
/// agree (1 when the rule file loses nothing).
pub fn round_trip(g: &Grammar, width: u32, height: u32) -> Result<f64, String> {
    let (w, h) = (width as f64, height as f64);
    let own = rasterize(&g.derive(w, h)?, width, height);
    let back = Grammar::parse(&g.to_text())?;
    let again = rasterize(&back.derive(w, h)?, width, height);
    let same = own
        .labels
        .classes
        .iter()
        .zip(&again.labels.classes)
        .filter(|(a, b)| a == b)
        .count();
    Ok(same as f64 / own.labels.classes.len().max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::facade::grammar::Scope;

    #[test]
    fn rasterize_takes_the_leaf_under_each_pixel_centre() {
        let s = |x0, y0, x1, y1| Scope { x0, y0, x1, y1 };
        let leaves = [
            Leaf {
                scope: s(0.0, 0.0, 4.0, 4.0),
                class: Class::Wall,
                source: s(0.0, 0.0, 4.0, 4.0),
                element: None,
            },
            Leaf {
                scope: s(1.4, 1.6, 2.6, 3.0),
                class: Class::Window,
                source: s(1.4, 1.6, 2.6, 3.0),
                element: None,
            },
        ];
        let p = rasterize(&leaves, 4, 4);
        // centres 1.5 and 2.5 lie in [1.4, 2.6); rows 1.5 does not lie in [1.6, 3), 2.5 does
        assert_eq!(
            p.windows,
            vec![Rect {
                x0: 1,
                y0: 2,
                x1: 3,
                y1: 3
            }]
        );
        assert_eq!(p.labels.count(Class::Window), 2);
    }
}
