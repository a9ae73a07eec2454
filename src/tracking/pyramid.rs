//! Images as the tracker sees them: linear float RGB levels of an image pyramid (each level
//! half the size of the one below, 2×2 box averages), bilinear sampling, the per-camera
//! background model (per-pixel temporal median of frames spread over the sequence) and the
//! global lighting gain of a frame against that background.

use image::RgbImage;

use crate::geometry::image::filters::half_size;
use crate::geometry::image::luma;

/// One pyramid level: `width × height` RGB pixels, row-major, values in 0..255.
#[derive(Clone, Debug, Default)]
pub struct Level {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Pixels, row-major.
    pub rgb: Vec<[f32; 3]>,
}

impl Level {
    /// The level of an 8-bit image.
    pub fn from_image(img: &RgbImage) -> Level {
        let mut level = Level::default();
        level.set_from_image(img);
        level
    }

    /// Refills this level from an 8-bit image (reusing its buffer).
    pub fn set_from_image(&mut self, img: &RgbImage) {
        self.width = img.width() as usize;
        self.height = img.height() as usize;
        self.rgb.clear();
        self.rgb.extend(
            img.pixels()
                .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]),
        );
    }

    /// The next coarser level: 2×2 box means (a trailing odd row or column is dropped).
    pub fn half_into(&self, out: &mut Level) {
        (out.width, out.height) = half_size(&self.rgb, self.width, self.height, &mut out.rgb);
    }

    /// Bilinear colour at pixel coordinates `(x, y)`, in the cameras' and the rasteriser's
    /// convention: pixel `(i, j)` is centred on `(i, j)`. `None` outside the image.
    pub fn sample(&self, x: f64, y: f64) -> Option<[f32; 3]> {
        let (fx, fy) = (x, y);
        if !(fx >= 0.0 && fy >= 0.0) {
            return None;
        }
        let (x0, y0) = (fx as usize, fy as usize);
        if x0 + 1 >= self.width || y0 + 1 >= self.height {
            return None;
        }
        let (tx, ty) = ((fx - x0 as f64) as f32, (fy - y0 as f64) as f32);
        let i = y0 * self.width + x0;
        let (a, b, c, d) = (
            self.rgb[i],
            self.rgb[i + 1],
            self.rgb[i + self.width],
            self.rgb[i + self.width + 1],
        );
        Some(std::array::from_fn(|k| {
            (a[k] * (1.0 - tx) + b[k] * tx) * (1.0 - ty) + (c[k] * (1.0 - tx) + d[k] * tx) * ty
        }))
    }

    /// Multiplies every pixel by `factor`.
    pub fn scale(&mut self, factor: f32) {
        for p in &mut self.rgb {
            for c in p.iter_mut() {
                *c *= factor;
            }
        }
    }
}

/// Builds levels `0..count` of `img` into `out` (reusing buffers): level 0 is the image.
pub fn build_pyramid(img: &RgbImage, count: usize, out: &mut Vec<Level>) {
    out.resize_with(count.max(1), Level::default);
    out[0].set_from_image(img);
    for l in 1..out.len() {
        let (lower, upper) = out.split_at_mut(l);
        lower[l - 1].half_into(&mut upper[0]);
    }
}

/// Per-pixel, per-channel median of `frames` (all of the same size): the background of a
/// static camera, as long as the person moves or covers each pixel in under half the frames.
pub fn median_background(frames: &[&RgbImage]) -> Level {
    let Some(first) = frames.first() else {
        return Level::default();
    };
    let (w, h) = (first.width() as usize, first.height() as usize);
    let mut rgb = vec![[0.0f32; 3]; w * h];
    let mut samples = Vec::with_capacity(frames.len());
    for (i, px) in rgb.iter_mut().enumerate() {
        let (x, y) = ((i % w) as u32, (i / w) as u32);
        for (c, out) in px.iter_mut().enumerate() {
            samples.clear();
            samples.extend(frames.iter().map(|f| f.get_pixel(x, y)[c]));
            samples.sort_unstable();
            let n = samples.len();
            *out = if n % 2 == 1 {
                samples[n / 2] as f32
            } else {
                0.5 * (samples[n / 2 - 1] as f32 + samples[n / 2] as f32)
            };
        }
    }
    Level {
        width: w,
        height: h,
        rgb,
    }
}

/// Global lighting gain of `image` against `background` (same size): the median ratio of
/// their luminances over pixels bright enough to measure it. The person covers a small part
/// of the picture, so the median ignores it. 1 when nothing can be measured.
pub fn lighting_gain(image: &Level, background: &Level, scratch: &mut Vec<f32>) -> f32 {
    scratch.clear();
    if image.rgb.len() != background.rgb.len() {
        return 1.0;
    }
    // every other pixel of every other row is plenty
    for y in (0..image.height).step_by(2) {
        for x in (0..image.width).step_by(2) {
            let i = y * image.width + x;
            let b = luma(background.rgb[i]);
            if b > 20.0 {
                scratch.push(luma(image.rgb[i]) / b);
            }
        }
    }
    if scratch.is_empty() {
        return 1.0;
    }
    let mid = scratch.len() / 2;
    let (_, m, _) = scratch.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    *m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_and_sample() {
        let img = RgbImage::from_fn(4, 2, |x, _| image::Rgb([(x * 10) as u8, 0, 0]));
        let l = Level::from_image(&img);
        let mut h = Level::default();
        l.half_into(&mut h);
        assert_eq!((h.width, h.height), (2, 1));
        assert_eq!(h.rgb[0][0], 5.0);
        assert_eq!(h.rgb[1][0], 25.0);
        // on pixel centre 1, and halfway between pixel centres 0 and 1
        assert_eq!(l.sample(1.0, 0.0).unwrap()[0], 10.0);
        assert_eq!(l.sample(0.5, 0.0).unwrap()[0], 5.0);
        assert!(l.sample(3.5, 0.0).is_none());
        assert!(l.sample(-0.1, 0.0).is_none());
    }

    #[test]
    fn median_ignores_a_passing_object() {
        let bg = RgbImage::from_pixel(3, 3, image::Rgb([50, 60, 70]));
        let mut fg = bg.clone();
        fg.put_pixel(1, 1, image::Rgb([255, 0, 0]));
        let m = median_background(&[&bg, &fg, &bg]);
        assert_eq!(m.rgb[4], [50.0, 60.0, 70.0]);
        let mut bright = Level::from_image(&bg);
        bright.scale(1.2);
        let g = lighting_gain(&bright, &m, &mut Vec::new());
        assert!((g - 1.2).abs() < 1e-5);
    }
}
