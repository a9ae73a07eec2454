//! Influence zones on the MediaPipe face mesh, shared by the FAPs ([`super`]) and the muscles
//! ([`crate::face::muscles`]): the mesh's edge graph with the mouth and the eyes cut open,
//! geodesic (shortest edge path) distances on it, and the compactly supported kernel.
//!
//! The canonical mesh has a single boundary loop (the face outline): the mouth and the eye
//! openings are triangulated across. Those triangles connect the upper inner lip
//! ([`UPPER_INNER_LIP`]) to the lower inner lip ([`LOWER_INNER_LIP`]) and each upper eyelid
//! rim to its lower rim; the graph here drops exactly those edges, so distances from a
//! lower-lip point to an upper-lip point go round a mouth corner (and likewise round the eye
//! corners). Zones measured with it keep the lips and the eyelids apart, as the seed's
//! "special treatment of the muscles of the mouth and eyes" does for its RBF interpolation.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::face::model::{FaceMesh, MEDIAPIPE_VERTICES};
use crate::face::FaceError;
use crate::geometry::Vec3;

/// Inner upper lip, subject's right corner side to left (corners 78 and 308 excluded).
pub const UPPER_INNER_LIP: [usize; 9] = [191, 80, 81, 82, 13, 312, 311, 310, 415];
/// Inner lower lip, paired index by index with [`UPPER_INNER_LIP`].
pub const LOWER_INNER_LIP: [usize; 9] = [95, 88, 178, 87, 14, 317, 402, 318, 324];
/// Upper rim of the subject's right eye, outer to inner (corners 33 and 133 excluded).
pub const RIGHT_UPPER_LID: [usize; 7] = [246, 161, 160, 159, 158, 157, 173];
/// Lower rim of the subject's right eye, paired index by index with [`RIGHT_UPPER_LID`].
pub const RIGHT_LOWER_LID: [usize; 7] = [7, 163, 144, 145, 153, 154, 155];
/// Upper rim of the subject's left eye, outer to inner (corners 263 and 362 excluded).
pub const LEFT_UPPER_LID: [usize; 7] = [466, 388, 387, 386, 385, 384, 398];
/// Lower rim of the subject's left eye, paired index by index with [`LEFT_UPPER_LID`].
pub const LEFT_LOWER_LID: [usize; 7] = [249, 390, 373, 374, 380, 381, 382];

/// The compactly supported kernel `(1 − r)³ (3r + 1)` of `r = distance / radius`: 1 at 0,
/// smooth, 0 from `r = 1` on.
pub fn kernel(r: f64) -> f64 {
    if r.is_nan() || r >= 1.0 {
        return 0.0;
    }
    let r = r.max(0.0);
    (1.0 - r).powi(3) * (3.0 * r + 1.0)
}

/// Kernel with a plateau: 1 up to `inner`, then [`kernel`] of `(d − inner) / (outer − inner)`.
pub fn plateau_kernel(d: f64, inner: f64, outer: f64) -> f64 {
    if d <= inner {
        1.0
    } else if outer > inner {
        kernel((d - inner) / (outer - inner))
    } else {
        0.0
    }
}

/// The edge graph of a face mesh with the mouth and the eyes cut open.
#[derive(Clone, Debug)]
pub struct ZoneGraph {
    /// Per vertex: neighbours and edge lengths (m).
    adjacency: Vec<Vec<(usize, f64)>>,
}

/// A Dijkstra queue entry (distance, vertex, source), ordered for a min-heap.
#[derive(PartialEq)]
struct Entry(f64, usize, usize);

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .0
            .total_cmp(&self.0)
            .then_with(|| other.1.cmp(&self.1))
            .then_with(|| other.2.cmp(&self.2))
    }
}

impl ZoneGraph {
    /// The graph of a mesh in MediaPipe vertex order, lips and eyelids cut apart. Fails on a
    /// mesh of another vertex count, an index out of range, or non-finite positions.
    pub fn mediapipe(mesh: &FaceMesh) -> Result<ZoneGraph, FaceError> {
        if mesh.positions.len() != MEDIAPIPE_VERTICES {
            return Err(FaceError::parameter(
                "mesh",
                format!(
                    "face animation needs the MediaPipe vertex order ({MEDIAPIPE_VERTICES} \
                     vertices), got {} vertices",
                    mesh.positions.len()
                ),
            ));
        }
        mesh.validate("face mesh")?;
        let cuts: [(&[usize], &[usize]); 3] = [
            (&UPPER_INNER_LIP, &LOWER_INNER_LIP),
            (&RIGHT_UPPER_LID, &RIGHT_LOWER_LID),
            (&LEFT_UPPER_LID, &LEFT_LOWER_LID),
        ];
        let cut = |a: usize, b: usize| {
            cuts.iter().any(|(u, l)| {
                (u.contains(&a) && l.contains(&b)) || (u.contains(&b) && l.contains(&a))
            })
        };
        let mut adjacency = vec![Vec::new(); mesh.positions.len()];
        for (i, nb) in mesh.neighbours().into_iter().enumerate() {
            for j in nb {
                if !cut(i, j) {
                    let d = (mesh.positions[i] - mesh.positions[j]).norm();
                    adjacency[i].push((j, d));
                }
            }
        }
        Ok(ZoneGraph { adjacency })
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.adjacency.len()
    }

    /// Whether the graph has no vertex.
    pub fn is_empty(&self) -> bool {
        self.adjacency.is_empty()
    }

    /// Multi-source shortest paths: `sources[s] = (vertex, initial distance)`. Returns per
    /// vertex the distance (infinite when unreachable) and the index `s` of its nearest source
    /// (`usize::MAX` when unreachable). Ties go to the lower source index, deterministically.
    pub fn distances(&self, sources: &[(usize, f64)]) -> (Vec<f64>, Vec<usize>) {
        let n = self.adjacency.len();
        let mut dist = vec![f64::INFINITY; n];
        let mut from = vec![usize::MAX; n];
        let mut heap = BinaryHeap::new();
        for (s, &(v, d0)) in sources.iter().enumerate() {
            if v < n && d0 < dist[v] {
                dist[v] = d0;
                from[v] = s;
                heap.push(Entry(d0, v, s));
            }
        }
        while let Some(Entry(d, v, s)) = heap.pop() {
            if d > dist[v] || (d == dist[v] && s != from[v]) {
                continue;
            }
            for &(w, len) in &self.adjacency[v] {
                let nd = d + len;
                if nd < dist[w] || (nd == dist[w] && s < from[w]) {
                    dist[w] = nd;
                    from[w] = s;
                    heap.push(Entry(nd, w, s));
                }
            }
        }
        (dist, from)
    }
}

/// A sparse displacement field: `(vertex, displacement)` for every vertex whose weight is not
/// zero, in vertex order. `seed_vectors[s]` is the displacement of source `s`, `weight(v, d)`
/// the weight of vertex `v` at geodesic distance `d` from its nearest source.
pub fn zone_field(
    graph: &ZoneGraph,
    sources: &[(usize, f64)],
    seed_vectors: &[Vec3],
    weight: impl Fn(usize, f64) -> f64,
) -> Vec<(u32, Vec3)> {
    let (dist, from) = graph.distances(sources);
    let mut out = Vec::new();
    for (v, (&d, &s)) in dist.iter().zip(&from).enumerate() {
        if s == usize::MAX || !d.is_finite() {
            continue;
        }
        let w = weight(v, d);
        if w > 0.0 {
            if let Some(vec) = seed_vectors.get(s) {
                let disp = vec * w;
                if disp != Vec3::zeros() {
                    out.push((v as u32, disp));
                }
            }
        }
    }
    out
}

/// Side mask between two facing rims (upper and lower lip, upper and lower eyelid): per vertex,
/// 1 on the side of `own`, 0 on the side of `other`, a linear ramp of width `2 × width` (m)
/// across the geodesic bisector (where the rims meet, at the mouth and eye corners).
pub fn side_mask(graph: &ZoneGraph, own: &[usize], other: &[usize], width: f64) -> Vec<f64> {
    let src = |r: &[usize]| r.iter().map(|&v| (v, 0.0)).collect::<Vec<_>>();
    let (d_own, _) = graph.distances(&src(own));
    let (d_other, _) = graph.distances(&src(other));
    d_own
        .iter()
        .zip(&d_other)
        .map(|(&a, &b)| match (a.is_finite(), b.is_finite()) {
            (true, true) => (0.5 + (b - a) / (2.0 * width)).clamp(0.0, 1.0),
            (true, false) => 1.0,
            _ => 0.0,
        })
        .collect()
}
