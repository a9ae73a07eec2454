//! Noticing a lost track from the tracker's own image fit, and the state of each frame.
//!
//! After each frame the tracked puppet's footprint is compared with the foreground (pixels
//! unlike the background, [`FOREGROUND_RHO`]) in every camera at pyramid level 1: the
//! **overlap** is their intersection over union, summed over cameras, counting only the
//! pixels the sequence changes. A body the puppet has lost leaves foreground uncovered and
//! covers background, so the overlap falls. The [`LossDetector`] compares each frame's
//! overlap with the median of the last good frames: a frame is lost when it falls below
//! [`LossSettings::ratio`] times that median (or below [`LossSettings::floor`]). The
//! sequence runner ([`super::sequence_run`]) then searches the body again
//! ([`Tracker::auto_pose`], seeded by the last good pose) and keeps whichever pose fits the
//! images better.

use std::collections::VecDeque;

pub use super::frame_status::FrameStatus;

use super::cost::Appearance;
use super::tracker::Tracker;
use super::visual_hull::FOREGROUND_RHO;
use crate::render::raster::{draw_triangles, project_vertices};

/// Pyramid level the overlap is measured at.
const FIT_LEVEL: usize = 1;

/// Thresholds of the loss detector.
#[derive(Clone, Copy, Debug)]
pub struct LossSettings {
    /// A frame is lost below this fraction of the median overlap of the last good frames.
    pub ratio: f64,
    /// A frame is lost below this overlap whatever came before.
    pub floor: f64,
    /// Good frames whose median is the reference.
    pub window: usize,
    /// Good frames needed before the ratio test applies.
    pub warmup: usize,
}

impl Default for LossSettings {
    fn default() -> Self {
        LossSettings {
            ratio: 0.85,
            floor: 0.4,
            window: 25,
            warmup: 5,
        }
    }
}

/// The running reference of good frames' overlaps.
#[derive(Clone, Debug, Default)]
pub struct LossDetector {
    /// Thresholds.
    pub settings: LossSettings,
    good: VecDeque<f64>,
    sorted: Vec<f64>,
}

impl LossDetector {
    /// A detector with `settings`.
    pub fn new(settings: LossSettings) -> Self {
        LossDetector {
            settings,
            ..Default::default()
        }
    }

    /// The median overlap of the good frames so far (`None` before the warm-up).
    pub fn reference(&mut self) -> Option<f64> {
        if self.good.len() < self.settings.warmup.max(1) {
            return None;
        }
        self.sorted.clear();
        self.sorted.extend(self.good.iter().copied());
        self.sorted.sort_by(f64::total_cmp);
        Some(self.sorted[self.sorted.len() / 2])
    }

    /// Whether a frame of this overlap is lost.
    pub fn is_lost(&mut self, overlap: f64) -> bool {
        !overlap.is_finite()
            || overlap < self.settings.floor
            || self
                .reference()
                .is_some_and(|m| overlap < self.settings.ratio * m)
    }

    /// Records a good frame's overlap.
    pub fn push_good(&mut self, overlap: f64) {
        self.good.push_back(overlap);
        while self.good.len() > self.settings.window.max(1) {
            self.good.pop_front();
        }
    }
}

impl Tracker {
    /// The overlap of pose `params` with the current frame's foreground: intersection over
    /// union of the puppet's footprint and the foreground pixels, over all cameras (counted
    /// pixels only), at pyramid level 1.
    pub fn overlap(&self, params: &[f64]) -> f64 {
        let app = Appearance {
            puppet: self.puppet(),
            mesh: &self.mesh,
            colours: None,
            lbs: self.options.lbs,
        };
        let mut ws = match self.workspaces[0].lock() {
            Ok(g) => g,
            Err(p) => p.into_inner(),
        };
        ws.pose_mesh(&app, params);
        let level = FIT_LEVEL.min(self.views.levels().saturating_sub(1));
        let (mut inter, mut union) = (0usize, 0usize);
        let mut projected = Vec::new();
        let mut target = None;
        for view in &self.views.views {
            let vl = &view[level];
            project_vertices(&vl.camera, &ws.skinned, &mut projected);
            let t = target.get_or_insert_with(|| {
                crate::render::raster::RasterTarget::new(
                    vl.camera.width as usize,
                    vl.camera.height as usize,
                )
            });
            if t.width != vl.camera.width as usize || t.height != vl.camera.height as usize {
                *t = crate::render::raster::RasterTarget::new(
                    vl.camera.width as usize,
                    vl.camera.height as usize,
                );
            }
            t.clear();
            let grey = vec![[128.0f32; 3]; ws.skinned.len()];
            draw_triangles(t, &projected, &grey, &self.mesh.triangles);
            for i in 0..vl.active.len().min(t.depth.len()) {
                if !vl.active[i] {
                    continue;
                }
                let p = t.depth[i] < f32::INFINITY;
                let f = vl.bg_cost[i] > FOREGROUND_RHO;
                inter += (p && f) as usize;
                union += (p || f) as usize;
            }
        }
        if union == 0 {
            0.0
        } else {
            inter as f64 / union as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fall_below_the_running_median_is_a_loss() {
        let mut d = LossDetector::new(LossSettings::default());
        // before the warm-up only the floor counts
        assert!(!d.is_lost(0.5));
        assert!(d.is_lost(0.3));
        for v in [0.80, 0.82, 0.78, 0.81, 0.79, 0.80] {
            assert!(!d.is_lost(v));
            d.push_good(v);
        }
        assert_eq!(d.reference(), Some(0.80));
        // 0.85 × 0.80 = 0.68
        assert!(!d.is_lost(0.69));
        assert!(d.is_lost(0.67));
        assert!(d.is_lost(f64::NAN));
        for c in 0..3 {
            assert_eq!(FrameStatus::from_code(c).map(FrameStatus::code), Some(c));
        }
    }
}
