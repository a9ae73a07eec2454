//! Binary morphology of masks (row-major `bool`s): the 3 × 3 opening (erosion, then
//! dilation), pixels outside the image counting as unset. Runs on `imageproc`'s distance-
//! transform morphology (L∞, radius 1) over the mask with a one-pixel unset border, which
//! gives what the 3 × 3 minimum and maximum give.

use image::GrayImage;
use imageproc::distance_transform::Norm;
use imageproc::morphology::open_mut;

/// The 3 × 3 opening of `mask` (`w × h`, row-major): set where a 3 × 3 square of set pixels,
/// wholly inside the image, covers the pixel. Removes lines and specks under 3 pixels wide.
pub fn open_3x3(mask: &[bool], w: usize, h: usize) -> Vec<bool> {
    let (pw, ph) = (w as u32 + 2, h as u32 + 2);
    let mut padded = GrayImage::new(pw, ph);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        padded.put_pixel((i % w) as u32 + 1, (i / w) as u32 + 1, image::Luma([255]));
    }
    open_mut(&mut padded, Norm::LInf, 1);
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h as u32 {
        out.extend((0..w as u32).map(|x| padded.get_pixel(x + 1, y + 1)[0] > 0));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Lcg64;

    /// The hand-written opening this replaced.
    fn reference(m: &[bool], w: usize, h: usize) -> Vec<bool> {
        let morph = |m: &[bool], erode: bool| {
            let mut out = vec![false; w * h];
            for y in 0..h {
                for x in 0..w {
                    let (mut all, mut any) = (true, false);
                    for dy in -1i64..=1 {
                        for dx in -1i64..=1 {
                            let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                            let v = nx >= 0
                                && ny >= 0
                                && nx < w as i64
                                && ny < h as i64
                                && m[ny as usize * w + nx as usize];
                            all &= v;
                            any |= v;
                        }
                    }
                    out[y * w + x] = if erode { all } else { any };
                }
            }
            out
        };
        morph(&morph(m, true), false)
    }

    #[test]
    fn the_opening_is_the_3x3_minimum_then_maximum() {
        let mut rng = Lcg64::new(5);
        for (w, h, density) in [
            (40, 30, 0.8),
            (17, 9, 0.95),
            (3, 3, 1.0),
            (1, 5, 1.0),
            (25, 25, 0.5),
        ] {
            let mask: Vec<bool> = (0..w * h)
                .map(|_| ((rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64) < density)
                .collect();
            assert_eq!(open_3x3(&mask, w, h), reference(&mask, w, h), "{w}×{h}");
        }
    }
}
