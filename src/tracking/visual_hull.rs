//! Finding the person in a multi-camera frame from the images alone: the foreground of each
//! camera (pixels unlike its background model) and the visual hull, the points of space
//! whose projection is foreground in every camera (the intersection of the silhouettes'
//! cones). Its centre and lowest point place the puppet; its volume says whether anybody is
//! there at all.
//!
//! A pixel the sequence never changes (a static occluder, see
//! [`ViewLevel::active`](super::cost::ViewLevel::active)) is unknown rather than background,
//! so one camera whose occluder hides a body part does not carve it away; a point needs
//! the foreground of every other camera.

use super::cost::FrameViews;
use crate::geometry::Vec3;

/// ρ(I − B) above which a pixel is foreground (Geman–McClure with the tracker's σ = 40
/// grey levels: 0.35 is an RGB distance of about 30 grey levels, about four times the
/// distance sensor noise of σ = 4 per channel gives).
pub const FOREGROUND_RHO: f32 = 0.35;

/// Smallest hull volume taken for a person (m³): a standing adult is about 0.07 m³ and
/// their four-camera hull larger still.
pub const MIN_PERSON_VOLUME: f64 = 0.02;

/// The visual hull of one frame, sampled on a grid.
#[derive(Clone, Debug)]
pub struct Hull {
    /// Centres of the cells inside the hull (metres, world).
    pub cells: Vec<Vec3>,
    /// Edge of a cell (metres).
    pub cell: f64,
}

impl Hull {
    /// Volume (m³).
    pub fn volume(&self) -> f64 {
        self.cells.len() as f64 * self.cell.powi(3)
    }

    /// Centroid of the cells, `None` when empty.
    pub fn centroid(&self) -> Option<Vec3> {
        (!self.cells.is_empty()).then(|| self.cells.iter().sum::<Vec3>() / self.cells.len() as f64)
    }

    /// Lowest cell height (metres), `None` when empty.
    pub fn lowest(&self) -> Option<f64> {
        self.cells.iter().map(|c| c.z).reduce(f64::min)
    }

    /// The cells of the largest group of face-adjacent cells (a person is one piece; the
    /// few cells where the cones of unrelated specks meet are not).
    pub fn largest_component(&self) -> Hull {
        use std::collections::HashMap;
        let key = |p: &Vec3| {
            [
                (p.x / self.cell).round() as i64,
                (p.y / self.cell).round() as i64,
                (p.z / self.cell).round() as i64,
            ]
        };
        let index: HashMap<[i64; 3], usize> = self
            .cells
            .iter()
            .enumerate()
            .map(|(i, p)| (key(p), i))
            .collect();
        let mut label = vec![usize::MAX; self.cells.len()];
        let (mut best, mut best_size) = (usize::MAX, 0);
        let mut stack = Vec::new();
        for start in 0..self.cells.len() {
            if label[start] != usize::MAX {
                continue;
            }
            label[start] = start;
            stack.push(start);
            let mut size = 0;
            while let Some(i) = stack.pop() {
                size += 1;
                let k = key(&self.cells[i]);
                for d in [
                    [1, 0, 0],
                    [-1, 0, 0],
                    [0, 1, 0],
                    [0, -1, 0],
                    [0, 0, 1],
                    [0, 0, -1],
                ] {
                    let n = [k[0] + d[0], k[1] + d[1], k[2] + d[2]];
                    if let Some(&j) = index.get(&n) {
                        if label[j] == usize::MAX {
                            label[j] = start;
                            stack.push(j);
                        }
                    }
                }
            }
            if size > best_size {
                (best, best_size) = (start, size);
            }
        }
        Hull {
            cells: (0..self.cells.len())
                .filter(|&i| label[i] == best)
                .map(|i| self.cells[i])
                .collect(),
            cell: self.cell,
        }
    }
}

/// What a camera's pixel says about a point.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Vote {
    Foreground,
    Background,
    Unknown,
}

/// The visual hull of the current frame of `views` at pyramid `level`, sampled on a grid of
/// `cell` metres over the box `lo`–`hi`: a cell is in when, in every camera, it projects
/// inside the image onto a foreground pixel or onto an unknown one (never-changing pixels,
/// in at most one camera).
pub fn visual_hull(views: &FrameViews, level: usize, lo: Vec3, hi: Vec3, cell: f64) -> Hull {
    let n = |a: f64, b: f64| (((b - a) / cell).floor() as usize).max(1);
    let (nx, ny, nz) = (n(lo.x, hi.x), n(lo.y, hi.y), n(lo.z, hi.z));
    let vote = |p: &Vec3, c: usize| -> Vote {
        let vl = &views.views[c][level.min(views.views[c].len() - 1)];
        let Some([u, v]) = vl.camera.project(p) else {
            return Vote::Background;
        };
        let (x, y) = (u.round(), v.round());
        let (w, h) = (vl.background.width, vl.background.height);
        if x < 0.0 || y < 0.0 || x >= w as f64 || y >= h as f64 {
            return Vote::Background;
        }
        let i = y as usize * w + x as usize;
        if !vl.active[i] {
            Vote::Unknown
        } else if vl.bg_cost[i] > FOREGROUND_RHO {
            Vote::Foreground
        } else {
            Vote::Background
        }
    };
    let mut cells = Vec::new();
    for iz in 0..nz {
        for iy in 0..ny {
            for ix in 0..nx {
                let p = Vec3::new(
                    lo.x + (ix as f64 + 0.5) * cell,
                    lo.y + (iy as f64 + 0.5) * cell,
                    lo.z + (iz as f64 + 0.5) * cell,
                );
                let mut unknown = 0;
                let mut inside = true;
                for c in 0..views.views.len() {
                    match vote(&p, c) {
                        Vote::Foreground => {}
                        Vote::Unknown if unknown == 0 => unknown += 1,
                        _ => {
                            inside = false;
                            break;
                        }
                    }
                }
                if inside {
                    cells.push(p);
                }
            }
        }
    }
    Hull { cells, cell }
}

/// The box searched for a person: the horizontal extent of the cameras' centres (they look
/// inward), from 2 m below the lowest camera to 1 m above the highest.
pub fn search_box(views: &FrameViews) -> (Vec3, Vec3) {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for v in &views.views {
        let c = v[0].camera.center();
        lo = lo.inf(&c);
        hi = hi.sup(&c);
    }
    (
        Vec3::new(lo.x, lo.y, lo.z - 2.0),
        Vec3::new(hi.x, hi.y, hi.z + 1.0),
    )
}

/// Fraction of each camera's counted pixels at `level` that are foreground.
pub fn foreground_fractions(views: &FrameViews, level: usize) -> Vec<f64> {
    views
        .views
        .iter()
        .map(|v| {
            let vl = &v[level.min(v.len() - 1)];
            let (mut fg, mut all) = (0usize, 0usize);
            for (a, &b) in vl.active.iter().zip(&vl.bg_cost) {
                if *a {
                    all += 1;
                    fg += (b > FOREGROUND_RHO) as usize;
                }
            }
            fg as f64 / all.max(1) as f64
        })
        .collect()
}
