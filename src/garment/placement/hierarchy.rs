//! The multi-resolution part of pre-positioning's energy minimisation (seed refs [37][38]):
//! the pattern is meshed again with edges twice as long, that coarse garment is pre-positioned
//! and relaxed (recursively), and the displacement its relaxation made is carried over to the
//! fine garment by barycentric interpolation in the pattern plane, so the fine relaxation sweeps
//! only have short-wavelength strain left to remove.

use crate::garment::mesh::GarmentMesh;
use crate::garment::P2;
use crate::geometry::Vec3;

/// The field `delta` given on the vertices of `coarse` (the same pattern, meshed coarser),
/// interpolated at every vertex of `fine`: each fine vertex takes the barycentric mix of the
/// coarse triangle of its piece that contains it (or the nearest, at curved outlines).
pub(super) fn interpolate(fine: &GarmentMesh, coarse: &GarmentMesh, delta: &[Vec3]) -> Vec<Vec3> {
    let mut out = vec![Vec3::zeros(); fine.flat.len()];
    for (fp, cp) in fine.pieces.iter().zip(&coarse.pieces) {
        let tris: Vec<[usize; 3]> = coarse.mesh.triangles[cp.triangles.clone()].to_vec();
        if tris.is_empty() {
            continue;
        }
        let grid = Buckets::new(&tris, &coarse.flat);
        for v in fp.vertices.clone() {
            let p = fine.flat[v];
            let mut best = (f64::NEG_INFINITY, [0.0; 3], 0usize);
            for &t in grid.near(p) {
                let b = barycentric(p, tris[t].map(|i| coarse.flat[i]));
                let worst = b[0].min(b[1]).min(b[2]);
                if worst > best.0 {
                    best = (worst, b, t);
                }
            }
            if best.0 == f64::NEG_INFINITY {
                // outside every bucket searched: scan the piece
                for (t, tri) in tris.iter().enumerate() {
                    let b = barycentric(p, tri.map(|i| coarse.flat[i]));
                    let worst = b[0].min(b[1]).min(b[2]);
                    if worst > best.0 {
                        best = (worst, b, t);
                    }
                }
            }
            // clamp onto the triangle so a vertex just outside the coarse outline is not
            // extrapolated
            let b = best.1.map(|w| w.max(0.0));
            let sum = b[0] + b[1] + b[2];
            let t = tris[best.2];
            out[v] =
                (delta[t[0]] * b[0] + delta[t[1]] * b[1] + delta[t[2]] * b[2]) / sum.max(1e-300);
        }
    }
    out
}

/// Barycentric coordinates of `p` in triangle `t` (any sign; degenerate: all equal).
fn barycentric(p: P2, t: [P2; 3]) -> [f64; 3] {
    let (a, b, c) = (t[0], t[1], t[2]);
    let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if det.abs() < 1e-300 {
        return [1.0 / 3.0; 3];
    }
    let l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / det;
    let l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / det;
    [1.0 - l1 - l2, l1, l2]
}

/// Triangles of one piece bucketed on a uniform grid by their boxes.
struct Buckets {
    origin: P2,
    cell: f64,
    nx: usize,
    ny: usize,
    start: Vec<usize>,
    items: Vec<usize>,
}

impl Buckets {
    fn new(tris: &[[usize; 3]], pos: &[P2]) -> Buckets {
        let boxes: Vec<[f64; 4]> = tris
            .iter()
            .map(|t| {
                t.iter()
                    .fold([f64::MAX, f64::MAX, f64::MIN, f64::MIN], |b, &i| {
                        let p = pos[i];
                        [
                            b[0].min(p[0]),
                            b[1].min(p[1]),
                            b[2].max(p[0]),
                            b[3].max(p[1]),
                        ]
                    })
            })
            .collect();
        let all = boxes
            .iter()
            .fold([f64::MAX, f64::MAX, f64::MIN, f64::MIN], |a, b| {
                [
                    a[0].min(b[0]),
                    a[1].min(b[1]),
                    a[2].max(b[2]),
                    a[3].max(b[3]),
                ]
            });
        let size: f64 = boxes
            .iter()
            .map(|b| (b[2] - b[0]).max(b[3] - b[1]))
            .sum::<f64>()
            / boxes.len() as f64;
        let cell = (2.0 * size).max(1e-6);
        let nx = (((all[2] - all[0]) / cell) as usize + 1).min(4096);
        let ny = (((all[3] - all[1]) / cell) as usize + 1).min(4096);
        let origin = [all[0], all[1]];
        let range = |lo: f64, hi: f64, o: f64, n: usize| {
            let a = (((lo - o) / cell).floor().max(0.0) as usize).min(n - 1);
            let b = (((hi - o) / cell).floor().max(0.0) as usize).min(n - 1);
            a..=b
        };
        let mut count = vec![0usize; nx * ny + 1];
        for b in &boxes {
            for j in range(b[1], b[3], origin[1], ny) {
                for i in range(b[0], b[2], origin[0], nx) {
                    count[j * nx + i + 1] += 1;
                }
            }
        }
        for k in 0..nx * ny {
            count[k + 1] += count[k];
        }
        let mut fill = count.clone();
        let mut items = vec![0; count[nx * ny]];
        for (t, b) in boxes.iter().enumerate() {
            for j in range(b[1], b[3], origin[1], ny) {
                for i in range(b[0], b[2], origin[0], nx) {
                    items[fill[j * nx + i]] = t;
                    fill[j * nx + i] += 1;
                }
            }
        }
        Buckets {
            origin,
            cell,
            nx,
            ny,
            start: count,
            items,
        }
    }

    /// The triangles whose boxes overlap the cell of `p` (empty outside the grid).
    fn near(&self, p: P2) -> &[usize] {
        let i = ((p[0] - self.origin[0]) / self.cell).floor();
        let j = ((p[1] - self.origin[1]) / self.cell).floor();
        if i < 0.0 || j < 0.0 || i as usize >= self.nx || j as usize >= self.ny {
            return &[];
        }
        let k = j as usize * self.nx + i as usize;
        &self.items[self.start[k]..self.start[k + 1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_weights_reproduce_the_point() {
        let t = [[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]];
        let b = barycentric([0.5, 0.25], t);
        let x = b[0] * t[0][0] + b[1] * t[1][0] + b[2] * t[2][0];
        let y = b[0] * t[0][1] + b[1] * t[1][1] + b[2] * t[2][1];
        assert!((x - 0.5).abs() < 1e-15 && (y - 0.25).abs() < 1e-15);
        assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
}
