//! Windows found as dark blobs of the rectified facade: a pixel belongs to a window candidate
//! when it is darker than its neighbourhood (glass shows the unlit inside), candidates are the
//! four-connected pieces of such pixels whose bounding box has a window's size, shape and
//! fill, and a candidate is kept only when another one of about its size stands in its row or
//! its column (windows repeat: Müller et al.'s prior, without asking for one global lattice,
//! which street photos of several buildings break), when its outline is a sharp step (a frame)
//! and when it stands above the ground floor. The parameters were chosen on the tuning half of
//! the labelled photos (`scripts/facades_eval.rhai --set half=tune`).

use super::rect::Rect;
use crate::geometry::image::filters::integral_image;
use crate::geometry::image::{components, Connectivity, Gray};

/// Parameters of the detector (fractions are of the facade region).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlobParams {
    /// Half-width of the neighbourhood a pixel is compared with, as a share of the region's
    /// larger side.
    pub scale: f64,
    /// How many of the neighbourhood's standard deviations below its mean a window pixel lies.
    pub contrast: f64,
    /// Least share of its bounding box a candidate fills.
    pub fill: f64,
    /// Smallest and largest bounding box, as shares of the region's area.
    pub area: (f64, f64),
    /// Least and greatest height / width of the bounding box.
    pub aspect: (f64, f64),
    /// Least overlap (share of the smaller extent) of two candidates in one row or column.
    pub align: f64,
    /// Greatest relative difference of height and of width of two candidates that support
    /// each other.
    pub similar: f64,
    /// Least mean grey step across the candidate's outline (a window has a sharp frame; a
    /// shadow or a patch of dark wall fades out).
    pub border: f64,
    /// Share of the region at its bottom where no window is kept: the street and the ground
    /// floor (shop fronts, doors, arcades, cars), which Müller et al. also leave to rules of
    /// their own.
    pub ground: f64,
    /// Widest gap between two panes of one window (a mullion, a transom), as a share of the
    /// narrower pane's extent across it: side by side or stacked panes of about the same size
    /// closer than this are merged into one window ([`merge_panes`]).
    pub pane_gap: f64,
}

impl Default for BlobParams {
    fn default() -> Self {
        BlobParams {
            scale: 0.08,
            contrast: 0.6,
            fill: 0.3,
            area: (0.0005, 0.03),
            aspect: (0.25, 4.0),
            align: 0.3,
            similar: 0.5,
            border: 11.0,
            ground: 0.2,
            pane_gap: 0.3,
        }
    }
}

/// The pixels darker than their neighbourhood's mean by `contrast` standard deviations (at
/// least one grey level), inside `region` only; row-major over the whole image.
pub fn dark_pixels(img: &Gray, region: &Rect, p: &BlobParams) -> Vec<bool> {
    let (w, h) = (img.width as usize, img.height as usize);
    let side = (region.x1 - region.x0).max(region.y1 - region.y0) as f64;
    let r = ((p.scale * side) as usize).max(3);
    let g = |i: usize| img.data[i] as f64;
    let s1 = integral_image((0..w * h).map(g), w, h);
    let s2 = integral_image((0..w * h).map(|i| g(i) * g(i)), w, h);
    let mut dark = vec![false; w * h];
    for y in region.y0 as usize..region.y1 as usize {
        let (ya, yb) = (y.saturating_sub(r), (y + r + 1).min(h));
        for x in region.x0 as usize..region.x1 as usize {
            let (xa, xb) = (x.saturating_sub(r), (x + r + 1).min(w));
            let sum = |s: &[f64]| {
                s[yb * (w + 1) + xb] - s[ya * (w + 1) + xb] - s[yb * (w + 1) + xa]
                    + s[ya * (w + 1) + xa]
            };
            let n = ((yb - ya) * (xb - xa)) as f64;
            let mean = sum(&s1) / n;
            let sd = (sum(&s2) / n - mean * mean).max(1.0).sqrt();
            dark[y * w + x] = g(y * w + x) < mean - p.contrast * sd;
        }
    }
    dark
}

/// Mean absolute grey step across the outline of `r`: between each pixel of its first and
/// last rows and columns and its neighbour outside (clamped at the image's edge).
pub fn border_step(img: &Gray, r: &Rect) -> f64 {
    let at = |x: u32, y: u32| img.at(x.min(img.width - 1), y.min(img.height - 1)) as f64;
    let step = |a: f64, b: f64| (a - b).abs();
    let (mut sum, mut n) = (0.0, 0.0);
    for y in r.y0..r.y1 {
        sum += step(at(r.x0, y), at(r.x0.saturating_sub(1), y));
        sum += step(at(r.x1, y), at(r.x1 - 1, y));
        n += 2.0;
    }
    for x in r.x0..r.x1 {
        sum += step(at(x, r.y0), at(x, r.y0.saturating_sub(1)));
        sum += step(at(x, r.y1), at(x, r.y1 - 1));
        n += 2.0;
    }
    if n > 0.0 {
        sum / n
    } else {
        0.0
    }
}

/// Whether two candidates support each other: about the same size, in one row or column.
fn supports(a: &Rect, b: &Rect, p: &BlobParams) -> bool {
    let (ha, hb) = ((a.y1 - a.y0) as f64, (b.y1 - b.y0) as f64);
    let (wa, wb) = ((a.x1 - a.x0) as f64, (b.x1 - b.x0) as f64);
    let like =
        (ha - hb).abs() <= p.similar * ha.max(hb) && (wa - wb).abs() <= p.similar * wa.max(wb);
    let rows = a.y1.min(b.y1) as f64 - a.y0.max(b.y0) as f64;
    let cols = a.x1.min(b.x1) as f64 - a.x0.max(b.x0) as f64;
    like && (rows > p.align * ha.min(hb) || cols > p.align * wa.min(wb))
}

/// The windows of the facade in `region` of the rectified photo (photo pixels), in the order
/// of their top-left pixel.
pub fn detect_windows(img: &Gray, region: &Rect, p: &BlobParams) -> Vec<Rect> {
    if region.area() == 0 {
        return Vec::new();
    }
    let dark = dark_pixels(img, region, p);
    let area = region.area() as f64;
    // rows below this are ground floor
    let ground = region.y1 - ((region.y1 - region.y0) as f64 * p.ground).round() as u32;
    let (w, h) = (img.width as usize, img.height as usize);
    let candidates: Vec<Rect> = components(&dark, w, h, Connectivity::Four)
        .into_iter()
        .map(|c| {
            let [x0, y0, x1, y1] = c.bbox;
            (Rect { x0, y0, x1, y1 }, c.pixels)
        })
        .filter(|(r, n)| {
            let a = r.area() as f64;
            let aspect = (r.y1 - r.y0) as f64 / (r.x1 - r.x0) as f64;
            a >= p.area.0 * area
                && a <= p.area.1 * area
                && *n as f64 >= p.fill * a
                && aspect >= p.aspect.0
                && aspect <= p.aspect.1
        })
        .map(|(r, _)| r)
        .collect();
    let kept = candidates
        .iter()
        .enumerate()
        .filter(|&(i, a)| {
            candidates
                .iter()
                .enumerate()
                .any(|(j, b)| j != i && supports(a, b, p))
        })
        .map(|(_, r)| *r)
        .filter(|r| border_step(img, r) >= p.border && r.y0 + r.y1 <= 2 * ground)
        .collect::<Vec<Rect>>();
    let shaped = |r: &Rect| {
        let aspect = (r.y1 - r.y0) as f64 / (r.x1 - r.x0) as f64;
        r.area() as f64 <= p.area.1 * area && aspect >= p.aspect.0 && aspect <= p.aspect.1
    };
    merge_panes(kept, p.pane_gap, shaped)
}

/// Least overlap across the gap (share of the smaller extent) of two panes of one window.
pub const PANE_ALIGN: f64 = 0.8;
/// Greatest relative difference of the two panes' extents across the gap.
pub const PANE_SIMILAR: f64 = 0.25;

/// Merges panes of one window: two rectangles side by side (or one above the other) that
/// overlap by [`PANE_ALIGN`] of the smaller one's height (width), differ in it by at most
/// [`PANE_SIMILAR`], and are at most `gap` of the narrower one's width (height) apart become
/// their bounding box when that is still `shaped` like a window, until no two do. Light bars
/// cut a window's dark glass into panes; neighbouring windows stand further apart than their
/// bars are wide, and several windows together are too large or too wide for one.
pub fn merge_panes(mut windows: Vec<Rect>, gap: f64, shaped: impl Fn(&Rect) -> bool) -> Vec<Rect> {
    let joins = |a: &Rect, b: &Rect, across_x: bool| {
        let (a0, a1, b0, b1, c0, c1, d0, d1) = if across_x {
            (a.y0, a.y1, b.y0, b.y1, a.x0, a.x1, b.x0, b.x1)
        } else {
            (a.x0, a.x1, b.x0, b.x1, a.y0, a.y1, b.y0, b.y1)
        };
        let (ea, eb) = ((a1 - a0) as f64, (b1 - b0) as f64);
        let overlap = a1.min(b1) as f64 - a0.max(b0) as f64;
        let (la, lb) = ((c1 - c0) as f64, (d1 - d0) as f64);
        // b after a along the other axis, a pixel of overlap allowed
        let between = d0 as f64 - c1 as f64;
        overlap >= PANE_ALIGN * ea.min(eb)
            && (ea - eb).abs() <= PANE_SIMILAR * ea.max(eb)
            && between >= -1.0
            && between <= gap * la.min(lb)
    };
    let mut alive = vec![true; windows.len()];
    let mut changed = true;
    while changed {
        changed = false;
        for i in 0..windows.len() {
            for j in 0..windows.len() {
                if i == j || !alive[i] || !alive[j] {
                    continue;
                }
                let (a, b) = (windows[i], windows[j]);
                let union = Rect::new(
                    a.x0.min(b.x0),
                    a.y0.min(b.y0),
                    a.x1.max(b.x1),
                    a.y1.max(b.y1),
                );
                if (joins(&a, &b, true) || joins(&a, &b, false)) && shaped(&union) {
                    windows[i] = union;
                    alive[j] = false;
                    changed = true;
                }
            }
        }
    }
    windows
        .into_iter()
        .zip(alive)
        .filter_map(|(w, a)| a.then_some(w))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A light wall with dark windows at `windows`.
    fn facade(w: u32, h: u32, windows: &[Rect]) -> Gray {
        let mut data = vec![200u8; (w * h) as usize];
        for r in windows {
            for y in r.y0..r.y1 {
                for x in r.x0..r.x1 {
                    data[(y * w + x) as usize] = 40;
                }
            }
        }
        Gray {
            width: w,
            height: h,
            data,
        }
    }

    #[test]
    fn a_grid_of_dark_windows_is_found_exactly_above_the_ground_floor() {
        // four rows of windows; the lowest stands in the bottom fifth (rows 208..260)
        let windows: Vec<Rect> = (0..4)
            .flat_map(|i| {
                (0..4).map(move |j| Rect::new(20 + 50 * j, 30 + 60 * i, 45 + 50 * j, 65 + 60 * i))
            })
            .collect();
        let img = facade(220, 260, &windows);
        let region = Rect::new(0, 0, 220, 260);
        let found = detect_windows(&img, &region, &BlobParams::default());
        assert_eq!(found, windows[..12]);
        // with no ground floor set apart, all four rows
        let all = BlobParams {
            ground: 0.0,
            ..BlobParams::default()
        };
        assert_eq!(detect_windows(&img, &region, &all), windows);
    }

    #[test]
    fn a_lone_dark_patch_is_no_window() {
        // one window-sized patch with nothing like it in its row or column
        let img = facade(200, 200, &[Rect::new(80, 80, 105, 115)]);
        let found = detect_windows(&img, &Rect::new(0, 0, 200, 200), &BlobParams::default());
        assert!(found.is_empty(), "{found:?}");
    }

    #[test]
    fn soft_dark_patches_without_a_frame_are_no_windows() {
        // a row of three shadows darkening gradually towards their centres (8 grey levels per
        // pixel): dark, repeated, window-sized, but with no sharp outline
        let (w, h) = (220u32, 120u32);
        let mut data = vec![200u8; (w * h) as usize];
        for cx in [50i64, 110, 170] {
            for y in 0..h as i64 {
                for x in 0..w as i64 {
                    let d = (x - cx).abs().max((y - 60).abs()) as f64;
                    let v = 200.0 - 160.0 * (1.0 - d / 20.0).max(0.0);
                    let i = (y * w as i64 + x) as usize;
                    data[i] = data[i].min(v.round() as u8);
                }
            }
        }
        let img = Gray {
            width: w,
            height: h,
            data,
        };
        let p = BlobParams::default();
        let found = detect_windows(&img, &Rect::new(0, 0, w, h), &p);
        assert!(found.is_empty(), "{found:?}");
        // without the outline test they would pass
        let lax = BlobParams { border: 0.0, ..p };
        assert_eq!(detect_windows(&img, &Rect::new(0, 0, w, h), &lax).len(), 3);
    }

    #[test]
    fn the_panes_of_a_window_merge_and_neighbouring_windows_do_not() {
        // two cross windows 24 × 33 (bars 2 px wide) whose piers are 19 px wide
        let panes = |x: u32| {
            [
                Rect::new(x, 10, x + 11, 30),
                Rect::new(x + 13, 10, x + 24, 30),
                Rect::new(x, 32, x + 11, 43),
                Rect::new(x + 13, 32, x + 24, 43),
            ]
        };
        let all: Vec<Rect> = panes(10).into_iter().chain(panes(53)).collect();
        let merged = merge_panes(all, 0.3, |_| true);
        assert_eq!(
            merged,
            vec![Rect::new(10, 10, 34, 43), Rect::new(53, 10, 77, 43)]
        );
        // side by side panes unlike in height stay apart (a window beside a door)
        let unlike = vec![Rect::new(0, 0, 10, 10), Rect::new(12, 0, 22, 30)];
        assert_eq!(merge_panes(unlike.clone(), 0.3, |_| true), unlike);
        // windows of a row close together (narrow piers) merge only while the union still has
        // a window's shape
        let row = vec![Rect::new(0, 0, 24, 33), Rect::new(29, 0, 53, 33)];
        assert_eq!(
            merge_panes(row.clone(), 0.3, |_| true),
            vec![Rect::new(0, 0, 53, 33)]
        );
        let narrow = |r: &Rect| r.x1 - r.x0 <= 40;
        assert_eq!(merge_panes(row.clone(), 0.3, narrow), row);
    }
}
