//! Integer pair counts `N_ij`: how many sampled segments joined patches i and j.
//!
//! Counts are symmetric (every pair counts once i -> j and once j -> i), so only the entry with `i <= j`
//! is stored. Memory follows the number of distinct visible pairs, not n_p^2: a dense ndarray while the
//! scene has at most [`DENSE_MAX_PATCHES`] patches, a sorted sparse list otherwise.

use ndarray::Array2;
use rayon::slice::ParallelSliceMut;

/// Scenes with at most this many patches keep their counts in a dense matrix (32 MiB at most).
pub const DENSE_MAX_PATCHES: usize = 2048;

/// The key of an unordered pair: `min << 32 | max`.
pub fn pair_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    (u64::from(lo) << 32) | u64::from(hi)
}

/// The two patches of a pair key, smaller first.
pub fn split_key(key: u64) -> (u32, u32) {
    ((key >> 32) as u32, key as u32)
}

/// Symmetric pair counts, dense or sparse.
#[derive(Clone, Debug)]
pub enum PairCounts {
    /// Upper triangle of an n_p x n_p matrix.
    Dense(Array2<u64>),
    /// `(pair key, count)` sorted by key, no repeats, no zero counts.
    Sparse(Vec<(u64, u64)>),
}

impl PairCounts {
    /// Empty counts for `patches` patches, dense or sparse by size.
    pub fn new(patches: usize) -> Self {
        if patches <= DENSE_MAX_PATCHES {
            PairCounts::Dense(Array2::zeros((patches, patches)))
        } else {
            PairCounts::Sparse(Vec::new())
        }
    }

    /// Counts built from a list of pair keys (sorted in place).
    pub fn from_keys(patches: usize, keys: &mut [u64]) -> Self {
        let mut counts = PairCounts::new(patches);
        match &mut counts {
            PairCounts::Dense(m) => {
                for &k in keys.iter() {
                    let (i, j) = split_key(k);
                    m[[i as usize, j as usize]] += 1;
                }
            }
            PairCounts::Sparse(list) => {
                keys.par_sort_unstable();
                *list = run_lengths(keys);
            }
        }
        counts
    }

    /// Counts for `patches` patches from per-batch counts ([`BatchCounts::of_keys`]: sorted run-length
    /// lists for the sparse layout, raw keys for the dense one). The order of the batches does not matter:
    /// integer sums do not depend on it.
    pub fn from_batches(patches: usize, batches: Vec<BatchCounts>) -> Self {
        let mut counts = PairCounts::new(patches);
        match &mut counts {
            PairCounts::Dense(m) => {
                for b in &batches {
                    let keys = match b {
                        BatchCounts::Keys(k) => k.as_slice(),
                        BatchCounts::Runs(_) => unreachable!("a dense scene's batches keep keys"),
                    };
                    for &k in keys {
                        let (i, j) = split_key(k);
                        m[[i as usize, j as usize]] += 1;
                    }
                }
            }
            PairCounts::Sparse(list) => {
                let runs: Vec<Vec<(u64, u64)>> = batches
                    .into_iter()
                    .map(|b| match b {
                        BatchCounts::Runs(r) => r,
                        BatchCounts::Keys(mut k) => {
                            k.sort_unstable();
                            run_lengths(&k)
                        }
                    })
                    .collect();
                *list = merge_all(runs);
            }
        }
        counts
    }

    /// How a batch of `patches` patches should hand over its pair keys (see [`BatchCounts::of_keys`]).
    pub fn is_dense_for(patches: usize) -> bool {
        patches <= DENSE_MAX_PATCHES
    }

    /// Adds `other` (of the same size and layout) into `self`.
    pub fn merge(&mut self, other: &PairCounts) {
        match (self, other) {
            (PairCounts::Dense(a), PairCounts::Dense(b)) => *a += b,
            (PairCounts::Sparse(a), PairCounts::Sparse(b)) => *a = merge_sorted(a, b),
            _ => unreachable!("counts of one scene always share a layout"),
        }
    }

    /// Visits every non-zero entry `(i, j, N_ij)` with `i <= j`.
    pub fn for_each(&self, mut f: impl FnMut(u32, u32, u64)) {
        match self {
            PairCounts::Dense(m) => {
                for ((i, j), &c) in m.indexed_iter() {
                    if c > 0 {
                        f(i as u32, j as u32, c);
                    }
                }
            }
            PairCounts::Sparse(list) => {
                for &(k, c) in list {
                    let (i, j) = split_key(k);
                    f(i, j, c);
                }
            }
        }
    }

    /// Number of distinct unordered pairs seen.
    pub fn distinct_pairs(&self) -> usize {
        match self {
            PairCounts::Dense(m) => m.iter().filter(|&&c| c > 0).count(),
            PairCounts::Sparse(list) => list.len(),
        }
    }

    /// Whether the dense layout is in use.
    pub fn is_dense(&self) -> bool {
        matches!(self, PairCounts::Dense(_))
    }
}

/// One batch's pair counts on their way to a group's [`PairCounts`]: the batch does the sorting of its own
/// keys (in parallel with the other batches) when the scene's counts are sparse.
#[derive(Clone, Debug)]
pub enum BatchCounts {
    /// Unsorted pair keys (dense layout: adding them to the matrix needs no order).
    Keys(Vec<u64>),
    /// `(key, count)` sorted by key, as [`PairCounts::Sparse`] holds them.
    Runs(Vec<(u64, u64)>),
}

impl BatchCounts {
    /// A batch's keys in the form its scene's layout merges fastest: sorted runs for sparse counts.
    pub fn of_keys(patches: usize, mut keys: Vec<u64>) -> Self {
        if PairCounts::is_dense_for(patches) {
            BatchCounts::Keys(keys)
        } else {
            keys.sort_unstable();
            BatchCounts::Runs(run_lengths(&keys))
        }
    }
}

/// Merges sorted run lists, adding the counts of equal keys: pairwise in a balanced tree, in parallel, so
/// each entry is copied O(log n) times. Integer sums make the result independent of the merge order.
fn merge_all(mut runs: Vec<Vec<(u64, u64)>>) -> Vec<(u64, u64)> {
    use rayon::prelude::*;
    while runs.len() > 1 {
        runs = runs
            .par_chunks(2)
            .map(|pair| match pair {
                [a, b] => merge_sorted(a, b),
                [a] => a.clone(),
                _ => unreachable!("chunks of two"),
            })
            .collect();
    }
    runs.pop().unwrap_or_default()
}

fn run_lengths(sorted: &[u64]) -> Vec<(u64, u64)> {
    let mut out: Vec<(u64, u64)> = Vec::new();
    for &k in sorted {
        match out.last_mut() {
            Some((last, c)) if *last == k => *c += 1,
            _ => out.push((k, 1)),
        }
    }
    out
}

fn merge_sorted(a: &[(u64, u64)], b: &[(u64, u64)]) -> Vec<(u64, u64)> {
    let mut out = Vec::with_capacity(a.len().max(b.len()));
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].0.cmp(&b[j].0) {
            std::cmp::Ordering::Less => {
                out.push(a[i]);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                out.push(b[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                out.push((a[i].0, a[i].1 + b[j].1));
                i += 1;
                j += 1;
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(c: &PairCounts) -> Vec<(u32, u32, u64)> {
        let mut v = Vec::new();
        c.for_each(|i, j, n| v.push((i, j, n)));
        v.sort();
        v
    }

    #[test]
    fn dense_and_sparse_agree() {
        let keys: Vec<u64> = [(3, 1), (1, 3), (0, 0), (2, 5), (5, 2), (5, 2)]
            .iter()
            .map(|&(a, b)| pair_key(a, b))
            .collect();
        let dense = PairCounts::from_keys(8, &mut keys.clone());
        let mut sparse = PairCounts::Sparse(Vec::new());
        if let PairCounts::Sparse(l) = &mut sparse {
            let mut k = keys.clone();
            k.sort_unstable();
            *l = run_lengths(&k);
        }
        assert!(dense.is_dense() && !sparse.is_dense());
        assert_eq!(entries(&dense), vec![(0, 0, 1), (1, 3, 2), (2, 5, 3)]);
        assert_eq!(entries(&dense), entries(&sparse));

        // Per-batch hand-over, both layouts, gives the same counts.
        let halves = |patches| {
            let (a, b) = keys.split_at(3);
            vec![
                BatchCounts::of_keys(patches, a.to_vec()),
                BatchCounts::of_keys(patches, b.to_vec()),
                BatchCounts::of_keys(patches, Vec::new()),
            ]
        };
        let from_dense = PairCounts::from_batches(8, halves(8));
        assert!(from_dense.is_dense());
        assert_eq!(entries(&from_dense), entries(&dense));
        let many = DENSE_MAX_PATCHES + 1;
        let from_sparse = PairCounts::from_batches(many, halves(many));
        assert!(!from_sparse.is_dense());
        assert_eq!(entries(&from_sparse), entries(&dense));

        let mut twice = sparse.clone();
        twice.merge(&sparse);
        assert_eq!(entries(&twice), vec![(0, 0, 2), (1, 3, 4), (2, 5, 6)]);
        let mut dtwice = dense.clone();
        dtwice.merge(&dense);
        assert_eq!(entries(&dtwice), entries(&twice));
    }
}
