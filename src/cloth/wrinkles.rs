//! Measures of a compressed cloth: how many stretch springs stay compressed (a cloth without a
//! buckling model gets stuck compressed instead of wrinkling), and the wrinkles along a line of
//! a grid cloth (half-waves, wavelength, amplitude).

use super::elements::SpringKind;
use super::model::ClothModel;
use crate::geometry::Vec3;

/// Compressed stretch springs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compression {
    /// Stretch springs in the model.
    pub springs: usize,
    /// Those shorter than (1 − strain) × their rest length.
    pub compressed: usize,
}

impl Compression {
    /// Share of the stretch springs compressed (0–1).
    pub fn fraction(&self) -> f64 {
        self.compressed as f64 / self.springs.max(1) as f64
    }
}

/// Counts the stretch springs of `model` at positions `x` compressed by more than `strain`.
pub fn compressed_springs(model: &ClothModel, x: &[Vec3], strain: f64) -> Compression {
    let mut c = Compression {
        springs: 0,
        compressed: 0,
    };
    for s in &model.springs {
        if let SpringKind::Stretch { .. } = s.kind {
            c.springs += 1;
            if (x[s.b] - x[s.a]).norm() < (1.0 - strain) * s.rest {
                c.compressed += 1;
            }
        }
    }
    c
}

/// Wrinkles along one line of particles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wrinkles {
    /// Half-waves: runs of the height profile above or below its mean by more than the
    /// threshold (a crest or a trough each).
    pub half_waves: usize,
    /// Mean wavelength (m): twice the line's span over the half-waves; infinite if none.
    pub wavelength: f64,
    /// Half the height range of the profile (m).
    pub amplitude: f64,
}

/// The wrinkles along the line of particles `line` (in order), heights measured along `up`:
/// the profile's deviation from its mean is followed with hysteresis `threshold` (m), so
/// ripples smaller than it do not count.
pub fn wrinkles_along(x: &[Vec3], line: &[usize], up: Vec3, threshold: f64) -> Wrinkles {
    if line.len() < 2 {
        return Wrinkles {
            half_waves: 0,
            wavelength: f64::INFINITY,
            amplitude: 0.0,
        };
    }
    let h: Vec<f64> = line.iter().map(|&i| x[i].dot(&up)).collect();
    let mean = h.iter().sum::<f64>() / h.len() as f64;
    let (lo, hi) = h
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    // state: 0 undecided, +1 above, −1 below
    let mut state = 0;
    let mut half_waves = 0;
    for v in &h {
        let d = v - mean;
        let next = if d > threshold {
            1
        } else if d < -threshold {
            -1
        } else {
            state
        };
        if next != state && next != 0 {
            half_waves += 1;
            state = next;
        }
    }
    let ends = (x[line[line.len() - 1]] - x[line[0]]).norm();
    Wrinkles {
        half_waves,
        wavelength: if half_waves > 0 {
            2.0 * ends / half_waves as f64
        } else {
            f64::INFINITY
        },
        amplitude: 0.5 * (hi - lo),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sine_profile_gives_its_wavelength() {
        // three full waves over 0.3 m, amplitude 5 mm
        let x: Vec<Vec3> = (0..301)
            .map(|k| {
                let s = k as f64 * 0.001;
                Vec3::new(s, 0.0, 0.005 * (2.0 * std::f64::consts::PI * s / 0.1).sin())
            })
            .collect();
        let line: Vec<usize> = (0..x.len()).collect();
        let w = wrinkles_along(&x, &line, Vec3::z(), 0.001);
        assert_eq!(w.half_waves, 6);
        assert!((w.wavelength - 0.1).abs() < 1e-9);
        assert!((w.amplitude - 0.005).abs() < 1e-6);
        // ripples below the threshold are no wrinkles
        assert_eq!(wrinkles_along(&x, &line, Vec3::z(), 0.01).half_waves, 0);
    }
}
