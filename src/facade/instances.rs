//! Window instances of a label map, as the protocol defines ground-truth windows: connected
//! components of the window mask after a 3×3 opening, components under 0.05 % of the image
//! dropped, each taken as its bounding rectangle; a window with half its rectangle or more
//! under ignored pixels (a tree in front) is "don't care".

use super::labels::{Class, LabelMap};
use super::rect::Rect;

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
    let opened = dilate(&erode(&mask, w, h), w, h);
    let min_area = (MIN_AREA_SHARE * (w * h) as f64).ceil() as usize;
    let mut seen = vec![false; w * h];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for start in 0..w * h {
        if !opened[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
        let mut area = 0;
        while let Some(p) = stack.pop() {
            let (x, y) = (p % w, p / w);
            area += 1;
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let q = ny as usize * w + nx as usize;
                    if opened[q] && !seen[q] {
                        seen[q] = true;
                        stack.push(q);
                    }
                }
            }
        }
        if area < min_area {
            continue;
        }
        let rect = Rect {
            x0: x0 as u32,
            y0: y0 as u32,
            x1: x1 as u32,
            y1: y1 as u32,
        };
        let ignored = map.count_in(&rect, Class::Ignore);
        out.push(Instance {
            rect,
            dont_care: 2 * ignored >= rect.area(),
        });
    }
    out
}

/// 3×3 erosion (pixels outside the image count as unset).
fn erode(m: &[bool], w: usize, h: usize) -> Vec<bool> {
    morph(m, w, h, true)
}

/// 3×3 dilation.
fn dilate(m: &[bool], w: usize, h: usize) -> Vec<bool> {
    morph(m, w, h, false)
}

fn morph(m: &[bool], w: usize, h: usize, erode: bool) -> Vec<bool> {
    let mut out = vec![false; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut all = true;
            let mut any = false;
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    let v = nx >= 0
                        && ny >= 0
                        && nx < w as i64
                        && ny < h as i64
                        && m[ny as usize * w + nx as usize];
                    all &= v;
                    any |= v;
                }
            }
            out[y * w + x] = if erode { all } else { any };
        }
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
