//! A run's state as a value: the tallies of its standard-error groups as they fill up, batch by batch,
//! and which batches are done. It can be saved, merged with the states of other shards of the same run,
//! and resumed ([`super::persist`]).
//!
//! Batch `b` belongs to group `b mod G`. Membership depends on the batch index only, so the groups fill
//! up evenly however long a run lasts, a run can stop at any batch (a time budget, a precision target,
//! Ctrl-C) and still have G comparable groups, and the batches can be done in any order, on any
//! machine: every count is an integer and every sum exact ([`crate::sample::exact`]), so the result is
//! the same to the last bit.

use rayon::prelude::*;

use super::batches::{map_traced_batches, LineStream};
use super::plan::{BatchPlan, BatchSet};
use crate::sample::counts::PairCounts;
use crate::sample::tally::{BatchTally, LineTally, Tally, Wanted};
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// Batches of a run, traced and paired but not yet counted: the parallel part of a round, which
/// [`RunState::add`] (the serial rest) may overlap with tracing the next round.
#[derive(Debug)]
pub struct TracedBatches {
    /// The batches and their indices, in batch order.
    batches: Vec<(u64, BatchTally)>,
}

impl TracedBatches {
    /// Traces and pairs the batches `batches` of `stream` in parallel (see
    /// [`super::batches::map_batches`] for `stop` and the flag returned).
    pub fn trace(
        scene: &Scene,
        tracer: &dyn Tracer,
        stream: &LineStream,
        batches: &[u64],
        wanted: Wanted,
        stop: &(dyn Fn(u64) -> bool + Sync),
    ) -> Result<(TracedBatches, bool), TraceError> {
        let tally = LineTally::new(scene, wanted).with_last_cosine(stream.last_cosine());
        let (batches, complete) = map_traced_batches(
            stream,
            tracer,
            scene,
            batches,
            stop,
            |_: &mut (), batch, hits| tally.batch(batch.lines, hits),
        )?;
        Ok((TracedBatches { batches }, complete))
    }

    /// Number of batches.
    pub fn len(&self) -> usize {
        self.batches.len()
    }

    /// Whether there are no batches.
    pub fn is_empty(&self) -> bool {
        self.batches.is_empty()
    }

    /// Deals the batches into `groups` groups by batch index modulo `groups`, keeping batch order within
    /// each group.
    fn split_into_groups(self, groups: u64) -> Vec<Vec<BatchTally>> {
        let mut out: Vec<Vec<BatchTally>> = (0..groups).map(|_| Vec::new()).collect();
        for (b, t) in self.batches {
            out[(b % groups) as usize].push(t);
        }
        out
    }

    /// Deals the batches into `groups` groups and tallies each (`None` for a group without batches).
    fn into_group_tallies(self, scene: &Scene, wanted: Wanted, groups: u64) -> Vec<Option<Tally>> {
        Tally::of_groups(scene, wanted, self.split_into_groups(groups))
    }
}

/// The groups of a run as they fill up.
#[derive(Clone, Debug)]
pub struct RunState {
    plan: BatchPlan,
    wanted: Wanted,
    /// The groups' tallies. The run's total counts are not kept beside them: they are summed once,
    /// when the run finishes, so that a long run on a large mesh holds only the groups' lists.
    groups: Vec<Option<Tally>>,
    /// The batches added, the partial last batch among them.
    done: BatchSet,
    /// The tally of the plan's last batch when it is partial (fewer lines than the others), kept apart
    /// so that a run extended to more lines can trace that batch whole instead ([`RunState::extend`]).
    tail: Option<(u64, Tally)>,
}

/// A run's tallies when it ends: all its lines, and each group that has lines.
#[derive(Clone, Debug)]
pub struct FinishedRun {
    /// All the lines.
    pub total: Tally,
    /// Each non-empty group, in group order.
    pub groups: Vec<Tally>,
    /// The pair counts of the first half of [`FinishedRun::groups`] (a run of about half the lines, the
    /// same whatever the threads, shards or resumes), summed with the total's: for telling whether the
    /// lines advice has settled. `None` without pair counts or with fewer than 2 groups.
    pub first_half: Option<PairCounts>,
}

/// The batches a state lacks of its run ([`RunState::missing_lines`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MissingLines {
    /// The batches done.
    pub done: u64,
    /// The run's batches.
    pub batches: u64,
    /// The missing lines, as ranges of line indices (a line's index fixes its stream).
    pub lines: Vec<std::ops::Range<u64>>,
}

impl MissingLines {
    /// What is missing, in words; `shards`: how many shards the run was cut into, if it was.
    pub fn message(&self, shards: Option<u32>) -> String {
        let lines: Vec<String> = self
            .lines
            .iter()
            .map(|r| format!("{}..{}", r.start, r.end))
            .collect();
        format!(
            "the states cover {} of the run's {} batches; lines {} are missing{}",
            self.done,
            self.batches,
            lines.join(", "),
            shards
                .map(|m| format!(" (the run was cut into {m} shards)"))
                .unwrap_or_default()
        )
    }
}

/// Why two states cannot be merged.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MergeError {
    /// Different line plans or group counts: not shards of one run.
    #[error("the states are not parts of one run ({0})")]
    Mismatch(String),
    /// A batch done in both.
    #[error("the states overlap: batches {0} are in both")]
    Overlap(String),
}

impl RunState {
    /// An empty run of `groups` groups gathering `wanted` over the batches of `plan`.
    pub fn new(plan: BatchPlan, groups: usize, wanted: Wanted) -> Self {
        RunState {
            plan,
            wanted,
            groups: vec![None; groups],
            done: BatchSet::default(),
            tail: None,
        }
    }

    /// The parts of a state, for saving ([`super::persist`]).
    pub fn parts(&self) -> StateParts<'_> {
        StateParts {
            plan: self.plan,
            wanted: self.wanted,
            groups: &self.groups,
            done: &self.done,
            tail: self.tail.as_ref(),
        }
    }

    /// A state from its saved parts.
    pub fn from_parts(
        plan: BatchPlan,
        wanted: Wanted,
        groups: Vec<Option<Tally>>,
        done: BatchSet,
        tail: Option<(u64, Tally)>,
    ) -> Self {
        RunState {
            plan,
            wanted,
            groups,
            done,
            tail,
        }
    }

    /// The plan of the run.
    pub fn plan(&self) -> BatchPlan {
        self.plan
    }

    /// What the run gathers.
    pub fn wanted(&self) -> Wanted {
        self.wanted
    }

    /// The number of groups.
    pub fn group_count(&self) -> u64 {
        self.groups.len() as u64
    }

    /// The batches done.
    pub fn done(&self) -> &BatchSet {
        &self.done
    }

    /// The lines of the run's batches that are not done (a merge of some of a run's shards, or a
    /// run stopped early); `None` when every batch is done.
    pub fn missing_lines(&self) -> Option<MissingLines> {
        let plan = self.plan;
        let missing = self.done.missing(plan.batches());
        if missing.is_empty() {
            return None;
        }
        let lines = missing
            .ranges()
            .iter()
            .map(|r| {
                plan.first_line(r.start)
                    ..plan.first_line(r.end - 1) + plan.batch_len(r.end - 1) as u64
            })
            .collect();
        Some(MissingLines {
            done: self.done.len(),
            batches: plan.batches(),
            lines,
        })
    }

    /// Batches done so far.
    pub fn batches_done(&self) -> u64 {
        self.done.len()
    }

    /// The groups that have lines so far (the partial last batch's lines not included).
    pub fn filled_groups(&self) -> Vec<&Tally> {
        self.groups.iter().flatten().collect()
    }

    /// Whether batch `b` is the plan's last and has fewer lines than the others.
    fn is_partial(&self, b: u64) -> bool {
        b + 1 == self.plan.batches() && (self.plan.batch_len(b) as u64) < self.plan.batch_size
    }

    /// Adds traced batches (none of them done before) to their groups, counting the groups in parallel.
    pub fn add(&mut self, scene: &Scene, mut traced: TracedBatches) {
        for &(b, _) in &traced.batches {
            debug_assert!(!self.done.contains(b), "batch {b} added twice");
            self.done.insert(b);
        }
        if let Some(k) = traced.batches.iter().position(|(b, _)| self.is_partial(*b)) {
            let (b, t) = traced.batches.remove(k);
            self.tail = Some((b, Tally::from_batches(scene, self.wanted, vec![t])));
        }
        let tallies = traced.into_group_tallies(scene, self.wanted, self.group_count());
        self.groups
            .par_iter_mut()
            .zip(tallies)
            .for_each(|(slot, tally)| match (slot.as_mut(), tally) {
                (Some(t), Some(new)) => t.merge(&new),
                (None, new) => *slot = new,
                (Some(_), None) => {}
            });
    }

    /// Adds the state of another part of the same run (a shard): the groups' tallies and the batches.
    /// The result keeps the per-patch sums of eq. (27), and the escapes' among them, only when both
    /// parts have them.
    pub fn absorb(&mut self, other: RunState) -> Result<(), MergeError> {
        if other.plan != self.plan || other.groups.len() != self.groups.len() {
            return Err(MergeError::Mismatch(format!(
                "{} lines in batches of {} and {} groups, against {} in batches of {} and {}",
                self.plan.lines,
                self.plan.batch_size,
                self.groups.len(),
                other.plan.lines,
                other.plan.batch_size,
                other.groups.len()
            )));
        }
        let measures = |w: Wanted| (w.discrete, w.continuous);
        if measures(other.wanted) != measures(self.wanted) {
            return Err(MergeError::Mismatch("different measures".into()));
        }
        if self.done.overlaps(&other.done) {
            let common: Vec<String> = other
                .done
                .ranges()
                .iter()
                .flat_map(|r| r.clone())
                .filter(|&b| self.done.contains(b))
                .take(3)
                .map(|b| b.to_string())
                .collect();
            return Err(MergeError::Overlap(common.join(", ")));
        }
        self.done.union(&other.done);
        self.tail = self.tail.take().or(other.tail);
        for (slot, theirs) in self.groups.iter_mut().zip(other.groups) {
            match (slot.as_mut(), theirs) {
                (Some(t), Some(new)) => t.merge(&new),
                (None, new) => *slot = new,
                (Some(_), None) => {}
            }
        }
        // A part without the per-patch sums of eq. (27) (its run was not asked for per-patch results)
        // leaves the whole without them: sums over only some of the lines would be silently wrong.
        if !(self.wanted.per_patch && other.wanted.per_patch) {
            self.drop_per_patch();
        } else if !(self.wanted.environment && other.wanted.environment) {
            self.drop_environment();
        }
        Ok(())
    }

    /// Forgets the per-patch sums of eq. (27), in every group and the partial last batch.
    pub(super) fn drop_per_patch(&mut self) {
        self.wanted.per_patch = false;
        self.wanted.environment = false;
        for t in self.tallies_mut() {
            t.kernel_by_patch = None;
        }
    }

    /// Forgets the escapes' per-patch sums of eq. (27) (`--enclose`), keeping the pairs'.
    fn drop_environment(&mut self) {
        self.wanted.environment = false;
        for t in self.tallies_mut() {
            if let Some(k) = &mut t.kernel_by_patch {
                k.environment_log2_kernel.clear();
                k.environment_ends.clear();
            }
        }
    }

    /// Every tally of the state: the groups' and the partial last batch's.
    fn tallies_mut(&mut self) -> impl Iterator<Item = &mut Tally> {
        let tail = self.tail.as_mut().map(|(_, t)| t);
        self.groups.iter_mut().flatten().chain(tail)
    }

    /// The state of the same run extended to the longer plan `plan` (resuming to more lines): the
    /// partial last batch of the old plan, whole in the new one, is dropped to be traced again.
    pub fn extend(mut self, plan: BatchPlan) -> Self {
        if let Some((b, _)) = self.tail.take() {
            self.done.remove(b);
        }
        self.plan = plan;
        self
    }

    /// The run so far as if it ended now (a copy: the run goes on).
    pub fn snapshot(&self, scene: &Scene) -> FinishedRun {
        self.clone().finish(scene)
    }

    /// The total of every group, and the groups with lines.
    pub fn finish(mut self, scene: &Scene) -> FinishedRun {
        if let Some((b, t)) = self.tail.take() {
            let group = (b % self.groups.len() as u64) as usize;
            let slot = &mut self.groups[group];
            match slot {
                Some(g) => g.merge(&t),
                None => *slot = Some(t.clone()),
            }
        }
        let groups: Vec<Tally> = self.groups.into_iter().flatten().collect();
        // The counts are integers and the sums exact: added in any order. Each thread adds copies of its
        // groups (without their pair counts) into one, rather than all of them copied at once: on a
        // large mesh each copy holds a list per patch.
        let mut total = groups
            .par_iter()
            .map(Tally::without_counts)
            .reduce_with(|mut a, b| {
                a.merge(&b);
                a
            })
            .unwrap_or_else(|| Tally::empty(scene, self.wanted));
        let counts: Vec<&PairCounts> = groups.iter().filter_map(|t| t.counts.as_ref()).collect();
        let mut first_half = None;
        if counts.len() >= 2 {
            let (all, half) =
                PairCounts::sum_and_sum_of_first(&counts, counts.len() / 2).expect("some counts");
            total.counts = Some(all);
            first_half = Some(half);
        } else {
            total.counts = PairCounts::sum_of(&counts);
        }
        FinishedRun {
            total,
            groups,
            first_half,
        }
    }
}

/// A state's parts, as saved.
#[derive(Clone, Copy, Debug)]
pub struct StateParts<'a> {
    /// The plan.
    pub plan: BatchPlan,
    /// What it gathers.
    pub wanted: Wanted,
    /// The groups' tallies.
    pub groups: &'a [Option<Tally>],
    /// The batches done.
    pub done: &'a BatchSet,
    /// The partial last batch's tally, kept apart.
    pub tail: Option<&'a (u64, Tally)>,
}
