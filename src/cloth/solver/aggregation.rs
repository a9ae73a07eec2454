//! Graph aggregation for the algebraic multigrid preconditioner: an undirected graph in
//! compressed form ([`Graph`]), its partition into aggregates (a node and its neighbours,
//! greedily, then the leftovers joined to a neighbouring aggregate), and the coarse graph whose
//! nodes are the aggregates. Deterministic: the result depends only on the node numbering.

/// An undirected graph: the neighbours of node `i` are `nbr[ptr[i]..ptr[i + 1]]`, sorted,
/// without `i` itself.
#[derive(Debug, Clone, Default)]
pub struct Graph {
    /// Start of each node's neighbours (length nodes + 1).
    pub ptr: Vec<usize>,
    /// Neighbour lists.
    pub nbr: Vec<u32>,
}

impl Graph {
    /// The graph on `n` nodes with an edge for each pair (both directions; loops and repeats
    /// dropped).
    pub fn from_pairs(n: usize, pairs: impl IntoIterator<Item = (usize, usize)>) -> Self {
        let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
        for (i, j) in pairs {
            if i != j {
                adj[i].push(j as u32);
                adj[j].push(i as u32);
            }
        }
        let mut ptr = Vec::with_capacity(n + 1);
        let mut nbr = Vec::new();
        ptr.push(0);
        for row in &mut adj {
            row.sort_unstable();
            row.dedup();
            nbr.extend_from_slice(row);
            ptr.push(nbr.len());
        }
        Graph { ptr, nbr }
    }

    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.ptr.len() - 1
    }

    /// Neighbours of node `i`.
    pub fn neighbours(&self, i: usize) -> &[u32] {
        &self.nbr[self.ptr[i]..self.ptr[i + 1]]
    }

    /// The graph of the aggregates: two are adjacent when an edge joins their members.
    pub fn coarsen(&self, agg: &[u32], count: usize) -> Graph {
        let pairs = (0..self.nodes()).flat_map(|i| {
            self.neighbours(i)
                .iter()
                .map(move |&j| (agg[i] as usize, agg[j as usize] as usize))
        });
        Graph::from_pairs(count, pairs)
    }
}

/// Partitions the nodes of `g` into aggregates; returns each node's aggregate and the number
/// of aggregates. First pass: a node whose neighbours are all free becomes an aggregate with
/// them (the aggregates are disjoint 1-rings). Second: each free node joins the aggregate of
/// the neighbour it shares most edges with. Third: what is left (nodes with no aggregated
/// neighbour) is grouped with its free neighbours.
pub fn aggregate(g: &Graph) -> (Vec<u32>, usize) {
    const FREE: u32 = u32::MAX;
    let n = g.nodes();
    let mut agg = vec![FREE; n];
    let mut count = 0u32;
    for i in 0..n {
        if agg[i] == FREE && g.neighbours(i).iter().all(|&j| agg[j as usize] == FREE) {
            agg[i] = count;
            for &j in g.neighbours(i) {
                agg[j as usize] = count;
            }
            count += 1;
        }
    }
    // second pass reads the first pass's aggregates only, so the order of joining is moot
    let first = agg.clone();
    for i in 0..n {
        if first[i] != FREE {
            continue;
        }
        let mut best = (0usize, FREE);
        for &j in g.neighbours(i) {
            let a = first[j as usize];
            if a == FREE {
                continue;
            }
            let links = g
                .neighbours(i)
                .iter()
                .filter(|&&k| first[k as usize] == a)
                .count();
            if links > best.0 || (links == best.0 && a < best.1) {
                best = (links, a);
            }
        }
        agg[i] = best.1;
    }
    for i in 0..n {
        if agg[i] == FREE {
            agg[i] = count;
            for &j in g.neighbours(i) {
                if agg[j as usize] == FREE {
                    agg[j as usize] = count;
                }
            }
            count += 1;
        }
    }
    (agg, count as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(nx: usize, ny: usize) -> Graph {
        let id = |i: usize, j: usize| i * nx + j;
        let mut pairs = Vec::new();
        for i in 0..ny {
            for j in 0..nx {
                if j + 1 < nx {
                    pairs.push((id(i, j), id(i, j + 1)));
                }
                if i + 1 < ny {
                    pairs.push((id(i, j), id(i + 1, j)));
                }
            }
        }
        Graph::from_pairs(nx * ny, pairs)
    }

    #[test]
    fn every_node_lands_in_one_connected_aggregate_of_a_few_nodes() {
        let g = grid(20, 15);
        let (agg, count) = aggregate(&g);
        assert!(agg.iter().all(|&a| (a as usize) < count));
        let mut sizes = vec![0; count];
        for &a in &agg {
            sizes[a as usize] += 1;
        }
        assert!(sizes.iter().all(|&s| (1..=9).contains(&s)), "{sizes:?}");
        // a 4-neighbour grid coarsens by roughly the size of a 1-ring
        let ratio = 300.0 / count as f64;
        assert!((2.5..=5.5).contains(&ratio), "coarsening ratio {ratio}");
        // each aggregate is connected through its own members
        for a in 0..count as u32 {
            let members: Vec<usize> = (0..300).filter(|&i| agg[i] == a).collect();
            let mut seen = vec![members[0]];
            let mut k = 0;
            while k < seen.len() {
                for &j in g.neighbours(seen[k]) {
                    let j = j as usize;
                    if agg[j] == a && !seen.contains(&j) {
                        seen.push(j);
                    }
                }
                k += 1;
            }
            assert_eq!(seen.len(), members.len(), "aggregate {a} is split");
        }
        let c = g.coarsen(&agg, count);
        assert_eq!(c.nodes(), count);
        assert!(!c.nbr.is_empty());
    }
}
