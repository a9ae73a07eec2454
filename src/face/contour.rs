//! The occluding contour (silhouette) of a face mesh seen by a camera, and the sliding matching
//! of the jaw-line landmarks (iBUG 0..=16) onto it.
//!
//! This file owns [`silhouette`], [`Silhouette`] and the sliding correspondence
//! ([`Silhouette::nearest`], [`match_jaw`]).
//!
//! A triangle is *front-facing* when its outward normal (counter-clockwise winding) points
//! towards the camera centre. The contour is made of the edges between a front-facing and a
//! back-facing triangle, plus the mesh's boundary edges whose triangle is front-facing (the
//! border of the face mask), kept when visible: the segment from the edge's midpoint to the
//! camera centre crosses no triangle not touching the edge. Each kept edge is projected to a 2D
//! segment. A jaw landmark does not correspond to a fixed vertex: on a real face it lies where
//! the line of sight grazes the skin, which moves when the head turns, so its 3D counterpart is
//! the point of the projected contour nearest to it, lifted back onto the mesh edge with a
//! perspective-correct parameter ([`ContourPoint`]). Fitting iterates this matching with the
//! deformation (ICP-like, in [`super::adapt`]).

use super::landmarks::is_contour;
use super::model::FaceMesh;
use crate::geometry::Camera;
use crate::geometry::Vec3;

/// One visible contour edge and its projection.
#[derive(Clone, Debug, PartialEq)]
pub struct SilhouetteSegment {
    /// First vertex of the edge.
    pub a: usize,
    /// Second vertex of the edge.
    pub b: usize,
    /// Projection of `a` (pixels).
    pub pa: [f64; 2],
    /// Projection of `b` (pixels).
    pub pb: [f64; 2],
    /// Camera-frame depth of `a`.
    pub za: f64,
    /// Camera-frame depth of `b`.
    pub zb: f64,
    /// Whether the edge is a mesh boundary edge (the mask's border) rather than a fold.
    pub boundary: bool,
}

/// The visible occluding contour of a mesh in one view, as projected segments.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Silhouette {
    /// The visible contour edges.
    pub segments: Vec<SilhouetteSegment>,
}

/// A point of the contour: on mesh edge `a → b` at 3D parameter `s`, seen at `image`.
#[derive(Clone, Debug, PartialEq)]
pub struct ContourPoint {
    /// First vertex of the edge.
    pub a: usize,
    /// Second vertex of the edge.
    pub b: usize,
    /// 3D parameter along the edge: the point is `(1 − s) a + s b`.
    pub s: f64,
    /// Its projection (pixels).
    pub image: [f64; 2],
    /// Distance from the query point to `image` (pixels).
    pub distance: f64,
}

impl ContourPoint {
    /// The 3D point on `mesh` (any mesh with the same vertex numbering: on the generic mesh it
    /// gives the control point's rest position).
    pub fn position(&self, mesh: &FaceMesh) -> Vec3 {
        mesh.positions[self.a] * (1.0 - self.s) + mesh.positions[self.b] * self.s
    }
}

/// Whether the open segment `o → o + d` (parameter in `(lo, hi)`) crosses triangle `abc`
/// (Möller–Trumbore).
fn segment_hits(o: &Vec3, d: &Vec3, lo: f64, hi: f64, a: &Vec3, b: &Vec3, c: &Vec3) -> bool {
    let e1 = b - a;
    let e2 = c - a;
    let p = d.cross(&e2);
    let det = e1.dot(&p);
    if det.abs() < 1e-18 {
        return false;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(&p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(&e1);
    let v = d.dot(&q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(&q) * inv;
    t > lo && t < hi
}

/// The visible occluding contour of `mesh` seen by `camera` (see the module docs). Edges with
/// a vertex behind the camera are left out.
pub fn silhouette(mesh: &FaceMesh, camera: &Camera) -> Silhouette {
    let centre = camera.center();
    let p = &mesh.positions;
    let front: Vec<bool> = mesh
        .triangles
        .iter()
        .map(|t| {
            if t.iter().any(|&i| i as usize >= p.len()) {
                return false;
            }
            let [a, b, c] = t.map(|i| p[i as usize]);
            let n = (b - a).cross(&(c - a));
            n.dot(&(centre - (a + b + c) / 3.0)) > 0.0
        })
        .collect();
    // edge → the triangles using it
    let mut edges: std::collections::BTreeMap<(usize, usize), Vec<usize>> = Default::default();
    for (ti, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            if a >= p.len() || b >= p.len() {
                continue;
            }
            edges.entry((a.min(b), a.max(b))).or_default().push(ti);
        }
    }
    let mut segments = Vec::new();
    for (&(a, b), tris) in &edges {
        let (is_contour, boundary) = match tris.as_slice() {
            [t] => (front[*t], true),
            [t, u] => (front[*t] != front[*u], false),
            _ => (false, false),
        };
        if !is_contour {
            continue;
        }
        let (ca, cb) = (camera.to_camera_frame(&p[a]), camera.to_camera_frame(&p[b]));
        let (Some(pa), Some(pb)) = (camera.project(&p[a]), camera.project(&p[b])) else {
            continue;
        };
        let mid = (p[a] + p[b]) * 0.5;
        let dir = centre - mid;
        let occluded = mesh.triangles.iter().any(|t| {
            let t = t.map(|i| i as usize);
            if t.contains(&a) || t.contains(&b) || t.iter().any(|&i| i >= p.len()) {
                return false;
            }
            segment_hits(&mid, &dir, 1e-9, 1.0, &p[t[0]], &p[t[1]], &p[t[2]])
        });
        if occluded {
            continue;
        }
        segments.push(SilhouetteSegment {
            a,
            b,
            pa,
            pb,
            za: ca.z,
            zb: cb.z,
            boundary,
        });
    }
    Silhouette { segments }
}

impl Silhouette {
    /// The contour point nearest to the image point `q`, or `None` when the contour is empty.
    pub fn nearest(&self, q: [f64; 2]) -> Option<ContourPoint> {
        let mut best: Option<ContourPoint> = None;
        for s in &self.segments {
            let (dx, dy) = (s.pb[0] - s.pa[0], s.pb[1] - s.pa[1]);
            let l2 = dx * dx + dy * dy;
            let t = if l2 > 0.0 {
                (((q[0] - s.pa[0]) * dx + (q[1] - s.pa[1]) * dy) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let img = [s.pa[0] + t * dx, s.pa[1] + t * dy];
            let dist = ((img[0] - q[0]).powi(2) + (img[1] - q[1]).powi(2)).sqrt();
            if best.as_ref().is_none_or(|b| dist < b.distance) {
                // perspective-correct 3D parameter of the image parameter t
                let den = (1.0 - t) * s.zb + t * s.za;
                let s3 = if den > 0.0 { t * s.za / den } else { t };
                best = Some(ContourPoint {
                    a: s.a,
                    b: s.b,
                    s: s3.clamp(0.0, 1.0),
                    image: img,
                    distance: dist,
                });
            }
        }
        best
    }

    /// Distance from `q` to the projected contour (pixels; infinite when it is empty).
    pub fn distance(&self, q: [f64; 2]) -> f64 {
        self.nearest(q).map_or(f64::INFINITY, |c| c.distance)
    }

    /// The contour's segments chained into 2D polylines (segments sharing a vertex are joined;
    /// where more than two meet, a new polyline starts).
    pub fn polylines(&self) -> Vec<Vec<[f64; 2]>> {
        let mut used = vec![false; self.segments.len()];
        let mut out = Vec::new();
        for start in 0..self.segments.len() {
            if used[start] {
                continue;
            }
            used[start] = true;
            let s = &self.segments[start];
            let mut verts = std::collections::VecDeque::from([(s.a, s.pa), (s.b, s.pb)]);
            for forward in [true, false] {
                loop {
                    let end = if forward {
                        verts.back().unwrap().0
                    } else {
                        verts.front().unwrap().0
                    };
                    let next = (0..self.segments.len()).find(|&k| {
                        !used[k] && (self.segments[k].a == end || self.segments[k].b == end)
                    });
                    let Some(k) = next else { break };
                    used[k] = true;
                    let g = &self.segments[k];
                    let other = if g.a == end { (g.b, g.pb) } else { (g.a, g.pa) };
                    if forward {
                        verts.push_back(other);
                    } else {
                        verts.push_front(other);
                    }
                }
            }
            out.push(verts.into_iter().map(|(_, p)| p).collect());
        }
        out
    }
}

/// Sliding correspondences of the jaw landmarks (iBUG 0..=16) of one view: for each landmark,
/// the nearest point of the visible contour of `mesh` in `camera`, or `None` when the contour
/// is farther than `max_px` pixels (or the landmark is not a jaw point). `landmarks` holds the
/// view's 68 points in crate pixel coordinates; only the jaw ones are read.
pub fn match_jaw(
    mesh: &FaceMesh,
    camera: &Camera,
    landmarks: &[[f64; 2]],
    max_px: f64,
) -> Vec<Option<ContourPoint>> {
    let sil = silhouette(mesh, camera);
    landmarks
        .iter()
        .enumerate()
        .map(|(i, &q)| {
            if !is_contour(i) {
                return None;
            }
            sil.nearest(q).filter(|c| c.distance <= max_px)
        })
        .collect()
}
