//! The club tracker's image evidence ([`super::club_track`]): per camera, each pixel's
//! colour distance from the background model (lighting gain removed), linear up to
//! `CONTRAST`, in a pyramid max-pooled 2×2 per level, so a line one pixel wide keeps its
//! strength at the coarse levels while the search's basin widens.

use super::cost::{camera_at_level, FrameViews};
use crate::geometry::Camera;

/// Colour distance from the background (grey levels, RGB norm) that counts as full
/// evidence: linear below it, so the faint copies of a shaft smeared by the shutter (each a
/// fifth of the contrast at five instants) still count.
const CONTRAST: f32 = 60.0;
/// Levels of the evidence pyramid (the coarse search runs on the last).
pub(super) const LEVELS: usize = 4;

/// One camera's evidence at one level: the background term, max-pooled 2×2 per level, so a
/// line one pixel wide stays at full strength while the search's basin widens.
pub(super) struct EvidenceLevel {
    pub(super) camera: Camera,
    width: usize,
    height: usize,
    map: Vec<f32>,
}

/// `pyramid[camera][level]` from the views' full-resolution background terms.
pub(super) fn evidence_pyramid(views: &FrameViews, pyramid: &mut Vec<Vec<EvidenceLevel>>) {
    pyramid.resize_with(views.views.len(), Vec::new);
    for (view, levels) in views.views.iter().zip(pyramid.iter_mut()) {
        let v0 = &view[0];
        levels.resize_with(LEVELS, || EvidenceLevel {
            camera: v0.camera.clone(),
            width: 0,
            height: 0,
            map: Vec::new(),
        });
        levels[0].camera = v0.camera.clone();
        (levels[0].width, levels[0].height) = (v0.background.width, v0.background.height);
        levels[0].map.clear();
        levels[0]
            .map
            .extend(v0.image.rgb.iter().zip(&v0.background.rgb).map(|(i, b)| {
                let d2 = (i[0] - b[0]).powi(2) + (i[1] - b[1]).powi(2) + (i[2] - b[2]).powi(2);
                (d2.sqrt() / CONTRAST).min(1.0)
            }));
        for l in 1..LEVELS {
            let (done, rest) = levels.split_at_mut(l);
            let (prev, next) = (&done[l - 1], &mut rest[0]);
            let (w, h) = (prev.width / 2, prev.height / 2);
            next.camera = camera_at_level(&v0.camera, l);
            (next.width, next.height) = (w, h);
            next.map.clear();
            next.map.extend((0..w * h).map(|i| {
                let (x, y) = (2 * (i % w), 2 * (i / w));
                let at = |dx: usize, dy: usize| prev.map[(y + dy) * prev.width + x + dx];
                at(0, 0).max(at(1, 0)).max(at(0, 1)).max(at(1, 1))
            }));
        }
    }
}

impl EvidenceLevel {
    /// The evidence at `(x, y)`, bilinear; 0 outside the image.
    pub(super) fn at(&self, x: f64, y: f64) -> f32 {
        let (w, h) = (self.width, self.height);
        if !(x >= 0.0 && y >= 0.0) {
            return 0.0;
        }
        let (x0, y0) = (x as usize, y as usize);
        if x0 + 1 >= w || y0 + 1 >= h {
            return 0.0;
        }
        let (tx, ty) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
        let i = y0 * w + x0;
        let g = &self.map;
        (g[i] * (1.0 - tx) + g[i + 1] * tx) * (1.0 - ty)
            + (g[i + w] * (1.0 - tx) + g[i + w + 1] * tx) * ty
    }
}
