//! Surface samples of a textured mesh: points fixed on its triangles (barycentric), one per
//! cell of a regular grid laid over the texture layout. They move with the mesh (pose and
//! expression) and carry the colour the tracker learnt for them, so a photometric cost needs no
//! rendering: project the samples, read the image there.

use super::model::FaceMesh;
use crate::geometry::Vec3;

/// Points on the mesh's triangles, in texture-space order.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceSamples {
    /// Triangle of each sample.
    pub triangle: Vec<u32>,
    /// Barycentric coordinates of each sample in its triangle.
    pub bary: Vec<[f64; 3]>,
}

impl SurfaceSamples {
    /// One sample per cell of a `grid × grid` lattice over the texture square that falls inside
    /// a texture triangle (the cell centre's triangle; the first triangle wins where layouts
    /// overlap).
    pub fn on_texture_grid(mesh: &FaceMesh, grid: usize) -> SurfaceSamples {
        let grid = grid.max(2);
        let mut owner: Vec<Option<(u32, [f64; 3])>> = vec![None; grid * grid];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| mesh.uvs[i as usize]);
            let lo = [a[0].min(b[0]).min(c[0]), a[1].min(b[1]).min(c[1])];
            let hi = [a[0].max(b[0]).max(c[0]), a[1].max(b[1]).max(c[1])];
            let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            if det.abs() < 1e-14 {
                continue;
            }
            let cell = |v: f64| (v * grid as f64 - 0.5).max(0.0);
            let (x0, x1) = (
                cell(lo[0]).floor() as usize,
                (cell(hi[0]).ceil() as usize).min(grid - 1),
            );
            let (y0, y1) = (
                cell(lo[1]).floor() as usize,
                (cell(hi[1]).ceil() as usize).min(grid - 1),
            );
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let p = [
                        (x as f64 + 0.5) / grid as f64,
                        (y as f64 + 0.5) / grid as f64,
                    ];
                    let l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / det;
                    let l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / det;
                    let l0 = 1.0 - l1 - l2;
                    if l0 >= 0.0 && l1 >= 0.0 && l2 >= 0.0 && owner[y * grid + x].is_none() {
                        owner[y * grid + x] = Some((t as u32, [l0, l1, l2]));
                    }
                }
            }
        }
        let (mut triangle, mut bary) = (Vec::new(), Vec::new());
        for (t, b) in owner.into_iter().flatten() {
            triangle.push(t);
            bary.push(b);
        }
        SurfaceSamples { triangle, bary }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.triangle.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.triangle.is_empty()
    }

    /// Sample positions on a mesh with vertex positions `positions` and triangles `triangles`,
    /// into `out` (no allocation once sized).
    pub fn positions(&self, positions: &[Vec3], triangles: &[[u32; 3]], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend(self.triangle.iter().zip(&self.bary).map(|(&t, b)| {
            let [i, j, k] = triangles[t as usize];
            positions[i as usize] * b[0]
                + positions[j as usize] * b[1]
                + positions[k as usize] * b[2]
        }));
    }

    /// Unit normals of the samples' triangles on a mesh.
    pub fn normals(&self, positions: &[Vec3], triangles: &[[u32; 3]], out: &mut Vec<Vec3>) {
        out.clear();
        out.extend(self.triangle.iter().map(|&t| {
            let [i, j, k] = triangles[t as usize].map(|v| positions[v as usize]);
            (j - i)
                .cross(&(k - i))
                .try_normalize(1e-20)
                .unwrap_or_else(Vec3::zeros)
        }));
    }

    /// The subset of samples whose triangle uses a vertex for which `moving` is true, as
    /// indices into this set.
    pub fn touching(&self, triangles: &[[u32; 3]], moving: &[bool]) -> Vec<usize> {
        (0..self.len())
            .filter(|&s| {
                triangles[self.triangle[s] as usize]
                    .iter()
                    .any(|&v| moving[v as usize])
            })
            .collect()
    }
}
