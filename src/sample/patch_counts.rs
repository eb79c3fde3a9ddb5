//! Counts per patch (the escapes, the absorbed segments) of a tally: a list of one count per patch, or
//! only the patches counted, whichever is smaller.
//!
//! Each of a run's 16 groups keeps its own counts, for the standard errors. On a mesh of millions of
//! patches a short run leaves most patches without an escape (2 M patches, 10^5 lines: 33,000 escapes),
//! and a list per group of one count per patch took 16 x 8 bytes per patch, a third of the run's peak
//! memory. Kept sparse, they take 16 bytes per patch counted, and never more than the dense list: counts
//! turn dense once half the patches have one. Small scenes keep the dense list from the start (the counts
//! of a round are then added one by one, without sorting).

use std::borrow::Cow;

/// Scenes of at most this many patches keep their counts dense.
const DENSE_PATCHES: usize = 1 << 16;

/// A count per patch of a scene of [`PatchCounts::len`] patches (0: none are kept).
#[derive(Clone, Debug, Default)]
pub struct PatchCounts {
    len: usize,
    store: Store,
}

#[derive(Clone, Debug)]
enum Store {
    Dense(Vec<u64>),
    /// The patches with a count, in increasing order, each with its count (never 0).
    Sparse(Vec<(u32, u64)>),
}

impl Default for Store {
    fn default() -> Self {
        Store::Sparse(Vec::new())
    }
}

impl PatchCounts {
    /// Zero for each of `len` patches.
    pub fn zeros(len: usize) -> Self {
        PatchCounts {
            len,
            store: if len <= DENSE_PATCHES {
                Store::Dense(vec![0; len])
            } else {
                Store::Sparse(Vec::new())
            },
        }
    }

    /// The counts of `len` patches in which each element of `patches` counts once for its patch.
    ///
    /// # Panics
    /// When a patch is not below `len`.
    pub fn of_patches(len: usize, mut patches: Vec<u32>) -> Self {
        let mut counts = PatchCounts::zeros(len);
        if let Store::Dense(d) = &mut counts.store {
            for &p in &patches {
                d[p as usize] += 1;
            }
            return counts;
        }
        patches.sort_unstable();
        let mut entries: Vec<(u32, u64)> = Vec::new();
        for p in patches {
            assert!((p as usize) < len, "patch {p} of {len}");
            match entries.last_mut() {
                Some((last, n)) if *last == p => *n += 1,
                _ => entries.push((p, 1)),
            }
        }
        counts.store = Store::Sparse(entries);
        counts.compact();
        counts
    }

    /// The counts of `len` patches from the patches with a count, in increasing order, each below
    /// `len` (zero counts are left out).
    pub fn of_entries(len: usize, entries: impl IntoIterator<Item = (u32, u64)>) -> Self {
        let mut counts = PatchCounts::zeros(len);
        match &mut counts.store {
            Store::Dense(d) => {
                for (p, n) in entries {
                    d[p as usize] = n;
                }
            }
            Store::Sparse(s) => {
                s.extend(entries.into_iter().filter(|&(_, n)| n > 0));
                debug_assert!(s.windows(2).all(|w| w[0].0 < w[1].0));
                debug_assert!(s.last().is_none_or(|&(p, _)| (p as usize) < len));
            }
        }
        counts.compact();
        counts
    }

    /// The number of patches (0 when no counts are kept).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no counts are kept.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The count of every patch, in patch order.
    pub fn dense(&self) -> Cow<'_, [u64]> {
        match &self.store {
            Store::Dense(d) => Cow::Borrowed(d),
            Store::Sparse(s) => {
                let mut d = vec![0; self.len];
                for &(p, n) in s {
                    d[p as usize] = n;
                }
                Cow::Owned(d)
            }
        }
    }

    /// Calls `f(patch, count)` for every patch whose count is not 0, in patch order.
    pub fn for_each_counted(&self, mut f: impl FnMut(u32, u64)) {
        match &self.store {
            Store::Dense(d) => {
                for (p, &n) in d.iter().enumerate() {
                    if n > 0 {
                        f(p as u32, n);
                    }
                }
            }
            Store::Sparse(s) => {
                for &(p, n) in s {
                    f(p, n);
                }
            }
        }
    }

    /// Adds `other`'s counts to these: per patch; counts not kept take `other`'s.
    pub fn add(&mut self, other: &PatchCounts) {
        if other.is_empty() {
            return;
        }
        if self.is_empty() {
            *self = other.clone();
            return;
        }
        debug_assert_eq!(self.len, other.len);
        match (&mut self.store, &other.store) {
            (Store::Dense(a), Store::Dense(b)) => {
                for (x, y) in a.iter_mut().zip(b) {
                    *x += y;
                }
            }
            (Store::Dense(a), Store::Sparse(b)) => {
                for &(p, n) in b {
                    a[p as usize] += n;
                }
            }
            (Store::Sparse(a), Store::Sparse(b)) => {
                *a = merged(a, b, |x, y| x + y);
                self.compact();
            }
            (Store::Sparse(_), Store::Dense(b)) => {
                let mut d = b.clone();
                self.for_each_counted(|p, n| d[p as usize] += n);
                self.store = Store::Dense(d);
            }
        }
    }

    /// These counts less `part`'s, a part of them (each of its counts at most this one's).
    pub fn minus(&self, part: &PatchCounts) -> PatchCounts {
        if part.is_empty() {
            return self.clone();
        }
        let store = match (&self.store, &part.store) {
            (Store::Sparse(a), Store::Sparse(b)) => Store::Sparse(merged(a, b, |x, y| x - y)),
            _ => {
                let mut d = self.dense().into_owned();
                part.for_each_counted(|p, n| d[p as usize] -= n);
                Store::Dense(d)
            }
        };
        PatchCounts {
            len: self.len,
            store,
        }
    }

    /// Turns sparse counts dense once they would take more room than a count per patch.
    fn compact(&mut self) {
        if let Store::Sparse(s) = &self.store {
            if s.len() * std::mem::size_of::<(u32, u64)>() > self.len * std::mem::size_of::<u64>() {
                self.store = Store::Dense(self.dense().into_owned());
            }
        }
    }
}

/// Two counts are equal when every patch's count is, however each is kept.
impl PartialEq for PatchCounts {
    fn eq(&self, other: &Self) -> bool {
        self.len == other.len && self.dense() == other.dense()
    }
}

/// The union of two sorted sparse lists, `combine` applied where both have a patch (results of 0 left
/// out).
fn merged(
    a: &[(u32, u64)],
    b: &[(u32, u64)],
    combine: impl Fn(u64, u64) -> u64,
) -> Vec<(u32, u64)> {
    let mut out = Vec::with_capacity(a.len().max(b.len()));
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let entry = match (a.get(i), b.get(j)) {
            (Some(&(p, x)), Some(&(q, y))) if p == q => {
                (i, j) = (i + 1, j + 1);
                (p, combine(x, y))
            }
            (Some(&(p, x)), Some(&(q, _))) if p < q => {
                i += 1;
                (p, x)
            }
            (Some(&(p, x)), None) => {
                i += 1;
                (p, x)
            }
            (_, Some(&(q, y))) => {
                j += 1;
                (q, combine(0, y))
            }
            (None, None) => unreachable!("the loop's condition"),
        };
        if entry.1 > 0 {
            out.push(entry);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dense and sparse counts (a scene above and below the dense limit) count, add, subtract and
    /// compare alike, and agree with a plain count per patch.
    #[test]
    fn sparse_and_dense_counts_agree_with_a_plain_count() {
        for len in [10, DENSE_PATCHES + 10] {
            let patches = |k: u32| -> Vec<u32> {
                (0..40 * k)
                    .map(|i| (i * 7919 + k) % len as u32 % (37 * k))
                    .collect()
            };
            let plain = |list: &[u32]| {
                let mut d = vec![0u64; len];
                for &p in list {
                    d[p as usize] += 1;
                }
                d
            };
            let (a, b) = (patches(1), patches(3));
            let mut sum = PatchCounts::of_patches(len, a.clone());
            assert_eq!(sum.dense().as_ref(), plain(&a).as_slice());
            let part = PatchCounts::of_patches(len, b.clone());
            sum.add(&part);
            let both: Vec<u32> = a.iter().chain(&b).copied().collect();
            assert_eq!(sum.dense().as_ref(), plain(&both).as_slice());
            assert_eq!(sum.minus(&part).dense().as_ref(), plain(&a).as_slice());
            let mut counted = Vec::new();
            sum.for_each_counted(|p, n| counted.push((p, n)));
            assert_eq!(PatchCounts::of_entries(len, counted), sum);
            let mut none = PatchCounts::default();
            none.add(&sum);
            assert_eq!(none, sum);
        }
    }

    /// Sparse counts turn dense once they would be larger, with the same counts.
    #[test]
    fn crowded_sparse_counts_turn_dense() {
        let len = DENSE_PATCHES + 4;
        let few = PatchCounts::of_patches(len, vec![5, 5, 9]);
        assert!(matches!(few.store, Store::Sparse(_)));
        let all = PatchCounts::of_patches(len, (0..len as u32).collect());
        assert!(matches!(all.store, Store::Dense(_)));
        assert!(all.dense().iter().all(|&n| n == 1));
        let mut sum = few.clone();
        sum.add(&all);
        assert_eq!(sum.dense()[5], 3);
        assert_eq!(sum.minus(&all), few);
    }
}
