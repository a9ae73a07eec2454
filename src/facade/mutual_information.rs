//! Mutual information between two equally sized image regions (Müller et al. 2007 §2.1): the
//! joint histogram of co-located pixel pairs, quantised to [`BINS`] grey levels (256 bins make
//! the histogram of a small band sparse and bias MI upwards), and
//! MI = (1/N) Σ n_ab ln(N n_ab / (n_a n_b)). MI rather than a pixel difference, so that floors
//! lit differently still match.

use crate::geometry::image::Gray;

/// Grey levels of the histograms.
pub const BINS: usize = 32;

/// Reusable joint and marginal histograms.
#[derive(Debug, Clone)]
pub struct MiWorkspace {
    joint: Vec<u32>,
    a: Vec<u32>,
    b: Vec<u32>,
    /// Pixel pairs are sampled every `stride` rows and columns of the bands (1: all).
    pub stride: usize,
}

impl Default for MiWorkspace {
    fn default() -> Self {
        MiWorkspace {
            joint: vec![0; BINS * BINS],
            a: vec![0; BINS],
            b: vec![0; BINS],
            stride: 1,
        }
    }
}

#[inline]
fn bin(v: u8) -> usize {
    v as usize * BINS / 256
}

impl MiWorkspace {
    /// A workspace sampling every `stride`-th row and column of the bands.
    pub fn with_stride(stride: usize) -> Self {
        MiWorkspace {
            stride: stride.max(1),
            ..MiWorkspace::default()
        }
    }

    /// MI of the horizontal bands `[y1, y1 + h)` and `[y2, y2 + h)` (full width).
    pub fn rows(&mut self, img: &Gray, y1: u32, y2: u32, h: u32) -> f64 {
        let w = img.width as usize;
        self.clear();
        for k in (0..h as usize).step_by(self.stride) {
            let (r1, r2) = ((y1 as usize + k) * w, (y2 as usize + k) * w);
            for x in (0..w).step_by(self.stride) {
                self.add(img.data[r1 + x], img.data[r2 + x]);
            }
        }
        self.value()
    }

    /// MI of the vertical bands `[x1, x1 + w)` and `[x2, x2 + w)` over rows `y0..y1`.
    pub fn columns(&mut self, img: &Gray, x1: u32, x2: u32, w: u32, y0: u32, y1: u32) -> f64 {
        let iw = img.width as usize;
        self.clear();
        for y in (y0 as usize..y1 as usize).step_by(self.stride) {
            let row = y * iw;
            for k in (0..w as usize).step_by(self.stride) {
                self.add(
                    img.data[row + x1 as usize + k],
                    img.data[row + x2 as usize + k],
                );
            }
        }
        self.value()
    }

    fn clear(&mut self) {
        self.joint.fill(0);
        self.a.fill(0);
        self.b.fill(0);
    }

    #[inline]
    fn add(&mut self, p: u8, q: u8) {
        let (i, j) = (bin(p), bin(q));
        self.joint[i * BINS + j] += 1;
        self.a[i] += 1;
        self.b[j] += 1;
    }

    fn value(&self) -> f64 {
        let n: u64 = self.a.iter().map(|&c| c as u64).sum();
        if n == 0 {
            return 0.0;
        }
        let nf = n as f64;
        let mut mi = 0.0;
        for i in 0..BINS {
            if self.a[i] == 0 {
                continue;
            }
            for j in 0..BINS {
                let c = self.joint[i * BINS + j];
                if c > 0 {
                    let c = c as f64;
                    mi += c * (nf * c / (self.a[i] as f64 * self.b[j] as f64)).ln();
                }
            }
        }
        mi / nf
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Lcg64;

    fn noise(width: u32, height: u32, seed: u64) -> Gray {
        let mut rng = Lcg64::new(seed);
        let data = (0..width * height)
            .map(|_| (rng.next_u64() >> 56) as u8)
            .collect();
        Gray {
            width,
            height,
            data,
        }
    }

    #[test]
    fn a_band_shares_all_its_information_with_itself_and_little_with_noise() {
        let img = noise(64, 40, 7);
        let mut ws = MiWorkspace::default();
        // identical bands: MI = entropy of the quantised band, near ln 32 for uniform noise
        let same = ws.rows(&img, 0, 0, 20);
        assert!(
            same > 0.9 * (BINS as f64).ln() && same <= (BINS as f64).ln() + 1e-12,
            "{same}"
        );
        // independent noise: small (positive bias of a finite sample only)
        let other = ws.rows(&img, 0, 20, 20);
        assert!(other < 0.25 * same, "{other} vs {same}");
        // a band and its inverse are as informative as identical ones
        let mut inv = img.clone();
        for v in &mut inv.data[20 * 64..] {
            *v = 255 - *v;
        }
        for k in 0..20 * 64 {
            inv.data[20 * 64 + k] = 255 - img.data[k];
        }
        let mirrored = ws.rows(&inv, 0, 20, 20);
        assert!((mirrored - same).abs() < 1e-9, "{mirrored} vs {same}");
        // columns: the same measure on vertical bands
        let c = ws.columns(&img, 3, 3, 10, 0, 40);
        assert!(c > 0.9 * (BINS as f64).ln());
    }
}
