//! Edge and hinge adjacency of a triangle mesh, built once per topology in a deterministic order.

use super::TriMesh;

/// A mesh edge `a < b`, with up to two incident triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// Smaller vertex index.
    pub a: usize,
    /// Larger vertex index.
    pub b: usize,
}

/// An interior edge `(a, b)` shared by two triangles, with the vertices `c` and `d` opposite it.
/// Triangle `(a, b, c)` and triangle `(b, a, d)` keep the mesh orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hinge {
    /// First vertex of the shared edge.
    pub a: usize,
    /// Second vertex of the shared edge.
    pub b: usize,
    /// Vertex opposite the edge in the first triangle.
    pub c: usize,
    /// Vertex opposite the edge in the second triangle.
    pub d: usize,
}

/// Unique edges and interior hinges of a mesh, sorted by vertex indices.
#[derive(Debug, Clone, Default)]
pub struct Topology {
    /// All unique edges, sorted by `(a, b)`.
    pub edges: Vec<Edge>,
    /// Interior edges with their opposite vertices (manifold edges only).
    pub hinges: Vec<Hinge>,
}

impl Topology {
    /// Builds edges and hinges of `mesh`. Edges with more than two triangles get no hinge.
    pub fn of(mesh: &TriMesh) -> Self {
        // (min, max, triangle's third vertex, oriented a, oriented b)
        let mut half: Vec<(usize, usize, usize, usize, usize)> =
            Vec::with_capacity(mesh.triangles.len() * 3);
        for t in &mesh.triangles {
            for k in 0..3 {
                let (p, q, r) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                half.push((p.min(q), p.max(q), r, p, q));
            }
        }
        half.sort_unstable();
        let mut edges = Vec::new();
        let mut hinges = Vec::new();
        let mut i = 0;
        while i < half.len() {
            let mut j = i;
            while j < half.len() && half[j].0 == half[i].0 && half[j].1 == half[i].1 {
                j += 1;
            }
            edges.push(Edge {
                a: half[i].0,
                b: half[i].1,
            });
            if j - i == 2 {
                let (_, _, c, a, b) = half[i];
                let d = half[i + 1].2;
                hinges.push(Hinge { a, b, c, d });
            }
            i = j;
        }
        Topology { edges, hinges }
    }
}
