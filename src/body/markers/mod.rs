//! Marker trials: labelled 3D points sampled over time by a motion-capture system, with the
//! invalid samples flagged. Read from C3D files ([`c3d`]); the body-level data that the
//! skeleton is fitted to.
//!
//! Positions are kept in metres in the file's own axes ([`MarkerTrial::position`]); the
//! engine's frame (+Z up) is one call away ([`MarkerTrial::world`]), through the one axis
//! convention of [`crate::geometry::export_frame`].

pub mod c3d;
mod c3d_bytes;
mod c3d_params;

pub use c3d::{parse_c3d, read_c3d};

use crate::geometry::export_frame::{ExportFrame, Units, UpAxis};
use crate::geometry::Vec3;

/// A marker trial: `frames × markers` samples, each a position (metres, file axes) and a
/// residual (metres; negative = invalid sample).
#[derive(Clone, Debug)]
pub struct MarkerTrial {
    /// Where the trial came from (a file name), for messages.
    pub source: String,
    /// One label per marker, in file order.
    pub labels: Vec<String>,
    /// Sampling rate, Hz.
    pub rate: f64,
    /// Number of frames.
    pub frames: usize,
    positions: Vec<Vec3>,
    residuals: Vec<f64>,
    /// The up axis of the positions: as the file declares it (`POINT:Y_SCREEN`), which some
    /// systems get wrong (GEARS declares +Z for y-up data); set it from
    /// [`MarkerTrial::infer_up`] when in doubt.
    pub up: UpAxis,
}

impl MarkerTrial {
    /// A trial from frame-major samples (`frames × labels.len()` positions and residuals).
    pub fn new(
        source: String,
        labels: Vec<String>,
        rate: f64,
        frames: usize,
        positions: Vec<Vec3>,
        residuals: Vec<f64>,
        up: UpAxis,
    ) -> MarkerTrial {
        assert_eq!(positions.len(), frames * labels.len());
        assert_eq!(residuals.len(), positions.len());
        MarkerTrial {
            source,
            labels,
            rate,
            frames,
            positions,
            residuals,
            up,
        }
    }

    /// Every `step`-th frame from frame 0 (rate divided by `step`; `step` 0 counts as 1): a
    /// shorter trial for quick fits.
    pub fn every(&self, step: usize) -> MarkerTrial {
        let step = step.max(1);
        let m = self.labels.len();
        let keep: Vec<usize> = (0..self.frames).step_by(step).collect();
        let pick = |v: &[f64]| -> Vec<f64> {
            keep.iter()
                .flat_map(|&f| v[f * m..(f + 1) * m].iter().copied())
                .collect()
        };
        MarkerTrial {
            source: self.source.clone(),
            labels: self.labels.clone(),
            rate: self.rate / step as f64,
            frames: keep.len(),
            positions: keep
                .iter()
                .flat_map(|&f| self.positions[f * m..(f + 1) * m].iter().copied())
                .collect(),
            residuals: pick(&self.residuals),
            up: self.up,
        }
    }

    /// Number of markers.
    pub fn markers(&self) -> usize {
        self.labels.len()
    }

    /// Index of the marker labelled `label`.
    pub fn marker(&self, label: &str) -> Option<usize> {
        self.labels.iter().position(|l| l == label)
    }

    /// Whether the sample of `marker` at `frame` (0-based) is valid.
    pub fn is_valid(&self, frame: usize, marker: usize) -> bool {
        self.residuals[frame * self.markers() + marker] >= 0.0
    }

    /// The residual of a sample, metres (negative = invalid).
    pub fn residual(&self, frame: usize, marker: usize) -> f64 {
        self.residuals[frame * self.markers() + marker]
    }

    /// Position of `marker` at `frame` in metres in the file's axes; `None` if invalid.
    pub fn position(&self, frame: usize, marker: usize) -> Option<Vec3> {
        self.is_valid(frame, marker)
            .then(|| self.positions[frame * self.markers() + marker])
    }

    /// Position of `marker` at `frame` in the engine's frame (metres, +Z up); `None` if invalid.
    pub fn world(&self, frame: usize, marker: usize) -> Option<Vec3> {
        let f = ExportFrame {
            up: self.up,
            units: Units::Metres,
        };
        self.position(frame, marker).map(|p| f.to_engine(&p))
    }

    /// Number of invalid samples over all frames and markers.
    pub fn invalid_count(&self) -> usize {
        self.residuals.iter().filter(|&&r| r < 0.0).count()
    }

    /// Duration from the first to the last frame, seconds.
    pub fn duration(&self) -> f64 {
        self.frames.saturating_sub(1) as f64 / self.rate
    }

    /// The up axis the data show: Y or Z, whichever the markers spread over most in a typical
    /// frame (the median over frames of the interquartile range across markers, so that a few
    /// stray points do not count; a person is taller than wide or deep). Z when no frame has
    /// four valid markers.
    pub fn infer_up(&self) -> UpAxis {
        let (mut spread_y, mut spread_z) = (Vec::new(), Vec::new());
        let (mut ys, mut zs) = (Vec::new(), Vec::new());
        for f in 0..self.frames {
            ys.clear();
            zs.clear();
            for m in 0..self.markers() {
                if let Some(p) = self.position(f, m) {
                    ys.push(p.y);
                    zs.push(p.z);
                }
            }
            if ys.len() >= 4 {
                spread_y.push(interquartile(&mut ys));
                spread_z.push(interquartile(&mut zs));
            }
        }
        if median(&mut spread_y) > median(&mut spread_z) {
            UpAxis::Y
        } else {
            UpAxis::Z
        }
    }
}

/// The median of `v` (sorted in place); 0 for an empty slice.
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

/// The interquartile range of `v` (sorted in place).
fn interquartile(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[3 * v.len() / 4] - v[v.len() / 4]
}
