//! Grey-level images for photometric fitting: luma of an RGB frame, Gaussian smoothing, and
//! bilinear samples of the value and its gradient.

use image::RgbImage;

/// A grey image (0..255) with its gradient images.
#[derive(Clone, Debug, Default)]
pub struct GrayImage {
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// Values, row-major.
    pub value: Vec<f32>,
    /// ∂/∂x (central differences).
    pub gx: Vec<f32>,
    /// ∂/∂y.
    pub gy: Vec<f32>,
}

impl GrayImage {
    /// Luma (Rec. 601 weights) of `img`, smoothed by a Gaussian of `sigma` pixels (none when
    /// `sigma < 0.3`), with gradients. Reuses this image's buffers.
    pub fn set_from_rgb(&mut self, img: &RgbImage, sigma: f64, scratch: &mut Vec<f32>) {
        let (w, h) = (img.width() as usize, img.height() as usize);
        self.width = w;
        self.height = h;
        self.value.clear();
        self.value.extend(
            img.pixels()
                .map(|p| 0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32),
        );
        if sigma >= 0.3 {
            blur(&mut self.value, w, h, sigma, scratch);
        }
        self.gradients();
    }

    /// Half the resolution of `src` (2×2 means of its values; the centre of pixel `(x, y)` here is
    /// `(2x + 0.5, 2y + 0.5)` there, as [`Camera::scaled`](crate::tracking::camera::Camera::scaled)
    /// with factor 2), smoothed by `sigma`, with gradients.
    pub fn set_half_of(&mut self, src: &GrayImage, sigma: f64, scratch: &mut Vec<f32>) {
        let (w, h) = (src.width / 2, src.height / 2);
        self.width = w;
        self.height = h;
        self.value.clear();
        for y in 0..h {
            for x in 0..w {
                let i = 2 * y * src.width + 2 * x;
                let v = &src.value;
                self.value
                    .push(0.25 * (v[i] + v[i + 1] + v[i + src.width] + v[i + src.width + 1]));
            }
        }
        if sigma >= 0.3 {
            blur(&mut self.value, w, h, sigma, scratch);
        }
        self.gradients();
    }

    fn gradients(&mut self) {
        let (w, h) = (self.width, self.height);
        self.gx.resize(w * h, 0.0);
        self.gy.resize(w * h, 0.0);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let (xl, xr) = (x.saturating_sub(1), (x + 1).min(w - 1));
                let (yu, yd) = (y.saturating_sub(1), (y + 1).min(h - 1));
                self.gx[i] =
                    (self.value[y * w + xr] - self.value[y * w + xl]) / (xr - xl).max(1) as f32;
                self.gy[i] =
                    (self.value[yd * w + x] - self.value[yu * w + x]) / (yd - yu).max(1) as f32;
            }
        }
    }

    /// Bilinear value and gradient at pixel coordinates `(x, y)` (the centre of the top-left
    /// pixel is `(0, 0)`); `None` outside the image (one pixel of margin).
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> Option<(f32, f32, f32)> {
        if !(x >= 0.0 && y >= 0.0 && x < (self.width - 1) as f64 && y < (self.height - 1) as f64) {
            return None;
        }
        let (x0, y0) = (x as usize, y as usize);
        let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
        let i = y0 * self.width + x0;
        let w = self.width;
        let lerp = |b: &[f32]| {
            let top = b[i] + (b[i + 1] - b[i]) * fx;
            let bottom = b[i + w] + (b[i + w + 1] - b[i + w]) * fx;
            top + (bottom - top) * fy
        };
        Some((lerp(&self.value), lerp(&self.gx), lerp(&self.gy)))
    }

    /// Bilinear value only.
    #[inline]
    pub fn value_at(&self, x: f64, y: f64) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0 && x < (self.width - 1) as f64 && y < (self.height - 1) as f64) {
            return None;
        }
        let (x0, y0) = (x as usize, y as usize);
        let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
        let i = y0 * self.width + x0;
        let b = &self.value;
        let top = b[i] + (b[i + 1] - b[i]) * fx;
        let bottom = b[i + self.width] + (b[i + self.width + 1] - b[i + self.width]) * fx;
        Some(top + (bottom - top) * fy)
    }
}

/// Separable Gaussian blur in place (kernel radius 3σ, edges clamped).
fn blur(v: &mut [f32], w: usize, h: usize, sigma: f64, tmp: &mut Vec<f32>) {
    let r = (3.0 * sigma).ceil() as i64;
    let k: Vec<f32> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp() as f32)
        .collect();
    let s: f32 = k.iter().sum();
    let k: Vec<f32> = k.iter().map(|x| x / s).collect();
    tmp.resize(w * h, 0.0);
    for y in 0..h {
        for x in 0..w {
            let mut acc = 0.0;
            for (j, kk) in k.iter().enumerate() {
                let xx = (x as i64 + j as i64 - r).clamp(0, w as i64 - 1) as usize;
                acc += kk * v[y * w + xx];
            }
            tmp[y * w + x] = acc;
        }
    }
    for y in 0..h {
        for x in 0..w {
            let mut acc = 0.0;
            for (j, kk) in k.iter().enumerate() {
                let yy = (y as i64 + j as i64 - r).clamp(0, h as i64 - 1) as usize;
                acc += kk * tmp[yy * w + x];
            }
            v[y * w + x] = acc;
        }
    }
}
