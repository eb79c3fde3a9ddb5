//! How a run's lines are cut into batches, and its batches into rounds.

use crate::sample::lines::LineSource;

/// The most lines traced in one round of a run (their pair keys are held until the round is counted).
pub const MAX_ROUND_LINES: u64 = 1 << 25;

/// The most pair keys (8 bytes each) a round of a run that counts pairs should hold. A round's keys,
/// their sorted copy, the round's new count lists and the next round's keys are alive at once, on top
/// of the lists of the run so far: rounds sized by the keys they hold keep that extra memory under about
/// 3 x 8 x this many bytes whatever the scene, where rounds sized by lines held ~30 bytes per line of a
/// full round (about a gigabyte) on scenes whose lines cross many surfaces.
pub const MAX_ROUND_KEYS: u64 = 1 << 24;

/// How `lines` lines are cut into batches: a function of the line count only, never of the threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchPlan {
    /// Lines in all.
    pub lines: u64,
    /// Lines per batch (the last batch may have fewer).
    pub batch_size: u64,
}

impl BatchPlan {
    /// The most lines in a batch.
    pub const MAX_BATCH: u64 = 4096;

    /// The fewest lines in a batch (but the last).
    pub const MIN_BATCH: u64 = 256;

    /// The batches a run has at least, when it has the lines for them: two for each of the default
    /// standard-error groups. Few enough that runs of modest length have full batches, and so can be
    /// continued to any count: a run's lines drawn through a box or polytope are fewer than its
    /// `--lines` (2/pi of them for a cube), and 3e5 of a cube's sphere lines are 190,987 box lines.
    pub const MIN_BATCHES: u64 = 32;

    /// From this many lines on, every run has batches of [`BatchPlan::MAX_BATCH`] lines.
    pub const FULL_FROM: u64 = BatchPlan::MIN_BATCHES * BatchPlan::MAX_BATCH;

    /// Batches of at most [`BatchPlan::MAX_BATCH`] lines, and at least [`BatchPlan::MIN_BATCHES`]
    /// batches when there are enough lines, so that the work spreads over threads and the standard-error
    /// groups each get several batches.
    pub fn new(lines: u64) -> Self {
        let batch_size = (lines / Self::MIN_BATCHES).clamp(Self::MIN_BATCH, Self::MAX_BATCH);
        BatchPlan { lines, batch_size }
    }

    /// The fewest lines drawn (before rounding to whole bundles; through the sphere, as `--lines` counts
    /// them, or through a box or polytope: `sample::bounds::sphere_lines_for_drawn`) whose plan for
    /// `source` has at least `batches` batches, the standard-error groups a run can have: the plan of
    /// [`BatchPlan::for_source`], or with `open_ended` [`BatchPlan::open_ended`]'s full batches.
    pub fn lines_for_batches(batches: u64, source: LineSource, open_ended: bool) -> u64 {
        let k = batches.max(1);
        let unit = source.lines_per_unit();
        if open_ended {
            let batch = BatchPlan::open_ended(unit, source).batch_size;
            return (k - 1) * batch + 1;
        }
        // The batches do not grow monotonically with the lines: walk the bundle counts (at most
        // k * MAX_BATCH lines) to the first plan with k batches.
        let mut bundles = 1;
        while BatchPlan::for_source(bundles * unit, source).batches() < k {
            bundles += 1;
        }
        (bundles - 1) * unit + 1
    }

    /// The plan for lines from `source`: the line count is rounded up to whole bundles, and each batch
    /// holds whole bundles only, so that a bundle never straddles two batches (nor two standard-error
    /// groups, which are made of whole batches). For independent lines this is [`BatchPlan::new`].
    pub fn for_source(lines: u64, source: LineSource) -> Self {
        let unit = source.lines_per_unit();
        let lines = lines.div_ceil(unit) * unit;
        let plain = BatchPlan::new(lines);
        let batch_size = (plain.batch_size / unit).max(1) * unit;
        BatchPlan { lines, batch_size }
    }

    /// A plan for a run whose length is not known in advance (a time or precision budget, with `lines`
    /// only a cap): always full batches (4096 lines, rounded to whole bundles), so a run's first batches
    /// are the same whatever the budget.
    pub fn open_ended(lines: u64, source: LineSource) -> Self {
        let unit = source.lines_per_unit();
        let batch_size = (Self::MAX_BATCH / unit).max(1) * unit;
        BatchPlan {
            lines: lines.div_ceil(unit) * unit,
            batch_size,
        }
    }

    /// The most lines whose plan ([`BatchPlan::new`]) still has batches of `batch_size`: a run of that
    /// batch size continues to at most this many ([`u64::MAX`] for full batches).
    pub fn most_lines_with_batch(batch_size: u64) -> u64 {
        if batch_size >= Self::MAX_BATCH {
            u64::MAX
        } else {
            Self::MIN_BATCHES * (batch_size + 1) - 1
        }
    }

    /// Number of batches.
    pub fn batches(&self) -> u64 {
        self.lines.div_ceil(self.batch_size)
    }

    /// Lines in batch `b`.
    pub fn batch_len(&self, b: u64) -> usize {
        let start = b * self.batch_size;
        (self.lines - start).min(self.batch_size) as usize
    }

    /// The index of batch `b`'s first line in the run.
    pub fn first_line(&self, b: u64) -> u64 {
        b * self.batch_size
    }
}

/// A set of batch indices, as sorted disjoint ranges: the batches a run, a shard or a resumed run has
/// done.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BatchSet {
    ranges: Vec<std::ops::Range<u64>>,
}

impl BatchSet {
    /// The set `0..n`.
    pub fn first(n: u64) -> Self {
        let mut s = BatchSet::default();
        s.insert_range(0..n);
        s
    }

    /// The set of the given ranges (in any order; overlaps are joined).
    pub fn from_ranges(ranges: impl IntoIterator<Item = std::ops::Range<u64>>) -> Self {
        let mut s = BatchSet::default();
        for r in ranges {
            s.insert_range(r);
        }
        s
    }

    /// The sorted disjoint ranges.
    pub fn ranges(&self) -> &[std::ops::Range<u64>] {
        &self.ranges
    }

    /// Number of batches.
    pub fn len(&self) -> u64 {
        self.ranges.iter().map(|r| r.end - r.start).sum()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    /// Whether batch `b` is in the set.
    pub fn contains(&self, b: u64) -> bool {
        let k = self.ranges.partition_point(|r| r.end <= b);
        self.ranges.get(k).is_some_and(|r| r.start <= b)
    }

    /// Adds a batch.
    pub fn insert(&mut self, b: u64) {
        self.insert_range(b..b + 1);
    }

    /// Adds a range of batches.
    pub fn insert_range(&mut self, r: std::ops::Range<u64>) {
        if r.is_empty() {
            return;
        }
        // The ranges touching or overlapping `r` merge with it.
        let first = self.ranges.partition_point(|x| x.end < r.start);
        let last = self.ranges.partition_point(|x| x.start <= r.end);
        let start = self.ranges[first..last]
            .iter()
            .map(|x| x.start)
            .fold(r.start, u64::min);
        let end = self.ranges[first..last]
            .iter()
            .map(|x| x.end)
            .fold(r.end, u64::max);
        self.ranges.splice(first..last, std::iter::once(start..end));
    }

    /// Removes a batch.
    pub fn remove(&mut self, b: u64) {
        let k = self.ranges.partition_point(|r| r.end <= b);
        let Some(r) = self.ranges.get(k).cloned().filter(|r| r.start <= b) else {
            return;
        };
        let pieces = [r.start..b, b + 1..r.end];
        self.ranges
            .splice(k..k + 1, pieces.into_iter().filter(|p| !p.is_empty()));
    }

    /// Whether the two sets share a batch.
    pub fn overlaps(&self, other: &BatchSet) -> bool {
        other
            .ranges
            .iter()
            .any(|r| self.intersection_len(r.clone()) > 0)
    }

    fn intersection_len(&self, r: std::ops::Range<u64>) -> u64 {
        self.ranges
            .iter()
            .map(|x| x.end.min(r.end).saturating_sub(x.start.max(r.start)))
            .sum()
    }

    /// The union with another set.
    pub fn union(&mut self, other: &BatchSet) {
        for r in &other.ranges {
            self.insert_range(r.clone());
        }
    }

    /// The batches of `0..n` not in the set.
    pub fn missing(&self, n: u64) -> BatchSet {
        let mut out = BatchSet::default();
        let mut at = 0;
        for r in &self.ranges {
            if r.start >= n {
                break;
            }
            out.insert_range(at..r.start);
            at = r.end;
        }
        out.insert_range(at..n);
        out
    }

    /// The batch indices of the set within `within`, in order.
    pub fn indices_within(&self, within: std::ops::Range<u64>) -> Vec<u64> {
        self.ranges
            .iter()
            .flat_map(|r| r.start.max(within.start)..r.end.min(within.end))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `lines_for_batches` is the least line count from which some plan has that many batches: found by
    /// walking every line count (the batches do not grow monotonically with the lines).
    #[test]
    fn the_lines_for_a_number_of_batches_are_the_least() {
        let mut most = 0;
        let mut first_with = vec![0u64];
        for lines in 1..=110 * BatchPlan::MAX_BATCH {
            let batches = BatchPlan::new(lines).batches();
            while batches > most {
                most += 1;
                first_with.push(lines);
            }
        }
        for k in 1..=100u64 {
            assert_eq!(
                BatchPlan::lines_for_batches(k, LineSource::default(), false),
                first_with[k as usize],
                "{k}"
            );
            let open = BatchPlan::lines_for_batches(k, LineSource::default(), true);
            assert!(BatchPlan::open_ended(open, LineSource::default()).batches() >= k);
            assert!(BatchPlan::open_ended(open - 1, LineSource::default()).batches() < k);
        }
        // Bundles of 64 x 64 lines: a bundle a batch, so 16 groups need 15 bundles and a line.
        let bundles = LineSource::Bundles { grid: 64 };
        for open_ended in [false, true] {
            let least = BatchPlan::lines_for_batches(16, bundles, open_ended);
            assert_eq!(least, 15 * 4096 + 1);
            let plan = |l| match open_ended {
                true => BatchPlan::open_ended(l, bundles),
                false => BatchPlan::for_source(l, bundles),
            };
            assert!(plan(least).batches() >= 16 && plan(least - 1).batches() < 16);
        }
    }

    #[test]
    fn batch_sets_join_split_and_complement() {
        let mut s = BatchSet::from_ranges([5..8, 0..2, 7..10]);
        assert_eq!(s.ranges(), [0..2, 5..10]);
        s.insert(2);
        assert_eq!(s.ranges(), [0..3, 5..10]);
        assert!(s.contains(6) && !s.contains(4) && !s.contains(10));
        assert_eq!(s.missing(12).ranges(), [3..5, 10..12]);
        s.remove(6);
        assert_eq!(s.ranges(), [0..3, 5..6, 7..10]);
        assert_eq!(s.len(), 7);
        assert!(s.overlaps(&BatchSet::from_ranges(std::iter::once(9..20))));
        assert!(!s.overlaps(&BatchSet::from_ranges([3..5, 6..7])));
        assert_eq!(s.indices_within(2..8), [2, 5, 7]);
        let mut u = BatchSet::from_ranges(std::iter::once(3..5));
        u.union(&BatchSet::from_ranges(std::iter::once(6..7)));
        u.union(&s);
        assert_eq!(u.ranges(), std::slice::from_ref(&(0..10)));
    }
}
