//! The one loop over batches of lines that every kind of run uses: draw each batch's lines from its own
//! random stream, hand them (traced, when asked) to a visitor, in parallel, and collect the results in
//! batch order, so that whatever is added up from them does not depend on the thread count.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rayon::prelude::*;

use super::plan::BatchPlan;
use crate::sample::bounds::{batch_lines_through, sobol_lines_through, LineBound, LineRegion};
use crate::sample::lines::{sobol_lines, LineSource, Sampler};
use crate::sample::tally::LastCosine;
use crate::scene::Scene;
use crate::trace::{Line, LineHits, RawHit, TraceError, Tracer};

/// The lines of a run: its batch plan, where its lines come from, and the seed of their streams. A
/// batch's lines depend on these and its index only.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineStream {
    /// How the lines are cut into batches.
    pub plan: BatchPlan,
    /// Independent lines or bundles (`plan` must hold whole bundles, [`BatchPlan::for_source`]).
    pub source: LineSource,
    /// Independent lines, or one randomised Sobol' sequence per group (then `source` is
    /// [`LineSource::Independent`]: [`crate::run::RunSpec::check`]).
    pub sampler: Sampler,
    /// Through the bounding sphere, box or polytope (with the last two, `source` is
    /// [`LineSource::Independent`]).
    pub bound: LineBound,
    /// The run's standard-error groups: batch `b` belongs to group `b mod groups`.
    pub groups: u64,
    /// Seed of the streams.
    pub seed: u64,
}

impl LineStream {
    /// `lines` independent lines from `seed`, in the batches of [`BatchPlan::new`]: the lines of `scx
    /// analyze --seed seed` without a budget.
    pub fn independent(lines: u64, seed: u64) -> Self {
        LineStream {
            plan: BatchPlan::new(lines),
            source: LineSource::Independent,
            sampler: Sampler::Independent,
            bound: LineBound::Sphere,
            groups: crate::run::DEFAULT_GROUPS as u64,
            seed,
        }
    }

    /// How eq. (27)'s sum takes the far cosine of each line's last pair for these lines: the first
    /// pair's near cosine for Sobol' lines drawn from a container's faces (the box's or the
    /// polytope's), whose entry the sequence's coordinates give; each pair's own otherwise
    /// ([`LastCosine`], docs/sampling.md).
    pub fn last_cosine(&self) -> LastCosine {
        match (self.sampler, self.bound) {
            (Sampler::Sobol, LineBound::Box | LineBound::Polytope) => LastCosine::FirstEntry,
            _ => LastCosine::Own,
        }
    }

    /// Appends batch `batch`'s lines to `out` (tracing space), drawn through `region` (which must be
    /// the scene's region for [`LineStream::bound`]). With the Sobol' sampler, batch `b` is the `k`-th
    /// batch of group `g = b mod G` (`k = b / G`) and takes points `k * batch_size ..` of that group's
    /// sequence: a group's lines are a prefix of one low-discrepancy sequence, whichever batches a
    /// thread, shard or resume draws.
    pub fn draw(&self, batch: u64, region: &LineRegion, out: &mut Vec<Line>) {
        let count = self.plan.batch_len(batch);
        let groups = self.groups.max(1);
        let (group, k) = (batch % groups, batch / groups);
        let first = k * self.plan.batch_size;
        match (self.sampler, region) {
            (Sampler::Independent, LineRegion::Sphere(radius)) => {
                self.source
                    .batch_lines(self.seed, batch, count, *radius, out);
            }
            (Sampler::Sobol, LineRegion::Sphere(radius)) => {
                debug_assert_eq!(self.source, LineSource::Independent, "checked by the spec");
                sobol_lines(self.seed, group, first, count, *radius, out);
            }
            (Sampler::Independent, LineRegion::Box(bounds)) => {
                debug_assert_eq!(self.source, LineSource::Independent, "checked by the spec");
                batch_lines_through(self.seed, batch, count, bounds.as_ref(), out);
            }
            (Sampler::Sobol, LineRegion::Box(bounds)) => {
                sobol_lines_through(self.seed, group, first, count, bounds.as_ref(), out);
            }
            (Sampler::Independent, LineRegion::Polytope(bounds)) => {
                debug_assert_eq!(self.source, LineSource::Independent, "checked by the spec");
                batch_lines_through(self.seed, batch, count, bounds.as_ref(), out);
            }
            (Sampler::Sobol, LineRegion::Polytope(bounds)) => {
                sobol_lines_through(self.seed, group, first, count, bounds.as_ref(), out);
            }
        }
    }
}

/// One batch of drawn lines.
#[derive(Clone, Copy, Debug)]
pub struct Batch<'a> {
    /// The batch's index in the run.
    pub index: u64,
    /// The index of its first line in the run.
    pub first_line: u64,
    /// Its lines.
    pub lines: &'a [Line],
}

/// The results of the batches that ran, with their indices, in batch order; and whether every batch
/// asked for ran.
pub type Mapped<T> = (Vec<(u64, T)>, bool);

/// Every batch of `stream`, in order.
pub fn all_batches(stream: &LineStream) -> Vec<u64> {
    (0..stream.plan.batches()).collect()
}

/// Draws the lines of `batches` (through `scene`'s region for the stream's bound) and hands each batch
/// to `visit` with a per-thread scratch `S`, in parallel; returns the results in batch order.
///
/// The threads take the batches in the order of the list, each the next one not taken yet, so a round
/// stopped early has done the list's first batches (and those in flight): consecutive batches, which
/// fall in different standard-error groups (batch `b` is in group `b mod G`) and keep each group's
/// share of a Sobol' sequence a prefix. Cutting the list in halves among the threads, as a parallel
/// iterator does, had a second thread start halfway: in a round of a multiple of 2G batches, the first
/// batch of each half is in group 0.
///
/// `stop(b)` is asked before batch `b` starts; when it says yes the batch is skipped. Every batch that
/// finished is kept (a stop keeps the work done, whichever batches it was); the flag says whether every
/// batch ran. The first error ends the work (batches already started finish) and is returned.
pub fn map_batches<S, T, E>(
    stream: &LineStream,
    scene: &Scene,
    batches: &[u64],
    stop: &(dyn Fn(u64) -> bool + Sync),
    visit: impl Fn(&mut S, Batch<'_>) -> Result<T, E> + Sync + Send,
) -> Result<Mapped<T>, E>
where
    S: Default + Send,
    T: Send,
    E: Send,
{
    let region = LineRegion::of(scene, stream.bound);
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let worker = |_| {
        let (mut lines, mut scratch) = (Vec::new(), S::default());
        let mut taken = Taken {
            done: Vec::new(),
            skipped: 0,
        };
        while !failed.load(Ordering::Relaxed) {
            let at = next.fetch_add(1, Ordering::Relaxed);
            let Some(&b) = batches.get(at) else { break };
            if stop(b) {
                taken.skipped += 1;
                continue;
            }
            lines.clear();
            stream.draw(b, &region, &mut lines);
            let batch = Batch {
                index: b,
                first_line: stream.plan.first_line(b),
                lines: &lines,
            };
            match visit(&mut scratch, batch) {
                Ok(t) => taken.done.push((at, b, t)),
                Err(e) => {
                    failed.store(true, Ordering::Relaxed);
                    return Err(e);
                }
            }
        }
        Ok(taken)
    };
    let workers = rayon::current_num_threads().clamp(1, batches.len().max(1));
    let parts: Vec<Taken<T>> = (0..workers)
        .into_par_iter()
        .map(worker)
        .collect::<Result<_, _>>()?;
    let mut finished: Vec<(usize, u64, T)> = Vec::with_capacity(batches.len());
    let mut skipped = 0;
    for part in parts {
        finished.extend(part.done);
        skipped += part.skipped;
    }
    finished.sort_unstable_by_key(|&(at, _, _)| at);
    let complete = skipped == 0 && finished.len() == batches.len();
    Ok((
        finished.into_iter().map(|(_, b, t)| (b, t)).collect(),
        complete,
    ))
}

/// What one thread of [`map_batches`] took from the list: the batches it finished (position in the
/// list, batch, result) and how many it skipped at a stop.
struct Taken<T> {
    done: Vec<(usize, u64, T)>,
    skipped: usize,
}

/// Buffers for tracing one batch, kept from batch to batch.
#[derive(Debug, Default)]
pub struct TraceBuffers {
    raw: Vec<RawHit>,
    /// The canonical hits of the batch's lines.
    pub hits: LineHits,
}

impl TraceBuffers {
    /// Traces `lines` with `tracer` into [`TraceBuffers::hits`].
    pub fn trace(&mut self, tracer: &dyn Tracer, lines: &[Line]) -> Result<(), TraceError> {
        tracer.all_hits(lines, &mut self.raw, &mut self.hits)
    }
}

/// [`map_batches`] with every batch traced first: `visit` gets the batch and its canonical hits.
pub fn map_traced_batches<S, T>(
    stream: &LineStream,
    tracer: &dyn Tracer,
    scene: &Scene,
    batches: &[u64],
    stop: &(dyn Fn(u64) -> bool + Sync),
    visit: impl Fn(&mut S, Batch<'_>, &LineHits) -> T + Sync + Send,
) -> Result<Mapped<T>, TraceError>
where
    S: Default + Send,
    T: Send,
{
    map_batches(
        stream,
        scene,
        batches,
        stop,
        |(buffers, scratch): &mut (TraceBuffers, S), batch| {
            buffers.trace(tracer, batch.lines)?;
            Ok(visit(scratch, batch, &buffers.hits))
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A round stopped after its first few batches keeps batches of as many groups: a run of 2 threads
    /// with a round of 4G batches (the first round of a run with a budget) stopped after 2 batches had
    /// both in group 0.
    #[test]
    fn a_round_stopped_early_keeps_batches_of_different_groups() {
        let scene = crate::scenes::load("@cube:1").unwrap();
        let groups = 16u64;
        let stream = LineStream {
            groups,
            ..LineStream::independent(64 * 4096, 1)
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        for allowed in [2usize, 3, 5] {
            let started = AtomicUsize::new(0);
            let stop = |_: u64| started.fetch_add(1, Ordering::SeqCst) >= allowed;
            let batches: Vec<u64> = (0..64).collect();
            let (done, complete) = pool
                .install(|| {
                    map_batches(&stream, &scene, &batches, &stop, |_: &mut (), batch| {
                        Ok::<_, ()>(batch.lines.len())
                    })
                })
                .unwrap();
            assert!(!complete);
            assert_eq!(done.len(), allowed);
            let mut in_groups: Vec<u64> = done.iter().map(|&(b, _)| b % groups).collect();
            in_groups.dedup();
            assert_eq!(in_groups.len(), allowed, "batches {done:?}");
            assert!(done.windows(2).all(|w| w[0].0 < w[1].0), "in batch order");
        }
    }
}
