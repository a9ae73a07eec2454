//! A random forest of classification trees on quantised features, hand-written: features are
//! cut into [`N_BINS`] bins at the training sample's quantiles, so a node's best split is
//! found from one class histogram per candidate feature (Gini impurity), as in histogram
//! gradient-boosting libraries. Trees grow in parallel (rayon), each from its own seeded
//! random subsample and feature draws, so a forest is the same on any number of threads.

use rayon::prelude::*;

use crate::geometry::SplitMix64;

use super::classes::N_CLASSES;

/// Bins per feature.
pub const N_BINS: usize = 32;

/// Per-feature bin edges: value `v` of feature `f` falls in bin "number of edges ≤ v".
#[derive(Debug, Clone, PartialEq)]
pub struct Quantizer {
    /// `edges[f]`: the `N_BINS − 1` ascending edges of feature `f`; bin `b` holds the values
    /// with exactly `b` edges below or at them.
    pub edges: Vec<Vec<f32>>,
}

impl Quantizer {
    /// Edges at the quantiles `k / N_BINS` of each feature over `rows` (`n × n_features`,
    /// row-major).
    pub fn fit(rows: &[f32], n_features: usize) -> Quantizer {
        let n = rows.len() / n_features.max(1);
        let edges = (0..n_features)
            .map(|f| {
                let mut v: Vec<f32> = (0..n).map(|i| rows[i * n_features + f]).collect();
                v.sort_by(|a, b| a.total_cmp(b));
                (1..N_BINS)
                    .map(|k| {
                        if n == 0 {
                            0.0
                        } else {
                            v[(k * n / N_BINS).min(n - 1)]
                        }
                    })
                    .collect()
            })
            .collect();
        Quantizer { edges }
    }

    /// The bin of value `v` of feature `f`.
    #[inline]
    pub fn bin(&self, f: usize, v: f32) -> u8 {
        self.edges[f].partition_point(|e| *e <= v) as u8
    }

    /// The bins of one row of features.
    pub fn bins(&self, row: &[f32], out: &mut [u8]) {
        for (f, (o, v)) in out.iter_mut().zip(row).enumerate() {
            *o = self.bin(f, *v);
        }
    }
}

/// How a forest grows.
#[derive(Debug, Clone, PartialEq)]
pub struct ForestParams {
    /// Trees.
    pub trees: usize,
    /// Deepest level (the root is 0).
    pub max_depth: usize,
    /// Fewest samples in a leaf.
    pub min_leaf: usize,
    /// Features tried at each node.
    pub mtry: usize,
    /// Share of the samples each tree grows from (drawn without replacement).
    pub subsample: f64,
    /// The features the forest may split on.
    pub features: Vec<usize>,
    /// Seed of the random draws.
    pub seed: u64,
}

/// A node: a split (`feature`, bins `≤ threshold` go to `left`) or a leaf (`feature ==
/// LEAF`, its class distribution at `dist[left · N_CLASSES ..]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Feature index, or [`LEAF`].
    pub feature: u16,
    /// Highest bin going left.
    pub threshold: u8,
    /// Left child, or the leaf's distribution index.
    pub left: u32,
    /// Right child.
    pub right: u32,
}

/// The `feature` of a leaf.
pub const LEAF: u16 = u16::MAX;

/// One classification tree.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Tree {
    /// Nodes, the root first.
    pub nodes: Vec<Node>,
    /// Leaf class distributions, `N_CLASSES` each, summing to 1.
    pub dist: Vec<f32>,
}

impl Tree {
    /// The class distribution of the leaf a row of bins reaches.
    #[inline]
    pub fn leaf(&self, bins: &[u8]) -> &[f32] {
        let mut k = 0usize;
        loop {
            let n = self.nodes[k];
            if n.feature == LEAF {
                let o = n.left as usize * N_CLASSES;
                return &self.dist[o..o + N_CLASSES];
            }
            k = if bins[n.feature as usize] <= n.threshold {
                n.left as usize
            } else {
                n.right as usize
            };
        }
    }
}

/// A forest: the mean of its trees' leaf distributions.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Forest {
    /// The trees.
    pub trees: Vec<Tree>,
}

impl Forest {
    /// Adds the forest's class probabilities for one row of bins to `out`.
    pub fn predict(&self, bins: &[u8], out: &mut [f32; N_CLASSES]) {
        *out = [0.0; N_CLASSES];
        let k = 1.0 / self.trees.len().max(1) as f32;
        for t in &self.trees {
            for (o, p) in out.iter_mut().zip(t.leaf(bins)) {
                *o += k * p;
            }
        }
    }

    /// Grows a forest on `bins` (`n × n_features` row-major) with classes `labels`.
    pub fn grow(bins: &[u8], n_features: usize, labels: &[u8], p: &ForestParams) -> Forest {
        let trees = (0..p.trees)
            .into_par_iter()
            .map(|t| grow_tree(bins, n_features, labels, p, t as u64))
            .collect();
        Forest { trees }
    }
}

type Hist = [[u32; N_CLASSES]; N_BINS];

/// Grows tree `t` of the forest.
fn grow_tree(bins: &[u8], nf: usize, labels: &[u8], p: &ForestParams, t: u64) -> Tree {
    let mut rng = SplitMix64::new(p.seed ^ (t + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let n = labels.len();
    let mut idx: Vec<u32> = (0..n as u32).collect();
    let take = ((n as f64 * p.subsample).round() as usize).clamp(1.min(n), n);
    for i in 0..take {
        let j = i + rng.below(n - i);
        idx.swap(i, j);
    }
    idx.truncate(take);
    let mut tree = Tree::default();
    tree.nodes.push(Node {
        feature: LEAF,
        threshold: 0,
        left: 0,
        right: 0,
    });
    let mut stack = vec![(0usize, 0usize, take, 0usize)];
    let mut feats = p.features.clone();
    let mut hist: Hist = [[0; N_CLASSES]; N_BINS];
    while let Some((node, lo, hi, depth)) = stack.pop() {
        let part = &mut idx[lo..hi];
        let mut counts = [0u32; N_CLASSES];
        for &i in part.iter() {
            counts[labels[i as usize] as usize] += 1;
        }
        let pure = counts.iter().filter(|c| **c > 0).count() <= 1;
        let split = if pure || depth >= p.max_depth || part.len() < 2 * p.min_leaf {
            None
        } else {
            best_split(
                bins, nf, labels, part, &counts, p, &mut feats, &mut rng, &mut hist,
            )
        };
        match split {
            None => {
                let total = part.len().max(1) as f32;
                tree.nodes[node] = Node {
                    feature: LEAF,
                    threshold: 0,
                    left: (tree.dist.len() / N_CLASSES) as u32,
                    right: 0,
                };
                tree.dist.extend(counts.iter().map(|c| *c as f32 / total));
            }
            Some((f, th)) => {
                // partition in place: bins ≤ th first
                let mut m = 0;
                for k in 0..part.len() {
                    if bins[part[k] as usize * nf + f] <= th {
                        part.swap(k, m);
                        m += 1;
                    }
                }
                let (l, r) = (tree.nodes.len(), tree.nodes.len() + 1);
                for _ in 0..2 {
                    tree.nodes.push(Node {
                        feature: LEAF,
                        threshold: 0,
                        left: 0,
                        right: 0,
                    });
                }
                tree.nodes[node] = Node {
                    feature: f as u16,
                    threshold: th,
                    left: l as u32,
                    right: r as u32,
                };
                stack.push((l, lo, lo + m, depth + 1));
                stack.push((r, lo + m, hi, depth + 1));
            }
        }
    }
    tree
}

/// The best (feature, threshold) among `mtry` features drawn from `feats` by Gini impurity,
/// both sides keeping `min_leaf` samples; `None` when no split lowers the impurity.
#[allow(clippy::too_many_arguments)]
fn best_split(
    bins: &[u8],
    nf: usize,
    labels: &[u8],
    part: &[u32],
    counts: &[u32; N_CLASSES],
    p: &ForestParams,
    feats: &mut [usize],
    rng: &mut SplitMix64,
    hist: &mut Hist,
) -> Option<(usize, u8)> {
    let n = part.len() as f64;
    let parent: f64 = counts.iter().map(|c| (*c as f64).powi(2)).sum::<f64>() / n;
    let mut best = (parent + 1e-9, None);
    let m = p.mtry.min(feats.len());
    for k in 0..m {
        let j = k + rng.below(feats.len() - k);
        feats.swap(k, j);
        let f = feats[k];
        *hist = [[0; N_CLASSES]; N_BINS];
        for &i in part {
            let i = i as usize;
            hist[bins[i * nf + f] as usize][labels[i] as usize] += 1;
        }
        let mut left = [0u32; N_CLASSES];
        let mut nl = 0usize;
        for (b, h) in hist.iter().enumerate().take(N_BINS - 1) {
            for c in 0..N_CLASSES {
                left[c] += h[c];
                nl += h[c] as usize;
            }
            let nr = part.len() - nl;
            if nl < p.min_leaf || nr < p.min_leaf {
                continue;
            }
            let (mut sl, mut sr) = (0.0, 0.0);
            for c in 0..N_CLASSES {
                sl += (left[c] as f64).powi(2);
                sr += ((counts[c] - left[c]) as f64).powi(2);
            }
            let score = sl / nl as f64 + sr / nr as f64;
            if score > best.0 {
                best = (score, Some((f, b as u8)));
            }
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_forest_learns_a_threshold_and_an_xor() {
        // class = (f0 > 0.5) xor (f1 > 0.5); f2 noise
        let mut rng = SplitMix64::new(3);
        let n = 4000;
        let mut rows = Vec::new();
        let mut labels = Vec::new();
        for _ in 0..n {
            let (a, b, c) = (
                rng.uniform() as f32,
                rng.uniform() as f32,
                rng.uniform() as f32,
            );
            rows.extend([a, b, c]);
            labels.push(((a > 0.5) ^ (b > 0.5)) as u8);
        }
        let q = Quantizer::fit(&rows, 3);
        let mut bins = vec![0u8; rows.len()];
        for i in 0..n {
            q.bins(&rows[i * 3..i * 3 + 3], &mut bins[i * 3..i * 3 + 3]);
        }
        let p = ForestParams {
            trees: 8,
            max_depth: 8,
            min_leaf: 5,
            mtry: 2,
            subsample: 0.7,
            features: vec![0, 1, 2],
            seed: 1,
        };
        let forest = Forest::grow(&bins, 3, &labels, &p);
        let mut right = 0;
        let mut out = [0.0; N_CLASSES];
        for (k, (a, b)) in [(0.2, 0.2), (0.2, 0.8), (0.8, 0.2), (0.8, 0.8)]
            .iter()
            .enumerate()
        {
            let mut bb = [0u8; 3];
            q.bins(&[*a, *b, 0.5], &mut bb);
            forest.predict(&bb, &mut out);
            let class = (out[1] > out[0]) as usize;
            right += (class == (k == 1 || k == 2) as usize) as usize;
        }
        assert_eq!(right, 4);
        assert_eq!(forest, Forest::grow(&bins, 3, &labels, &p), "deterministic");
    }
}
