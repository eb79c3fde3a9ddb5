//! Integer pair counts `N_ij`: how many sampled segments joined patches i and j.
//!
//! Counts are symmetric (every pair counts once i -> j and once j -> i), so only the entry with `i <= j`
//! is stored. Memory follows the number of distinct visible pairs, not n_p^2: a dense ndarray while the
//! scene has at most [`DENSE_MAX_PATCHES`] patches, a sorted sparse list otherwise.

use ndarray::Array2;

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
                sort_keys(patches, keys);
                *list = run_lengths(keys);
            }
        }
        counts
    }

    /// Counts for `patches` patches from the pair keys of several batches, in any order (integer sums do
    /// not depend on it). Sparse counts radix-sort all the keys at once ([`sort_keys`]).
    pub fn from_batches(patches: usize, batches: Vec<Vec<u64>>) -> Self {
        let mut counts = PairCounts::new(patches);
        match &mut counts {
            PairCounts::Dense(m) => {
                for &k in batches.iter().flatten() {
                    let (i, j) = split_key(k);
                    m[[i as usize, j as usize]] += 1;
                }
            }
            PairCounts::Sparse(list) => {
                let mut keys = batches.concat();
                sort_keys(patches, &mut keys);
                *list = run_lengths(&keys);
            }
        }
        counts
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

/// Sorts pair keys of a scene of `patches` patches. Below 2^16 patches a key is first packed into
/// `i * patches + j < 2^32` and sorted by an LSD radix sort in passes of 11 bits (3 passes at most,
/// linear time: a group's keys are mostly distinct, so a comparison sort or a merge of sorted batches
/// would cost log n times more); larger scenes fall back to a comparison sort.
fn sort_keys(patches: usize, keys: &mut [u64]) {
    let n = patches as u64;
    if n == 0 || n >= 1 << 16 {
        keys.sort_unstable();
        return;
    }
    let mut packed: Vec<u32> = keys
        .iter()
        .map(|&k| {
            let (i, j) = split_key(k);
            (u64::from(i) * n + u64::from(j)) as u32
        })
        .collect();
    let bits = 64 - (n * n - 1).max(1).leading_zeros();
    radix_sort_u32(&mut packed, bits);
    for (k, &p) in keys.iter_mut().zip(&packed) {
        *k = pair_key((u64::from(p) / n) as u32, (u64::from(p) % n) as u32);
    }
}

/// Least-significant-digit radix sort of values below 2^bits, 11 bits per pass.
fn radix_sort_u32(values: &mut Vec<u32>, bits: u32) {
    const DIGIT: u32 = 11;
    let mut scratch = vec![0u32; values.len()];
    let mut shift = 0;
    while shift < bits {
        let mut offsets = [0usize; 1 << DIGIT];
        let digit = |v: u32| ((v >> shift) & ((1 << DIGIT) - 1)) as usize;
        for &v in values.iter() {
            offsets[digit(v)] += 1;
        }
        let mut sum = 0;
        for o in offsets.iter_mut() {
            (*o, sum) = (sum, sum + *o);
        }
        for &v in values.iter() {
            let d = digit(v);
            scratch[offsets[d]] = v;
            offsets[d] += 1;
        }
        std::mem::swap(values, &mut scratch);
        shift += DIGIT;
    }
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

/// Merges two sorted `(key, count)` lists, adding the counts of equal keys. Branch-free in the loop body
/// (which list advances is data, not control flow: the keys of two groups interleave at random, so a
/// branch would be mispredicted half the time), and the output is allocated once at its largest size.
fn merge_sorted(a: &[(u64, u64)], b: &[(u64, u64)]) -> Vec<(u64, u64)> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let ((ka, ca), (kb, cb)) = (a[i], b[j]);
        let (take_a, take_b) = (ka <= kb, kb <= ka);
        let key = if take_a { ka } else { kb };
        let count = u64::from(take_a) * ca + u64::from(take_b) * cb;
        out.push((key, count));
        i += usize::from(take_a);
        j += usize::from(take_b);
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

        // Radix sort of packed keys equals a comparison sort.
        let mut rng = 12345u64;
        let mut many: Vec<u64> = (0..5000)
            .map(|_| {
                rng = rng
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let (a, b) = ((rng >> 33) as u32 % 3000, (rng >> 13) as u32 % 3000);
                pair_key(a, b)
            })
            .collect();
        let mut expected = many.clone();
        expected.sort_unstable();
        sort_keys(3000, &mut many);
        assert_eq!(many, expected);

        // Per-batch hand-over, both layouts, gives the same counts.
        let halves = || {
            let (a, b) = keys.split_at(3);
            vec![a.to_vec(), b.to_vec(), Vec::new()]
        };
        let from_dense = PairCounts::from_batches(8, halves());
        assert!(from_dense.is_dense());
        assert_eq!(entries(&from_dense), entries(&dense));
        let many = DENSE_MAX_PATCHES + 1;
        let from_sparse = PairCounts::from_batches(many, halves());
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
