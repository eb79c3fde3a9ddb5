//! Sparse pair counts packed eight bytes an entry: the storage of `N_ij` for scenes too large for a
//! dense matrix, whose size follows the number of distinct visible pairs.
//!
//! A long run on a large mesh holds one list per standard-error group and one for the whole run, and
//! those lists are most of its memory. An entry packs the pair's two patch indices, in as many bits as
//! the scene needs, above its count: with `p` bits per patch index the count has `64 - 2p` bits (30 for a
//! 100,000-patch scene). A count that does not fit (rare: it takes more segments on one pair than the
//! field holds) stores the field's largest value and its whole count in a side list, so no count is ever
//! clipped. The packed keys sort like the pairs `(min, max)`, so every walk over the entries visits the
//! pairs in the same order as before packing, and sums over them come out the same to the bit.

use rayon::prelude::*;

/// The key of an unordered pair: `min << 32 | max`.
pub fn pair_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    (u64::from(lo) << 32) | u64::from(hi)
}

/// The two patches of a pair key, smaller first.
pub fn split_key(key: u64) -> (u32, u32) {
    ((key >> 32) as u32, key as u32)
}

/// How a pair and its count are packed into one `u64` for a scene of a given size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Packing {
    /// Bits of one patch index.
    patch_bits: u32,
    /// Bits of the count field (the rest of the 64).
    count_bits: u32,
}

impl Packing {
    /// The packing for a scene of `patches` patches.
    pub fn for_patches(patches: usize) -> Self {
        let patch_bits = (usize::BITS - patches.saturating_sub(1).leading_zeros()).max(1);
        Packing {
            patch_bits,
            count_bits: 64 - 2 * patch_bits,
        }
    }

    /// Bits of one patch index.
    pub fn patch_bits(self) -> u32 {
        self.patch_bits
    }

    /// The largest value of the count field; a field holding it means "see the side list".
    fn field_max(self) -> u64 {
        if self.count_bits == 0 {
            0
        } else {
            u64::MAX >> (64 - self.count_bits)
        }
    }

    /// The pair `(lo, hi)` as `lo << p | hi`, which sorts like `(lo, hi)`.
    pub fn pack_pair(self, lo: u32, hi: u32) -> u64 {
        (u64::from(lo) << self.patch_bits) | u64::from(hi)
    }

    /// The packed pair of a [`pair_key`].
    pub fn pack_key(self, key: u64) -> u64 {
        let (lo, hi) = split_key(key);
        self.pack_pair(lo, hi)
    }

    /// The two patches of a packed pair, smaller first.
    pub fn unpack_pair(self, packed: u64) -> (u32, u32) {
        let hi = packed & ((1 << self.patch_bits) - 1);
        ((packed >> self.patch_bits) as u32, hi as u32)
    }

    fn entry(self, packed: u64, count: u64) -> u64 {
        (packed << self.count_bits) | count.min(self.field_max())
    }

    fn packed_of(self, entry: u64) -> u64 {
        if self.count_bits == 0 {
            entry
        } else {
            entry >> self.count_bits
        }
    }

    fn field_of(self, entry: u64) -> u64 {
        entry & self.field_max()
    }
}

/// `(pair, count)` entries sorted by pair, each pair once, no zero counts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SparseCounts {
    packing: Packing,
    /// Packed entries, sorted.
    entries: Vec<u64>,
    /// `(packed pair, count)` of the entries whose count fills their field, sorted.
    wide: Vec<(u64, u64)>,
}

impl SparseCounts {
    /// No counts, for a scene of `patches` patches.
    pub fn new(patches: usize) -> Self {
        SparseCounts::with_packing(Packing::for_patches(patches))
    }

    /// No counts, packed so.
    pub fn with_packing(packing: Packing) -> Self {
        SparseCounts {
            packing,
            entries: Vec::new(),
            wide: Vec::new(),
        }
    }

    /// Empty counts with room for `len` entries.
    pub fn with_capacity(packing: Packing, len: usize) -> Self {
        SparseCounts {
            packing,
            entries: Vec::with_capacity(len),
            wide: Vec::new(),
        }
    }

    /// How the entries are packed.
    pub fn packing(&self) -> Packing {
        self.packing
    }

    /// Distinct pairs.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether there are no counts.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Appends the count of a packed pair above every pair so far (`count > 0`).
    pub fn push(&mut self, packed: u64, count: u64) {
        debug_assert!(count > 0, "no zero counts");
        debug_assert!(
            self.entries
                .last()
                .is_none_or(|&e| self.packing.packed_of(e) < packed),
            "pairs pushed in increasing order"
        );
        if count >= self.packing.field_max() {
            self.wide.push((packed, count));
        }
        self.entries.push(self.packing.entry(packed, count));
    }

    /// Counts from `(pair key, count)` entries, each key once, in any order.
    pub fn from_entries(patches: usize, mut entries: Vec<(u64, u64)>) -> Self {
        let mut out = SparseCounts::new(patches);
        let packing = out.packing;
        for e in entries.iter_mut() {
            e.0 = packing.pack_key(e.0);
        }
        entries.sort_unstable();
        out.entries.reserve_exact(entries.len());
        for (packed, count) in entries {
            if count > 0 {
                out.push(packed, count);
            }
        }
        out
    }

    /// Counts of sorted pair keys (repeats counted).
    pub fn from_sorted_keys(patches: usize, sorted: &[u64]) -> Self {
        let mut out = SparseCounts::new(patches);
        let packing = out.packing;
        let mut k = 0;
        while k < sorted.len() {
            let key = sorted[k];
            let run = sorted[k..].iter().take_while(|&&x| x == key).count();
            out.push(packing.pack_key(key), run as u64);
            k += run;
        }
        out
    }

    /// Visits every `(packed pair, count)` in order.
    pub fn for_each_packed(&self, mut f: impl FnMut(u64, u64)) {
        let (packing, max) = (self.packing, self.packing.field_max());
        let mut wide = self.wide.iter();
        for &e in &self.entries {
            let (packed, field) = (packing.packed_of(e), packing.field_of(e));
            let count = if field == max {
                let &(w, c) = wide.next().expect("a full field has its side entry");
                debug_assert_eq!(w, packed);
                c
            } else {
                field
            };
            f(packed, count);
        }
    }

    /// Visits every `(i, j, N_ij)` with `i <= j`, in order.
    pub fn for_each(&self, mut f: impl FnMut(u32, u32, u64)) {
        let packing = self.packing;
        self.for_each_packed(|packed, count| {
            let (i, j) = packing.unpack_pair(packed);
            f(i, j, count);
        });
    }

    /// The entries as `(pair key, count)`, in order.
    pub fn to_entries(&self) -> Vec<(u64, u64)> {
        let mut out = Vec::with_capacity(self.len());
        self.for_each(|i, j, c| out.push((pair_key(i, j), c)));
        out
    }

    /// Visits every `(i, j, N_ij, T_ij)` of these counts, where `T_ij` is the entry of `total`, counts
    /// that include these (every pair here is in `total`, with at least the same count).
    pub fn for_each_with_total(&self, total: &SparseCounts, mut f: impl FnMut(u32, u32, u64, u64)) {
        assert_eq!(self.packing, total.packing, "counts of one scene");
        let mut totals = Walk::new(total);
        self.for_each_packed(|packed, count| {
            let t = totals.count_of(packed);
            let (i, j) = self.packing.unpack_pair(packed);
            f(i, j, count, t);
        });
    }

    /// These counts without `part` (counts of the same scene that these include).
    pub fn without(&self, part: &SparseCounts) -> SparseCounts {
        assert_eq!(self.packing, part.packing, "counts of one scene");
        let mut out = SparseCounts::with_capacity(self.packing, self.len());
        let mut parts = Walk::new(part);
        self.for_each_packed(|packed, count| {
            let left = count - parts.count_of_or_zero(packed);
            if left > 0 {
                out.push(packed, left);
            }
        });
        out
    }

    /// Adds `other` (packed the same) into these counts.
    ///
    /// In place, from the back: the entries only grow by `other`'s length (a long run's lists hold
    /// millions of entries, and a fresh list for every merge cost a page fault per 4 KiB on top of the
    /// copy), then the merged entries are written from the end down, which never overtakes the unread
    /// part (the gap between them is what is left of `other` plus the pairs merged so far), and finally
    /// moved down over that gap. Branch-free in the common case (which list advances is data, not control
    /// flow: the pairs of two groups interleave at random, so a branch would be mispredicted half the
    /// time); only counts that reach their field's largest value take the slow path.
    pub fn merge(&mut self, other: &SparseCounts) {
        assert_eq!(self.packing, other.packing, "counts of one scene");
        let packing = self.packing;
        let max = packing.field_max();
        let (n, m) = (self.entries.len(), other.entries.len());
        let a = &mut self.entries;
        let b = &other.entries;
        a.resize(n + m, 0);
        let (mut i, mut j, mut w) = (n, m, n + m);
        // Side entries are read from the back as their entries are.
        let (mut wa, mut wb) = (self.wide.len(), other.wide.len());
        let mut wide_out: Vec<(u64, u64)> = Vec::new();
        while i > 0 && j > 0 {
            let (ea, eb) = (a[i - 1], b[j - 1]);
            let (ka, kb) = (packing.packed_of(ea), packing.packed_of(eb));
            let (take_a, take_b) = (ka >= kb, kb >= ka);
            let key = if take_a { ka } else { kb };
            let fa = packing.field_of(ea) * u64::from(take_a);
            let fb = packing.field_of(eb) * u64::from(take_b);
            w -= 1;
            if fa == max || fb == max || fa + fb >= max {
                let ca = if take_a && fa == max {
                    wa -= 1;
                    self.wide[wa].1
                } else {
                    fa
                };
                let cb = if take_b && fb == max {
                    wb -= 1;
                    other.wide[wb].1
                } else {
                    fb
                };
                wide_out.push((key, ca + cb));
                a[w] = packing.entry(key, ca + cb);
            } else {
                a[w] = packing.entry(key, fa + fb);
            }
            i -= usize::from(take_a);
            j -= usize::from(take_b);
        }
        // What is left of `other` goes before the merged tail; what is left of these already is in
        // place, with the side entries of both below the ones merged.
        a[w - j..w].copy_from_slice(&b[..j]);
        w -= j;
        if w > i {
            a.copy_within(w.., i);
            a.truncate(n + m - (w - i));
        }
        let mut wide: Vec<(u64, u64)> = Vec::with_capacity(wa + wb + wide_out.len());
        wide.extend_from_slice(&self.wide[..wa]);
        wide.extend_from_slice(&other.wide[..wb]);
        wide.sort_unstable();
        wide_out.reverse();
        wide.extend(wide_out);
        self.wide = wide;
    }

    /// The sum of several counts packed the same (a run's total from its groups' counts), each pair once.
    ///
    /// The key range is cut into pieces of a few thousand entries a part, merged in parallel a wave at a
    /// time, in cache, straight from the parts (no copies of them), and appended in order to one list.
    /// That list reserves the parts' total length, an upper bound of its own, but only the pages it
    /// writes become resident, so no more than the result, the parts and two waves are ever held (a list
    /// grown as it goes is copied when it outgrows its block, which holds the old and the new one at
    /// once).
    pub fn sum_of(parts: &[&SparseCounts]) -> SparseCounts {
        SparseCounts::sums(parts, None).0
    }

    /// The sum of all `parts` and, from the same pass, the sum of the first `first` of them (the
    /// first half of a run's groups, a run of half its lines): the merge sums each key range's first
    /// parts and its others apart before adding the two, so the first sum costs only its copy.
    pub fn sum_and_sum_of_first(
        parts: &[&SparseCounts],
        first: usize,
    ) -> (SparseCounts, SparseCounts) {
        let (all, firsts) = SparseCounts::sums(parts, Some(first.min(parts.len())));
        (all, firsts.expect("asked for"))
    }

    fn sums(parts: &[&SparseCounts], first: Option<usize>) -> (SparseCounts, Option<SparseCounts>) {
        let packing = match parts.first() {
            Some(p) => p.packing,
            None => {
                let empty = SparseCounts::with_packing(Packing::for_patches(2));
                return (empty.clone(), first.map(|_| empty));
            }
        };
        assert!(
            parts.iter().all(|p| p.packing == packing),
            "counts of one scene"
        );
        let dense = dense_pieces(parts);
        let pieces = dense.clone().unwrap_or_else(|| key_pieces(parts));
        let bound = |parts: &[&SparseCounts]| parts.iter().map(|p| p.len()).sum();
        let mut out = SparseCounts::with_capacity(packing, bound(parts));
        let mut out_first = first.map(|k| SparseCounts::with_capacity(packing, bound(&parts[..k])));
        let wave = 8 * rayon::current_num_threads();
        // A wave is appended (one thread: copies into pages touched for the first time) while the next
        // one is merged.
        let mut merged = Vec::new();
        for some in pieces.chunks(wave) {
            let (next, ()) = rayon::join(
                || match dense {
                    Some(_) => some
                        .par_iter()
                        .map(|piece| {
                            DENSE_TABLE.with_borrow_mut(|table| {
                                table.resize(DENSE_SLOTS as usize, 0);
                                dense_piece(parts, piece, first, table)
                            })
                        })
                        .collect(),
                    None => some
                        .par_iter()
                        .map(|piece| merge_piece(parts, piece, first))
                        .collect(),
                },
                || append_pieces(&mut out, &mut out_first, std::mem::take(&mut merged)),
            );
            merged = next;
        }
        append_pieces(&mut out, &mut out_first, merged);
        (out, out_first)
    }

    /// Appends counts of pairs that all come after these ones.
    fn append(&mut self, later: &SparseCounts) {
        self.entries.extend_from_slice(&later.entries);
        self.wide.extend_from_slice(&later.wide);
    }

    /// The entries (and side entries) whose packed pairs lie in `from..to`.
    fn slice(&self, from: u64, to: u64) -> Run<'_> {
        let packing = self.packing;
        let at = |k: u64| self.entries.partition_point(|&e| packing.packed_of(e) < k);
        let wide_at = |k: u64| self.wide.partition_point(|&(w, _)| w < k);
        Run {
            entries: &self.entries[at(from)..at(to)],
            wide: &self.wide[wide_at(from)..wide_at(to)],
        }
    }

    /// All of these counts as a [`Run`].
    fn run(&self) -> Run<'_> {
        Run {
            entries: &self.entries,
            wide: &self.wide,
        }
    }

    /// The raw parts, for the grouped counting of the counts module, which writes entries in parallel.
    pub(super) fn from_parts(packing: Packing, entries: Vec<u64>, wide: Vec<(u64, u64)>) -> Self {
        SparseCounts {
            packing,
            entries,
            wide,
        }
    }

    /// The packed entry of a pair and its count, and whether the count needs a side entry.
    pub(super) fn entry_of(packing: Packing, packed: u64, count: u64) -> (u64, bool) {
        (packing.entry(packed, count), count >= packing.field_max())
    }
}

/// Appends merged pieces, in key order, to the sum of all and to the sum of the first parts.
fn append_pieces(
    out: &mut SparseCounts,
    out_first: &mut Option<SparseCounts>,
    pieces: Vec<(SparseCounts, Option<SparseCounts>)>,
) {
    for (all, firsts) in pieces {
        out.append(&all);
        if let (Some(o), Some(f)) = (out_first.as_mut(), firsts) {
            o.append(&f);
        }
    }
}

/// Key slots of one piece summed through a table ([`dense_piece`]): 256 KiB of counts, which stay in a
/// core's second-level cache.
const DENSE_SLOTS: u64 = 1 << 15;

thread_local! {
    /// Each thread's table for [`dense_piece`], kept between pieces and sums (zeroed once, and left
    /// zeroed by every piece) rather than made and zeroed for each.
    static DENSE_TABLE: std::cell::RefCell<Vec<u64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The parts are summed through tables when they hold at least one entry per this many slots of the
/// key range they span: the table's scan then costs less than the merges' passes it replaces.
const DENSE_SLOTS_PER_ENTRY: u64 = 4;

/// The pieces of the sum of `parts` through tables ([`dense_piece`]): consecutive ranges of
/// [`DENSE_SLOTS`] packed pairs over the range the parts span, when their entries fill it densely
/// enough ([`DENSE_SLOTS_PER_ENTRY`]) and none has a count too large for its field; else `None`, and
/// the sum merges the parts' entries ([`key_pieces`]). A scene of a few thousand patches cast with
/// tens of millions of lines (`@cube:30`) has most of its pairs in every group: its groups' entries
/// fill half the slots of their range, and summing them through a table touches each entry once where
/// the merges' balanced tree of 16 groups read it four times.
fn dense_pieces(parts: &[&SparseCounts]) -> Option<Vec<(u64, u64)>> {
    let packing = parts.first()?.packing;
    if parts.iter().any(|p| !p.wide.is_empty()) {
        return None;
    }
    let filled = parts.iter().filter(|p| !p.entries.is_empty());
    let lo = filled
        .clone()
        .map(|p| packing.packed_of(p.entries[0]))
        .min()?;
    let hi = filled
        .map(|p| packing.packed_of(p.entries[p.entries.len() - 1]))
        .max()?;
    let entries: u64 = parts.iter().map(|p| p.len() as u64).sum();
    // (A scene of 2^32 patches packs pairs into all 64 bits: its range's end would not be a `u64`.)
    let span = (hi - lo).checked_add(1).filter(|_| hi < u64::MAX)?;
    if span / DENSE_SLOTS_PER_ENTRY > entries {
        return None;
    }
    let starts = (0..span.div_ceil(DENSE_SLOTS)).map(|k| lo + k * DENSE_SLOTS);
    Some(
        starts
            .map(|from| (from, (from + DENSE_SLOTS).min(hi + 1)))
            .collect(),
    )
}

/// [`merge_piece`] through a table of counts, one slot per packed pair of the piece's range: each
/// part's entries are added into their slots, and the slots read back in order. `table` holds
/// [`DENSE_SLOTS`] zeros, and is left so.
fn dense_piece(
    parts: &[&SparseCounts],
    &(from, to): &(u64, u64),
    first: Option<usize>,
    table: &mut [u64],
) -> (SparseCounts, Option<SparseCounts>) {
    let packing = parts[0].packing;
    let table = &mut table[..(to - from) as usize];
    let add = |table: &mut [u64], parts: &[&SparseCounts]| {
        for p in parts {
            for &e in p.slice(from, to).entries {
                table[(packing.packed_of(e) - from) as usize] += packing.field_of(e);
            }
        }
    };
    let read = |table: &mut [u64], clear: bool| {
        let mut out = SparseCounts::with_packing(packing);
        for (slot, count) in table.iter_mut().enumerate() {
            if *count != 0 {
                out.push(from + slot as u64, *count);
                if clear {
                    *count = 0;
                }
            }
        }
        out
    };
    let Some(k) = first else {
        add(table, parts);
        return (read(table, true), None);
    };
    add(table, &parts[..k]);
    let firsts = read(table, false);
    add(table, &parts[k..]);
    (read(table, true), Some(firsts))
}

/// Cuts the packed pairs of `parts` into consecutive ranges `from..to` of about 8,192 entries of the
/// longest part each (the last range open-ended): the parts' stretches of one range and their merges fit
/// in a core's cache.
fn key_pieces(parts: &[&SparseCounts]) -> Vec<(u64, u64)> {
    const PIECE: usize = 1 << 13;
    let longest = parts.iter().max_by_key(|p| p.len()).expect("some parts");
    let packing = longest.packing;
    let cuts: Vec<u64> = (1..longest.len().div_ceil(PIECE))
        .map(|k| packing.packed_of(longest.entries[k * PIECE]))
        .collect();
    let starts = std::iter::once(0).chain(cuts.iter().copied());
    let ends = cuts.iter().copied().chain(std::iter::once(u64::MAX));
    starts.zip(ends).collect()
}

/// The sum of the parts' entries in one range and, when `first` is given, the sum of the first `first`
/// parts' entries in it (which the sum of all is then made from).
fn merge_piece(
    parts: &[&SparseCounts],
    piece: &(u64, u64),
    first: Option<usize>,
) -> (SparseCounts, Option<SparseCounts>) {
    let Some(k) = first else {
        return (merge_tree(parts, piece), None);
    };
    let (firsts, others) = (
        merge_tree(&parts[..k], piece),
        merge_tree(&parts[k..], piece),
    );
    let all = merge_runs(parts[0].packing, firsts.run(), others.run());
    (all, Some(firsts))
}

/// The sum of the parts' entries in one range, merged pairwise as a balanced tree.
fn merge_tree(parts: &[&SparseCounts], &(from, to): &(u64, u64)) -> SparseCounts {
    let Some(packing) = parts.first().map(|p| p.packing) else {
        return SparseCounts::with_packing(Packing::for_patches(2));
    };
    let runs: Vec<Run> = parts
        .iter()
        .map(|p| p.slice(from, to))
        .filter(|r| !r.entries.is_empty())
        .collect();
    // The first level merges the parts' stretches in place; later ones merge what it made.
    let mut level: Vec<SparseCounts> = runs
        .chunks(2)
        .map(|pair| match pair {
            [a, b] => merge_runs(packing, *a, *b),
            [a] => a.to_counts(packing),
            _ => unreachable!("chunks of one or two"),
        })
        .collect();
    while level.len() > 1 {
        level = level
            .chunks(2)
            .map(|pair| match pair {
                [a, b] => merge_runs(packing, a.run(), b.run()),
                [a] => a.clone(),
                _ => unreachable!("chunks of one or two"),
            })
            .collect();
    }
    level
        .pop()
        .unwrap_or_else(|| SparseCounts::with_packing(packing))
}

/// A borrowed stretch of counts: sorted entries and the side entries of those whose field is full.
#[derive(Clone, Copy, Debug)]
struct Run<'a> {
    entries: &'a [u64],
    wide: &'a [(u64, u64)],
}

impl Run<'_> {
    fn to_counts(self, packing: Packing) -> SparseCounts {
        SparseCounts {
            packing,
            entries: self.entries.to_vec(),
            wide: self.wide.to_vec(),
        }
    }
}

/// The sum of two runs, front to back. As in [`SparseCounts::merge`], which list advances is data, not
/// control flow; only a sum that reaches the field's largest value takes the slow path, which reads
/// whole counts from the side entries (every full field is met there in order, so `wa` and `wb` stay
/// in step with the entries).
fn merge_runs(packing: Packing, a: Run, b: Run) -> SparseCounts {
    let max = packing.field_max();
    let (ea, eb) = (a.entries, b.entries);
    let mut entries = Vec::with_capacity(ea.len() + eb.len());
    let mut wide = Vec::new();
    let (mut i, mut j, mut wa, mut wb) = (0, 0, 0, 0);
    while i < ea.len() && j < eb.len() {
        let (x, y) = (ea[i], eb[j]);
        let (kx, ky) = (packing.packed_of(x), packing.packed_of(y));
        let (take_a, take_b) = (kx <= ky, ky <= kx);
        let fx = packing.field_of(x) * u64::from(take_a);
        let fy = packing.field_of(y) * u64::from(take_b);
        let key = if take_a { kx } else { ky };
        if fx == max || fy == max || fx + fy >= max {
            let cx = if take_a && fx == max {
                wa += 1;
                a.wide[wa - 1].1
            } else {
                fx
            };
            let cy = if take_b && fy == max {
                wb += 1;
                b.wide[wb - 1].1
            } else {
                fy
            };
            wide.push((key, cx + cy));
            entries.push(packing.entry(key, cx + cy));
        } else {
            // The key's bits and a field that does not overflow: the lower entry plus the other's count.
            entries.push((if take_a { x } else { y }) + fy * u64::from(take_a));
        }
        i += usize::from(take_a);
        j += usize::from(take_b);
    }
    entries.extend_from_slice(&ea[i..]);
    entries.extend_from_slice(&eb[j..]);
    wide.extend_from_slice(&a.wide[wa..]);
    wide.extend_from_slice(&b.wide[wb..]);
    SparseCounts {
        packing,
        entries,
        wide,
    }
}

/// A forward walk along sorted counts, looking up pairs in increasing order.
struct Walk<'a> {
    counts: &'a SparseCounts,
    next: usize,
    wide: usize,
}

impl<'a> Walk<'a> {
    fn new(counts: &'a SparseCounts) -> Self {
        Walk {
            counts,
            next: 0,
            wide: 0,
        }
    }

    /// The count of `packed`, 0 when absent; pairs must be asked in increasing order.
    fn count_of_or_zero(&mut self, packed: u64) -> u64 {
        let packing = self.counts.packing;
        let entries = &self.counts.entries;
        while self.next < entries.len() && packing.packed_of(entries[self.next]) < packed {
            self.step();
        }
        match entries.get(self.next) {
            Some(&e) if packing.packed_of(e) == packed => {
                let field = packing.field_of(e);
                if field == packing.field_max() {
                    self.counts.wide[self.wide].1
                } else {
                    field
                }
            }
            _ => 0,
        }
    }

    /// The count of `packed`, which must be present.
    fn count_of(&mut self, packed: u64) -> u64 {
        let c = self.count_of_or_zero(packed);
        debug_assert!(c > 0, "a part's pair is in the total");
        c
    }

    fn step(&mut self) {
        let packing = self.counts.packing;
        if packing.field_of(self.counts.entries[self.next]) == packing.field_max() {
            self.wide += 1;
        }
        self.next += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn lcg(state: &mut u64, m: u64) -> u64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 24) % m
    }

    /// Random `(pair key, count)` maps over `patches` patches, some counts large.
    fn random_map(rng: &mut u64, patches: u64, len: usize, big: u64) -> BTreeMap<(u32, u32), u64> {
        let mut map = BTreeMap::new();
        for _ in 0..len {
            let (a, b) = (lcg(rng, patches) as u32, lcg(rng, patches) as u32);
            let c = if lcg(rng, 10) == 0 {
                big + lcg(rng, 3)
            } else {
                lcg(rng, 4) + 1
            };
            *map.entry((a.min(b), a.max(b))).or_insert(0) += c;
        }
        map
    }

    fn of_map(patches: usize, map: &BTreeMap<(u32, u32), u64>) -> SparseCounts {
        SparseCounts::from_entries(
            patches,
            map.iter()
                .map(|(&(i, j), &c)| (pair_key(i, j), c))
                .collect(),
        )
    }

    fn to_map(c: &SparseCounts) -> BTreeMap<(u32, u32), u64> {
        let mut map = BTreeMap::new();
        c.for_each(|i, j, n| {
            assert!(map.insert((i, j), n).is_none(), "each pair once");
        });
        map
    }

    /// Packing a pair keeps the order of `(min, max)`, for patch counts at and around powers of two.
    #[test]
    fn packed_pairs_sort_like_pairs_and_unpack() {
        for patches in [2usize, 3, 4096, 4097, 101_400, 1 << 20, u32::MAX as usize] {
            let p = Packing::for_patches(patches);
            let top = (patches - 1) as u32;
            let mut pairs = vec![(0, 0), (0, 1), (0, top), (1, 1), (top / 2, top), (top, top)];
            pairs.sort_unstable();
            pairs.dedup();
            let packed: Vec<u64> = pairs.iter().map(|&(a, b)| p.pack_pair(a, b)).collect();
            assert!(packed.windows(2).all(|w| w[0] < w[1]), "{patches}");
            for (&(a, b), &k) in pairs.iter().zip(&packed) {
                assert_eq!(p.unpack_pair(k), (a, b));
                assert_eq!(p.pack_key(pair_key(b, a)), k);
            }
        }
    }

    /// Counts too large for their field keep their whole value, through building, walking, merging and
    /// taking a part out, with a field of 30 bits (100k patches), 8 bits and none at all.
    #[test]
    fn counts_beyond_the_field_are_kept_whole() {
        let mut rng = 5;
        for (patches, big) in [
            (101_400usize, 1u64 << 30),
            (1 << 28, 254),
            (1 << 28, 1 << 40),
            (u32::MAX as usize, 1),
        ] {
            let a = random_map(&mut rng, patches as u64, 400, big);
            let b = random_map(&mut rng, patches as u64, 300, big);
            let (ca, cb) = (of_map(patches, &a), of_map(patches, &b));
            assert_eq!(to_map(&ca), a, "{patches}");
            let mut sum = a.clone();
            for (&k, &c) in &b {
                *sum.entry(k).or_insert(0) += c;
            }
            let mut merged = ca.clone();
            merged.merge(&cb);
            assert_eq!(to_map(&merged), sum, "merge, {patches}");
            let mut other_way = cb.clone();
            other_way.merge(&ca);
            assert_eq!(other_way, merged, "the same list either way, {patches}");
            assert_eq!(to_map(&merged.without(&cb)), a, "without, {patches}");
            let mut seen = 0;
            cb.for_each_with_total(&merged, |i, j, c, t| {
                assert_eq!((c, t), (b[&(i, j)], sum[&(i, j)]));
                seen += 1;
            });
            assert_eq!(seen, b.len());
        }
    }

    /// The sum of many parts equals adding them one by one, with parts long enough to be cut into
    /// several pieces, empty parts, and counts beyond the field.
    #[test]
    fn the_sum_of_parts_equals_merging_them_in_turn() {
        let mut rng = 11;
        let patches = 1 << 28;
        let parts: Vec<SparseCounts> = [70_000, 0, 40_000, 100_000, 5]
            .iter()
            .map(|&len| of_map(patches, &random_map(&mut rng, 5000, len, 1 << 9)))
            .collect();
        let mut expected = parts[0].clone();
        for p in &parts[1..] {
            expected.merge(p);
        }
        let refs: Vec<&SparseCounts> = parts.iter().collect();
        let sum = SparseCounts::sum_of(&refs);
        assert!(key_pieces(&refs).len() > 2);
        assert_eq!(sum, expected);
        assert_eq!(SparseCounts::sum_of(&refs[1..2]), parts[1]);
    }

    /// The sum of the first parts, made in the same pass as the sum of all, is the sum of the first
    /// parts' maps, and the sum of all unchanged, for every split point (empty parts, side entries and
    /// several pieces included).
    #[test]
    fn the_sum_of_the_first_parts_comes_with_the_sum() {
        let mut rng = 17;
        let patches = 1 << 28;
        let maps: Vec<BTreeMap<(u32, u32), u64>> = [60_000, 0, 30_000, 90_000, 7, 20_000]
            .iter()
            .map(|&len| random_map(&mut rng, 4000, len, 1 << 9))
            .collect();
        let parts: Vec<SparseCounts> = maps.iter().map(|m| of_map(patches, m)).collect();
        let refs: Vec<&SparseCounts> = parts.iter().collect();
        assert!(key_pieces(&refs).len() > 2);
        let sum_of_maps = |maps: &[BTreeMap<(u32, u32), u64>]| {
            let mut sum = BTreeMap::new();
            for (&k, &c) in maps.iter().flatten() {
                *sum.entry(k).or_insert(0) += c;
            }
            sum
        };
        for first in 1..=parts.len() {
            let (all, firsts) = SparseCounts::sum_and_sum_of_first(&refs, first);
            assert_eq!(to_map(&all), sum_of_maps(&maps), "all, first {first}");
            assert_eq!(all, SparseCounts::sum_of(&refs), "first {first}");
            assert_eq!(
                to_map(&firsts),
                sum_of_maps(&maps[..first]),
                "first {first}"
            );
        }
    }

    /// Parts that fill their key range densely are summed through tables ([`dense_piece`]), to the same
    /// lists as merging them in turn: the sum of all, the sum of the first parts for every split point,
    /// over several pieces; and sums that fill an 8-bit field spill into the side list there too.
    #[test]
    fn dense_parts_sum_through_tables_to_the_same_lists() {
        let mut rng = 23;
        let patches = 300;
        let maps: Vec<BTreeMap<(u32, u32), u64>> = (0..16)
            .map(|k| {
                random_map(
                    &mut rng,
                    patches as u64,
                    if k == 3 { 0 } else { 4000 },
                    1 << 9,
                )
            })
            .collect();
        let parts: Vec<SparseCounts> = maps.iter().map(|m| of_map(patches, m)).collect();
        let refs: Vec<&SparseCounts> = parts.iter().collect();
        let pieces = dense_pieces(&refs).expect("dense enough for tables");
        assert!(pieces.len() > 2, "{} pieces", pieces.len());
        let in_turn = |parts: &[SparseCounts]| {
            let mut sum = parts[0].clone();
            for p in &parts[1..] {
                sum.merge(p);
            }
            sum
        };
        for first in [1, 5, 8, 16] {
            let (all, firsts) = SparseCounts::sum_and_sum_of_first(&refs, first);
            assert_eq!(all, in_turn(&parts), "first {first}");
            assert_eq!(firsts, in_turn(&parts[..first]), "first {first}");
        }
        assert_eq!(SparseCounts::sum_of(&refs), in_turn(&parts));
        // Sparse parts (a few pairs of a large scene) are merged, not tabled.
        let sparse = of_map(1 << 20, &random_map(&mut rng, 1 << 20, 1000, 1));
        assert!(dense_pieces(&[&sparse, &sparse]).is_none());
        // 8-bit fields (2^28 patches): rows 0 and 1 of 50 patches each, counts up to 200 a part.
        let big = 1usize << 28;
        let part = |c: u64| {
            SparseCounts::from_entries(
                big,
                (0..100u32)
                    .map(|k| (pair_key(k / 50, k % 50 + 2), 1 + (c * u64::from(k)) % 200))
                    .collect(),
            )
        };
        let small: Vec<SparseCounts> = (1..=4).map(part).collect();
        let refs: Vec<&SparseCounts> = small.iter().collect();
        assert!(dense_pieces(&refs).is_none(), "rows 2^28 slots apart");
        let one_row = |c: u64| {
            SparseCounts::from_entries(
                big,
                (0..50u32)
                    .map(|k| (pair_key(0, k), 100 + (c * u64::from(k)) % 100))
                    .collect(),
            )
        };
        let row: Vec<SparseCounts> = (1..=3).map(one_row).collect();
        let refs: Vec<&SparseCounts> = row.iter().collect();
        assert!(dense_pieces(&refs).is_some());
        let sum = SparseCounts::sum_of(&refs);
        assert!(!sum.wide.is_empty(), "sums of 300 and more spill");
        assert_eq!(sum, in_turn(&row));
    }

    /// A field that fills up only when two counts are added spills into the side list.
    #[test]
    fn a_sum_that_fills_the_field_spills() {
        let patches = 1 << 28; // 8-bit counts: the field's largest value, 255, means "see the side"
        let one = |c| SparseCounts::from_entries(patches, vec![(pair_key(3, 7), c)]);
        for (x, y) in [(100, 154), (100, 155), (200, 200), (255, 1), (1000, 1000)] {
            let mut a = one(x);
            a.merge(&one(y));
            assert_eq!(to_map(&a), BTreeMap::from([((3, 7), x + y)]), "{x} + {y}");
        }
    }
}
