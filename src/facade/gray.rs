//! Grayscale images for the structure analysis: 8-bit Rec. 601 luma, row-major, as the
//! mutual-information search reads them.

use std::path::Path;

use super::error::FacadeError;

/// An 8-bit grayscale image.
#[derive(Debug, Clone, PartialEq)]
pub struct Gray {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Luma of pixel (x, y) at `y · width + x`.
    pub data: Vec<u8>,
}

impl Gray {
    /// Reads a photo (JPEG or PNG) and converts it to luma.
    pub fn read(path: &Path) -> Result<Self, FacadeError> {
        Ok(Gray::from_rgb(&read_rgb(path)?))
    }

    /// The luma of a colour image (0.299 R + 0.587 G + 0.114 B, rounded).
    pub fn from_rgb(img: &image::RgbImage) -> Self {
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
    /// total width `noise`, drawn pixel by pixel in row order from `seed` (a 64-bit LCG),
    /// clamped to 0–255.
    pub fn painted(
        width: u32,
        height: u32,
        seed: u64,
        noise: f64,
        base: impl Fn(u32, u32) -> f64,
    ) -> Self {
        let mut s = seed;
        let mut data = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let n = ((s >> 40) as f64 / (1u64 << 24) as f64 - 0.5) * noise;
                data.push((base(x, y) + n).clamp(0.0, 255.0) as u8);
            }
        }
        Gray {
            width,
            height,
            data,
        }
    }

    /// Luma at (x, y).
    #[inline]
    pub fn at(&self, x: u32, y: u32) -> u8 {
        self.data[y as usize * self.width as usize + x as usize]
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

/// Reads an image file (JPEG or PNG) as 8-bit RGB, errors naming the file.
pub(crate) fn read_rgb(path: &Path) -> Result<image::RgbImage, FacadeError> {
    Ok(image::open(path)
        .map_err(|e| FacadeError::File {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?
        .to_rgb8())
}
