//! A run's state as a value: the tallies of its standard-error groups as they fill up, batch by batch.
//!
//! Batch `b` belongs to group `b mod G`. Membership depends on the batch index only, so the groups fill
//! up evenly however long a run lasts, and a run can stop at any batch (a time budget, a precision
//! target, Ctrl-C) and still have G comparable groups.

use std::ops::Range;

use rayon::prelude::*;

use super::batches::{map_traced_batches, LineStream};
use crate::sample::counts::{count_by_group, PairCounts, DENSE_MAX_PATCHES};
use crate::sample::tally::{tally_lines, BatchTally, Tally, Wanted};
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// Consecutive batches of a run, traced and paired but not yet counted: the parallel part of a round,
/// which [`RunState::add`] (the serial rest) may overlap with tracing the next round.
#[derive(Debug)]
pub struct TracedBatches {
    /// Index of the first batch.
    first: u64,
    /// The batches, consecutive from `first`.
    batches: Vec<BatchTally>,
}

impl TracedBatches {
    /// Traces and pairs the batches `batches` of `stream` in parallel (see
    /// [`super::batches::map_batches`] for `stop` and the flag returned).
    pub fn trace(
        scene: &Scene,
        tracer: &dyn Tracer,
        stream: &LineStream,
        batches: Range<u64>,
        wanted: Wanted,
        stop: &(dyn Fn(u64) -> bool + Sync),
    ) -> Result<(TracedBatches, bool), TraceError> {
        let first = batches.start;
        let (batches, complete) = map_traced_batches(
            stream,
            tracer,
            scene.bounding_radius(),
            batches,
            stop,
            |_: &mut (), batch, hits| tally_lines(scene, batch.lines, hits, wanted),
        )?;
        Ok((TracedBatches { first, batches }, complete))
    }

    /// Number of batches.
    pub fn len(&self) -> usize {
        self.batches.len()
    }

    /// Whether there are no batches.
    pub fn is_empty(&self) -> bool {
        self.batches.is_empty()
    }

    /// Adds the batches up in batch order and counts their pairs.
    pub fn into_tally(self, scene: &Scene, wanted: Wanted) -> Tally {
        Tally::from_batches(scene, wanted, self.batches)
    }

    /// Deals the batches into `groups` groups by batch index modulo `groups`, keeping batch order within
    /// each group.
    fn split_into_groups(self, groups: u64) -> Vec<TracedBatches> {
        let first = self.first;
        let mut out: Vec<TracedBatches> = (0..groups)
            .map(|_| TracedBatches {
                first,
                batches: Vec::new(),
            })
            .collect();
        for (k, b) in self.batches.into_iter().enumerate() {
            out[((first + k as u64) % groups) as usize].batches.push(b);
        }
        out
    }

    /// Deals the batches into `groups` groups by batch index modulo `groups` and tallies each (`None`
    /// for a group without batches). With sparse counts also returns the counts of all the groups
    /// together, from the same sort ([`count_by_group`]).
    fn into_group_tallies(
        self,
        scene: &Scene,
        wanted: Wanted,
        groups: u64,
    ) -> (Vec<Option<Tally>>, Option<PairCounts>) {
        let patches = scene.patch_count();
        if !wanted.discrete || patches <= DENSE_MAX_PATCHES {
            let tallies = self
                .split_into_groups(groups)
                .into_par_iter()
                .map(|piece| (!piece.is_empty()).then(|| piece.into_tally(scene, wanted)))
                .collect();
            return (tallies, None);
        }
        let keyed: Vec<(usize, &[u64])> = self
            .batches
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let group = (self.first + k as u64) % groups;
                (group as usize, b.pair_keys.as_slice())
            })
            .collect();
        let counted = count_by_group(patches, groups as usize, &keyed);
        let tallies = self
            .split_into_groups(groups)
            .into_par_iter()
            .zip(counted.groups)
            .map(|(piece, counts)| {
                (!piece.is_empty()).then(|| {
                    let (mut tally, _) = Tally::sum_batches(scene, wanted, piece.batches);
                    tally.counts = Some(PairCounts::Sparse(counts));
                    tally
                })
            })
            .collect();
        (tallies, Some(PairCounts::Sparse(counted.total)))
    }
}

/// The groups of a run as they fill up.
#[derive(Clone, Debug)]
pub struct RunState {
    wanted: Wanted,
    groups: Vec<Option<Tally>>,
    /// With sparse counts, those of all the groups together (counted with the groups', so that the
    /// total needs no merging of the groups at the end).
    total_counts: Option<PairCounts>,
    batches_done: u64,
}

/// A run's tallies when it ends: all its lines, and each group that has lines.
#[derive(Clone, Debug)]
pub struct FinishedRun {
    /// All the lines.
    pub total: Tally,
    /// Each non-empty group, in group order.
    pub groups: Vec<Tally>,
}

impl RunState {
    /// An empty run of `groups` groups gathering `wanted`.
    pub fn new(groups: usize, wanted: Wanted) -> Self {
        RunState {
            wanted,
            groups: vec![None; groups],
            total_counts: None,
            batches_done: 0,
        }
    }

    /// The number of groups.
    pub fn group_count(&self) -> u64 {
        self.groups.len() as u64
    }

    /// Batches added so far.
    pub fn batches_done(&self) -> u64 {
        self.batches_done
    }

    /// The groups that have lines so far.
    pub fn filled_groups(&self) -> Vec<&Tally> {
        self.groups.iter().flatten().collect()
    }

    /// Adds traced batches (consecutive from `batches_done`) to their groups, counting the groups in
    /// parallel.
    pub fn add(&mut self, scene: &Scene, traced: TracedBatches) {
        let batches = traced.len() as u64;
        let (tallies, total_counts) =
            traced.into_group_tallies(scene, self.wanted, self.group_count());
        let merge_total = || match (&mut self.total_counts, total_counts) {
            (Some(t), Some(new)) => t.merge(&new),
            (slot, new) => *slot = slot.take().or(new),
        };
        let merge_groups = || {
            self.groups
                .par_iter_mut()
                .zip(tallies)
                .for_each(|(slot, tally)| match (slot.as_mut(), tally) {
                    (Some(t), Some(new)) => t.merge(&new),
                    (None, new) => *slot = new,
                    (Some(_), None) => {}
                });
        };
        rayon::join(merge_total, merge_groups);
        self.batches_done += batches;
    }

    /// The run so far as if it ended now (a copy: the run goes on).
    pub fn snapshot(&self, scene: &Scene) -> FinishedRun {
        self.clone().finish(scene)
    }

    /// The total of every group, and the groups with lines.
    pub fn finish(self, scene: &Scene) -> FinishedRun {
        let groups: Vec<Tally> = self.groups.into_iter().flatten().collect();
        // The sums merge in a fixed tree; the counts are integers, added in any order: the sparse ones
        // were counted with the groups', the dense ones are added up here.
        let sums = groups.iter().map(Tally::without_counts).collect();
        let mut total = merge_tree(sums).unwrap_or_else(|| Tally::empty(scene, self.wanted));
        total.counts = self.total_counts.or_else(|| dense_total(&groups));
        FinishedRun { total, groups }
    }
}

/// The sum of the groups' dense counts (`None` without counts).
fn dense_total(groups: &[Tally]) -> Option<PairCounts> {
    let mut counts = groups.iter().filter_map(|t| t.counts.as_ref());
    let mut total = counts.next()?.clone();
    counts.for_each(|c| total.merge(c));
    Some(total)
}

/// Merges tallies pairwise in a balanced binary tree, the two halves in parallel. The tree's shape
/// depends only on the number of tallies, so the f64 sums are added in the same order whatever the
/// thread count; every count is merged O(log G) times.
fn merge_tree(mut tallies: Vec<Tally>) -> Option<Tally> {
    if tallies.len() <= 1 {
        return tallies.pop();
    }
    let right = tallies.split_off(tallies.len() / 2);
    let (left, right) = rayon::join(|| merge_tree(tallies), || merge_tree(right));
    let (mut left, right) = (left?, right?);
    left.merge(&right);
    Some(left)
}
