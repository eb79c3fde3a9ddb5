//! One analysis run: lines -> hits -> pairs -> counts -> measures, every measure with its standard error.
//!
//! [`analyze`] is the one entry point, for the visibility measures (paper sec. 3) and, when the scene
//! emits, the radiosity measures (sec. 4). It plans rounds of batches, traces a round while it counts
//! the last ([`RunState`]), stops at the line count, the budget or a stop request, and computes every
//! measure on the whole run and on each group ([`super::errors`]).
//!
//! A stopped run keeps the longest prefix of finished batches, so its lines are always batches `0..k`: the
//! same seed gives the same numbers for the same number of lines, whatever the thread count.

use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::batches::LineStream;
use super::control::{Budget, RunControl, StopReason, TargetMeasure};
use super::errors::{ErrorMethod, Spread};
use super::patches::{self as per_patch, PatchEstimate, PatchLight};
use super::plan::{BatchPlan, BatchSet, MAX_ROUND_KEYS, MAX_ROUND_LINES};
use super::radiosity::{self, RadiosityOutcome, SolveFailure};
use super::readings::VisibilityEstimates;
use super::reliability::{self, SamplingReport, Verdict, VisibilityReliability, COVERAGE_OK};
use super::state::{FinishedRun, RunState, TracedBatches};
use super::warnings::{self, RunWarning};
use crate::measure::bias::{self, CorrectedValues};
use crate::measure::channel;
use crate::measure::entropy::xlog2x;
use crate::measure::estimators::EntropyEstimator;
use crate::measure::radiosity::{MaterialError, PatchMaterials, SolveOptions};
use crate::measure::rows::Rows;
use crate::measure::sampling::{lines_factor_for_coverage, Sampling};
use crate::measure::visibility::{self, ContinuousValues, DiscreteValues};
use crate::measure::Estimate;
use crate::sample::lines::LineSource;
use crate::sample::tally::{ObjectSides, Tally, Wanted};
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// Default number of independent groups of lines behind every standard error.
pub const DEFAULT_GROUPS: usize = 16;

/// The entropy estimator behind the bias-corrected H_s and I_s, chosen by measurement against the exact
/// I_s of `@cube:N` (README, "Error against run time").
pub const DEFAULT_ESTIMATOR: EntropyEstimator = EntropyEstimator::ChaoWangJost;

/// Which families of measures a run computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Measures {
    /// The discrete measures from pair counts (H_s, I_s, E(MSE), ..., paper sec. 3.1).
    pub discrete: bool,
    /// The continuous mutual information I_s^c (eq. 27, sec. 3.2).
    pub continuous: bool,
    /// The radiosity measures (sec. 4), when the scene emits; they need the pair counts, which are then
    /// gathered whatever `discrete` says.
    pub radiosity: bool,
}

impl Measures {
    /// Every measure.
    pub const ALL: Measures = Measures {
        discrete: true,
        continuous: true,
        radiosity: true,
    };

    /// The visibility measures only (no radiosity).
    pub const VISIBILITY: Measures = Measures {
        discrete: true,
        continuous: true,
        radiosity: false,
    };
}

/// What to run.
#[derive(Clone, Copy, Debug)]
pub struct AnalysisConfig {
    /// Global lines to cast (a cap when a budget is set).
    pub lines: u64,
    /// Seed of the line streams.
    pub seed: u64,
    /// Which measures to compute.
    pub measures: Measures,
    /// Groups for the standard errors ([`super::errors`]).
    pub groups: usize,
    /// The estimator of the bias-corrected H_s and I_s.
    pub estimator: EntropyEstimator,
    /// How the standard errors of the count-based measures are estimated.
    pub errors: ErrorMethod,
    /// When to stop before `lines`.
    pub budget: Budget,
    /// Independent lines, or bundles of parallel lines ([`LineSource`]); a bundle never straddles two
    /// batches, so the group spread includes the correlation within a bundle.
    pub source: LineSource,
    /// Close an open scene with the environment patch ([`crate::sample::environment`]): escapes become
    /// pairs with it, and every measure is that of the enclosed scene. Changes nothing when nothing
    /// escapes.
    pub enclose: bool,
    /// How the radiosity system is solved.
    pub solve: SolveOptions,
    /// Also share the measures out among the patches ([`Analysis::patches`]); gathers eq. (27)'s terms
    /// per patch, which costs nothing when left off. Not with `enclose` on an open scene.
    pub per_patch: bool,
}

impl AnalysisConfig {
    /// `lines` lines from `seed`, every measure, default groups and estimator, no budget.
    pub fn new(lines: u64, seed: u64) -> Self {
        AnalysisConfig {
            lines,
            seed,
            measures: Measures::ALL,
            groups: DEFAULT_GROUPS,
            estimator: DEFAULT_ESTIMATOR,
            errors: ErrorMethod::Groups,
            budget: Budget::default(),
            source: LineSource::Independent,
            enclose: false,
            solve: SolveOptions::default(),
            per_patch: false,
        }
    }
}

/// Why an analysis failed.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// A material outside the physical range (bad input), found before any line is cast.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// The radiosity system has no solution, or the solver gave up (bad input: the materials).
    #[error(transparent)]
    Solve(#[from] SolveFailure),
    /// Tracing failed.
    #[error(transparent)]
    Trace(#[from] TraceError),
}

impl AnalysisError {
    /// Whether the scene's own data are at fault (materials), not the machinery.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, AnalysisError::Trace(_))
    }
}

/// Everything a run found.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// Lines cast.
    pub lines: u64,
    /// Seed.
    pub seed: u64,
    /// Wall-clock seconds of tracing, counting and measuring.
    pub seconds: f64,
    /// Why the run ended.
    pub stop_reason: StopReason,
    /// How the run's lines are cut into batches.
    pub plan: BatchPlan,
    /// The batches the report covers (all of the plan's but when interrupted, or for a partial merge).
    pub covered: BatchSet,
    /// Groups behind the standard errors.
    pub groups: usize,
    /// The estimator of the corrected measures.
    pub estimator: EntropyEstimator,
    /// How the standard errors of the count-based measures were estimated (batch means when the
    /// jackknife was asked for but does not apply).
    pub errors: ErrorMethod,
    /// Canonical hits.
    pub hits: u64,
    /// Visible pairs.
    pub pairs: u64,
    /// Segments escaping from a front side (0 in a closed scene).
    pub escapes: u64,
    /// Segments joining no two front sides.
    pub unpaired: u64,
    /// Pairs with coincident points, left out of eq. (27).
    pub degenerate_pairs: u64,
    /// Distinct patch pairs seen (when counted).
    pub distinct_pairs: Option<usize>,
    /// Patches no segment left from, and their area fraction (when counted).
    pub unsampled: Option<(usize, f64)>,
    /// With `--enclose` when something escaped: the environment patch's area in scene units (see
    /// [`crate::sample::environment`]); `None` otherwise.
    pub environment_area: Option<Estimate>,
    /// The visibility measures.
    pub visibility: VisibilityEstimates,
    /// How well the lines sampled the rows of F (when the discrete measures were counted).
    pub sampling: Option<SamplingReport>,
    /// The verdict on every visibility reading.
    pub reliability: VisibilityReliability,
    /// The precision target, when there was one, and whether it was met.
    pub target: Option<TargetOutcome>,
    /// The radiosity measures, or why there are none.
    pub radiosity: RadiosityOutcome,
    /// What the user must know about these numbers (an open scene, unsampled patches, ...).
    pub warnings: Vec<RunWarning>,
    /// Per object of the scene: how lines met its sides (the evidence behind the orientation warnings).
    pub orientation: Vec<ObjectSides>,
    /// The full-run counts, for form factors (when counted).
    pub tally: Tally,
    /// Each patch's results, with standard errors, when [`AnalysisConfig::per_patch`] asked for them
    /// (`None` as well for an enclosed open scene).
    pub patches: Option<Vec<PatchEstimate>>,
}

impl Analysis {
    /// Whether the report covers every batch of its plan.
    pub fn is_complete(&self) -> bool {
        self.covered.len() == self.plan.batches()
    }

    /// The line ranges the report covers (of the plan's `0..lines`).
    pub fn covered_lines(&self) -> Vec<std::ops::Range<u64>> {
        self.covered
            .ranges()
            .iter()
            .map(|r| {
                self.plan.first_line(r.start)
                    ..self.plan.first_line(r.end - 1) + self.plan.batch_len(r.end - 1) as u64
            })
            .collect()
    }

    /// The fraction of the segments leaving a front side that escape the scene (`None` without
    /// segments).
    pub fn escape_fraction(&self) -> Option<f64> {
        warnings::escape_fraction(&self.tally.counters)
    }
}

/// A precision target at the end of a run: met only when the standard error is small enough *and* the
/// reading is reliable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetOutcome {
    /// The measure watched.
    pub measure: TargetMeasure,
    /// The standard error asked for.
    pub stderr_goal: f64,
    /// The standard error reached (`None`: none could be estimated).
    pub stderr: Option<f64>,
    /// The verdict on the reading (`None`: not computed).
    pub verdict: Option<Verdict>,
}

impl TargetOutcome {
    /// Whether the target was met: the standard error within the goal and the reading reliable.
    pub fn met(&self) -> bool {
        self.stderr.is_some_and(|se| se <= self.stderr_goal) && self.verdict == Some(Verdict::Ok)
    }
}

/// Measures of one group, of one group left out, or of the whole run.
#[derive(Clone, Copy, Debug)]
struct GroupValues {
    discrete: Option<DiscreteValues>,
    corrected: Option<CorrectedValues>,
    continuous: Option<ContinuousValues>,
    /// The environment patch's area (tracing space), when enclosed.
    environment_area: Option<f64>,
    /// How the rows were sampled (when counted).
    sampling: Option<Sampling>,
    /// The factor on the lines for a coverage of [`COVERAGE_OK`] (the whole run's values only).
    lines_factor: Option<f64>,
}

impl GroupValues {
    /// The values of a tally; of the enclosed scene when `enclose` ([`Tally::enclosed`]); with the
    /// extrapolation of the rows' coverage when `extrapolate` (the whole run's).
    fn of(
        scene: &Scene,
        t: &Tally,
        estimator: EntropyEstimator,
        enclose: bool,
        extrapolate: bool,
    ) -> Self {
        if enclose {
            let (enclosed, areas) = t.enclosed(scene);
            return GroupValues {
                environment_area: Some(t.environment_area(scene)),
                ..GroupValues::plain(&areas, &enclosed, estimator, extrapolate)
            };
        }
        GroupValues::plain(&areas(scene), t, estimator, extrapolate)
    }

    fn plain(areas: &[f64], t: &Tally, estimator: EntropyEstimator, extrapolate: bool) -> Self {
        let mut values = GroupValues {
            discrete: None,
            corrected: None,
            continuous: ContinuousValues::from_sum(
                t.counters.cmi_sum.value(),
                t.counters.cmi_pairs,
            ),
            environment_area: None,
            sampling: None,
            lines_factor: None,
        };
        let Some(c) = t.counts.as_ref().filter(|_| t.counters.lines > 0) else {
            return values;
        };
        // One pass over the counts serves the plug-in and the corrected measures and the sampling.
        let a = channel::area_distribution(areas);
        let a = a.as_slice().expect("a fresh array is contiguous");
        let rows = Rows::gather(a, c, &t.escapes_by_patch, estimator);
        values.discrete = Some(visibility::discrete_from_rows(a, &rows.sums));
        values.corrected = Some(bias::corrected_from_rows(a, &rows, c, &t.escapes_by_patch));
        values.sampling = Some(Sampling::of_rows(a, &rows.sums));
        if extrapolate {
            values.lines_factor = lines_factor_for_coverage(a, &rows.sums, COVERAGE_OK);
        }
        values
    }

    fn accuracy(&self) -> Option<f64> {
        Some(self.discrete?.mutual_information / self.continuous?.mutual_information)
    }

    fn accuracy_corrected(&self) -> Option<f64> {
        Some(self.corrected?.mutual_information / self.continuous?.mutual_information)
    }
}

fn areas(scene: &Scene) -> Vec<f64> {
    scene.patches.iter().map(|p| p.area).collect()
}

/// Runs an analysis that `control` can watch and stop: casts `cfg.lines` global lines (or fewer, by the
/// budget) and computes the measures `cfg.measures` asks for, each with its standard error.
///
/// With radiosity asked for, the materials are checked before any line is cast; when nothing emits the
/// radiosity measures are left out with the reason. Uses the current rayon thread pool; results do not
/// depend on its size. [`start`], [`cast`] and [`finish`] are its three steps, for runs that are
/// sharded, checkpointed or resumed.
pub fn analyze(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &AnalysisConfig,
    control: &RunControl,
) -> Result<Analysis, AnalysisError> {
    let started = Instant::now();
    let mut state = start(scene, cfg)?;
    let stop_reason = cast(
        scene,
        tracer,
        cfg,
        &mut state,
        CastOptions::default(),
        control,
        &mut |_| {},
    )?;
    finish(
        scene,
        cfg,
        state,
        stop_reason,
        started.elapsed().as_secs_f64(),
    )
}

/// Which measures a run of `cfg` gathers on `scene`: the pair counts also for the radiosity measures
/// when something emits. Checks the materials first when radiosity is asked for.
fn gathered(scene: &Scene, cfg: &AnalysisConfig) -> Result<Wanted, AnalysisError> {
    let lit = if cfg.measures.radiosity {
        PatchMaterials::of_scene(scene)?.any_emission()
    } else {
        false
    };
    Ok(Wanted {
        discrete: cfg.measures.discrete || lit || cfg.per_patch,
        continuous: cfg.measures.continuous,
        per_patch: cfg.per_patch && cfg.measures.continuous,
    })
}

/// The batch plan of a run of `cfg`: fixed by the line count, or full batches when a budget may end the
/// run anywhere.
pub fn plan_of(cfg: &AnalysisConfig) -> BatchPlan {
    if cfg.budget.is_open_ended() {
        BatchPlan::open_ended(cfg.lines, cfg.source)
    } else {
        BatchPlan::for_source(cfg.lines, cfg.source)
    }
}

/// The empty state of a run of `cfg` on `scene`, checked before any line is cast (the materials, when
/// radiosity is asked for).
pub fn start(scene: &Scene, cfg: &AnalysisConfig) -> Result<RunState, AnalysisError> {
    let plan = plan_of(cfg);
    // A short fixed run has fewer batches than groups: one group per batch then.
    let groups = (cfg.groups.max(2) as u64).min(plan.batches().max(2)) as usize;
    Ok(RunState::new(plan, groups, gathered(scene, cfg)?))
}

/// The batches a run casts: all of them, or one shard's share.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    /// Every batch of the plan.
    All,
    /// Shard `index` (from 1) of `count`: a contiguous block of about 1/count of the batches.
    Shard {
        /// Which shard, 1 to `count`.
        index: u32,
        /// How many shards.
        count: u32,
    },
}

impl Scope {
    /// The batches of a plan of `batches` batches in this scope.
    pub fn batches(self, batches: u64) -> std::ops::Range<u64> {
        match self {
            Scope::All => 0..batches,
            Scope::Shard { index, count } => {
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
    cfg: &AnalysisConfig,
    state: &mut RunState,
    options: CastOptions,
    control: &RunControl,
    after_round: &mut dyn FnMut(&RunState),
) -> Result<StopReason, TraceError> {
    let start = Instant::now();
    let plan = state.plan();
    let wanted = state.wanted();
    let stream = LineStream {
        plan,
        source: cfg.source,
        seed: cfg.seed,
    };
    let deadline = cfg
        .budget
        .seconds
        .map(|s| start + Duration::from_secs_f64(s.max(0.0)));
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
    let stop_reason = loop {
        let (batches, next) = next_batches(state.done(), cursor, scope.end, round);
        let trace = || TracedBatches::trace(scene, tracer, &stream, &batches, wanted, &stop);
        let (traced, complete) = match pending.take() {
            Some(previous) => {
                let (traced, ()) = rayon::join(trace, || state.add(scene, previous));
                after_round(state);
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
            after_round(state);
        } else {
            pending = Some(traced);
        }
        if let Some(reason) = ended {
            break reason;
        }
        if let Some(target) = cfg.budget.target {
            let done = state.batches_done();
            let (se, verdict) = current_reading(scene, state, cfg, target.measure);
            let reliable = verdict == Some(Verdict::Ok);
            match se {
                Some(se) if se <= target.stderr && reliable => break StopReason::Target,
                // stderr ~ 1/sqrt(lines): aim 10% past the predicted need, at most doubling per round.
                Some(se) if se > target.stderr => {
                    let need = done as f64 * (se / target.stderr).powi(2) * 1.1;
                    round = ((need as u64).saturating_sub(done)).clamp(1, done.max(1));
                }
                // Small enough an error on a biased reading: double, since the bias falls faster.
                _ => round = done.max(1),
            }
        } else if let Some(seconds) = options.round_seconds {
            // Rounds of about `seconds` at the rate so far.
            let rate = cast_batches as f64 / start.elapsed().as_secs_f64().max(1e-3);
            round = ((rate * seconds) as u64).max(first_round);
        } else {
            // Doubling: few rounds, and a time budget is checked before every batch anyway.
            round = state.batches_done().max(64);
        }
        round = round.min(max_round_batches(plan, wanted, state));
    };
    Ok(stop_reason)
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

/// The measures of a run's state: every reading with its standard error and verdict, the radiosity
/// measures when the scene emits, and the warnings. `seconds` is the run's time before its measures;
/// the report's [`Analysis::seconds`] adds the time they take here (summing the groups into the run's
/// total and estimating from them is part of what a user waits for).
pub fn finish(
    scene: &Scene,
    cfg: &AnalysisConfig,
    state: RunState,
    stop_reason: StopReason,
    seconds: f64,
) -> Result<Analysis, AnalysisError> {
    let began = Instant::now();
    let materials = if cfg.measures.radiosity {
        Some(PatchMaterials::of_scene(scene)?)
    } else {
        None
    };
    let lit = materials.as_ref().is_some_and(|m| m.any_emission());
    let wanted = state.wanted();
    let plan = state.plan();
    let covered = state.done().clone();
    let run = state.finish(scene);
    let enclose = cfg.enclose && run.groups.iter().any(|t| t.counters.escapes > 0);
    let jackknife = cfg.errors == ErrorMethod::Jackknife
        && !enclose
        && cfg.estimator != EntropyEstimator::ChaoShen
        && run.groups.len() >= 2;
    let visibility = visibility_estimates(scene, &run, cfg.estimator, enclose, jackknife, wanted);
    let target = cfg.budget.target.map(|t| TargetOutcome {
        measure: t.measure,
        stderr_goal: t.stderr,
        stderr: visibility.estimates.of(t.measure).and_then(|e| e.stderr),
        verdict: visibility.reliability.of(t.measure).map(|r| r.verdict),
    });
    let radiosity = match &materials {
        None => RadiosityOutcome::NotRequested,
        Some(_) if !lit => RadiosityOutcome::Skipped(radiosity::NOTHING_EMITS.into()),
        Some(m) => radiosity::estimates(
            scene,
            m,
            &run,
            &cfg.solve,
            cfg.estimator,
            visibility.jackknifed,
            visibility
                .sampling
                .as_ref()
                .expect("radiosity counts the pairs"),
        )?,
    };
    let patches = (cfg.per_patch && !enclose)
        .then(|| {
            let light = materials.as_ref().filter(|_| lit).map(|m| PatchLight {
                materials: m,
                solve: &cfg.solve,
            });
            per_patch::estimates(scene, &run, cfg.estimator, light)
        })
        .flatten();
    let FinishedRun { total, .. } = run;
    let mut warnings = warnings::of_run(
        &scene.name,
        &total.counters,
        visibility.unsampled,
        visibility.environment_area,
    );
    warnings.extend(super::orientation::warnings(scene, &total, enclose));
    let mut visibility = visibility;
    if total.counters.pairs == 0 && !enclose {
        visibility.estimates = undefined_without_pairs(&visibility.estimates);
    }
    Ok(Analysis {
        lines: total.counters.lines,
        seed: cfg.seed,
        seconds: seconds + began.elapsed().as_secs_f64(),
        stop_reason,
        plan,
        covered,
        groups: visibility.groups,
        estimator: cfg.estimator,
        errors: if visibility.jackknifed {
            ErrorMethod::Jackknife
        } else {
            ErrorMethod::Groups
        },
        hits: total.counters.hits,
        pairs: total.counters.pairs,
        escapes: total.counters.escapes,
        unpaired: total.counters.unpaired,
        degenerate_pairs: total.counters.degenerate_pairs,
        environment_area: visibility.environment_area,
        distinct_pairs: total.counts.as_ref().map(|c| c.distinct_pairs()),
        unsampled: visibility.unsampled,
        visibility: visibility.estimates,
        sampling: visibility.sampling,
        reliability: visibility.reliability,
        target,
        radiosity,
        warnings,
        orientation: total.orientation.clone(),
        tally: total,
        patches,
    })
}

/// The estimates of a run in which no segment joined two patches: only the positional entropy (exact,
/// from the areas) is defined; every visibility measure has no pair to be computed from, and zeros would
/// read as measurements.
fn undefined_without_pairs(estimates: &VisibilityEstimates) -> VisibilityEstimates {
    VisibilityEstimates {
        positional_entropy: estimates.positional_entropy,
        ..VisibilityEstimates::default()
    }
}

/// The standard error of `measure` and the verdict on its reading, from the run so far. Batch means:
/// the jackknife needs the total's counts, which a dense run merges only at the end; batch means are
/// larger where they differ, so a target is never met early.
fn current_reading(
    scene: &Scene,
    state: &RunState,
    cfg: &AnalysisConfig,
    measure: TargetMeasure,
) -> (Option<f64>, Option<Verdict>) {
    let wanted = state.wanted();
    let run = state.snapshot(scene);
    let enclose = cfg.enclose && run.groups.iter().any(|t| t.counters.escapes > 0);
    let v = visibility_estimates(scene, &run, cfg.estimator, enclose, false, wanted);
    (
        v.estimates.of(measure).and_then(|e| e.stderr),
        v.reliability.of(measure).map(|r| r.verdict),
    )
}

/// The visibility side of a finished run.
struct VisibilityOfRun {
    estimates: VisibilityEstimates,
    /// The groups with lines.
    groups: usize,
    /// Patches no segment left, and their area fraction (when counted).
    unsampled: Option<(usize, f64)>,
    /// The environment's area in scene units, when enclosed.
    environment_area: Option<Estimate>,
    /// Whether the standard errors came from the jackknife.
    jackknifed: bool,
    /// How the rows were sampled (when counted).
    sampling: Option<SamplingReport>,
    /// The verdict on every reading.
    reliability: VisibilityReliability,
}

/// Every visibility measure of a finished run with its standard error (by the jackknife when asked and
/// possible), and the environment's area when enclosed.
fn visibility_estimates(
    scene: &Scene,
    run: &FinishedRun,
    estimator: EntropyEstimator,
    enclose: bool,
    jackknife: bool,
    wanted: Wanted,
) -> VisibilityOfRun {
    let values_of = |t: &Tally| GroupValues::of(scene, t, estimator, enclose, false);
    let (all, per_group): (GroupValues, Vec<GroupValues>) = rayon::join(
        || GroupValues::of(scene, &run.total, estimator, enclose, true),
        || run.groups.par_iter().map(values_of).collect(),
    );
    let replicates = jackknife
        .then(|| jackknife_replicates(scene, &run.total, &run.groups, estimator))
        .flatten();
    let areas = areas(scene);
    let spread = Spread {
        all: &all,
        groups: &per_group,
        replicates: replicates.as_deref(),
    };
    let mut estimates = if run.total.counters.lines == 0 {
        VisibilityEstimates {
            positional_entropy: Some(Estimate::exact(positional_entropy(&areas))),
            ..VisibilityEstimates::default()
        }
    } else {
        estimates(&areas, &spread, wanted)
    };
    let mut environment_area = None;
    if enclose {
        // The environment's area is counted, so H_p has a spread over the groups too.
        estimates.positional_entropy = spread.batch_means(|g| Some(g.discrete?.positional_entropy));
        let scale2 = scene.normalization.scale.powi(2);
        environment_area = spread.batch_means(|g| Some(g.environment_area? * scale2));
    }
    let lines = run.total.counters.lines;
    let sampling = all.sampling.map(|sampling| SamplingReport {
        sampling,
        lines_for_coverage: all.lines_factor.map(|k| (k * lines as f64).ceil() as u64),
    });
    let reliability = reliability::visibility(
        &estimates,
        sampling.as_ref(),
        lines,
        run.total.counters.pairs,
    );
    VisibilityOfRun {
        estimates,
        sampling,
        reliability,
        groups: per_group.len(),
        unsampled: all
            .discrete
            .map(|d| (d.unsampled_patches, d.unsampled_area_fraction)),
        environment_area,
        jackknifed: replicates.is_some(),
    }
}

/// The delete-a-group jackknife's replicates: the run's values with each group's lines left out, from
/// the total's row sums lowered by that group's counts ([`Rows::without_group`]). `None` without pair
/// counts. Not for an enclosed scene (the environment patch's area is itself estimated from the lines)
/// nor for Chao–Shen (its second pass needs every count of the replicate): the caller checks.
fn jackknife_replicates(
    scene: &Scene,
    total: &Tally,
    groups: &[Tally],
    estimator: EntropyEstimator,
) -> Option<Vec<GroupValues>> {
    let total_counts = total.counts.as_ref()?;
    let a = channel::area_distribution(&areas(scene));
    let a = a.as_slice()?;
    let rows = Rows::gather(a, total_counts, &total.escapes_by_patch, estimator);
    groups
        .par_iter()
        .map(|g| {
            let counts = g.counts.as_ref()?;
            let left = rows.without_group(
                a,
                (total_counts, &total.escapes_by_patch),
                (counts, &g.escapes_by_patch),
            );
            Some(GroupValues {
                discrete: Some(visibility::discrete_from_rows(a, &left.sums)),
                // The counts are read only by Chao–Shen, excluded by the caller.
                corrected: Some(bias::corrected_from_rows(
                    a,
                    &left,
                    counts,
                    &g.escapes_by_patch,
                )),
                continuous: ContinuousValues::from_sum(
                    total.counters.cmi_sum.minus(g.counters.cmi_sum).value(),
                    total.counters.cmi_pairs - g.counters.cmi_pairs,
                ),
                environment_area: None,
                sampling: None,
                lines_factor: None,
            })
        })
        .collect()
}

/// Eq. (19), exact from the areas.
fn positional_entropy(areas: &[f64]) -> f64 {
    -channel::area_distribution(areas)
        .iter()
        .map(|&x| xlog2x(x))
        .sum::<f64>()
}

/// Every measure with its standard error: by the delete-a-group jackknife when the spread has
/// replicates, except I_s^c, a mean, whose batch-means error is exact; else, and for I_s^c, by batch
/// means.
fn estimates(areas: &[f64], spread: &Spread<GroupValues>, wanted: Wanted) -> VisibilityEstimates {
    let both = wanted.discrete && wanted.continuous;
    let est = |f: &dyn Fn(&GroupValues) -> Option<f64>| spread.estimate(f);
    VisibilityEstimates {
        positional_entropy: Some(Estimate::exact(positional_entropy(areas))),
        entropy: est(&|g| Some(g.discrete?.entropy)),
        entropy_corrected: est(&|g| Some(g.corrected?.entropy)),
        joint_entropy: est(&|g| Some(g.discrete?.joint_entropy)),
        mutual_information: est(&|g| Some(g.discrete?.mutual_information)),
        mutual_information_corrected: est(&|g| Some(g.corrected?.mutual_information)),
        continuous_mutual_information: spread
            .batch_means(|g| Some(g.continuous?.mutual_information)),
        accuracy: if both { est(&|g| g.accuracy()) } else { None },
        accuracy_corrected: if both {
            est(&|g| g.accuracy_corrected())
        } else {
            None
        },
        relative_error: if both {
            est(&|g| Some(1.0 - g.accuracy()?))
        } else {
            None
        },
        mse_per_line: est(&|g| Some(g.discrete?.mse_per_line)),
    }
}
