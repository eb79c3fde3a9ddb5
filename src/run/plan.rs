//! How a run's lines are cut into batches, and its batches into rounds.

use crate::sample::lines::LineSource;

/// The most lines traced in one round of a run (their pair keys are held until the round is counted).
pub const MAX_ROUND_LINES: u64 = 1 << 25;

/// How `lines` lines are cut into batches: a function of the line count only, never of the threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchPlan {
    /// Lines in all.
    pub lines: u64,
    /// Lines per batch (the last batch may have fewer).
    pub batch_size: u64,
}

impl BatchPlan {
    /// Batches of at most 4096 lines, and at least 64 batches when there are enough lines, so that the
    /// work spreads over threads and the standard-error groups each get several batches.
    pub fn new(lines: u64) -> Self {
        let batch_size = (lines / 64).clamp(256, 4096);
        BatchPlan { lines, batch_size }
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
        let batch_size = (4096 / unit).max(1) * unit;
        BatchPlan {
            lines: lines.div_ceil(unit) * unit,
            batch_size,
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
