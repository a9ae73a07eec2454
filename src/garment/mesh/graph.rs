//! Shortest paths along a triangle mesh's edges (Dijkstra, lengths in a 2D embedding such as
//! the pattern or the figurine plane), for ramps that fade with the distance along a piece.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::garment::P2;

/// Vertex adjacency of a triangle mesh (compressed rows).
pub(crate) struct Adjacency {
    start: Vec<usize>,
    next: Vec<usize>,
}

impl Adjacency {
    /// The adjacency of `triangles` over `n` vertices.
    pub(crate) fn new(triangles: &[[usize; 3]], n: usize) -> Adjacency {
        let mut pairs: Vec<(usize, usize)> = triangles
            .iter()
            .flat_map(|t| {
                (0..3).flat_map(move |k| [(t[k], t[(k + 1) % 3]), (t[(k + 1) % 3], t[k])])
            })
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let mut start = vec![0; n + 1];
        for &(a, _) in &pairs {
            start[a + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        Adjacency {
            start,
            next: pairs.into_iter().map(|(_, b)| b).collect(),
        }
    }

    /// The vertices sharing an edge with `v`.
    pub(crate) fn neighbours(&self, v: usize) -> &[usize] {
        &self.next[self.start[v]..self.start[v + 1]]
    }

    /// Shortest path lengths (in the 2D embedding `pos`) from `sources` along mesh edges, up
    /// to `limit`, and each reached vertex's nearest source (unreached vertices: distance
    /// infinite, nearest `usize::MAX`).
    pub(crate) fn nearest(
        &self,
        sources: &[usize],
        pos: &[P2],
        limit: f64,
    ) -> (Vec<f64>, Vec<usize>) {
        let n = self.start.len() - 1;
        let mut dist = vec![f64::INFINITY; n];
        let mut near = vec![usize::MAX; n];
        let mut heap = BinaryHeap::new();
        for &s in sources {
            dist[s] = 0.0;
            near[s] = s;
            heap.push(Entry(0.0, s));
        }
        while let Some(Entry(d, v)) = heap.pop() {
            if d > dist[v] {
                continue;
            }
            for &w in &self.next[self.start[v]..self.start[v + 1]] {
                let e = (pos[v][0] - pos[w][0]).hypot(pos[v][1] - pos[w][1]);
                let dw = d + e;
                if dw < dist[w] && dw < limit {
                    dist[w] = dw;
                    near[w] = near[v];
                    heap.push(Entry(dw, w));
                }
            }
        }
        (dist, near)
    }
}

/// A heap entry ordered by smallest distance first.
struct Entry(f64, usize);

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_run_along_edges_and_stop_at_the_limit() {
        // a unit square split along its diagonal 0–2
        let tris = [[0, 1, 2], [0, 2, 3]];
        let pos = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let adj = Adjacency::new(&tris, 4);
        let (d, near) = adj.nearest(&[0], &pos, 10.0);
        assert_eq!(d[1], 1.0);
        assert!((d[2] - 2f64.sqrt()).abs() < 1e-15);
        assert_eq!(near, vec![0; 4]);
        let (d, near) = adj.nearest(&[1], &pos, 1.5);
        assert!(
            d[3].is_infinite() && near[3] == usize::MAX,
            "1–0–3 and 1–2–3 are 2 long"
        );
    }
}
