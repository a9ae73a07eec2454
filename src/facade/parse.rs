//! Facade parsing (Müller et al. 2007 §2–3): a rectified photo → floors and tiles by mutual
//! information ([`super::repetition`]), the irreducible tile (every repeated tile averaged, so
//! occluders average out), the window inside it from the tile's edge profiles, and the shape
//! grammar of the whole ([`super::grammar`]).

use std::time::Instant;

use super::grammar::Grammar;
use super::labels::{Class, LabelMap};
use super::parse_grammar::grammar_of;
use super::parse_structure::Structure;
use super::rasterize::rasterize;
use super::rect::Rect;
use super::refinement::Refinement;
use super::repetition::{detect, Axis};
use super::score::PixelScore;
use super::tile_refinement::measure;
use super::window_blobs::{detect_windows, BlobParams};
use super::window_grammar::grammar_of_windows;
use crate::geometry::image::Gray;

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

/// Least window contrast of a cell, as a share of the irreducible tile's, for the cell to
/// hold the tile's window.
pub const MIN_CELL_CONTRAST: f64 = 0.0;

/// Parses a rectified facade photo into its grammar. Fails with a message when no floor or
/// tile repetition is found (not a facade, or a failed rectification).
pub fn parse(img: &Gray, priors: &Priors) -> Result<(Grammar, Structure), String> {
    let full = Rect {
        x0: 0,
        y0: 0,
        x1: img.width,
        y1: img.height,
    };
    parse_region(img, full, priors)
}

/// Parses the facade in `region` of a rectified photo (the part that holds photo pixels after
/// rectification); outside it is wall. The grammar covers the whole photo.
pub fn parse_region(
    full: &Gray,
    region: Rect,
    priors: &Priors,
) -> Result<(Grammar, Structure), String> {
    if region.x1 > full.width || region.y1 > full.height || region.area() == 0 {
        return Err(format!("region {region:?} is not inside the photo"));
    }
    let img = &crop(full, &region);
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
    let t0_tile = irreducible_tile(
        img,
        &cells(&floors.splits, fh, h),
        &cells(&tiles.splits, tw, w),
        fh,
        tw,
    );
    let window0 = tile_window(&t0_tile, tw, fh, priors.window);
    let t3 = Instant::now();
    // re-phase the comb so whole windows lie in whole cells, then keep the cells that look
    // like the tile and average those again
    let phase = |v: &[u32], p: u32| v.first().map_or(0, |&f| f % p);
    let (top, nf, above) = layout(h, phase(&floors.splits, fh), fh, (window0.y0, window0.y1));
    let (left, nt, beside) = layout(w, phase(&tiles.splits, tw), tw, (window0.x0, window0.x1));
    let rows: Vec<(u32, u32)> = (0..nf)
        .map(|i| (top as u32 + i as u32 * fh, top as u32 + (i as u32 + 1) * fh))
        .collect();
    let cols: Vec<(u32, u32)> = (0..nt)
        .map(|j| {
            (
                left as u32 + j as u32 * tw,
                left as u32 + (j as u32 + 1) * tw,
            )
        })
        .collect();
    // the window in the layout's cell frame (where the re-phasing put it), then each cell
    // keeps it when its window stands out from its wall like the tile's does; the tile and its
    // window are then found again from the kept cells
    let mut present = vec![true; nf * nt];
    let mut tile = irreducible_tile(img, &rows, &cols, fh, tw);
    let (b, a) = (beside as u32, above as u32);
    let mut window = Rect {
        x0: b,
        y0: a,
        x1: b + window0.x1 - window0.x0,
        y1: a + window0.y1 - window0.y0,
    };
    for _ in 0..2 {
        let reference = contrast(&tile, tw, 0, 0, tw, &window);
        for (i, r) in rows.iter().enumerate() {
            for (j, c) in cols.iter().enumerate() {
                let k = contrast(&img.data, img.width, c.0, r.0, tw, &window_in(&window, fh));
                present[i * nt + j] = k * reference.signum() > MIN_CELL_CONTRAST * reference.abs();
            }
        }
        let kept: Vec<Cell> = rows
            .iter()
            .enumerate()
            .flat_map(|(i, r)| cols.iter().enumerate().map(move |(j, c)| (i, j, *r, *c)))
            .filter(|&(i, j, _, _)| present[i * nt + j])
            .map(|(_, _, r, c)| (r, c))
            .collect();
        if kept.is_empty() {
            break;
        }
        tile = mean_of_cells(img, &kept, fh, tw);
        window = tile_window(&tile, tw, fh, priors.window);
    }
    let (row_starts, col_starts) = synchronise(img, &rows, &cols, &mut present, &window, fh, tw);
    let t4 = Instant::now();
    let windows = detect_windows(full, &region, &BlobParams::default());
    let off = |v: &[u32], o: u32| v.iter().map(|&x| x + o).collect::<Vec<u32>>();
    let offf = |v: Vec<f64>, o: u32| v.into_iter().map(|x| x + o as f64).collect::<Vec<f64>>();
    let mut structure = Structure {
        floor: fh,
        floor_splits: off(&floors.splits, region.y0),
        tile: tw,
        tile_splits: off(&tiles.splits, region.x0),
        window,
        origin: (region.x0 + left as u32, region.y0 + top as u32),
        count: (nf, nt),
        row_starts: offf(row_starts, region.y0),
        col_starts: offf(col_starts, region.x0),
        present,
        strength: (floors.strength, tiles.strength),
        irreducible: tile,
        windows,
        from_windows: false,
        refinement: Refinement::default(),
        seconds: [
            (t1 - t0).as_secs_f64(),
            (t2 - t1).as_secs_f64(),
            (t3 - t2).as_secs_f64(),
            (t4 - t3).as_secs_f64(),
            0.0,
        ],
    };
    let none = Refinement::default();
    let grid = grammar_of(&structure, full.width, full.height, none);
    structure.from_windows = !structure.windows.is_empty()
        && window_agreement(&grid, &structure.windows, full.width, full.height) < GRID_AGREEMENT;
    // tile refinement: the frame and sill round the chosen grammar's windows (all of them,
    // for the report; the windows found one by one get theirs size by size)
    let windows = if structure.from_windows {
        structure.windows.clone()
    } else {
        let leaves = grid.derive(full.width as f64, full.height as f64)?;
        rasterize(&leaves, full.width, full.height).windows
    };
    structure.refinement = measure(full, &windows, !structure.from_windows);
    let grammar = if structure.from_windows {
        grammar_of_windows(&structure.windows, full.width, full.height, &|ws| {
            measure(full, ws, false)
        })
    } else {
        grammar_of(&structure, full.width, full.height, structure.refinement)
    };
    structure.seconds[4] = t4.elapsed().as_secs_f64();
    Ok((grammar, structure))
}

/// Least agreement (IoU of the window pixels) of the layout's windows with the windows found
/// one by one for the grammar to be the layout's.
pub const GRID_AGREEMENT: f64 = 0.6;

/// IoU of the window pixels of `g` derived at `width` × `height` and of `windows`.
fn window_agreement(g: &Grammar, windows: &[Rect], width: u32, height: u32) -> f64 {
    let Ok(leaves) = g.derive(width as f64, height as f64) else {
        return 0.0;
    };
    let grid = rasterize(&leaves, width, height).labels;
    let mut found = LabelMap::filled(width, height, Class::Wall);
    for r in windows {
        found.paint(r, Class::Window);
    }
    PixelScore::of(&grid, &found).map_or(0.0, |s| s.iou(Class::Window))
}

/// Least difference (grey levels) between a window and its wall for a cell to keep its window.
pub const MIN_WINDOW_CONTRAST: f64 = 10.0;

/// How far (as a share of the cell) a window may move from the comb in synchronisation.
const SYNC_REACH: f64 = 1.0 / 6.0;

/// Local then global synchronisation of the windows: each kept cell's window is moved to the
/// offset where it stands out most from its wall (within [`SYNC_REACH`] of the cell), then each
/// floor takes the median vertical offset of its cells and each column the median horizontal
/// one. Returns the floor and tile boundaries (image pixels) with the cells moved by those
/// offsets; the regular comb when the moved cells would no longer hold their window.
fn synchronise(
    img: &Gray,
    rows: &[(u32, u32)],
    cols: &[(u32, u32)],
    present: &mut [bool],
    window: &Rect,
    fh: u32,
    tw: u32,
) -> (Vec<f64>, Vec<f64>) {
    let (nf, nt) = (rows.len(), cols.len());
    let comb = |v: &[(u32, u32)]| -> Vec<f64> {
        let mut b: Vec<f64> = v.iter().map(|c| c.0 as f64).collect();
        b.push(v.last().map_or(0.0, |c| c.1 as f64));
        b
    };
    let (rx, ry) = (
        (tw as f64 * SYNC_REACH) as i64,
        (fh as f64 * SYNC_REACH) as i64,
    );
    let (w, h) = (img.width as i64, img.height as i64);
    let mut dx: Vec<Vec<i64>> = vec![Vec::new(); nt];
    let mut dy: Vec<Vec<i64>> = vec![Vec::new(); nf];
    let win = window_in(window, fh);
    for (i, r) in rows.iter().enumerate() {
        for (j, c) in cols.iter().enumerate() {
            if !present[i * nt + j] {
                continue;
            }
            let mut best = (f64::NEG_INFINITY, 0, 0);
            for oy in -ry..=ry {
                for ox in -rx..=rx {
                    let (x0, y0) = (c.0 as i64 + ox, r.0 as i64 + oy);
                    if x0 < 0 || y0 < 0 || x0 + tw as i64 > w || y0 + fh as i64 > h {
                        continue;
                    }
                    let k = contrast(&img.data, img.width, x0 as u32, y0 as u32, tw, &win).abs();
                    // nearer offsets win ties
                    if k > best.0 + 1e-9 * k.abs() {
                        best = (k, ox, oy);
                    }
                }
            }
            if best.0 < MIN_WINDOW_CONTRAST {
                present[i * nt + j] = false;
                continue;
            }
            dx[j].push(best.1);
            dy[i].push(best.2);
        }
    }
    let median = |v: &mut Vec<i64>| -> i64 {
        if v.is_empty() {
            return 0;
        }
        v.sort_unstable();
        v[v.len() / 2]
    };
    let mdx: Vec<i64> = dx.iter_mut().map(median).collect();
    let mdy: Vec<i64> = dy.iter_mut().map(median).collect();
    let moved = |v: &[(u32, u32)], d: &[i64], size: u32| -> Vec<f64> {
        let mut b: Vec<f64> = v
            .iter()
            .zip(d)
            .map(|(c, o)| (c.0 as i64 + o) as f64)
            .collect();
        b.push(b.last().copied().unwrap_or(0.0) + size as f64);
        b
    };
    let (rs, cs) = (moved(rows, &mdy, fh), moved(cols, &mdx, tw));
    let fits = |b: &[f64], need: u32, n: i64| {
        b.first().is_some_and(|&f| f >= 0.0)
            && b.last().is_some_and(|&l| l <= n as f64)
            && b.windows(2).all(|p| p[1] - p[0] >= need as f64)
    };
    if fits(&rs, window.y1, h) && fits(&cs, window.x1, w) && nf > 0 && nt > 0 {
        (rs, cs)
    } else {
        (comb(rows), comb(cols))
    }
}

/// The pixels of `r`.
fn crop(img: &Gray, r: &Rect) -> Gray {
    let (w, h) = (r.x1 - r.x0, r.y1 - r.y0);
    let mut data = Vec::with_capacity((w * h) as usize);
    for y in r.y0..r.y1 {
        let s = (y * img.width + r.x0) as usize;
        data.extend_from_slice(&img.data[s..s + w as usize]);
    }
    Gray {
        width: w,
        height: h,
        data,
    }
}

/// The window rectangle `w` (cell frame) clipped to a cell of height `fh`.
fn window_in(w: &Rect, fh: u32) -> Rect {
    Rect {
        y1: w.y1.min(fh),
        ..*w
    }
}

/// Mean of the wall minus mean of the window in the cell of `data` (row stride `stride`)
/// whose top-left is (`x0`, `y0`) and width `tw`; the window `w` in cell coordinates; the
/// wall is the window's frame of half its size around it, within the cell.
fn contrast<T: Copy + Into<f64>>(
    data: &[T],
    stride: u32,
    x0: u32,
    y0: u32,
    tw: u32,
    w: &Rect,
) -> f64 {
    let (mx, my) = ((w.x1 - w.x0) / 2, (w.y1 - w.y0) / 2);
    let outer = Rect {
        x0: w.x0.saturating_sub(mx),
        y0: w.y0.saturating_sub(my),
        x1: (w.x1 + mx).min(tw),
        y1: w.y1 + my,
    };
    let (mut si, mut ni, mut so, mut no) = (0.0, 0.0, 0.0, 0.0);
    for y in outer.y0..outer.y1 {
        let row = ((y0 + y) * stride + x0) as usize;
        if row + tw as usize > data.len() {
            break;
        }
        for x in outer.x0..outer.x1 {
            let v: f64 = data[row + x as usize].into();
            if (w.x0..w.x1).contains(&x) && (w.y0..w.y1).contains(&y) {
                si += v;
                ni += 1.0;
            } else {
                so += v;
                no += 1.0;
            }
        }
    }
    if ni == 0.0 || no == 0.0 {
        0.0
    } else {
        so / no - si / ni
    }
}

/// A cell of the layout: its row span and its column span (pixels).
type Cell = ((u32, u32), (u32, u32));

/// The mean of the given cells, each `fh` × `tw`.
fn mean_of_cells(img: &Gray, cells: &[Cell], fh: u32, tw: u32) -> Vec<f64> {
    let mut acc = vec![0.0; (fh * tw) as usize];
    for &((y0, _), (x0, _)) in cells {
        for y in 0..fh {
            let src = &img.data[((y0 + y) * img.width + x0) as usize..][..tw as usize];
            for (a, &v) in acc[(y * tw) as usize..][..tw as usize].iter_mut().zip(src) {
                *a += v as f64;
            }
        }
    }
    let n = cells.len().max(1) as f64;
    acc.iter_mut().for_each(|a| *a /= n);
    acc
}

/// The cells (start, end) of a comb of `splits` one `period` apart that lie inside `0..n`.
fn cells(splits: &[u32], period: u32, n: u32) -> Vec<(u32, u32)> {
    splits
        .iter()
        .filter(|&&s| s + period <= n)
        .map(|&s| (s, s + period))
        .collect()
}

/// The mean of every repeated tile: the cells of `rows` × `cols` averaged pixel by pixel.
fn irreducible_tile(
    img: &Gray,
    rows: &[(u32, u32)],
    cols: &[(u32, u32)],
    fh: u32,
    tw: u32,
) -> Vec<f64> {
    let all: Vec<Cell> = rows
        .iter()
        .flat_map(|r| cols.iter().map(move |c| (*r, *c)))
        .collect();
    mean_of_cells(img, &all, fh, tw)
}

/// The window of the irreducible tile: the band of columns that stands out most from the rest
/// of the tile (largest between-class variance of the column means, Otsu's criterion for a
/// band), then within it the band of rows, then the columns again within those rows; each
/// band between `extent` fractions of the tile. Windows are darker (glass) or lighter
/// (reflections, frames) than their wall; the criterion takes either.
fn tile_window(t: &[f64], tw: u32, fh: u32, extent: (f64, f64)) -> Rect {
    let (w, h) = (tw as usize, fh as usize);
    let at = |x: usize, y: usize| t[y * w + x];
    let col_means = |y0: usize, y1: usize| -> Vec<f64> {
        (0..w)
            .map(|x| (y0..y1).map(|y| at(x, y)).sum::<f64>() / (y1 - y0).max(1) as f64)
            .collect()
    };
    let row_means = |x0: usize, x1: usize| -> Vec<f64> {
        (0..h)
            .map(|y| (x0..x1).map(|x| at(x, y)).sum::<f64>() / (x1 - x0).max(1) as f64)
            .collect()
    };
    let (x0, x1) = best_band(&col_means(0, h), extent);
    let (y0, y1) = best_band(&row_means(x0, x1), extent);
    let (x0, x1) = best_band(&col_means(y0, y1), extent);
    Rect {
        x0: x0 as u32,
        y0: y0 as u32,
        x1: x1 as u32,
        y1: y1 as u32,
    }
}

/// The band `a..b` of `p` (length within `extent` fractions of `p.len()`) with the largest
/// between-class variance n_in n_out (μ_in − μ_out)² / n².
fn best_band(p: &[f64], extent: (f64, f64)) -> (usize, usize) {
    let n = p.len();
    let lo = ((n as f64 * extent.0).ceil() as usize).max(1);
    let hi = ((n as f64 * extent.1).floor() as usize).min(n.saturating_sub(1));
    let mut prefix = vec![0.0; n + 1];
    for (k, v) in p.iter().enumerate() {
        prefix[k + 1] = prefix[k] + v;
    }
    let total = prefix[n];
    let mut best = (f64::NEG_INFINITY, (n / 4, 3 * n / 4));
    for a in 0..n {
        for b in (a + lo)..=(a + hi).min(n) {
            let (ni, no) = ((b - a) as f64, (n - (b - a)) as f64);
            if no <= 0.0 {
                continue;
            }
            let si = prefix[b] - prefix[a];
            let d = si / ni - (total - si) / no;
            let v = ni * no * d * d;
            if v > best.0 {
                best = (v, (a, b));
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
    fn best_band_finds_the_dark_band() {
        let mut p = vec![100.0; 40];
        for v in &mut p[8..30] {
            *v = 40.0;
        }
        assert_eq!(best_band(&p, (0.25, 0.85)), (8, 30));
    }
}
