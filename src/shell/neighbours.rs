//! Neighbour search in the rest parameter plane: a uniform bucket grid over the sample points,
//! each point stored once in the cell of its position (counting sort, built once), and the
//! local spacing (distance to the nearest other point) that sets every support radius.
//! Queries return point ids in increasing order, so results never depend on the build order.

use super::error::ShellError;

/// A uniform bucket grid over 2D points.
#[derive(Debug, Clone)]
pub struct PointGrid {
    origin: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    /// Start of each cell's ids in `ids` (length cells + 1).
    starts: Vec<usize>,
    ids: Vec<usize>,
    points: Vec<[f64; 2]>,
}

impl PointGrid {
    /// The grid over `points` with square cells of side `cell` (> 0).
    pub fn new(points: &[[f64; 2]], cell: f64) -> Result<PointGrid, ShellError> {
        if !(cell.is_finite() && cell > 0.0) {
            return Err(ShellError::Invalid(format!(
                "neighbour grid cell must be positive and finite, got {cell}"
            )));
        }
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for (i, p) in points.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(ShellError::Invalid(format!(
                    "sample point {i} has a non-finite coordinate ({}, {})",
                    p[0], p[1]
                )));
            }
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if points.is_empty() {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        let dims = [0, 1].map(|k| (((hi[k] - lo[k]) / cell).floor() as usize + 1).min(1 << 20));
        let ncell = dims[0] * dims[1];
        let mut counts = vec![0usize; ncell + 1];
        let cell_of = |p: &[f64; 2]| {
            let cx = (((p[0] - lo[0]) / cell) as usize).min(dims[0] - 1);
            let cy = (((p[1] - lo[1]) / cell) as usize).min(dims[1] - 1);
            cy * dims[0] + cx
        };
        for p in points {
            counts[cell_of(p) + 1] += 1;
        }
        for c in 0..ncell {
            counts[c + 1] += counts[c];
        }
        let starts = counts.clone();
        let mut fill = counts;
        let mut ids = vec![0usize; points.len()];
        for (i, p) in points.iter().enumerate() {
            let c = cell_of(p);
            ids[fill[c]] = i;
            fill[c] += 1;
        }
        Ok(PointGrid {
            origin: lo,
            cell,
            dims,
            starts,
            ids,
            points: points.to_vec(),
        })
    }

    /// Ids of the points within distance `r` of `x` (closed ball), ascending, into `out`.
    pub fn within(&self, x: [f64; 2], r: f64, out: &mut Vec<usize>) {
        out.clear();
        if self.points.is_empty() {
            return;
        }
        let range = |k: usize| {
            let a = ((x[k] - r - self.origin[k]) / self.cell).floor();
            let b = ((x[k] + r - self.origin[k]) / self.cell).floor();
            let top = (self.dims[k] - 1) as f64;
            (a.clamp(0.0, top) as usize, b.clamp(0.0, top) as usize)
        };
        let (x0, x1) = range(0);
        let (y0, y1) = range(1);
        let r2 = r * r;
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let c = cy * self.dims[0] + cx;
                for &i in &self.ids[self.starts[c]..self.starts[c + 1]] {
                    let p = self.points[i];
                    let d2 = (p[0] - x[0]).powi(2) + (p[1] - x[1]).powi(2);
                    if d2 <= r2 {
                        out.push(i);
                    }
                }
            }
        }
        out.sort_unstable();
    }
}

/// The local spacing of each point: the distance to its nearest other point (searched in growing
/// rings, starting from `guess`). A point that coincides with another is an error naming both.
pub fn local_spacing(points: &[[f64; 2]], guess: f64) -> Result<Vec<f64>, ShellError> {
    if points.len() < 2 {
        return Err(ShellError::Invalid(format!(
            "a shell needs at least 2 sample points, got {}",
            points.len()
        )));
    }
    let grid = PointGrid::new(points, guess)?;
    let mut found = Vec::new();
    let mut out = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let mut r = guess;
        loop {
            grid.within(*p, r, &mut found);
            let nearest = found
                .iter()
                .filter(|&&j| j != i)
                .map(|&j| ((points[j][0] - p[0]).powi(2) + (points[j][1] - p[1]).powi(2)).sqrt())
                .fold(f64::INFINITY, f64::min);
            if nearest.is_finite() {
                if nearest <= 1e-12 * guess.max(1e-300) {
                    let j = found.iter().find(|&&j| j != i).copied().unwrap_or(i);
                    return Err(ShellError::Invalid(format!(
                        "sample points {i} and {j} coincide at ({}, {})",
                        p[0], p[1]
                    )));
                }
                out.push(nearest);
                break;
            }
            r *= 2.0;
        }
    }
    Ok(out)
}
