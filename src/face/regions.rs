//! Per-vertex facial regions of the MediaPipe mesh — upper and lower lip, upper and lower eyelid
//! of each eye, the rest — so that the mouth and eye control points of one side of an opening do
//! not pull the other side during the RBF deformation ([`super::rbf`], seed report §5.2.1:
//! "curves from the upper and the lower parts, being close to each other in 3D space, didn't
//! influence each other during RBF interpolation").
//!
//! This file owns the labelling of vertices ([`FaceRegions`]) and of the 68 iBUG landmarks
//! ([`landmark_region`]).
//!
//! # How vertices are labelled
//!
//! The canonical MediaPipe mesh is *closed* at the mouth and the eyes: its only boundary loop is
//! the outer border of the mask (checked by [`FaceRegions::mediapipe`], which reports how many
//! loops it found). The openings are therefore not read from the topology but from the landmark
//! vertices: the *cut line* of the mouth is the polyline through the mouth corners and the
//! midpoints of the inner-lip pairs (iBUG 61/67, 62/66, 63/65), that of an eye the polyline
//! through its corners and the midpoints of its lid pairs (37/41, 38/40 and mirror). Around each
//! cut line an elliptic zone is drawn (half-width 1.15 × the opening's half-width, heights given
//! relative to the nose base, the chin, or the eye width); a vertex in the zone is on the upper
//! or the lower side of the cut. The inner part of the zone (normalised radius ≤ 1) has weight 1
//! and *is* the region ([`FaceRegions::label`]); a band out to radius [`BLEND_RADIUS`] fades the
//! weight smoothly to 0, so the deformation of [`super::rbf::deform`] stays continuous.

use super::landmarks::IBUG68_TO_MEDIAPIPE;
use super::model::{FaceMesh, MEDIAPIPE_VERTICES};
use super::FaceError;
use crate::geometry::Vec3;

/// Normalised zone radius where a region's weight reaches 0 (it is 1 up to radius 1).
pub const BLEND_RADIUS: f64 = 1.6;

/// A facial region. "Left" and "right" are the subject's (left = `+x`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Region {
    /// Above the mouth cut line.
    UpperLip,
    /// Below the mouth cut line.
    LowerLip,
    /// Above the left eye's cut line.
    UpperLidLeft,
    /// Below the left eye's cut line.
    LowerLidLeft,
    /// Above the right eye's cut line.
    UpperLidRight,
    /// Below the right eye's cut line.
    LowerLidRight,
    /// Everything else (also the mouth and eye corners, shared by both sides).
    Other,
}

impl Region {
    /// The six separated regions (all but [`Region::Other`]).
    pub const SEPARATED: [Region; 6] = [
        Region::UpperLip,
        Region::LowerLip,
        Region::UpperLidLeft,
        Region::LowerLidLeft,
        Region::UpperLidRight,
        Region::LowerLidRight,
    ];

    /// The region across the same opening, whose control points must not influence this one
    /// (`None` for [`Region::Other`]).
    pub fn opposite(self) -> Option<Region> {
        Some(match self {
            Region::UpperLip => Region::LowerLip,
            Region::LowerLip => Region::UpperLip,
            Region::UpperLidLeft => Region::LowerLidLeft,
            Region::LowerLidLeft => Region::UpperLidLeft,
            Region::UpperLidRight => Region::LowerLidRight,
            Region::LowerLidRight => Region::UpperLidRight,
            Region::Other => return None,
        })
    }
}

/// The region of iBUG landmark `i` (0-based). Mouth and eye corners are [`Region::Other`]: they
/// belong to both sides of the opening.
pub fn landmark_region(i: usize) -> Region {
    match i {
        37 | 38 => Region::UpperLidRight,
        40 | 41 => Region::LowerLidRight,
        43 | 44 => Region::UpperLidLeft,
        46 | 47 => Region::LowerLidLeft,
        49..=53 | 61..=63 => Region::UpperLip,
        55..=59 | 65..=67 => Region::LowerLip,
        _ => Region::Other,
    }
}

/// Region and weight of every vertex of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct FaceRegions {
    /// The zone each vertex lies in (upper or lower side of an opening), [`Region::Other`] when
    /// it is in no zone.
    pub zone: Vec<Region>,
    /// How strongly the zone applies: 1 inside the region proper, fading to 0 in the blend band.
    pub weight: Vec<f64>,
    /// Number of boundary loops found on the mesh (1 for the canonical mesh: its outer border).
    pub boundary_loops: usize,
}

/// One cut line with its elliptic zone.
struct Opening {
    /// Cut line vertices (x increasing).
    line: Vec<[f64; 2]>,
    /// Zone centre x and half-width.
    cx: f64,
    half: f64,
    /// Zone heights above and below the cut line.
    up: f64,
    down: f64,
    upper: Region,
    lower: Region,
}

impl Opening {
    /// The cut line's height at `x` (linear between its vertices, constant past its ends).
    fn line_y(&self, x: f64) -> f64 {
        let l = &self.line;
        if x <= l[0][0] {
            return l[0][1];
        }
        for w in l.windows(2) {
            if x <= w[1][0] {
                let t = (x - w[0][0]) / (w[1][0] - w[0][0]).max(1e-12);
                return w[0][1] + t * (w[1][1] - w[0][1]);
            }
        }
        l[l.len() - 1][1]
    }

    /// Side and normalised radius of a point.
    fn classify(&self, p: &Vec3) -> (Region, f64) {
        let dy = p.y - self.line_y(p.x);
        let xi = (p.x - self.cx) / self.half;
        let (side, eta) = if dy >= 0.0 {
            (self.upper, dy / self.up)
        } else {
            (self.lower, -dy / self.down)
        };
        (side, (xi * xi + eta * eta).sqrt())
    }
}

/// Smooth weight: 1 for `rho ≤ 1`, 0 for `rho ≥ BLEND_RADIUS`, C¹ in between.
fn fade(rho: f64) -> f64 {
    if rho <= 1.0 {
        1.0
    } else if rho >= BLEND_RADIUS {
        0.0
    } else {
        let t = (BLEND_RADIUS - rho) / (BLEND_RADIUS - 1.0);
        t * t * (3.0 - 2.0 * t)
    }
}

/// Counts the boundary loops of a mesh (connected components of its boundary edges).
pub fn boundary_loop_count(mesh: &FaceMesh) -> usize {
    let edges = mesh.boundary_edges();
    let n = mesh.positions.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    let mut on = vec![false; n];
    for &(a, b) in &edges {
        on[a] = true;
        on[b] = true;
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        parent[ra] = rb;
    }
    (0..n)
        .filter(|&i| on[i] && find(&mut parent, i) == i)
        .count()
}

impl FaceRegions {
    /// Labels the vertices of a mesh in MediaPipe vertex order (468 vertices; the landmark
    /// vertices of [`IBUG68_TO_MEDIAPIPE`] define the cut lines — see the module docs).
    pub fn mediapipe(mesh: &FaceMesh) -> Result<FaceRegions, FaceError> {
        if mesh.positions.len() != MEDIAPIPE_VERTICES {
            return Err(FaceError::parameter(
                "mesh",
                format!(
                    "regions need the MediaPipe vertex order ({MEDIAPIPE_VERTICES} vertices), \
                     got {}",
                    mesh.positions.len()
                ),
            ));
        }
        mesh.validate("mesh")?;
        let lm = |i: usize| {
            let [a, b] = IBUG68_TO_MEDIAPIPE[i];
            (mesh.positions[a] + mesh.positions[b]) * 0.5
        };
        let mid = |i: usize, j: usize| {
            let p = (lm(i) + lm(j)) * 0.5;
            [p.x, p.y]
        };
        let xy = |i: usize| [lm(i).x, lm(i).y];
        let sorted = |mut v: Vec<[f64; 2]>| {
            v.sort_by(|a, b| a[0].total_cmp(&b[0]));
            v
        };
        // Mouth: corners 60, 64, inner-lip pairs; zone up towards the nose base (33), down
        // towards the chin (8).
        let mouth_line = sorted(vec![xy(60), mid(61, 67), mid(62, 66), mid(63, 65), xy(64)]);
        let mouth_half = 0.5 * (lm(54).x - lm(48).x).abs() * 1.15;
        let mouth_y = mid(62, 66)[1];
        let mouth = Opening {
            cx: 0.5 * (lm(48).x + lm(54).x),
            half: mouth_half,
            up: 0.7 * (lm(33).y - mouth_y).abs(),
            down: 0.35 * (mouth_y - lm(8).y).abs(),
            line: mouth_line,
            upper: Region::UpperLip,
            lower: Region::LowerLip,
        };
        let eye = |outer: usize, up1: usize, up2: usize, inner: usize, lo2: usize, lo1: usize| {
            let half = 0.5 * (lm(outer).x - lm(inner).x).abs() * 1.2;
            Opening {
                cx: 0.5 * (lm(outer).x + lm(inner).x),
                half,
                up: 1.0 * half,
                down: 0.8 * half,
                line: sorted(vec![xy(outer), mid(up1, lo1), mid(up2, lo2), xy(inner)]),
                upper: Region::UpperLidRight,
                lower: Region::LowerLidRight,
            }
        };
        let right_eye = eye(36, 37, 38, 39, 40, 41);
        let mut left_eye = eye(45, 44, 43, 42, 47, 46);
        left_eye.upper = Region::UpperLidLeft;
        left_eye.lower = Region::LowerLidLeft;
        let openings = [mouth, right_eye, left_eye];
        if openings
            .iter()
            .any(|o| !(o.half > 0.0 && o.up > 0.0 && o.down > 0.0))
        {
            return Err(FaceError::Failed(
                "mesh: degenerate mouth or eye landmarks, cannot label regions".into(),
            ));
        }
        let mut zone = vec![Region::Other; mesh.positions.len()];
        let mut weight = vec![0.0; mesh.positions.len()];
        for (v, p) in mesh.positions.iter().enumerate() {
            // the zone with the smallest normalised radius wins (zones do not overlap on faces)
            let mut best = (f64::INFINITY, Region::Other);
            for o in &openings {
                let (side, rho) = o.classify(p);
                if rho < best.0 {
                    best = (rho, side);
                }
            }
            let w = fade(best.0);
            if w > 0.0 {
                zone[v] = best.1;
                weight[v] = w;
            }
        }
        Ok(FaceRegions {
            zone,
            weight,
            boundary_loops: boundary_loop_count(mesh),
        })
    }

    /// The region of vertex `v`: its zone where the weight is 1, [`Region::Other`] elsewhere.
    pub fn label(&self, v: usize) -> Region {
        if self.weight.get(v).copied().unwrap_or(0.0) >= 1.0 {
            self.zone[v]
        } else {
            Region::Other
        }
    }

    /// Number of vertices labelled `region` (by [`FaceRegions::label`]).
    pub fn count(&self, region: Region) -> usize {
        (0..self.zone.len())
            .filter(|&v| self.label(v) == region)
            .count()
    }

    /// Regions for a mesh with no separation: every vertex [`Region::Other`].
    pub fn none(vertices: usize) -> FaceRegions {
        FaceRegions {
            zone: vec![Region::Other; vertices],
            weight: vec![0.0; vertices],
            boundary_loops: 0,
        }
    }
}
