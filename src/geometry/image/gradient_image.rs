//! The float grey image that photometric fitting samples: luma of an RGB frame (or half of a
//! finer level), Gaussian-smoothed, with its central-difference gradients, and bilinear
//! samples of the value and the gradient.

use image::RgbImage;

use super::filters::{central_differences, gaussian_blur, half_size};
use crate::geometry::image::Gray;

/// A float grey image (0..255) with its gradient images.
#[derive(Clone, Debug, Default)]
pub struct GradientImage {
    /// Values.
    pub value: Gray<f32>,
    /// ∂/∂x (central differences), row-major as `value`.
    pub gx: Vec<f32>,
    /// ∂/∂y.
    pub gy: Vec<f32>,
}

impl GradientImage {
    /// Luma (Rec. 601 weights) of `img`, smoothed by a Gaussian of `sigma` pixels (none when
    /// `sigma < 0.3`), with gradients. Reuses this image's buffers.
    pub fn set_from_rgb(&mut self, img: &RgbImage, sigma: f64) {
        self.value.set_luma_of(img);
        self.smooth_and_differentiate(sigma);
    }

    /// Half the resolution of `src` (2×2 means of its values; the centre of pixel `(x, y)` here
    /// is `(2x + 0.5, 2y + 0.5)` there, as a camera scaled by ½), smoothed by `sigma`, with
    /// gradients.
    pub fn set_half_of(&mut self, src: &GradientImage, sigma: f64) {
        let v = &src.value;
        let (w, h) = half_size(
            &v.data,
            v.width as usize,
            v.height as usize,
            &mut self.value.data,
        );
        self.value.width = w as u32;
        self.value.height = h as u32;
        self.smooth_and_differentiate(sigma);
    }

    fn smooth_and_differentiate(&mut self, sigma: f64) {
        if sigma >= 0.3 {
            self.value = gaussian_blur(&self.value, sigma);
        }
        central_differences(&self.value, &mut self.gx, &mut self.gy);
    }

    /// Width, pixels.
    #[inline]
    pub fn width(&self) -> usize {
        self.value.width as usize
    }

    /// Height, pixels.
    #[inline]
    pub fn height(&self) -> usize {
        self.value.height as usize
    }

    /// The top-left pixel of the cell holding `(x, y)` and the fractions across it; `None`
    /// outside the image (one pixel of margin).
    #[inline]
    fn cell(&self, x: f64, y: f64) -> Option<(usize, f32, f32)> {
        let w = self.width();
        if !(x >= 0.0 && y >= 0.0 && x < (w - 1) as f64 && y < (self.height() - 1) as f64) {
            return None;
        }
        let (x0, y0) = (x as usize, y as usize);
        let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
        Some((y0 * w + x0, fx, fy))
    }

    /// Bilinear interpolation of `b` (row-major as this image) in the cell of [`Self::cell`].
    #[inline]
    fn lerp(&self, b: &[f32], (i, fx, fy): (usize, f32, f32)) -> f32 {
        let w = self.width();
        let top = b[i] + (b[i + 1] - b[i]) * fx;
        let bottom = b[i + w] + (b[i + w + 1] - b[i + w]) * fx;
        top + (bottom - top) * fy
    }

    /// Bilinear value and gradient at pixel coordinates `(x, y)` (the centre of the top-left
    /// pixel is `(0, 0)`); `None` outside the image (one pixel of margin).
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> Option<(f32, f32, f32)> {
        let c = self.cell(x, y)?;
        Some((
            self.lerp(&self.value.data, c),
            self.lerp(&self.gx, c),
            self.lerp(&self.gy, c),
        ))
    }

    /// Bilinear value only.
    #[inline]
    pub fn value_at(&self, x: f64, y: f64) -> Option<f32> {
        let c = self.cell(x, y)?;
        Some(self.lerp(&self.value.data, c))
    }
}
