//! Casting a run's lines: its empty state, and the rounds of batches that fill it until the line count,
//! the budget or a stop request ends it.
//!
//! A stopped run keeps the longest prefix of finished batches, so its lines are always batches `0..k`: the
//! same seed gives the same numbers for the same number of lines, whatever the thread count.

use std::time::{Duration, Instant};

use super::batches::LineStream;
use super::control::{RunControl, StopReason};
use super::plan::{BatchPlan, BatchSet, MAX_ROUND_KEYS, MAX_ROUND_LINES};
use super::spec::{RunSpec, SpecError};
use super::state::{RunState, TracedBatches};
use crate::measure::radiosity::{MaterialError, PatchMaterials};
use crate::sample::tally::Wanted;
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// What a precision target's measure reads on the run so far: its standard error, and whether its
/// reading is reliable. The analysis computes it (`analysis::cast`); the engine only decides, from
/// it, whether to stop and how long the next round is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetReading {
    /// The standard error (`None`: none could be estimated yet).
    pub stderr: Option<f64>,
    /// Whether the reading's verdict is ok.
    pub reliable: bool,
    /// Whether its standard error is below what f32 tracing resolves: more lines cannot make it ok.
    pub floored: bool,
}

/// Reads a precision target's measure on a run's state (between rounds).
pub type TargetWatch<'a> = &'a (dyn Fn(&RunState) -> TargetReading + Sync);

/// What a run's caller sees between rounds: the precision target's reading (the run stops when its
/// target is met), and the state after each round (to save a checkpoint).
pub struct CastHooks<'a> {
    /// Reads the target's measure; without it a target never stops the run.
    pub target: Option<TargetWatch<'a>>,
    /// Sees the state after each round.
    pub after_round: &'a mut dyn FnMut(&RunState),
}

/// Which measures a run of `cfg` gathers on `scene`: the pair counts also for the radiosity measures
/// when something emits, and the escapes' per-patch sums of eq. (27) for the per-patch results of an
/// enclosed scene. Checks the materials first when radiosity is asked for.
fn gathered(scene: &Scene, cfg: &RunSpec) -> Result<Wanted, MaterialError> {
    let lit = if cfg.measures.radiosity {
        PatchMaterials::of_scene(scene)?.any_emission()
    } else {
        false
    };
    Ok(Wanted {
        discrete: cfg.measures.discrete || lit || cfg.per_patch,
        continuous: cfg.measures.continuous,
        per_patch: cfg.per_patch && cfg.measures.continuous,
        environment: cfg.per_patch && cfg.measures.continuous && cfg.enclose,
    })
}

/// Why a run cannot start.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StartError {
    /// A material outside the physical range (radiosity asked for).
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// Settings that contradict each other.
    #[error(transparent)]
    Spec(#[from] SpecError),
}

/// The empty state of a run of `cfg` on `scene`, checked before any line is cast (its settings, and the
/// materials when radiosity is asked for).
pub fn start(scene: &Scene, cfg: &RunSpec) -> Result<RunState, StartError> {
    cfg.check()?;
    let wanted = gathered(scene, cfg)?;
    if !wanted.discrete && !wanted.continuous {
        // Only the radiosity measures were asked for, and nothing emits.
        return Err(SpecError::NothingToCompute.into());
    }
    check_target_is_gathered(cfg, wanted)?;
    Ok(RunState::new(cfg.plan(), cfg.group_count(), wanted))
}

/// A precision target on a measure the run does not gather is refused: its reading never comes, so the
/// run would go on to its line cap (or, without one, forever) and end with the target not met.
fn check_target_is_gathered(cfg: &RunSpec, wanted: Wanted) -> Result<(), SpecError> {
    let Some(target) = cfg.budget.target else {
        return Ok(());
    };
    let info = target.measure.info();
    if info.needs.met_by(wanted.discrete, wanted.continuous) {
        return Ok(());
    }
    let gathered = match (wanted.discrete, wanted.continuous) {
        (true, false) => "the pair counts alone",
        (false, true) => "eq. (27)'s sums alone",
        _ => "neither the pair counts nor eq. (27)'s sums",
    };
    Err(SpecError::TargetNotGathered {
        measure: info.key,
        gathered,
    })
}

/// Shard `index` (from 1) of `count`: a contiguous block of about 1/count of a run's batches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    /// Which shard, 1 to `count`.
    pub index: u32,
    /// How many shards.
    pub count: u32,
}

/// The batches a run casts: all of them, or one shard's share.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    /// Every batch of the plan.
    All,
    /// One shard's batches.
    Shard(Shard),
}

impl Scope {
    /// The scope of a run that is `shard`, or all of it.
    pub fn of(shard: Option<Shard>) -> Self {
        shard.map_or(Scope::All, Scope::Shard)
    }

    /// The batches of a plan of `batches` batches in this scope.
    pub fn batches(self, batches: u64) -> std::ops::Range<u64> {
        match self {
            Scope::All => 0..batches,
            Scope::Shard(Shard { index, count }) => {
                let (k, m) = (u64::from(index.max(1) - 1), u64::from(count.max(1)));
                (k * batches / m)..((k + 1) * batches / m)
            }
        }
    }
}

/// How a run casts its batches: which of them, and in rounds of about how long.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CastOptions {
    /// The batches to cast.
    pub scope: Scope,
    /// Keep rounds to about this many seconds (a checkpointed run saves between rounds); `None`: rounds
    /// as large as memory allows. Rounds change nothing in the numbers.
    pub round_seconds: Option<f64>,
}

impl Default for CastOptions {
    fn default() -> Self {
        CastOptions {
            scope: Scope::All,
            round_seconds: None,
        }
    }
}

/// Lines still to cast in `scope` for a run in `state`.
pub fn remaining_lines(state: &RunState, scope: Scope) -> u64 {
    let plan = state.plan();
    let range = scope.batches(plan.batches());
    let missing = state.done().missing(range.end);
    missing
        .indices_within(range)
        .into_iter()
        .map(|b| plan.batch_len(b) as u64)
        .sum()
}

/// Casts the batches of `options.scope` not done yet in `state`, in rounds, until they are all done,
/// the budget is spent or a stop is requested; every finished batch is kept, and `after_round` sees the
/// state after each round (to save a checkpoint).
pub fn cast(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &RunSpec,
    state: &mut RunState,
    options: CastOptions,
    control: &RunControl,
    hooks: CastHooks,
) -> Result<StopReason, TraceError> {
    let start = Instant::now();
    let plan = state.plan();
    let wanted = state.wanted();
    let stream = LineStream {
        plan,
        source: cfg.source,
        sampler: cfg.sampler,
        bound: cfg.bound,
        groups: state.group_count(),
        seed: cfg.seed,
    };
    // A budget longer than the clock can count (`--seconds 1e30`) is no limit: the run ends with its
    // lines, as it would long before such a deadline.
    let deadline = cfg.budget.seconds.and_then(|s| {
        Duration::try_from_secs_f64(s.max(0.0))
            .ok()
            .and_then(|d| start.checked_add(d))
    });
    let stop = |b: u64| {
        let late = deadline.is_some_and(|d| Instant::now() >= d);
        if control.stop_requested() || late {
            return true;
        }
        control.started(plan.batch_len(b) as u64);
        false
    };
    let scope = options.scope.batches(plan.batches());
    // Rounds bound the memory held in pair keys and let a budget run check itself.
    let first_round = (4 * state.group_count()).max(64);
    let mut round = if cfg.budget.is_open_ended() || options.round_seconds.is_some() {
        first_round
    } else {
        max_round_batches(plan, wanted, state)
    };
    let mut cast_batches = 0u64;
    // The next batch to look at, and the last round's batches when they are not counted yet: without a
    // precision target the next round's size does not depend on the counts, so a round is counted while
    // the next one is traced, which keeps both cores busy through the counting's serial parts.
    let mut cursor = scope.start;
    let mut pending: Option<TracedBatches> = None;
    // Whether a precision target's next check was planned by an earlier reading.
    let mut planned = false;
    let stop_reason = loop {
        let (batches, next) = next_batches(state.done(), cursor, scope.end, round);
        let trace = || TracedBatches::trace(scene, tracer, &stream, &batches, wanted, &stop);
        let (traced, complete) = match pending.take() {
            Some(previous) => {
                let (traced, ()) = rayon::join(trace, || state.add(scene, previous));
                (hooks.after_round)(state);
                traced?
            }
            None => trace()?,
        };
        cursor = next;
        cast_batches += traced.len() as u64;
        let ended = if !complete {
            Some(if control.stop_requested() {
                StopReason::Interrupted
            } else {
                StopReason::Seconds
            })
        } else if cursor >= scope.end {
            Some(StopReason::Lines)
        } else if deadline.is_some_and(|d| Instant::now() >= d) {
            Some(StopReason::Seconds)
        } else {
            None
        };
        if ended.is_some() || cfg.budget.target.is_some() {
            state.add(scene, traced);
            (hooks.after_round)(state);
        } else {
            pending = Some(traced);
        }
        if let Some(reason) = ended {
            break reason;
        }
        if let (Some(target), Some(watch)) = (cfg.budget.target, hooks.target) {
            let done = state.batches_done();
            let TargetReading {
                stderr: se,
                reliable,
                floored,
            } = watch(state);
            let ready = se.is_some_and(|se| se <= target.stderr) && reliable;
            // The first reading only plans: a run stopped there would be stopped by its own error's dip.
            if ready && planned {
                break StopReason::Target;
            }
            if floored && planned {
                break StopReason::Floor;
            }
            planned = true;
            round = match se {
                Some(se) if se > target.stderr || ready => {
                    rounds_to_target(done, se, target.stderr)
                }
                // Small enough an error on a biased reading: double, since the bias falls faster.
                _ => done.max(1),
            };
        } else if let Some(seconds) = options.round_seconds {
            // Rounds of about `seconds` at the rate so far.
            let rate = cast_batches as f64 / start.elapsed().as_secs_f64().max(1e-3);
            round = ((rate * seconds) as u64).max(first_round);
        } else {
            // Doubling: few rounds, and a time budget is checked before every batch anyway. The round
            // still to be counted is part of the run so far.
            let counted_or_not =
                state.batches_done() + pending.as_ref().map_or(0, |p| p.len() as u64);
            round = counted_or_not.max(64);
        }
        round = round.min(max_round_batches(plan, wanted, state));
        if pending.is_some() {
            round = leaving_a_short_last_round(round, scope.end - cursor, state.batches_done());
        }
    };
    Ok(stop_reason)
}

/// The next round of a run with `remaining` batches left after it is cast, when it would be the last:
/// shortened so that a last round of about an eighth of the `done` batches (at least 64) follows. The
/// last round's counting has no tracing to overlap with, so the shorter it is, the less of the run is
/// spent with one core idle; the round before it is counted while it is traced.
fn leaving_a_short_last_round(round: u64, remaining: u64, done: u64) -> u64 {
    let last = (done / 8).max(64);
    if remaining > round || remaining <= last {
        return round;
    }
    remaining - last
}

/// How far past the predicted need of a precision target a run goes before it checks again.
const TARGET_MARGIN: f64 = 1.3;

/// The batches of the next round of a run of `done` batches whose standard error `se` is above the goal
/// `goal`. The error falls like 1 / sqrt(lines); the round aims [`TARGET_MARGIN`] past the lines the
/// reading predicts, and grows the run by 1.5 to 4 times. Checking every few lines would stop a run the
/// first time its estimated error dips below the goal, and a low estimated error goes with a low value
/// for skewed terms such as those of eq. (27): the intervals of runs so stopped cover less than 95%.
/// Checked at geometric line counts with a margin, a run stops where an earlier reading planned it, and
/// never at its first check (measured on `@cube` with a goal of 0.005 on I_s^c over 200 seeds: 9 runs
/// stopped at the first check on a dip of their 16-group error).
fn rounds_to_target(done: u64, se: f64, goal: f64) -> u64 {
    let need = done as f64 * (se / goal).powi(2) * TARGET_MARGIN;
    let more = (need as u64).saturating_sub(done);
    more.clamp((done / 2).max(1), (3 * done).max(1))
}

/// The most batches a round may hold: [`MAX_ROUND_LINES`], and when pairs are counted no more than
/// about [`MAX_ROUND_KEYS`] pair keys at the run's pairs per line so far (a first round assumes four).
/// Rounds change no number, only the memory and the time between counts.
fn max_round_batches(plan: BatchPlan, wanted: Wanted, state: &RunState) -> u64 {
    let by_lines = MAX_ROUND_LINES;
    let by_keys = if wanted.discrete {
        let (lines, pairs) = state
            .filled_groups()
            .iter()
            .fold((0u64, 0u64), |(l, p), t| {
                (l + t.counters.lines, p + t.counters.pairs)
            });
        let pairs_per_line = if lines > 0 {
            pairs as f64 / lines as f64
        } else {
            4.0
        };
        (MAX_ROUND_KEYS as f64 / pairs_per_line.max(0.25)) as u64
    } else {
        u64::MAX
    };
    (by_lines.min(by_keys) / plan.batch_size).max(1)
}

/// Up to `count` batches from `cursor` to `end` that are not `done`, and where to look next.
fn next_batches(done: &BatchSet, mut cursor: u64, end: u64, count: u64) -> (Vec<u64>, u64) {
    let mut out = Vec::with_capacity(count.min(1 << 16) as usize);
    while cursor < end && (out.len() as u64) < count {
        if !done.contains(cursor) {
            out.push(cursor);
        }
        cursor += 1;
    }
    (out, cursor)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A round that would end the run leaves a last round of an eighth of the batches done (at least
    /// 64); other rounds, and a last round already that short, are left as they are; every batch is
    /// still cast.
    #[test]
    fn the_last_round_is_short() {
        assert_eq!(leaving_a_short_last_round(2000, 1948, 5376), 1948 - 672);
        assert_eq!(leaving_a_short_last_round(2000, 1948, 100), 1948 - 64);
        assert_eq!(leaving_a_short_last_round(2000, 5000, 5376), 2000);
        assert_eq!(leaving_a_short_last_round(2000, 672, 5376), 2000);
        let (mut done, mut left, mut rounds) = (1024u64, 7324 - 1024, Vec::new());
        while left > 0 {
            let round = leaving_a_short_last_round(done.max(64), left, done).min(left);
            rounds.push(round);
            (done, left) = (done + round, left - round);
        }
        assert_eq!(rounds.iter().sum::<u64>(), 7324 - 1024);
        assert!(*rounds.last().unwrap() <= 7324 / 8, "{rounds:?}");
    }
}
