//! Grey images: one type, [`Gray`], row-major pixels of any channel type — 8-bit luma as the
//! facade pipeline reads photos (rounded Rec. 601), float luma as photometric fitting smooths
//! and samples it — with reading photos, luma, synthetic pictures and bilinear samples.

use std::path::Path;

use image::RgbImage;

use crate::geometry::{GeometryError, Lcg64};

/// A grey image: `width × height` pixels, row-major.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Gray<T = u8> {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Pixel (x, y) at `y · width + x`.
    pub data: Vec<T>,
}

impl<T: Copy> Gray<T> {
    /// Pixel at (x, y).
    #[inline]
    pub fn at(&self, x: u32, y: u32) -> T {
        self.data[y as usize * self.width as usize + x as usize]
    }
}

impl Gray<u8> {
    /// Reads a photo (JPEG or PNG) and converts it to luma.
    pub fn read(path: &Path) -> Result<Self, GeometryError> {
        Ok(Gray::from_rgb(&read_rgb(path)?))
    }

    /// The luma of a colour image (0.299 R + 0.587 G + 0.114 B, rounded).
    pub fn from_rgb(img: &RgbImage) -> Self {
        let data = img
            .pixels()
            .map(|p| {
                let [r, g, b] = p.0;
                (0.299 * r as f64 + 0.587 * g as f64 + 0.114 * b as f64).round() as u8
            })
            .collect();
        Gray {
            width: img.width(),
            height: img.height(),
            data,
        }
    }

    /// A synthetic picture (for tests and demonstrations): `base(x, y)` plus uniform noise of
    /// total width `noise`, drawn pixel by pixel in row order from `seed` ([`Lcg64`]),
    /// clamped to 0–255.
    pub fn painted(
        width: u32,
        height: u32,
        seed: u64,
        noise: f64,
        base: impl Fn(u32, u32) -> f64,
    ) -> Self {
        let mut rng = Lcg64::new(seed);
        let mut data = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                let n = ((rng.next_u64() >> 40) as f64 / (1u64 << 24) as f64 - 0.5) * noise;
                data.push((base(x, y) + n).clamp(0.0, 255.0) as u8);
            }
        }
        Gray {
            width,
            height,
            data,
        }
    }

    /// Bilinear sample at continuous pixel index (u, v) (pixel k's centre at k), `None`
    /// outside.
    pub fn bilinear(&self, u: f64, v: f64) -> Option<f64> {
        let (w, h) = (self.width as f64, self.height as f64);
        if !(u >= -0.5 && v >= -0.5 && u <= w - 0.5 && v <= h - 0.5) {
            return None;
        }
        let (u, v) = (u.clamp(0.0, w - 1.0), v.clamp(0.0, h - 1.0));
        let (x0, y0) = (u.floor() as u32, v.floor() as u32);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (fx, fy) = (u - x0 as f64, v - y0 as f64);
        let p = |x, y| self.at(x, y) as f64;
        Some(
            p(x0, y0) * (1.0 - fx) * (1.0 - fy)
                + p(x1, y0) * fx * (1.0 - fy)
                + p(x0, y1) * (1.0 - fx) * fy
                + p(x1, y1) * fx * fy,
        )
    }
}

impl Gray<f32> {
    /// The float luma ([`luma`]) of a colour image, not rounded; reuses this image's buffer.
    pub fn set_luma_of(&mut self, img: &RgbImage) {
        self.width = img.width();
        self.height = img.height();
        self.data.clear();
        self.data.extend(
            img.pixels()
                .map(|p| luma([p[0] as f32, p[1] as f32, p[2] as f32])),
        );
    }
}

/// Rec. 601 luma of an RGB pixel: 0.299 R + 0.587 G + 0.114 B.
#[inline]
pub fn luma(rgb: [f32; 3]) -> f32 {
    0.299 * rgb[0] + 0.587 * rgb[1] + 0.114 * rgb[2]
}

/// Reads a photo as 8-bit RGB, any of the formats of
/// [`PHOTO_EXTENSIONS`](super::photo_formats::PHOTO_EXTENSIONS); the error names the file
/// ([`read_photo`](super::photo_formats::read_photo)).
pub fn read_rgb(path: &Path) -> Result<RgbImage, GeometryError> {
    super::photo_formats::read_photo(path)
}
