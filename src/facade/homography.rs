//! Plane homographies for rectification: the homography of four point correspondences (the
//! direct linear transform, Hartley–Zisserman alg. 4.1 with normalised coordinates), the
//! rectifying homography of a facade quadrilateral, and warping images and label maps through
//! it (bilinear for photos, nearest for labels, so classes never blend).

use image::RgbImage;
use nalgebra::{DMatrix, Matrix3, Vector3};

use super::labels::{Class, LabelMap};
use crate::geometry::image::Gray;

/// A 3×3 homography acting on homogeneous pixel coordinates (x, y, 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Homography(pub Matrix3<f64>);

impl Homography {
    /// Maps a point; `None` when it goes to infinity.
    pub fn apply(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let q = self.0 * Vector3::new(p[0], p[1], 1.0);
        (q.z.abs() > 1e-12).then(|| [q.x / q.z, q.y / q.z])
    }

    /// The inverse map, if the matrix is invertible.
    pub fn inverse(&self) -> Option<Homography> {
        self.0.try_inverse().map(Homography)
    }

    /// The homography taking each `from[k]` to `to[k]` (four points, no three collinear), or
    /// `None` for a degenerate configuration.
    pub fn from_points(from: &[[f64; 2]; 4], to: &[[f64; 2]; 4]) -> Option<Homography> {
        if has_collinear_triple(from) || has_collinear_triple(to) {
            return None;
        }
        let (tf, nf) = normalisation(from);
        let (tt, nt) = normalisation(to);
        let mut a = DMatrix::<f64>::zeros(9, 9);
        for k in 0..4 {
            let [x, y] = nf[k];
            let [u, v] = nt[k];
            let r = 2 * k;
            let row1 = [-x, -y, -1.0, 0.0, 0.0, 0.0, u * x, u * y, u];
            let row2 = [0.0, 0.0, 0.0, -x, -y, -1.0, v * x, v * y, v];
            for c in 0..9 {
                a[(r, c)] = row1[c];
                a[(r + 1, c)] = row2[c];
            }
        }
        // the 9th row stays zero: the null vector of the 8 equations is the smallest singular
        // vector of the square matrix
        let svd = a.svd(false, true);
        let vt = svd.v_t?;
        let (k, smin) =
            svd.singular_values
                .iter()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |b, (i, &s)| if s < b.1 { (i, s) } else { b },
                );
        let second = svd
            .singular_values
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != k)
            .map(|(_, &s)| s)
            .fold(f64::INFINITY, f64::min);
        let rank_deficient = second.is_nan() || second <= 1e-9 * svd.singular_values.max();
        if rank_deficient || !smin.is_finite() {
            return None;
        }
        let h = vt.row(k);
        let hn = Matrix3::new(h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], h[8]);
        let m = tt.try_inverse()? * hn * tf;
        if m[(2, 2)].abs() < 1e-300 || !m.iter().all(|v| v.is_finite()) {
            return None;
        }
        let m = m / m[(2, 2)];
        // degenerate (three points collinear): the map is singular
        (m.determinant().abs() > 1e-12).then_some(Homography(m))
    }

    /// The homography taking the facade quadrilateral `corners` (top-left, top-right,
    /// bottom-right, bottom-left, in image pixels) to an upright `width` × `height` rectangle
    /// at the origin.
    pub fn rectifying(corners: &[[f64; 2]; 4], width: f64, height: f64) -> Option<Homography> {
        Homography::from_points(
            corners,
            &[[0.0, 0.0], [width, 0.0], [width, height], [0.0, height]],
        )
    }
}

/// Whether three of the four points are (nearly) collinear: a triangle of them has an area
/// under 1e-9 of the squared spread of the points.
fn has_collinear_triple(p: &[[f64; 2]; 4]) -> bool {
    let spread = p
        .iter()
        .flat_map(|a| {
            p.iter()
                .map(move |b| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2))
        })
        .fold(0.0, f64::max);
    let area = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() * 0.5
    };
    [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)]
        .iter()
        .any(|&(i, j, k)| area(p[i], p[j], p[k]) <= 1e-9 * spread)
}

/// Hartley's normalisation: translate the points' centroid to the origin and scale their
/// mean distance to √2. Returns the transform and the normalised points.
fn normalisation(p: &[[f64; 2]; 4]) -> (Matrix3<f64>, [[f64; 2]; 4]) {
    let c = [
        p.iter().map(|q| q[0]).sum::<f64>() / 4.0,
        p.iter().map(|q| q[1]).sum::<f64>() / 4.0,
    ];
    let d = p
        .iter()
        .map(|q| ((q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2)).sqrt())
        .sum::<f64>()
        / 4.0;
    let s = if d > 0.0 { 2f64.sqrt() / d } else { 1.0 };
    let t = Matrix3::new(s, 0.0, -s * c[0], 0.0, s, -s * c[1], 0.0, 0.0, 1.0);
    let n = p.map(|q| [s * (q[0] - c[0]), s * (q[1] - c[1])]);
    (t, n)
}

/// The `width` × `height` image whose pixel centre (x + ½, y + ½) shows the source at
/// `h⁻¹`(that point), bilinear; outside the source: 0.
pub fn warp_gray(src: &Gray, h: &Homography, width: u32, height: u32) -> Option<Gray> {
    let inv = h.inverse()?;
    let mut data = Vec::with_capacity(width as usize * height as usize);
    for y in 0..height {
        for x in 0..width {
            let v = inv
                .apply([x as f64 + 0.5, y as f64 + 0.5])
                .and_then(|[u, v]| src.bilinear(u - 0.5, v - 0.5))
                .unwrap_or(0.0);
            data.push(v.round().clamp(0.0, 255.0) as u8);
        }
    }
    Some(Gray {
        width,
        height,
        data,
    })
}

/// The colour photo warped like [`warp_gray`] (bilinear per channel); outside the source:
/// black.
pub fn warp_rgb(src: &RgbImage, h: &Homography, width: u32, height: u32) -> Option<RgbImage> {
    let inv = h.inverse()?;
    let (sw, sh) = (src.width() as f64, src.height() as f64);
    let mut out = RgbImage::new(width, height);
    for (x, y, px) in out.enumerate_pixels_mut() {
        let Some([u, v]) = inv.apply([x as f64 + 0.5, y as f64 + 0.5]) else {
            continue;
        };
        let (u, v) = (u - 0.5, v - 0.5);
        if !(u >= -0.5 && v >= -0.5 && u <= sw - 0.5 && v <= sh - 0.5) {
            continue;
        }
        let (u, v) = (u.clamp(0.0, sw - 1.0), v.clamp(0.0, sh - 1.0));
        let (x0, y0) = (u.floor() as u32, v.floor() as u32);
        let (x1, y1) = (
            (x0 + 1).min(src.width() - 1),
            (y0 + 1).min(src.height() - 1),
        );
        let (fx, fy) = (u - x0 as f64, v - y0 as f64);
        for c in 0..3 {
            let p = |x, y| src.get_pixel(x, y).0[c] as f64;
            let val = p(x0, y0) * (1.0 - fx) * (1.0 - fy)
                + p(x1, y0) * fx * (1.0 - fy)
                + p(x0, y1) * (1.0 - fx) * fy
                + p(x1, y1) * fx * fy;
            px.0[c] = val.round().clamp(0.0, 255.0) as u8;
        }
    }
    Some(out)
}

/// The label map warped like [`warp_gray`], nearest pixel; outside the source: ignore.
pub fn warp_labels(src: &LabelMap, h: &Homography, width: u32, height: u32) -> Option<LabelMap> {
    let inv = h.inverse()?;
    let mut out = LabelMap::filled(width, height, Class::Ignore);
    for y in 0..height {
        for x in 0..width {
            if let Some([u, v]) = inv.apply([x as f64 + 0.5, y as f64 + 0.5]) {
                let (i, j) = (u.floor(), v.floor());
                if i >= 0.0 && j >= 0.0 && i < src.width as f64 && j < src.height as f64 {
                    out.classes[y as usize * width as usize + x as usize] =
                        src.at(i as u32, j as u32);
                }
            }
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_points_give_the_homography_that_maps_them() {
        let h = Homography(Matrix3::new(
            0.9, 0.12, 14.0, -0.05, 1.1, 7.0, 2e-4, -3e-4, 1.0,
        ));
        let from = [[10.0, 20.0], [300.0, 15.0], [320.0, 260.0], [5.0, 240.0]];
        let to = from.map(|p| h.apply(p).unwrap());
        let g = Homography::from_points(&from, &to).unwrap();
        assert!((g.0 - h.0).norm() < 1e-9 * h.0.norm(), "{}", g.0);
        // any other point follows
        let p = [123.0, 77.0];
        let (a, b) = (g.apply(p).unwrap(), h.apply(p).unwrap());
        assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
        // three collinear points: refused
        let bad = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [0.0, 5.0]];
        assert!(Homography::from_points(&bad, &to).is_none());
    }
}
