//! The repetition grid of a labelled facade (`facade-reconstruction.md` §4.2 C): ground-truth
//! windows clustered into rows (vertical intervals overlapping by half the smaller height or
//! more, single linkage) and columns likewise; rows and columns of two windows or more make
//! the grid, whose floor height and tile width are the median spacings of their centres.

use super::instances::Instance;
use super::rect::Rect;

/// The grid of a facade's windows.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowGrid {
    /// Centre (pixels) of each row of two windows or more, top to bottom.
    pub rows: Vec<f64>,
    /// Centre of each column of two windows or more, left to right.
    pub columns: Vec<f64>,
}

impl WindowGrid {
    /// Clusters the windows (don't-care ones left out).
    pub fn of(windows: &[Instance]) -> Self {
        let rects: Vec<Rect> = windows
            .iter()
            .filter(|w| !w.dont_care)
            .map(|w| w.rect)
            .collect();
        let rows = clusters(&rects, |r| (r.y0, r.y1));
        let columns = clusters(&rects, |r| (r.x0, r.x1));
        WindowGrid { rows, columns }
    }

    /// Median spacing of consecutive rows (`None` with fewer than two rows).
    pub fn floor_height(&self) -> Option<f64> {
        median_spacing(&self.rows)
    }

    /// Median spacing of consecutive columns.
    pub fn tile_width(&self) -> Option<f64> {
        median_spacing(&self.columns)
    }
}

/// The root of `i` in the union-find forest `parent` (paths halved on the way): single-linkage
/// clustering of windows, here and in [`super::window_grammar`].
pub(crate) fn root(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Centres of the single-linkage clusters of `rects` by interval overlap, clusters of two or
/// more only, sorted.
fn clusters(rects: &[Rect], interval: impl Fn(&Rect) -> (u32, u32)) -> Vec<f64> {
    let n = rects.len();
    let mut parent: Vec<usize> = (0..n).collect();
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (interval(&rects[i]), interval(&rects[j]));
            let overlap = a.1.min(b.1).saturating_sub(a.0.max(b.0));
            let smaller = (a.1 - a.0).min(b.1 - b.0);
            if 2 * overlap >= smaller && smaller > 0 {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                parent[ri.max(rj)] = ri.min(rj);
            }
        }
    }
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); n];
    for i in 0..n {
        let r = root(&mut parent, i);
        groups[r].push(i);
    }
    let mut centres: Vec<f64> = groups
        .iter()
        .filter(|g| g.len() >= 2)
        .map(|g| {
            g.iter()
                .map(|&i| {
                    let (a, b) = interval(&rects[i]);
                    0.5 * (a + b) as f64
                })
                .sum::<f64>()
                / g.len() as f64
        })
        .collect();
    centres.sort_by(f64::total_cmp);
    centres
}

fn median_spacing(c: &[f64]) -> Option<f64> {
    if c.len() < 2 {
        return None;
    }
    let mut d: Vec<f64> = c.windows(2).map(|w| w[1] - w[0]).collect();
    d.sort_by(f64::total_cmp);
    Some(if d.len() % 2 == 1 {
        d[d.len() / 2]
    } else {
        0.5 * (d[d.len() / 2 - 1] + d[d.len() / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_cluster_into_rows_and_columns() {
        let w = |x0, y0| Instance {
            rect: Rect {
                x0,
                y0,
                x1: x0 + 20,
                y1: y0 + 30,
            },
            dont_care: false,
        };
        // 3 floors × 2 columns, 60 px and 45 px apart, slightly uneven, plus a lone door
        let mut ws = vec![
            w(10, 10),
            w(55, 12),
            w(11, 70),
            w(56, 70),
            w(10, 130),
            w(54, 131),
        ];
        ws.push(Instance {
            rect: Rect {
                x0: 120,
                y0: 150,
                x1: 140,
                y1: 200,
            },
            dont_care: false,
        });
        let g = WindowGrid::of(&ws);
        assert_eq!(g.rows.len(), 3);
        assert_eq!(g.columns.len(), 2);
        assert!((g.floor_height().unwrap() - 60.0).abs() < 1.5);
        assert!((g.tile_width().unwrap() - 44.67).abs() < 1.0);
    }
}
