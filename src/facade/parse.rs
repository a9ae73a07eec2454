//! Facade parsing (Müller et al. 2007 §2–3): a rectified photo → floors and tiles by mutual
//! information ([`super::repetition`]), the irreducible tile (every repeated tile averaged, so
//! occluders average out), the window inside it from the tile's edge profiles, and the shape
//! grammar of the whole ([`super::grammar`]). [`rasterize`] turns a derived grammar back into a
//! per-pixel parse for scoring.

use std::time::Instant;

use super::grammar::{Body, Dir, Grammar, Leaf, Size};
use super::gray::Gray;
use super::labels::{Class, LabelMap};
use super::rect::Rect;
use super::repetition::{detect, Axis};
use super::report::FacadeParse;

/// Priors of the parse, as fractions of the image's extent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Priors {
    /// Shortest and longest floor height (fractions of the image height).
    pub floor: (f64, f64),
    /// Narrowest and widest tile (fractions of the image width).
    pub tile: (f64, f64),
    /// Smallest and largest window extent within its tile (fractions of the tile's).
    pub window: (f64, f64),
}

impl Default for Priors {
    fn default() -> Self {
        Priors {
            floor: (0.06, 0.5),
            tile: (0.04, 0.5),
            window: (0.25, 0.85),
        }
    }
}

/// What the parse found, with the time per stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    /// Floor height and the rows of the floor splits.
    pub floor: u32,
    /// Floor split rows (first and last bound the repeated floors).
    pub floor_splits: Vec<u32>,
    /// Tile width.
    pub tile: u32,
    /// Tile split columns.
    pub tile_splits: Vec<u32>,
    /// The window within the irreducible tile (tile pixels).
    pub window: Rect,
    /// The irreducible tile (mean of the repeated tiles), row-major, `tile × floor`.
    pub irreducible: Vec<f64>,
    /// Seconds spent in: floor search, tile search, irreducible tile, window.
    pub seconds: [f64; 4],
}

/// Parses a rectified facade photo into its grammar. Fails with a message when no floor or
/// tile repetition is found (not a facade, or a failed rectification).
pub fn parse(img: &Gray, priors: &Priors) -> Result<(Grammar, Structure), String> {
    let (w, h) = (img.width, img.height);
    let span = |n: u32, (a, b): (f64, f64)| ((n as f64 * a) as u32, (n as f64 * b) as u32);
    let t0 = Instant::now();
    let (fmin, fmax) = span(h, priors.floor);
    let floors = detect(img, Axis::Rows, fmin, fmax)
        .ok_or_else(|| format!("no repeated floors between {fmin} and {fmax} px"))?;
    let t1 = Instant::now();
    let (tmin, tmax) = span(w, priors.tile);
    let tiles = detect(img, Axis::Columns, tmin, tmax)
        .ok_or_else(|| format!("no repeated tiles between {tmin} and {tmax} px"))?;
    let t2 = Instant::now();
    let (fh, tw) = (floors.period, tiles.period);
    let irreducible = irreducible_tile(img, &floors.splits, fh, &tiles.splits, tw);
    let t3 = Instant::now();
    let window = tile_window(&irreducible, tw, fh, priors.window);
    let t4 = Instant::now();
    let structure = Structure {
        floor: fh,
        floor_splits: floors.splits,
        tile: tw,
        tile_splits: tiles.splits,
        window,
        irreducible,
        seconds: [
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            (t3 - t2).as_secs_f64(),
            (t4 - t3).as_secs_f64(),
        ],
    };
    Ok((grammar_of(&structure, w, h), structure))
}

/// The cells (start, end) of a comb of `splits` one `period` apart that lie inside `0..n`.
fn cells(splits: &[u32], period: u32, n: u32) -> Vec<(u32, u32)> {
    splits
        .iter()
        .filter(|&&s| s + period <= n)
        .map(|&s| (s, s + period))
        .collect()
}

/// The mean of every repeated tile: floors × tiles cells averaged pixel by pixel.
fn irreducible_tile(img: &Gray, fs: &[u32], fh: u32, ts: &[u32], tw: u32) -> Vec<f64> {
    let (rows, cols) = (cells(fs, fh, img.height), cells(ts, tw, img.width));
    let mut acc = vec![0.0; (fh * tw) as usize];
    let n = (rows.len() * cols.len()).max(1) as f64;
    for &(y0, _) in &rows {
        for &(x0, _) in &cols {
            for y in 0..fh {
                let src = &img.data[((y0 + y) * img.width + x0) as usize..][..tw as usize];
                for (a, &v) in acc[(y * tw) as usize..][..tw as usize].iter_mut().zip(src) {
                    *a += v as f64;
                }
            }
        }
    }
    acc.iter_mut().for_each(|a| *a /= n);
    acc
}

/// The window of the irreducible tile: the pair of columns with the strongest vertical edges
/// (a window's jambs), then within them the pair of rows with the strongest horizontal edges
/// (sill and lintel), each pair between `extent` fractions of the tile apart.
fn tile_window(t: &[f64], tw: u32, fh: u32, extent: (f64, f64)) -> Rect {
    let (w, h) = (tw as usize, fh as usize);
    let at = |x: usize, y: usize| t[y * w + x];
    // vertical-edge strength per column, horizontal-edge strength per row (central differences)
    let mut col = vec![0.0; w];
    for (x, c) in col.iter_mut().enumerate().take(w.saturating_sub(1)).skip(1) {
        *c = (0..h)
            .map(|y| (at(x + 1, y) - at(x - 1, y)).abs())
            .sum::<f64>();
    }
    let (x0, x1) = best_pair(&col, extent, w);
    let mut row = vec![0.0; h];
    for (y, r) in row.iter_mut().enumerate().take(h.saturating_sub(1)).skip(1) {
        *r = (x0..x1)
            .map(|x| (at(x, y + 1) - at(x, y - 1)).abs())
            .sum::<f64>();
    }
    let (y0, y1) = best_pair(&row, extent, h);
    Rect {
        x0: x0 as u32,
        y0: y0 as u32,
        x1: x1 as u32,
        y1: y1 as u32,
    }
}

/// Positions a < b with b − a within `extent` fractions of `n` maximising p[a] + p[b].
fn best_pair(p: &[f64], extent: (f64, f64), n: usize) -> (usize, usize) {
    let lo = ((n as f64 * extent.0).ceil() as usize).max(1);
    let hi = ((n as f64 * extent.1).floor() as usize).min(n.saturating_sub(1));
    let mut best = (f64::NEG_INFINITY, (n / 4, 3 * n / 4));
    for a in 0..n {
        for b in (a + lo)..=(a + hi).min(n.saturating_sub(1)) {
            let s = p[a] + p[b];
            if s > best.0 {
                best = (s, (a, b));
            }
        }
    }
    best.1
}

/// How a comb of cells one `period` apart (first split at `phase`) with an element at
/// `elem` (offsets within the cell) is laid out along an axis of length `n`: the cells are
/// re-phased so that every element that lies wholly inside the image sits in a whole cell
/// (the split lines may move anywhere within the wall between elements). Returns the first
/// cell's start, the number of cells and the wall before the element within a cell.
fn layout(n: u32, phase: u32, period: u32, elem: (u32, u32)) -> (f64, usize, f64) {
    let (n, p, e0) = (n as i64, period as i64, elem.0 as i64);
    let len = (elem.1 - elem.0) as i64;
    let slack = p - len;
    // element starts t_k = phase + e0 + k p inside [0, n − len]
    let t0 = phase as i64 + e0;
    let k_min = (-t0).div_euclid(p) + i64::from((-t0).rem_euclid(p) != 0);
    let k_max = (n - len - t0).div_euclid(p);
    let mut count = k_max - k_min + 1;
    while count >= 1 {
        let first = t0 + k_min * p;
        let last_end = t0 + (k_min + count - 1) * p + len;
        let (lo, hi) = ((slack - (n - last_end)).max(0), slack.min(first));
        if lo <= hi {
            let before = e0.clamp(lo, hi);
            return ((first - before) as f64, count as usize, before as f64);
        }
        count -= 1;
    }
    // no whole element fits: one cell of the image's extent, element as found
    (0.0, 0, e0 as f64)
}

/// The grammar of a parse: margins around the repeated floors and tiles, a window in each
/// tile with wall around it. Facade units are the photo's pixels.
pub fn grammar_of(s: &Structure, width: u32, height: u32) -> Grammar {
    let (w, h) = (width as f64, height as f64);
    let (fh, tw) = (s.floor as f64, s.tile as f64);
    let win = s.window;
    let phase = |v: &[u32], p: u32| v.first().map_or(0, |&f| f % p);
    let (top, nf, wall_above) = layout(
        height,
        phase(&s.floor_splits, s.floor),
        s.floor,
        (win.y0, win.y1),
    );
    let (left, nt, wall_left) = layout(
        width,
        phase(&s.tile_splits, s.tile),
        s.tile,
        (win.x0, win.x1),
    );
    let (floors_h, tiles_w) = (nf as f64 * fh, nt as f64 * tw);
    let (bottom, right) = (h - top - floors_h, w - left - tiles_w);
    let (win_w, win_h) = ((win.x1 - win.x0) as f64, (win.y1 - win.y0) as f64);
    let leaf = |c: Class| Body::Leaf(c);
    let split = |dir: Dir, parts: Vec<(Size, &str)>| Body::Split {
        dir,
        parts: parts.into_iter().map(|(z, r)| (z, r.to_string())).collect(),
    };
    let mut rules = std::collections::BTreeMap::new();
    if nf == 0 || nt == 0 {
        rules.insert("Facade".to_string(), leaf(Class::Wall));
        return Grammar {
            rules,
            axiom: "Facade".into(),
            size: (w, h),
        };
    }
    rules.insert(
        "Facade".to_string(),
        split(
            Dir::Y,
            vec![
                (Size::Fixed(top), "Top"),
                (Size::Floating(floors_h), "Floors"),
                (Size::Fixed(bottom), "Ground"),
            ],
        ),
    );
    rules.insert(
        "Floors".to_string(),
        Body::Repeat {
            dir: Dir::Y,
            size: fh,
            rule: "Floor".into(),
        },
    );
    rules.insert(
        "Floor".to_string(),
        split(
            Dir::X,
            vec![
                (Size::Fixed(left), "Wall"),
                (Size::Floating(tiles_w), "Tiles"),
                (Size::Fixed(right), "Wall"),
            ],
        ),
    );
    rules.insert(
        "Tiles".to_string(),
        Body::Repeat {
            dir: Dir::X,
            size: tw,
            rule: "Tile".into(),
        },
    );
    rules.insert(
        "Tile".to_string(),
        split(
            Dir::X,
            vec![
                (Size::Floating(wall_left), "Wall"),
                (Size::Fixed(win_w), "Column"),
                (Size::Floating(tw - wall_left - win_w), "Wall"),
            ],
        ),
    );
    rules.insert(
        "Column".to_string(),
        split(
            Dir::Y,
            vec![
                (Size::Floating(wall_above), "Wall"),
                (Size::Fixed(win_h), "Window"),
                (Size::Floating(fh - wall_above - win_h), "Wall"),
            ],
        ),
    );
    rules.insert("Top".to_string(), leaf(Class::Wall));
    rules.insert("Ground".to_string(), leaf(Class::Wall));
    rules.insert("Wall".to_string(), leaf(Class::Wall));
    rules.insert("Window".to_string(), leaf(Class::Window));
    Grammar {
        rules,
        axiom: "Facade".into(),
        size: (w, h),
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_keeps_every_whole_element() {
        // cells of 57 from 53, element at 15..49: elements start at 11, 68, …, 296 (n = 342)
        let (start, count, before) = layout(342, 53, 57, (15, 49));
        assert_eq!(count, 6, "tops 11 + 57k ≤ 342 − 34");
        assert!(start >= 0.0 && start + 6.0 * 57.0 <= 342.0);
        assert_eq!(start + before, 11.0);
        // nothing fits
        assert_eq!(layout(30, 0, 57, (15, 49)).1, 0);
    }

    #[test]
    fn best_pair_finds_the_two_peaks() {
        let mut p = vec![0.0; 40];
        p[8] = 5.0;
        p[30] = 4.0;
        p[20] = 1.0;
        assert_eq!(best_pair(&p, (0.25, 0.85), 40), (8, 30));
    }

    #[test]
    fn rasterize_takes_the_leaf_under_each_pixel_centre() {
        use super::super::grammar::Scope;
        let s = |x0, y0, x1, y1| Scope { x0, y0, x1, y1 };
        let leaves = [
            Leaf {
                scope: s(0.0, 0.0, 4.0, 4.0),
                class: Class::Wall,
                source: s(0.0, 0.0, 4.0, 4.0),
            },
            Leaf {
                scope: s(1.4, 1.6, 2.6, 3.0),
                class: Class::Window,
                source: s(1.4, 1.6, 2.6, 3.0),
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
