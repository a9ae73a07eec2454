//! Per-pixel features of a facade photo for the learned classifier, computed at a working
//! resolution (the longer side [`WORK_SIDE`] pixels): colour (CIE Lab at three scales),
//! texture (gradients, local contrast and spread, second derivatives), the pixel's
//! normalised position, row and column projections (Müller's floors and tiles show as bands
//! of horizontal and vertical edges), and repetition: the floor and tile periods found by
//! autocorrelation of those projections, and what the pixel's darkness and look are one
//! period up, down, left and right (a window repeats; a shadow or a tree seldom does); and
//! context: how much lighter the surroundings are at eight directions and three distances
//! (the offset comparisons of Shotton et al.'s TextonBoost forests: a window is darker than
//! the wall a half-window away on every side).

use image::RgbImage;

use crate::geometry::image::filters::gaussian_blur;
use crate::geometry::image::Gray;

/// Longer side of the working image, pixels.
pub const WORK_SIDE: u32 = 320;

/// Offsets (pixels at the working resolution) at which the look of the surroundings is
/// compared with the pixel's: eight directions at each of these radii.
pub const OFFSET_RADII: [f32; 3] = [4.0, 10.0, 20.0];

/// Features before the offset comparisons.
pub const N_BASE_FEATURES: usize = 33;

/// Number of features per pixel.
pub const N_FEATURES: usize = N_BASE_FEATURES + 8 * OFFSET_RADII.len();

/// The features' names, in order.
pub const FEATURE_NAMES: [&str; N_FEATURES] = [
    "L",
    "a",
    "b",
    "L_s3",
    "a_s3",
    "b_s3",
    "L_s10",
    "a_s10",
    "b_s10",
    "dark_s10",
    "dark_s3_s10",
    "grad_s1",
    "gx_s3",
    "gy_s3",
    "grad_s8",
    "std_s3",
    "Lxx_s2",
    "Lyy_s2",
    "x",
    "y",
    "row_L",
    "col_L",
    "row_gy",
    "col_gx",
    "row_dark",
    "col_dark",
    "rep_dark_y",
    "rep_dark_x",
    "rep_diff_y",
    "rep_diff_x",
    "floor_period",
    "tile_period",
    "L_rel",
    "off4_e",
    "off4_ne",
    "off4_n",
    "off4_nw",
    "off4_w",
    "off4_sw",
    "off4_s",
    "off4_se",
    "off10_e",
    "off10_ne",
    "off10_n",
    "off10_nw",
    "off10_w",
    "off10_sw",
    "off10_s",
    "off10_se",
    "off20_e",
    "off20_ne",
    "off20_n",
    "off20_nw",
    "off20_w",
    "off20_sw",
    "off20_s",
    "off20_se",
];

/// Indices of the features that describe the pixel and its neighbourhood alone (colour and
/// texture), without position, projections or repetition: the "local" alternative.
pub const LOCAL_FEATURES: std::ops::Range<usize> = 0..18;

/// The features of every pixel of one working image.
#[derive(Debug, Clone)]
pub struct PixelFeatures {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Feature `f` of pixel `i = y · width + x` at `i · N_FEATURES + f`.
    pub values: Vec<f32>,
}

impl PixelFeatures {
    /// The features of pixel `i`.
    pub fn of(&self, i: usize) -> &[f32] {
        &self.values[i * N_FEATURES..(i + 1) * N_FEATURES]
    }
}

/// The size a `width × height` photo is analysed at: the longer side [`WORK_SIDE`] (never
/// enlarged), at least 1 × 1.
pub fn working_size(width: u32, height: u32) -> (u32, u32) {
    let s = (WORK_SIDE as f64 / width.max(height).max(1) as f64).min(1.0);
    (
        ((width as f64 * s).round() as u32).max(1),
        ((height as f64 * s).round() as u32).max(1),
    )
}

/// `img` resized to its [`working_size`] (triangle filter).
pub fn working_image(img: &RgbImage) -> RgbImage {
    let (w, h) = working_size(img.width(), img.height());
    if (w, h) == img.dimensions() {
        return img.clone();
    }
    image::imageops::resize(img, w, h, image::imageops::FilterType::Triangle)
}

/// sRGB (0–255) to CIE Lab (D65).
pub fn lab(rgb: [u8; 3]) -> [f32; 3] {
    let lin = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let (r, g, b) = (lin(rgb[0]), lin(rgb[1]), lin(rgb[2]));
    let x = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047;
    let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
    let z = (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883;
    let f = |t: f32| {
        if t > 0.008856 {
            t.cbrt()
        } else {
            7.787 * t + 16.0 / 116.0
        }
    };
    let (fx, fy, fz) = (f(x), f(y), f(z));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

fn gray(w: u32, h: u32, data: Vec<f32>) -> Gray<f32> {
    Gray {
        width: w,
        height: h,
        data,
    }
}

/// The period of a profile (detrended by a moving mean of `n/8`): the smallest lag in
/// `[n/16, n/2]` whose normalised autocorrelation is within 85 % of the largest there; 0 when that is below 0.1 (no
/// repetition).
pub fn profile_period(p: &[f32]) -> usize {
    let n = p.len();
    let (lo, hi) = ((n / 16).max(3), n / 2);
    if hi <= lo {
        return 0;
    }
    // detrended: minus a moving mean over n/8 (sky above, street below are no period)
    let r = (n / 16).max(1);
    let d: Vec<f32> = (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(r), (i + r + 1).min(n));
            p[i] - p[a..b].iter().sum::<f32>() / (b - a) as f32
        })
        .collect();
    let var: f32 = d.iter().map(|v| v * v).sum::<f32>() / n as f32;
    if var <= 1e-12 {
        return 0;
    }
    let ac: Vec<f32> = (lo..=hi)
        .map(|lag| {
            let s: f32 = (0..n - lag).map(|i| d[i] * d[i + lag]).sum();
            s / ((n - lag) as f32 * var)
        })
        .collect();
    let best = ac.iter().cloned().fold(f32::MIN, f32::max);
    if best < 0.1 {
        return 0;
    }
    lo + ac.iter().position(|&a| a >= 0.85 * best).unwrap_or(0)
}

/// Mean over the pixel's neighbours one period `t` away along a line (`get(k)` at positions
/// `k ± t` inside `0..n`), or `own` when `t` is 0 or both fall outside.
fn periodic_mean(k: usize, t: usize, n: usize, get: impl Fn(usize) -> f32, own: f32) -> f32 {
    if t == 0 {
        return own;
    }
    let (mut s, mut c) = (0.0, 0.0);
    if k >= t {
        s += get(k - t);
        c += 1.0;
    }
    if k + t < n {
        s += get(k + t);
        c += 1.0;
    }
    if c > 0.0 {
        s / c
    } else {
        own
    }
}

/// The features of every pixel of `img` (already at its working size).
pub fn pixel_features(img: &RgbImage) -> PixelFeatures {
    let (w, h) = img.dimensions();
    let (wu, hu) = (w as usize, h as usize);
    let n = wu * hu;
    let mut chan = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
    for (i, p) in img.pixels().enumerate() {
        let l = lab(p.0);
        for c in 0..3 {
            chan[c][i] = l[c];
        }
    }
    let blur = |c: &Vec<f32>, s: f64| gaussian_blur(&gray(w, h, c.clone()), s).data;
    let s0: Vec<Vec<f32>> = chan.iter().map(|c| blur(c, 0.7)).collect();
    let s3: Vec<Vec<f32>> = chan.iter().map(|c| blur(c, 3.0)).collect();
    let s10: Vec<Vec<f32>> = chan.iter().map(|c| blur(c, 10.0)).collect();
    let l = &s0[0];
    let at = |v: &Vec<f32>, x: usize, y: usize| v[y * wu + x];
    // gradients of L (central differences, clamped)
    let (mut gx, mut gy) = (vec![0f32; n], vec![0f32; n]);
    for y in 0..hu {
        for x in 0..wu {
            let (xl, xr) = (x.saturating_sub(1), (x + 1).min(wu - 1));
            let (yu, yd) = (y.saturating_sub(1), (y + 1).min(hu - 1));
            gx[y * wu + x] = 0.5 * (at(l, xr, y) - at(l, xl, y));
            gy[y * wu + x] = 0.5 * (at(l, x, yd) - at(l, x, yu));
        }
    }
    let mag: Vec<f32> = gx.iter().zip(&gy).map(|(a, b)| a.hypot(*b)).collect();
    let agx = blur(&gx.iter().map(|v| v.abs()).collect(), 3.0);
    let agy = blur(&gy.iter().map(|v| v.abs()).collect(), 3.0);
    let mag8 = blur(&mag, 8.0);
    let sq3 = blur(&chan[0].iter().map(|v| v * v).collect(), 3.0);
    let l2 = blur(&chan[0], 2.0);
    let dark: Vec<f32> = (0..n).map(|i| l[i] - s10[0][i]).collect();
    // projections: rows and columns
    let mean_l = l.iter().sum::<f32>() / n as f32;
    let mean_g = (mag.iter().sum::<f32>() / n as f32).max(1e-3);
    let row = |v: &Vec<f32>| -> Vec<f32> {
        (0..hu)
            .map(|y| v[y * wu..(y + 1) * wu].iter().sum::<f32>() / wu as f32)
            .collect()
    };
    let col = |v: &Vec<f32>| -> Vec<f32> {
        let mut c = vec![0f32; wu];
        for y in 0..hu {
            for x in 0..wu {
                c[x] += v[y * wu + x];
            }
        }
        c.iter().map(|s| s / hu as f32).collect()
    };
    let agy_raw: Vec<f32> = gy.iter().map(|v| v.abs()).collect();
    let agx_raw: Vec<f32> = gx.iter().map(|v| v.abs()).collect();
    let (row_l, col_l) = (row(l), col(l));
    let (row_gy, col_gx) = (row(&agy_raw), col(&agx_raw));
    let (row_dark, col_dark) = (row(&dark), col(&dark));
    let ty = profile_period(&row_gy);
    let tx = profile_period(&col_gx);
    let mut values = vec![0f32; n * N_FEATURES];
    for y in 0..hu {
        for x in 0..wu {
            let i = y * wu + x;
            let f = &mut values[i * N_FEATURES..(i + 1) * N_FEATURES];
            for c in 0..3 {
                f[c] = s0[c][i];
                f[3 + c] = s3[c][i];
                f[6 + c] = s10[c][i];
            }
            f[9] = dark[i];
            f[10] = s3[0][i] - s10[0][i];
            f[11] = mag[i];
            f[12] = agx[i];
            f[13] = agy[i];
            f[14] = mag8[i];
            f[15] = (sq3[i] - s3[0][i] * s3[0][i]).max(0.0).sqrt();
            let (xl, xr) = (x.saturating_sub(2), (x + 2).min(wu - 1));
            let (yu, yd) = (y.saturating_sub(2), (y + 2).min(hu - 1));
            f[16] = at(&l2, xl, y) + at(&l2, xr, y) - 2.0 * l2[i];
            f[17] = at(&l2, x, yu) + at(&l2, x, yd) - 2.0 * l2[i];
            f[18] = (x as f32 + 0.5) / w as f32;
            f[19] = (y as f32 + 0.5) / h as f32;
            f[20] = row_l[y] - mean_l;
            f[21] = col_l[x] - mean_l;
            f[22] = row_gy[y] / mean_g;
            f[23] = col_gx[x] / mean_g;
            f[24] = row_dark[y];
            f[25] = col_dark[x];
            let own3 = s3[0][i];
            f[26] = periodic_mean(y, ty, hu, |k| dark[k * wu + x], dark[i]);
            f[27] = periodic_mean(x, tx, wu, |k| dark[y * wu + k], dark[i]);
            f[28] = periodic_mean(y, ty, hu, |k| (s3[0][k * wu + x] - own3).abs(), 0.0);
            f[29] = periodic_mean(x, tx, wu, |k| (s3[0][y * wu + k] - own3).abs(), 0.0);
            f[30] = ty as f32 / h as f32;
            f[31] = tx as f32 / w as f32;
            f[32] = l[i] - mean_l;
            for (k, r) in OFFSET_RADII.iter().enumerate() {
                for d in 0..8 {
                    let a = d as f32 * std::f32::consts::FRAC_PI_4;
                    let ox = (x as f32 + r * a.cos()).round().clamp(0.0, (wu - 1) as f32);
                    let oy = (y as f32 - r * a.sin()).round().clamp(0.0, (hu - 1) as f32);
                    f[N_BASE_FEATURES + 8 * k + d] = s3[0][oy as usize * wu + ox as usize] - own3;
                }
            }
        }
    }
    PixelFeatures {
        width: w,
        height: h,
        values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_of_white_black_and_red_are_the_published_values() {
        let w = lab([255, 255, 255]);
        assert!((w[0] - 100.0).abs() < 0.05 && w[1].abs() < 0.05 && w[2].abs() < 0.05);
        assert!(lab([0, 0, 0])[0].abs() < 1e-4);
        // sRGB red: L 53.24, a 80.09, b 67.20 (CIE Lab, D65)
        let r = lab([255, 0, 0]);
        assert!((r[0] - 53.24).abs() < 0.1, "{r:?}");
        assert!(
            (r[1] - 80.09).abs() < 0.3 && (r[2] - 67.20).abs() < 0.3,
            "{r:?}"
        );
    }

    #[test]
    fn the_period_of_a_comb_is_its_spacing() {
        let p: Vec<f32> = (0..200)
            .map(|i| if i % 37 < 4 { 1.0 } else { 0.0 })
            .collect();
        assert_eq!(profile_period(&p), 37);
        assert_eq!(profile_period(&[0.5; 100]), 0);
    }
}
