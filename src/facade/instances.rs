//! Window instances of a label map, as the protocol defines ground-truth windows: connected
//! components of the window mask after a 3×3 opening, components under 0.05 % of the image
//! dropped, each taken as its bounding rectangle; a window with half its rectangle or more
//! under ignored pixels (a tree in front) is "don't care".

use super::labels::{Class, LabelMap};
use super::rect::Rect;
use crate::geometry::image::morphology::open_3x3;
use crate::geometry::image::{components, Connectivity};

/// Smallest component kept, as a share of the image.
pub const MIN_AREA_SHARE: f64 = 0.0005;

/// A ground-truth window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instance {
    /// Its bounding rectangle.
    pub rect: Rect,
    /// Half or more of the rectangle is ignored: neither a hit nor a miss.
    pub dont_care: bool,
}

/// The windows of `map`.
pub fn window_instances(map: &LabelMap) -> Vec<Instance> {
    let (w, h) = (map.width as usize, map.height as usize);
    let mask: Vec<bool> = map.classes.iter().map(|c| *c == Class::Window).collect();
    let opened = open_3x3(&mask, w, h);
    let min_area = (MIN_AREA_SHARE * (w * h) as f64).ceil() as usize;
    let mut out = Vec::new();
    for c in components(&opened, w, h, Connectivity::Eight) {
        if (c.pixels as usize) < min_area {
            continue;
        }
        let [x0, y0, x1, y1] = c.bbox;
        let rect = Rect { x0, y0, x1, y1 };
        let ignored = map.count_in(&rect, Class::Ignore);
        out.push(Instance {
            rect,
            dont_care: 2 * ignored >= rect.area(),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_are_components_after_an_opening() {
        let mut m = LabelMap::filled(200, 100, Class::Wall);
        // two windows, a one-pixel line joining them (removed by the opening), a speck
        m.paint(
            &Rect {
                x0: 10,
                y0: 10,
                x1: 30,
                y1: 40,
            },
            Class::Window,
        );
        m.paint(
            &Rect {
                x0: 50,
                y0: 10,
                x1: 70,
                y1: 40,
            },
            Class::Window,
        );
        m.paint(
            &Rect {
                x0: 30,
                y0: 20,
                x1: 50,
                y1: 21,
            },
            Class::Window,
        );
        m.paint(
            &Rect {
                x0: 100,
                y0: 80,
                x1: 103,
                y1: 83,
            },
            Class::Window,
        );
        // a window behind a tree: only a 3-pixel frame of it shows
        m.paint(
            &Rect {
                x0: 120,
                y0: 10,
                x1: 140,
                y1: 40,
            },
            Class::Window,
        );
        m.paint(
            &Rect {
                x0: 123,
                y0: 13,
                x1: 137,
                y1: 37,
            },
            Class::Ignore,
        );
        let w = window_instances(&m);
        assert_eq!(w.len(), 3, "{w:?}");
        assert_eq!(
            w[0].rect,
            Rect {
                x0: 10,
                y0: 10,
                x1: 30,
                y1: 40
            }
        );
        assert_eq!(
            w[1].rect,
            Rect {
                x0: 50,
                y0: 10,
                x1: 70,
                y1: 40
            }
        );
        assert!(!w[0].dont_care && !w[1].dont_care);
        // the occluded one: its rectangle is more than half tree
        assert_eq!(
            w[2].rect,
            Rect {
                x0: 120,
                y0: 10,
                x1: 140,
                y1: 40
            }
        );
        assert!(w[2].dont_care);
    }
}
