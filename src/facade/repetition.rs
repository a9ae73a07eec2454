//! Repetition along one axis of a facade image (Müller et al. 2007 §2.2 and §2.4): the period
//! from mutual information, the split lines from edges. MI of a band with the band one period
//! away is high wherever the band starts, so MI finds the period but not where the splits go
//! (`facade-reconstruction.md` §1.3, caveat); the splits are placed where Müller's edge
//! interest profile is lowest along the comb of that period (floors are split through wall
//! and along ledges, not through windows).

use rayon::prelude::*;

use super::mutual_information::MiWorkspace;
use crate::geometry::image::filters::gaussian_smooth_1d;
use crate::geometry::image::Gray;

/// Which way the facade repeats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Floors: horizontal bands repeating down the image.
    Rows,
    /// Tiles: vertical bands repeating across it.
    Columns,
}

/// Band offsets at which S(·, h) is sampled per candidate period.
const SAMPLES: usize = 24;
/// A shorter period wins when its peak stands out at least this share of the best one's
/// (multiples of the true period match as well as the period itself).
const HARMONIC_SHARE: f64 = 0.6;

/// A detected repetition.
#[derive(Debug, Clone, PartialEq)]
pub struct Repetition {
    /// Period (pixels).
    pub period: u32,
    /// Mean MI of bands one period apart, relative to the mean MI of a band with itself
    /// (1 = perfectly repeated).
    pub strength: f64,
    /// Split lines (pixel rows or columns), one period apart, at the edge profile's comb
    /// minimum.
    pub splits: Vec<u32>,
}

/// Length of the image along `axis`.
fn extent(img: &Gray, axis: Axis) -> u32 {
    match axis {
        Axis::Rows => img.height,
        Axis::Columns => img.width,
    }
}

/// Mean over [`SAMPLES`] offsets `y` of MI(band [y, y+h), band [y−h, y)), and the same for a
/// band with itself.
fn period_score(img: &Gray, axis: Axis, h: u32, ws: &mut MiWorkspace) -> (f64, f64) {
    let n = extent(img, axis);
    if 2 * h > n {
        return (0.0, 1.0);
    }
    let span = n - 2 * h;
    let (mut s, mut own) = (0.0, 0.0);
    for k in 0..SAMPLES {
        let y = h + (span as u64 * k as u64 / (SAMPLES as u64 - 1).max(1)) as u32;
        let (a, b) = match axis {
            Axis::Rows => (ws.rows(img, y, y - h, h), ws.rows(img, y, y, h)),
            Axis::Columns => (
                ws.columns(img, y, y - h, h, 0, img.height),
                ws.columns(img, y, y, h, 0, img.height),
            ),
        };
        s += a;
        own += b;
    }
    (s / SAMPLES as f64, own / SAMPLES as f64)
}

/// Edge weight of the other direction (Müller's α) and of the parallel edges (β).
const ALPHA: f64 = 0.9;
const BETA: f64 = 0.1;

/// The split-line interest profile along `axis` (Müller et al. 2007 eq. 3–4): for rows,
/// Ver(y) = Σ_x ver(x, y) − β Σ_x hor(x, y), where ver = max(I_x²(1−α) − I_y²α, 0) responds to
/// vertical edges (a horizontal split line should not cross them) and hor likewise to
/// horizontal ones (it may lie along them); central differences, smoothed by a Gaussian of
/// standard deviation `sigma` pixels. Low values are good places for a split. For columns the
/// roles swap.
pub fn edge_profile(img: &Gray, axis: Axis, sigma: f64) -> Vec<f64> {
    let (w, h) = (img.width as i64, img.height as i64);
    let px = |x: i64, y: i64| img.at(x.clamp(0, w - 1) as u32, y.clamp(0, h - 1) as u32) as f64;
    let n = match axis {
        Axis::Rows => h,
        Axis::Columns => w,
    } as usize;
    let mut raw = vec![0.0; n];
    for y in 0..h {
        for x in 0..w {
            let ix = 0.5 * (px(x + 1, y) - px(x - 1, y));
            let iy = 0.5 * (px(x, y + 1) - px(x, y - 1));
            let (ix2, iy2) = (ix * ix, iy * iy);
            let ver = (ix2 * (1.0 - ALPHA) - iy2 * ALPHA).max(0.0);
            let hor = (iy2 * (1.0 - ALPHA) - ix2 * ALPHA).max(0.0);
            match axis {
                Axis::Rows => raw[y as usize] += ver - BETA * hor,
                Axis::Columns => raw[x as usize] += hor - BETA * ver,
            }
        }
    }
    gaussian_smooth_1d(&raw, sigma)
}

/// Relative scores `(h, S, S/S_own)` of the candidate periods `hs`, each scored
/// independently (in parallel; the result does not depend on the thread count).
fn period_scores(img: &Gray, axis: Axis, hs: &[u32]) -> Vec<(u32, f64, f64)> {
    hs.par_iter()
        .map_init(
            || {
                let large = img.width as u64 * img.height as u64 >= SPARSE_PIXELS;
                MiWorkspace::with_stride(if large { 2 } else { 1 })
            },
            |ws, &h| {
                let (s, own) = period_score(img, axis, h, ws);
                (h, s, if own > 0.0 { s / own } else { 0.0 })
            },
        )
        .collect()
}

/// In images of at least this many pixels, MI samples every second row and column of the
/// bands (a quarter of the pairs: still thousands per histogram of 32 × 32 bins).
const SPARSE_PIXELS: u64 = 120_000;

/// Finds the repetition of `img` along `axis` with a period in `min..=max` pixels (clamped
/// so that two periods fit), or `None` when no period fits.
/// Candidates are scored in parallel, each independently, so the result does not depend on
/// the thread count.
pub fn detect(img: &Gray, axis: Axis, min: u32, max: u32) -> Option<Repetition> {
    let n = extent(img, axis);
    let (min, max) = (min.max(2), max.min(n / 2));
    if min > max {
        return None;
    }
    let hs: Vec<u32> = (min..=max).collect();
    let scores = period_scores(img, axis, &hs);
    let (period, _, strength) = scores[choose_period(&scores)?];
    Some(place(img, axis, period, strength))
}

/// Index of the period among the scored candidates (`None` without an interior peak).
fn choose_period(scores: &[(u32, f64, f64)]) -> Option<usize> {
    // the period: a peak of the relative score standing out of its surroundings. Bands next to
    // each other look alike in any photo (sky above, road below, smooth shading), so the
    // score falls from the shortest period on whether or not the facade repeats: a period
    // must be an interior peak, ranked by its prominence over the lowest score within a third
    // of its length on either side; the shortest peak nearly as prominent as the best wins (a
    // multiple of the period matches as well as the period itself).
    let rel: Vec<f64> = scores.iter().map(|s| s.2).collect();
    let prominence = |k: usize| -> f64 {
        let reach = (scores[k].0 / 3).max(1) as usize;
        let lo = k.saturating_sub(reach);
        let hi = (k + reach).min(rel.len() - 1);
        let left = rel[lo..k].iter().copied().fold(f64::INFINITY, f64::min);
        let right = rel[k + 1..=hi]
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        rel[k] - left.max(right)
    };
    let peaks: Vec<(usize, f64)> = (1..rel.len().saturating_sub(1))
        .filter(|&k| rel[k - 1] <= rel[k] && rel[k + 1] <= rel[k])
        .map(|k| (k, prominence(k)))
        .filter(|p| p.1 > 0.0)
        .collect();
    let best = peaks.iter().map(|p| p.1).fold(0.0, f64::max);
    let k = peaks
        .iter()
        .find(|p| p.1 >= HARMONIC_SHARE * best)
        .map(|p| p.0)?;
    Some(k)
}

/// The repetition of `period` with its splits: the phase whose comb of lines crosses the
/// fewest edges.
fn place(img: &Gray, axis: Axis, period: u32, strength: f64) -> Repetition {
    let n = extent(img, axis);
    let profile = edge_profile(img, axis, period as f64 / 16.0);
    let phase = (0..period)
        .min_by(|&a, &b| {
            let comb = |p: u32| -> f64 {
                (p..n)
                    .step_by(period as usize)
                    .map(|y| profile[y as usize])
                    .sum::<f64>()
                    / ((n - p).div_ceil(period)) as f64
            };
            comb(a).total_cmp(&comb(b)).then(a.cmp(&b))
        })
        .unwrap_or(0);
    let splits = (phase..n).step_by(period as usize).collect();
    Repetition {
        period,
        strength,
        splits,
    }
}
