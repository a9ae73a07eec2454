//! Optimal one-to-one assignment (the Hungarian method, Kuhn–Munkres with potentials): match
//! predicted to ground-truth windows maximising their total overlap.

/// For a `rows` × `cols` cost matrix (row-major), the column assigned to each row (`None` for
/// rows left over when there are more rows than columns), minimising the total cost.
/// O(n² m) for n = min(rows, cols), m = max(rows, cols).
pub fn min_cost_assignment(cost: &[f64], rows: usize, cols: usize) -> Vec<Option<usize>> {
    assert_eq!(cost.len(), rows * cols, "cost matrix size");
    if rows == 0 || cols == 0 {
        return vec![None; rows];
    }
    // the method below needs n ≤ m: transpose when there are more rows than columns
    let transposed = rows > cols;
    let (n, m) = if transposed {
        (cols, rows)
    } else {
        (rows, cols)
    };
    let c = |i: usize, j: usize| -> f64 {
        if transposed {
            cost[j * cols + i]
        } else {
            cost[i * cols + j]
        }
    };
    // 1-based potentials u (rows), v (columns); p[j] = row matched to column j (0: none)
    let inf = f64::INFINITY;
    let mut u = vec![0.0; n + 1];
    let mut v = vec![0.0; m + 1];
    let mut p = vec![0usize; m + 1];
    let mut way = vec![0usize; m + 1];
    for i in 1..=n {
        p[0] = i;
        let mut j0 = 0;
        let mut minv = vec![inf; m + 1];
        let mut used = vec![false; m + 1];
        loop {
            used[j0] = true;
            let i0 = p[j0];
            let mut delta = inf;
            let mut j1 = 0;
            for j in 1..=m {
                if !used[j] {
                    let cur = c(i0 - 1, j - 1) - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            for j in 0..=m {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut out = vec![None; rows];
    for j in 1..=m {
        if p[j] != 0 {
            let (i, jj) = (p[j] - 1, j - 1);
            if transposed {
                out[jj] = Some(i);
            } else {
                out[i] = Some(jj);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Lcg64;

    /// Brute force over all injective assignments of a small matrix.
    fn brute(cost: &[f64], rows: usize, cols: usize) -> f64 {
        fn go(r: usize, rows: usize, cols: usize, cost: &[f64], used: &mut Vec<bool>) -> f64 {
            if r == rows {
                return 0.0;
            }
            let mut best = f64::INFINITY;
            let free = used.iter().filter(|u| !**u).count();
            // a row may stay unassigned only when rows outnumber columns
            if rows - r > free {
                best = go(r + 1, rows, cols, cost, used);
            }
            for j in 0..cols {
                if !used[j] {
                    used[j] = true;
                    best = best.min(cost[r * cols + j] + go(r + 1, rows, cols, cost, used));
                    used[j] = false;
                }
            }
            best
        }
        go(0, rows, cols, cost, &mut vec![false; cols])
    }

    #[test]
    fn assignment_is_optimal_on_small_matrices() {
        let mut rng = Lcg64::new(12345);
        let mut rnd = || (rng.next_u64() >> 33) as f64 / (1u64 << 31) as f64;
        for (rows, cols) in [(3, 3), (2, 5), (5, 2), (4, 4), (1, 3), (4, 1)] {
            for _ in 0..20 {
                let cost: Vec<f64> = (0..rows * cols).map(|_| rnd()).collect();
                let a = min_cost_assignment(&cost, rows, cols);
                let mut seen = vec![false; cols];
                let mut total = 0.0;
                for (i, j) in a.iter().enumerate() {
                    if let Some(j) = j {
                        assert!(!seen[*j], "column {j} used twice");
                        seen[*j] = true;
                        total += cost[i * cols + j];
                    }
                }
                assert_eq!(a.iter().flatten().count(), rows.min(cols));
                assert!(
                    (total - brute(&cost, rows, cols)).abs() < 1e-12,
                    "{rows}×{cols}"
                );
            }
        }
    }
}
