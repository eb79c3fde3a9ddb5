//! Accumulation: what a set of global lines found, as integers (counts) and f64 sums.
//!
//! The hot loop (trace a batch, pair its hits, tally) knows nothing of I/O. Batches are independent and
//! each has its own random stream, so they run in parallel with rayon; their tallies are merged in batch
//! order, which keeps even the f64 sums bit-identical whatever the number of threads.

use std::ops::Range;

use rayon::prelude::*;

use super::counts::{pair_key, PairCounts};
use super::lines::LineSource;
use super::pairs::{segments, Segment};
use crate::scene::Scene;
use crate::trace::{LineHits, RawHit, TraceError, Tracer};

/// Which estimates a run must gather; leaving one out skips its work (paper sec. 3.1 and 3.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Wanted {
    /// Pair counts N_ij for the discrete measures (H_s, I_s, ...).
    pub discrete: bool,
    /// The per-pair sum of eq. (27) for the continuous mutual information.
    pub continuous: bool,
}

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

    /// Number of batches.
    pub fn batches(&self) -> u64 {
        self.lines.div_ceil(self.batch_size)
    }

    /// Lines in batch `b`.
    pub fn batch_len(&self, b: u64) -> usize {
        let start = b * self.batch_size;
        (self.lines - start).min(self.batch_size) as usize
    }
}

/// What a set of lines found.
#[derive(Clone, Debug)]
pub struct Tally {
    /// Lines traced.
    pub lines: u64,
    /// Canonical hits (crossings) found.
    pub hits: u64,
    /// Visible pairs (each counted once, though it enters N_ij and N_ji).
    pub pairs: u64,
    /// Segments from a front side out of the scene.
    pub escapes: u64,
    /// Segments that join no two front sides.
    pub unpaired: u64,
    /// Pairs whose two points coincide in f64 (touching surfaces): left out of eq. (27).
    pub degenerate_pairs: u64,
    /// Escapes per patch (empty unless the discrete measures are wanted).
    pub escapes_by_patch: Vec<u64>,
    /// Pair counts (only when the discrete measures are wanted).
    pub counts: Option<PairCounts>,
    /// Sum over pairs of log2(A_T cos cos / (pi d^2)), eq. (27).
    pub cmi_sum: f64,
    /// Pairs that entered `cmi_sum`.
    pub cmi_pairs: u64,
}

impl Tally {
    /// An empty tally for a scene.
    pub fn empty(scene: &Scene, wanted: Wanted) -> Self {
        Tally {
            lines: 0,
            hits: 0,
            pairs: 0,
            escapes: 0,
            unpaired: 0,
            degenerate_pairs: 0,
            escapes_by_patch: if wanted.discrete {
                vec![0; scene.patch_count()]
            } else {
                Vec::new()
            },
            counts: wanted
                .discrete
                .then(|| PairCounts::new(scene.patch_count())),
            cmi_sum: 0.0,
            cmi_pairs: 0,
        }
    }

    /// Adds another tally of the same scene into this one.
    pub fn merge(&mut self, other: &Tally) {
        self.lines += other.lines;
        self.hits += other.hits;
        self.pairs += other.pairs;
        self.escapes += other.escapes;
        self.unpaired += other.unpaired;
        self.degenerate_pairs += other.degenerate_pairs;
        for (a, b) in self
            .escapes_by_patch
            .iter_mut()
            .zip(&other.escapes_by_patch)
        {
            *a += b;
        }
        if let (Some(a), Some(b)) = (&mut self.counts, &other.counts) {
            a.merge(b);
        }
        self.cmi_sum += other.cmi_sum;
        self.cmi_pairs += other.cmi_pairs;
    }
}

/// One batch's findings, before its pair keys become counts.
#[derive(Debug, Default)]
struct BatchTally {
    lines: u64,
    hits: u64,
    pairs: u64,
    escapes: u64,
    unpaired: u64,
    degenerate_pairs: u64,
    pair_keys: Vec<u64>,
    escape_patches: Vec<u32>,
    cmi_sum: f64,
    cmi_pairs: u64,
}

/// Per-thread scratch buffers, reused from batch to batch.
#[derive(Default)]
struct Scratch {
    lines: Vec<crate::trace::Line>,
    raw: Vec<RawHit>,
    hits: LineHits,
}

/// Traces and tallies the batches `batches` of `plan` in parallel, merging in batch order (independent
/// lines).
pub fn tally_batches(
    scene: &Scene,
    tracer: &dyn Tracer,
    plan: &BatchPlan,
    seed: u64,
    batches: Range<u64>,
    wanted: Wanted,
) -> Result<Tally, TraceError> {
    tally_batches_from(
        scene,
        tracer,
        plan,
        LineSource::Independent,
        seed,
        batches,
        wanted,
    )
}

/// Traces and tallies the batches `batches` of `plan`, with lines from `source`, in parallel, merging in
/// batch order. `plan` must come from [`BatchPlan::for_source`] with the same source.
pub fn tally_batches_from(
    scene: &Scene,
    tracer: &dyn Tracer,
    plan: &BatchPlan,
    source: LineSource,
    seed: u64,
    batches: Range<u64>,
    wanted: Wanted,
) -> Result<Tally, TraceError> {
    let per_batch: Vec<BatchTally> = batches
        .into_par_iter()
        .map_init(Scratch::default, |scratch, b| {
            let lines = BatchLines {
                source,
                seed,
                batch: b,
                count: plan.batch_len(b),
            };
            tally_batch(scene, tracer, lines, wanted, scratch)
        })
        .collect::<Result<_, _>>()?;

    let mut tally = Tally::empty(scene, wanted);
    let mut keys = Vec::with_capacity(per_batch.iter().map(|b| b.pair_keys.len()).sum());
    for b in &per_batch {
        tally.lines += b.lines;
        tally.hits += b.hits;
        tally.pairs += b.pairs;
        tally.escapes += b.escapes;
        tally.unpaired += b.unpaired;
        tally.degenerate_pairs += b.degenerate_pairs;
        tally.cmi_sum += b.cmi_sum;
        tally.cmi_pairs += b.cmi_pairs;
        keys.extend_from_slice(&b.pair_keys);
        for &p in &b.escape_patches {
            tally.escapes_by_patch[p as usize] += 1;
        }
    }
    drop(per_batch);
    if wanted.discrete {
        tally.counts = Some(PairCounts::from_keys(scene.patch_count(), &mut keys));
    }
    Ok(tally)
}

/// Which lines a batch casts.
#[derive(Clone, Copy, Debug)]
struct BatchLines {
    source: LineSource,
    seed: u64,
    batch: u64,
    count: usize,
}

fn tally_batch(
    scene: &Scene,
    tracer: &dyn Tracer,
    lines: BatchLines,
    wanted: Wanted,
    scratch: &mut Scratch,
) -> Result<BatchTally, TraceError> {
    let count = lines.count;
    scratch.lines.clear();
    lines.source.batch_lines(
        lines.seed,
        lines.batch,
        count,
        scene.bounding_radius(),
        &mut scratch.lines,
    );
    tracer.all_hits(&scratch.lines, &mut scratch.raw, &mut scratch.hits)?;

    let log2_area_over_pi = (scene.total_area() / std::f64::consts::PI).log2();
    let mut t = BatchTally {
        lines: count as u64,
        hits: scratch.hits.hits.len() as u64,
        ..BatchTally::default()
    };
    for (k, line) in scratch.lines.iter().enumerate() {
        segments(scene, line, scratch.hits.of_line(k), |s| match s {
            Segment::Pair {
                from,
                to,
                distance,
                cos_from,
                cos_to,
            } => {
                t.pairs += 1;
                if wanted.discrete {
                    t.pair_keys.push(pair_key(from, to));
                }
                if wanted.continuous {
                    add_continuous_term(&mut t, log2_area_over_pi, distance, cos_from * cos_to);
                }
            }
            Segment::Escape { patch } => {
                t.escapes += 1;
                if wanted.discrete {
                    t.escape_patches.push(patch);
                }
            }
            Segment::Unpaired => t.unpaired += 1,
        });
    }
    Ok(t)
}

/// Eq. (27): adds log2(A_T cos_x cos_y / (pi d^2)) for one pair; a pair whose points coincide (d = 0, the
/// surfaces touch there) has an infinite term and is counted apart instead of poisoning the sum.
fn add_continuous_term(
    t: &mut BatchTally,
    log2_area_over_pi: f64,
    distance: f64,
    cos_product: f64,
) {
    if distance > 0.0 && cos_product > 0.0 {
        let term = log2_area_over_pi + (cos_product / (distance * distance)).log2();
        if term.is_finite() {
            t.cmi_sum += term;
            t.cmi_pairs += 1;
            return;
        }
    }
    t.degenerate_pairs += 1;
}
