//! Integer pair counts `N_ij`: how many sampled segments joined patches i and j.
//!
//! Counts are symmetric (every pair counts once i -> j and once j -> i), so only the entry with `i <= j`
//! is stored. Memory follows the number of distinct visible pairs, not n_p^2: a dense ndarray while the
//! scene has at most `DENSE_MAX_PATCHES` patches, a sorted sparse list otherwise.

use ndarray::Array2;
use rayon::prelude::*;

pub use super::sparse::{pair_key, split_key};
use super::sparse::{Packing, SparseCounts};

/// Scenes with at most this many patches keep their counts in a dense matrix (32 MiB at most).
const DENSE_MAX_PATCHES: usize = 2048;

/// Symmetric pair counts. How they are stored is theirs to decide, by the scene's size: a dense matrix
/// while it is small, a sorted sparse list of eight-byte entries otherwise ([`SparseCounts`]).
#[derive(Clone, Debug)]
pub struct PairCounts(Layout);

#[derive(Clone, Debug)]
enum Layout {
    /// Upper triangle of an n_p x n_p matrix.
    Dense(Array2<u64>),
    /// Sorted `(pair, count)` entries.
    Sparse(SparseCounts),
}

impl PairCounts {
    /// Empty counts for `patches` patches.
    pub fn new(patches: usize) -> Self {
        PairCounts(if patches <= DENSE_MAX_PATCHES {
            Layout::Dense(Array2::zeros((patches, patches)))
        } else {
            Layout::Sparse(SparseCounts::new(patches))
        })
    }

    /// Whether the counts of a scene of `patches` patches come from sorting their pair keys (which is
    /// best done for many groups at once, [`count_by_group`]), rather than from adding them up one by
    /// one.
    pub fn counted_by_sorting(patches: usize) -> bool {
        patches > DENSE_MAX_PATCHES
    }

    /// Counts built from a list of pair keys (sorted in place).
    pub fn from_keys(patches: usize, keys: &mut [u64]) -> Self {
        let mut counts = PairCounts::new(patches);
        match &mut counts.0 {
            Layout::Dense(m) => {
                for &k in keys.iter() {
                    let (i, j) = split_key(k);
                    m[[i as usize, j as usize]] += 1;
                }
            }
            Layout::Sparse(list) => {
                sort_keys(patches, keys);
                *list = SparseCounts::from_sorted_keys(patches, keys);
            }
        }
        counts
    }

    /// Counts for `patches` patches from the pair keys of several batches, in any order (integer sums do
    /// not depend on it). Sparse counts radix-sort all the keys at once.
    pub fn from_batches(patches: usize, batches: Vec<Vec<u64>>) -> Self {
        let mut counts = PairCounts::new(patches);
        if let Layout::Dense(m) = &mut counts.0 {
            for &k in batches.iter().flatten() {
                let (i, j) = split_key(k);
                m[[i as usize, j as usize]] += 1;
            }
            return counts;
        }
        let mut keys = batches.concat();
        PairCounts::from_keys(patches, &mut keys)
    }

    /// Counts of `patches` patches from `(key, count)` entries, each key once, in any order.
    pub fn from_entries(patches: usize, entries: Vec<(u64, u64)>) -> Self {
        match PairCounts::new(patches).0 {
            Layout::Dense(mut m) => {
                for (k, c) in entries {
                    let (i, j) = split_key(k);
                    m[[i as usize, j as usize]] += c;
                }
                PairCounts(Layout::Dense(m))
            }
            Layout::Sparse(_) => {
                PairCounts(Layout::Sparse(SparseCounts::from_entries(patches, entries)))
            }
        }
    }

    /// These counts without `part` (counts of the same scene that these include).
    pub fn without(&self, part: &PairCounts) -> PairCounts {
        PairCounts(match (&self.0, &part.0) {
            (Layout::Dense(a), Layout::Dense(b)) => Layout::Dense(a - b),
            (Layout::Sparse(total), Layout::Sparse(part)) => Layout::Sparse(total.without(part)),
            _ => unreachable!("counts of one scene always share a layout"),
        })
    }

    /// Adds `other` (of the same scene) into `self`.
    pub fn merge(&mut self, other: &PairCounts) {
        match (&mut self.0, &other.0) {
            (Layout::Dense(a), Layout::Dense(b)) => *a += b,
            (Layout::Sparse(a), Layout::Sparse(b)) => a.merge(b),
            _ => unreachable!("counts of one scene always share a layout"),
        }
    }

    /// Visits every non-zero entry `(i, j, N_ij)` with `i <= j`, in pair-key order (`i`, then `j`).
    pub fn for_each(&self, mut f: impl FnMut(u32, u32, u64)) {
        match &self.0 {
            Layout::Dense(m) => {
                for ((i, j), &c) in m.indexed_iter() {
                    if c > 0 {
                        f(i as u32, j as u32, c);
                    }
                }
            }
            Layout::Sparse(list) => list.for_each(f),
        }
    }

    /// Visits every non-zero entry `(i, j, N_ij, T_ij)` of these counts with `i <= j`, where `T_ij` is
    /// the entry of `total`, counts of the same scene that include these (every pair here is in
    /// `total`, with at least the same count).
    pub fn for_each_with_total(&self, total: &PairCounts, mut f: impl FnMut(u32, u32, u64, u64)) {
        match (&self.0, &total.0) {
            (Layout::Dense(_), Layout::Dense(t)) => {
                self.for_each(|i, j, c| f(i, j, c, t[[i as usize, j as usize]]));
            }
            (Layout::Sparse(list), Layout::Sparse(t)) => list.for_each_with_total(t, f),
            _ => unreachable!("counts of one scene always share a layout"),
        }
    }

    /// The sum of counts of one scene; `None` without any.
    pub fn sum_of(parts: &[&PairCounts]) -> Option<PairCounts> {
        let first = *parts.first()?;
        if let Layout::Dense(_) = first.0 {
            let mut total = first.clone();
            parts[1..].iter().for_each(|p| total.merge(p));
            return Some(total);
        }
        let lists: Vec<&SparseCounts> = parts.iter().map(|p| p.sparse()).collect();
        Some(PairCounts(Layout::Sparse(SparseCounts::sum_of(&lists))))
    }

    /// The sum of counts of one scene and, from the same pass, the sum of the first `first` of them
    /// ([`SparseCounts::sum_and_sum_of_first`]); `None` without any.
    pub fn sum_and_sum_of_first(
        parts: &[&PairCounts],
        first: usize,
    ) -> Option<(PairCounts, PairCounts)> {
        let head = *parts.first()?;
        if let Layout::Dense(_) = head.0 {
            let firsts = PairCounts::sum_of(&parts[..first.clamp(1, parts.len())])?;
            let mut all = firsts.clone();
            parts[first.clamp(1, parts.len())..]
                .iter()
                .for_each(|p| all.merge(p));
            return Some((all, firsts));
        }
        let lists: Vec<&SparseCounts> = parts.iter().map(|p| p.sparse()).collect();
        let (all, firsts) = SparseCounts::sum_and_sum_of_first(&lists, first);
        Some((
            PairCounts(Layout::Sparse(all)),
            PairCounts(Layout::Sparse(firsts)),
        ))
    }

    fn sparse(&self) -> &SparseCounts {
        match &self.0 {
            Layout::Sparse(list) => list,
            Layout::Dense(_) => unreachable!("counts of one scene always share a layout"),
        }
    }

    /// Number of distinct unordered pairs seen.
    pub fn distinct_pairs(&self) -> usize {
        match &self.0 {
            Layout::Dense(m) => m.iter().filter(|&&c| c > 0).count(),
            Layout::Sparse(list) => list.len(),
        }
    }

    /// Whether the dense layout is in use (for tests of both layouts).
    pub fn is_dense(&self) -> bool {
        matches!(self.0, Layout::Dense(_))
    }
}

/// Sorts pair keys of a scene of `patches` patches: packed into as few bits as the scene needs
/// ([`TagLayout`]) and radix sorted (linear time: a group's keys are mostly distinct, so a comparison
/// sort would cost log n times more).
fn sort_keys(patches: usize, keys: &mut [u64]) {
    let layout = TagLayout::new(patches, 1);
    let mut packed: Vec<u64> = keys.iter().map(|&k| layout.tag(k, 0)).collect();
    radix_sort(&mut packed, layout.bits, &mut Vec::new());
    for (k, &p) in keys.iter_mut().zip(&packed) {
        let (i, j) = layout.packing.unpack_pair(layout.untag(p).0);
        *k = pair_key(i, j);
    }
}

/// Counts the pair keys of `batches` (each `(group, keys)`, groups below `groups`) per group, for a
/// scene of `patches` patches, in one sort. The batches' keys are freed as soon as they are
/// dealt, so that they and the sorted copy are not both held through the sort.
///
/// Each key is tagged with its group in its lowest bits, so that after sorting the entries of one patch
/// pair lie together, group by group: one pass then yields every group's counts.
/// The sort is a radix sort in two stages that both run in parallel: the keys are first dealt by their
/// top bits into buckets of a few thousand (one pass, per chunk of batches), then each bucket is sorted
/// in cache on the remaining bits and writes its runs into its own stretch of every list. The result
/// does not depend on the order of the batches nor on the threads (integer counts of sorted keys).
pub fn count_by_group(
    patches: usize,
    groups: usize,
    batches: Vec<(usize, Vec<u64>)>,
) -> Vec<PairCounts> {
    let layout = TagLayout::new(patches, groups);
    let keys: usize = batches.iter().map(|(_, k)| k.len()).sum();
    // Buckets of ~4096 keys on average.
    let top_bits = (usize::BITS - (keys >> 12).leading_zeros()).clamp(1, layout.bits.min(12));
    let low_bits = layout.bits - top_bits;

    // Stage 1: deal the tagged keys into one array, bucket after bucket: each chunk of batches (one per
    // thread) counts its keys per bucket, then writes them into its own stretch of every bucket.
    let buckets = 1usize << top_bits;
    let chunk = batches.len().div_ceil(rayon::current_num_threads()).max(1);
    let mut chunks: Vec<Vec<(usize, Vec<u64>)>> = Vec::new();
    let mut batches = batches.into_iter().peekable();
    while batches.peek().is_some() {
        chunks.push(batches.by_ref().take(chunk).collect());
    }
    let per_chunk: Vec<Vec<usize>> = chunks
        .par_iter()
        .map(|chunk| {
            let mut counts = vec![0; buckets];
            for (group, keys) in chunk {
                for &k in keys {
                    counts[(layout.tag(k, *group) >> low_bits) as usize] += 1;
                }
            }
            counts
        })
        .collect();
    let mut dealt = vec![0u64; keys];
    // Bucket-major: bucket 0's stretch of chunk 0, of chunk 1, ..., then bucket 1's.
    let mut stretches = split_by_lengths(
        &mut dealt,
        (0..buckets).flat_map(|b| per_chunk.iter().map(move |c| c[b])),
    );
    let mut targets: Vec<Vec<&mut [u64]>> = (0..chunks.len()).map(|_| Vec::new()).collect();
    for (k, stretch) in stretches.drain(..).enumerate() {
        targets[k % chunks.len()].push(stretch);
    }
    chunks
        .into_par_iter()
        .zip(targets)
        .for_each(|(chunk, mut targets)| {
            let mut next = vec![0; buckets];
            // Each batch's keys are dropped once dealt.
            for (group, keys) in chunk {
                for k in keys {
                    let t = layout.tag(k, group);
                    let b = (t >> low_bits) as usize;
                    targets[b][next[b]] = t;
                    next[b] += 1;
                }
            }
        });

    // Stage 2: sort each bucket on its low bits, and count its runs per group.
    let bucket_lengths = (0..buckets).map(|b| per_chunk.iter().map(|c| c[b]).sum());
    let mut sorted: Vec<(&mut [u64], Vec<usize>)> = split_by_lengths(&mut dealt, bucket_lengths)
        .into_iter()
        .map(|values| (values, Vec::new()))
        .collect();
    sorted
        .par_iter_mut()
        .for_each_init(Vec::new, |scratch, (values, runs)| {
            sort_bucket(values, low_bits, scratch);
            *runs = layout.run_counts(values, groups);
        });

    // Stage 3: every bucket writes its runs into its own stretch of each list (buckets hold consecutive
    // key ranges, so the lists come out sorted), and its counts too large for their field apart.
    let lists_len = |l: usize| sorted.iter().map(|(_, r)| r[l]).sum::<usize>();
    let mut entries: Vec<Vec<u64>> = (0..groups).map(|l| vec![0; lists_len(l)]).collect();
    let mut lists: Vec<Vec<&mut [u64]>> = entries
        .iter_mut()
        .enumerate()
        .map(|(l, list)| split_by_lengths(list, sorted.iter().map(|(_, r)| r[l])))
        .collect();
    // Transposed: per bucket, its stretch of every list.
    let mut per_bucket: Vec<Vec<&mut [u64]>> = (0..sorted.len()).map(|_| Vec::new()).collect();
    for list in &mut lists {
        for (b, stretch) in list.drain(..).enumerate() {
            per_bucket[b].push(stretch);
        }
    }
    let wide_per_bucket: Vec<Vec<Vec<(u64, u64)>>> = sorted
        .par_iter()
        .zip(per_bucket)
        .map(|((values, _), mut lists)| layout.write_runs(values, &mut lists))
        .collect();
    drop(dealt);
    entries
        .into_iter()
        .enumerate()
        .map(|(l, entries)| {
            let wide = wide_per_bucket
                .iter()
                .flat_map(|w| w[l].iter().copied())
                .collect();
            PairCounts(Layout::Sparse(SparseCounts::from_parts(
                layout.packing,
                entries,
                wide,
            )))
        })
        .collect()
}

/// Cuts `slice` into consecutive pieces of the given lengths (which must not add up to more).
fn split_by_lengths<T>(
    mut slice: &mut [T],
    lengths: impl IntoIterator<Item = usize>,
) -> Vec<&mut [T]> {
    lengths
        .into_iter()
        .map(|n| {
            let (head, tail) = std::mem::take(&mut slice).split_at_mut(n);
            slice = tail;
            head
        })
        .collect()
}

/// How pair keys are tagged for sorting: `packed pair << g | group`, the pair packed as the sparse lists
/// pack it ([`Packing`]), with `g` bits for a group (0 when there is one).
#[derive(Clone, Copy, Debug)]
struct TagLayout {
    packing: Packing,
    group_bits: u32,
    /// Bits of a tagged key.
    bits: u32,
}

impl TagLayout {
    fn new(patches: usize, groups: usize) -> Self {
        let bits_for = |n: usize| usize::BITS - n.saturating_sub(1).leading_zeros();
        let packing = Packing::for_patches(patches);
        let group_bits = bits_for(groups);
        TagLayout {
            packing,
            group_bits,
            bits: 2 * packing.patch_bits() + group_bits,
        }
    }

    fn tag(&self, key: u64, group: usize) -> u64 {
        (self.packing.pack_key(key) << self.group_bits) | group as u64
    }

    /// The packed pair and the group of a tagged key.
    fn untag(&self, tagged: u64) -> (u64, usize) {
        let group = (tagged & ((1 << self.group_bits) - 1)) as usize;
        (tagged >> self.group_bits, group)
    }

    /// Calls `f(tagged key, count)` for each run of equal tagged keys in `sorted`.
    fn for_each_run(sorted: &[u64], mut f: impl FnMut(u64, u64)) {
        let mut k = 0;
        while k < sorted.len() {
            let tagged = sorted[k];
            let run = sorted[k..].iter().take_while(|&&t| t == tagged).count();
            f(tagged, run as u64);
            k += run;
        }
    }

    /// How many entries sorted tagged keys make in each group's list.
    fn run_counts(&self, sorted: &[u64], groups: usize) -> Vec<usize> {
        let mut runs = vec![0; groups];
        Self::for_each_run(sorted, |tagged, _| {
            runs[self.untag(tagged).1] += 1;
        });
        runs
    }

    /// Writes the runs of sorted tagged keys as packed entries into `lists` (one per group), each
    /// exactly as long as [`TagLayout::run_counts`] said; returns, per list, the `(packed pair, count)`
    /// of the counts too large for their field.
    fn write_runs(&self, sorted: &[u64], lists: &mut [&mut [u64]]) -> Vec<Vec<(u64, u64)>> {
        let mut wide: Vec<Vec<(u64, u64)>> = vec![Vec::new(); lists.len()];
        let mut next = vec![0usize; lists.len()];
        Self::for_each_run(sorted, |tagged, count| {
            let (pair, group) = self.untag(tagged);
            let (entry, is_wide) = SparseCounts::entry_of(self.packing, pair, count);
            lists[group][next[group]] = entry;
            next[group] += 1;
            if is_wide {
                wide[group].push((pair, count));
            }
        });
        wide
    }
}

/// Sorts values by their low `bits` bits (the higher ones being equal): in cache by [`radix_sort`] when
/// there are few, else first split by the top 8 of those bits and each part sorted so, in parallel. The
/// buckets of [`count_by_group`] are cut by the top bits of the smaller patch of a pair, and in a scene
/// whose few large patches come first (a room's walls, then its furniture) one bucket can hold half of
/// all keys: sorted in one piece, it fell out of cache and onto one thread (28 ms of a 60 ms count on
/// `@cubes512` at 10^6 lines).
fn sort_bucket(values: &mut [u64], bits: u32, scratch: &mut Vec<u64>) {
    const IN_CACHE: usize = 1 << 15;
    const SPLIT_BITS: u32 = 8;
    if values.len() <= IN_CACHE || bits <= 2 * SPLIT_BITS {
        radix_sort(values, bits, scratch);
        return;
    }
    let shift = bits - SPLIT_BITS;
    let part = |v: u64| ((v >> shift) & ((1 << SPLIT_BITS) - 1)) as usize;
    let mut offsets = [0usize; 1 << SPLIT_BITS];
    for &v in values.iter() {
        offsets[part(v)] += 1;
    }
    let lengths = offsets;
    let mut sum = 0;
    for o in offsets.iter_mut() {
        (*o, sum) = (sum, sum + *o);
    }
    let scratch = scratch_of_len(scratch, values.len());
    for &v in values.iter() {
        let p = part(v);
        scratch[offsets[p]] = v;
        offsets[p] += 1;
    }
    values.copy_from_slice(scratch);
    split_by_lengths(values, lengths)
        .into_par_iter()
        .for_each_init(Vec::new, |scratch, part| sort_bucket(part, shift, scratch));
}

/// The first `len` values of `scratch`, grown if need be. What it held is left there: every caller
/// overwrites all `len` before reading, and zeroing a bucket's scratch on every sort cost ~2% of an
/// analysis.
fn scratch_of_len(scratch: &mut Vec<u64>, len: usize) -> &mut [u64] {
    if scratch.len() < len {
        scratch.resize(len, 0);
    }
    &mut scratch[..len]
}

/// Least-significant-digit radix sort of values below 2^bits, 11 bits per pass, in place; `scratch` is
/// reused between calls.
fn radix_sort(values: &mut [u64], bits: u32, scratch: &mut Vec<u64>) {
    const DIGIT: u32 = 11;
    let len = values.len();
    let (mut from, mut to): (&mut [u64], &mut [u64]) = (values, scratch_of_len(scratch, len));
    let mut shift = 0;
    let mut passes = 0;
    while shift < bits {
        let mut offsets = [0usize; 1 << DIGIT];
        let digit = |v: u64| ((v >> shift) & ((1 << DIGIT) - 1)) as usize;
        for &v in from.iter() {
            offsets[digit(v)] += 1;
        }
        let mut sum = 0;
        for o in offsets.iter_mut() {
            (*o, sum) = (sum, sum + *o);
        }
        for &v in from.iter() {
            let d = digit(v);
            to[offsets[d]] = v;
            offsets[d] += 1;
        }
        std::mem::swap(&mut from, &mut to);
        shift += DIGIT;
        passes += 1;
    }
    if passes % 2 == 1 {
        // The sorted values are in the scratch (`from`); `to` is the caller's slice again.
        to.copy_from_slice(from);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The entries of sparse counts as stored (in their own order, not sorted here).
    fn sparse_entries(c: &PairCounts) -> Vec<(u64, u64)> {
        match &c.0 {
            Layout::Sparse(list) => list.to_entries(),
            Layout::Dense(_) => panic!("counted by sorting: sparse"),
        }
    }

    fn entries(c: &PairCounts) -> Vec<(u32, u32, u64)> {
        let mut v = Vec::new();
        c.for_each(|i, j, n| v.push((i, j, n)));
        v.sort();
        v
    }

    /// `count` pair keys of patches below `patches`, from a 64-bit LCG at `rng`.
    fn random_keys(rng: &mut u64, count: usize, patches: u32) -> Vec<u64> {
        (0..count)
            .map(|_| {
                *rng = rng
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                pair_key((*rng >> 33) as u32 % patches, (*rng >> 13) as u32 % patches)
            })
            .collect()
    }

    #[test]
    fn dense_and_sparse_agree() {
        let keys: Vec<u64> = [(3, 1), (1, 3), (0, 0), (2, 5), (5, 2), (5, 2)]
            .iter()
            .map(|&(a, b)| pair_key(a, b))
            .collect();
        let dense = PairCounts::from_keys(8, &mut keys.clone());
        let mut sorted = keys.clone();
        sorted.sort_unstable();
        let sparse = PairCounts(Layout::Sparse(SparseCounts::from_sorted_keys(8, &sorted)));
        assert!(dense.is_dense() && !sparse.is_dense());
        assert_eq!(entries(&dense), vec![(0, 0, 1), (1, 3, 2), (2, 5, 3)]);
        assert_eq!(entries(&dense), entries(&sparse));

        // Radix sort of packed keys equals a comparison sort.
        let mut many = random_keys(&mut 12345, 5000, 3000);
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

    /// The sum of the first parts, made with the sum of all, in both layouts: the same as merging them
    /// in turn.
    #[test]
    fn the_first_parts_are_summed_with_all() {
        let mut rng = 77u64;
        for patches in [300usize, DENSE_MAX_PATCHES + 1] {
            let parts: Vec<PairCounts> = (0..5)
                .map(|_| PairCounts::from_keys(patches, &mut random_keys(&mut rng, 4000, 300)))
                .collect();
            let refs: Vec<&PairCounts> = parts.iter().collect();
            for first in 1..=parts.len() {
                let (all, firsts) = PairCounts::sum_and_sum_of_first(&refs, first).unwrap();
                let in_turn = |parts: &[PairCounts]| {
                    let mut sum = parts[0].clone();
                    parts[1..].iter().for_each(|p| sum.merge(p));
                    entries(&sum)
                };
                assert_eq!(entries(&all), in_turn(&parts), "{patches}, first {first}");
                assert_eq!(
                    entries(&firsts),
                    in_turn(&parts[..first]),
                    "{patches}, first {first}"
                );
            }
        }
    }

    /// A bucket too large for the cache is split by its top bits first; the result is sorted all the
    /// same, with an odd number of radix passes too.
    #[test]
    fn large_buckets_sort_like_a_comparison_sort() {
        let mut rng = 3u64;
        for bits in [27, 28, 33] {
            let mut values: Vec<u64> = (0..200_000)
                .map(|_| {
                    rng = rng
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    // Skewed: half of the values share their top 8 bits.
                    let v = rng >> (64 - bits);
                    if rng & 1 == 0 {
                        v & ((1 << (bits - 8)) - 1)
                    } else {
                        v
                    }
                })
                .collect();
            let mut expected = values.clone();
            expected.sort_unstable();
            sort_bucket(&mut values, bits, &mut Vec::new());
            assert_eq!(values, expected, "{bits} bits");
        }
    }

    /// Counting tagged keys in one sort gives each group the counts it would have alone, and their sum
    /// the counts of all keys; with many groups, buckets, self pairs, repeats, an empty group, and a
    /// scene size that is no power of two.
    #[test]
    fn grouped_counting_equals_counting_each_group() {
        let patches = 3001;
        let mut rng = 99u64;
        let mut next = |m: u64| {
            rng = rng
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (rng >> 24) % m
        };
        let groups = 5;
        let batches: Vec<(usize, Vec<u64>)> = (0..40)
            .map(|b| {
                // Group 3 gets no batch; skewed patches so that some pairs repeat often.
                let group = [0, 1, 2, 4][b % 4];
                let keys = (0..(b * 997 % 5000))
                    .map(|_| {
                        let i = next(patches) * next(2) + next(8);
                        let j = if next(10) == 0 { i } else { next(patches) };
                        pair_key(i as u32, j as u32)
                    })
                    .collect();
                (group, keys)
            })
            .collect();
        let counted = count_by_group(patches as usize, groups, batches.clone());
        assert_eq!(counted.len(), groups);
        for (g, counted_g) in counted.iter().enumerate() {
            let mut keys: Vec<u64> = batches
                .iter()
                .filter(|b| b.0 == g)
                .flat_map(|b| b.1.iter().copied())
                .collect();
            let alone = PairCounts::from_keys(patches as usize, &mut keys);
            assert_eq!(entries(counted_g), entries(&alone), "group {g}");
            let keys = sparse_entries(counted_g);
            assert!(keys.windows(2).all(|w| w[0].0 < w[1].0));
        }
        assert_eq!(counted[3].distinct_pairs(), 0);
        let mut all: Vec<u64> = batches.iter().flat_map(|b| b.1.iter().copied()).collect();
        let total = PairCounts::from_keys(patches as usize, &mut all);
        let parts: Vec<&PairCounts> = counted.iter().collect();
        assert_eq!(
            entries(&PairCounts::sum_of(&parts).unwrap()),
            entries(&total)
        );

        // A scene so small that the buckets are told apart by the group bits too.
        let keys: Vec<u64> = (0..9000u64)
            .map(|k| pair_key((k % 3) as u32, (k % 2) as u32))
            .collect();
        let tiny: Vec<(usize, Vec<u64>)> = keys
            .chunks(1000)
            .enumerate()
            .map(|(b, k)| (b % 5, k.to_vec()))
            .collect();
        let counted = count_by_group(3, 5, tiny.clone());
        let sum: u64 = counted
            .iter()
            .flat_map(sparse_entries)
            .map(|(_, c)| c)
            .sum();
        assert_eq!(sum, 9000);
        for (g, counted_g) in counted.iter().enumerate() {
            let mut alone: Vec<u64> = tiny
                .iter()
                .filter(|b| b.0 == g)
                .flat_map(|b| b.1.clone())
                .collect();
            let alone = PairCounts::from_keys(3, &mut alone);
            assert_eq!(entries(counted_g), entries(&alone), "tiny group {g}");
        }
    }
}
