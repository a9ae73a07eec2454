//! Straight line segments of a grayscale photo, for the vanishing-point rectification
//! ([`super::vanishing`]). This module owns edge-segment detection only, in the spirit of LSD
//! (von Gioi et al. 2010) but simpler: a light Gaussian blur, Sobel gradients, region growing
//! of strong-gradient pixels whose gradient orientation stays within a tolerance of the
//! region's mean orientation, a principal-axis fit of each region, and a rectangle-density
//! check that rejects blobs and curves.
//!
//! Coordinates are continuous pixel coordinates with pixel (x, y)'s centre at
//! (x + ½, y + ½), as [`super::homography`] uses them.

use std::f64::consts::PI;

use crate::geometry::image::filters::{binomial_blur, sobel};
use crate::geometry::image::Gray;

/// A straight edge segment in continuous pixel coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// One end.
    pub a: [f64; 2],
    /// The other end.
    pub b: [f64; 2],
    /// Mean gradient magnitude of its pixels (gray levels per pixel).
    pub strength: f64,
}

impl Segment {
    /// Distance between the ends.
    pub fn length(&self) -> f64 {
        (self.b[0] - self.a[0]).hypot(self.b[1] - self.a[1])
    }

    /// Direction angle in [0, π): 0 along +x, π/2 along +y (downwards in the image).
    pub fn angle(&self) -> f64 {
        let t = (self.b[1] - self.a[1]).atan2(self.b[0] - self.a[0]);
        let t = t.rem_euclid(PI);
        if t >= PI {
            0.0
        } else {
            t
        }
    }

    /// The midpoint.
    pub fn midpoint(&self) -> [f64; 2] {
        [0.5 * (self.a[0] + self.b[0]), 0.5 * (self.a[1] + self.b[1])]
    }
}

/// Tuning of [`detect_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentParams {
    /// Smallest gradient magnitude (gray levels per pixel) of a segment pixel. LSD's 5.2 is
    /// the gradient a quantisation error of 2 levels can fake at the 22.5° tolerance.
    pub gradient_threshold: f64,
    /// Largest difference (radians) between a pixel's gradient orientation and its region's.
    pub angle_tolerance: f64,
    /// Shortest segment kept, as a share of the image diagonal.
    pub min_length_share: f64,
    /// Smallest share of the fitted rectangle covered by region pixels.
    pub min_density: f64,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            gradient_threshold: 5.2,
            angle_tolerance: 22.5f64.to_radians(),
            min_length_share: 0.02,
            min_density: 0.7,
        }
    }
}

/// The segments of `img` with the default parameters.
pub fn detect(img: &Gray) -> Vec<Segment> {
    detect_with(img, &SegmentParams::default())
}

/// The segments of `img`, strongest seeds first (a deterministic order: by gradient magnitude,
/// ties by pixel index). Images under 5×5 pixels, or whose data does not match their size,
/// have none.
pub fn detect_with(img: &Gray, p: &SegmentParams) -> Vec<Segment> {
    let (w, h) = (img.width as usize, img.height as usize);
    if w < 5 || h < 5 || img.data.len() != w * h {
        return Vec::new();
    }
    let (mag, ang) = sobel(&binomial_blur(img));
    let thr = p.gradient_threshold.max(0.0) as f32;
    let diag = (w as f64).hypot(h as f64);
    let min_len = (p.min_length_share * diag).max(3.0);

    let mut seeds: Vec<u32> = (0..w * h)
        .filter(|&i| mag[i] > thr)
        .map(|i| i as u32)
        .collect();
    seeds.sort_unstable_by(|&i, &j| mag[j as usize].total_cmp(&mag[i as usize]).then(i.cmp(&j)));

    // 0: free, 1: taken by a region (or not usable)
    let mut used: Vec<u8> = mag.iter().map(|&m| u8::from(m <= thr)).collect();
    let mut region: Vec<u32> = Vec::new();
    let mut out = Vec::new();
    let tol = p.angle_tolerance;
    for &seed in &seeds {
        let s = seed as usize;
        if used[s] != 0 {
            continue;
        }
        used[s] = 1;
        region.clear();
        region.push(seed);
        let a0 = ang[s] as f64;
        let (mut sc, mut ss) = (a0.cos(), a0.sin());
        let mut theta = a0;
        let mut k = 0;
        while k < region.len() {
            let q = region[k] as usize;
            let (x, y) = (q % w, q / w);
            for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                    let n = ny * w + nx;
                    if used[n] != 0 {
                        continue;
                    }
                    let an = ang[n] as f64;
                    if angle_diff(an, theta) <= tol {
                        used[n] = 1;
                        region.push(n as u32);
                        sc += an.cos();
                        ss += an.sin();
                        theta = ss.atan2(sc);
                    }
                }
            }
            k += 1;
        }
        if (region.len() as f64) < min_len {
            continue;
        }
        if let Some(seg) = fit(&region, &mag, w, theta, tol, min_len, p.min_density) {
            out.push(seg);
        }
    }
    out
}

/// Absolute difference of two angles, in [0, π].
#[inline]
fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * PI);
    if d > PI {
        2.0 * PI - d
    } else {
        d
    }
}

/// The segment of a region: weighted centroid and principal axis; `None` when the axis is not
/// across the region's gradient, the rectangle is too short or too sparsely covered.
fn fit(
    region: &[u32],
    mag: &[f32],
    w: usize,
    theta: f64,
    tol: f64,
    min_len: f64,
    min_density: f64,
) -> Option<Segment> {
    let (mut sw, mut sx, mut sy) = (0.0, 0.0, 0.0);
    for &q in region {
        let q = q as usize;
        let m = mag[q] as f64;
        sw += m;
        sx += m * ((q % w) as f64 + 0.5);
        sy += m * ((q / w) as f64 + 0.5);
    }
    if sw <= 0.0 {
        return None;
    }
    let (cx, cy) = (sx / sw, sy / sw);
    let (mut ixx, mut iyy, mut ixy) = (0.0, 0.0, 0.0);
    for &q in region {
        let q = q as usize;
        let m = mag[q] as f64;
        let (dx, dy) = ((q % w) as f64 + 0.5 - cx, (q / w) as f64 + 0.5 - cy);
        ixx += m * dx * dx;
        iyy += m * dy * dy;
        ixy += m * dx * dy;
    }
    // direction of largest spread
    let phi = 0.5 * (2.0 * ixy).atan2(ixx - iyy);
    let (dx, dy) = (phi.cos(), phi.sin());
    // the edge runs across its gradient
    if angle_diff(phi, theta + PI / 2.0).min(angle_diff(phi, theta - PI / 2.0)) > tol {
        return None;
    }
    let (mut l0, mut l1, mut n0, mut n1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &q in region {
        let q = q as usize;
        let (px, py) = ((q % w) as f64 + 0.5 - cx, (q / w) as f64 + 0.5 - cy);
        let l = px * dx + py * dy;
        let n = -px * dy + py * dx;
        l0 = l0.min(l);
        l1 = l1.max(l);
        n0 = n0.min(n);
        n1 = n1.max(n);
    }
    let (len, wid) = (l1 - l0 + 1.0, n1 - n0 + 1.0);
    let density = region.len() as f64 / (len * wid);
    if l1 - l0 < min_len || density < min_density || len < 2.5 * wid {
        return None;
    }
    Some(Segment {
        a: [cx + l0 * dx, cy + l0 * dy],
        b: [cx + l1 * dx, cy + l1 * dy],
        strength: sw / region.len() as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dark rectangle on a light ground: its four sides come back as segments.
    #[test]
    fn a_rectangle_gives_its_four_sides() {
        let (w, h) = (120u32, 100u32);
        let mut data = vec![200u8; (w * h) as usize];
        for y in 20..80 {
            for x in 30..90 {
                data[(y * w + x) as usize] = 60;
            }
        }
        let segs = detect(&Gray {
            width: w,
            height: h,
            data,
        });
        assert_eq!(segs.len(), 4, "{segs:?}");
        let vertical = segs
            .iter()
            .filter(|s| (s.angle() - PI / 2.0).abs() < 0.02)
            .count();
        let horizontal = segs
            .iter()
            .filter(|s| s.angle() < 0.02 || s.angle() > PI - 0.02)
            .count();
        assert_eq!((vertical, horizontal), (2, 2), "{segs:?}");
        for s in &segs {
            assert!(s.length() > 50.0 && s.length() < 64.0, "{s:?}");
        }
        // the left side lies on the edge between columns 29 and 30
        let left = segs
            .iter()
            .find(|s| (s.angle() - PI / 2.0).abs() < 0.02 && s.midpoint()[0] < 60.0);
        let mid = left.map(|s| s.midpoint()[0]).unwrap_or(0.0);
        assert!((mid - 30.0).abs() < 0.6, "{mid}");
    }

    #[test]
    fn degenerate_images_have_no_segments() {
        for (w, h) in [(0, 0), (1, 1), (4, 50), (50, 4)] {
            let g = Gray {
                width: w,
                height: h,
                data: vec![7; (w * h) as usize],
            };
            assert!(detect(&g).is_empty());
        }
        let flat = Gray {
            width: 64,
            height: 64,
            data: vec![128; 64 * 64],
        };
        assert!(detect(&flat).is_empty());
        // data shorter than the stated size: no panic
        let bad = Gray {
            width: 64,
            height: 64,
            data: vec![0; 10],
        };
        assert!(detect(&bad).is_empty());
    }
}
