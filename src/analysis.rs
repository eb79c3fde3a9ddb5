//! One analysis run: lines -> hits -> pairs -> counts -> measures, with standard errors from groups.
//!
//! Lines come in batches (each with its own random stream, see [`crate::sample::lines`]). Batch `b`
//! belongs to group `b mod G`; every measure is computed on each group alone as well as on all lines, and
//! the spread of the group values gives the standard error ([`crate::measure::estimate`]). Because
//! membership depends on the batch index only, the groups fill up evenly however long a run lasts, so a
//! run can stop at any batch (a time budget, a precision target, Ctrl-C) and still has G comparable groups.
//!
//! A stopped run keeps the longest prefix of finished batches, so its lines are always batches `0..k`: the
//! same seed gives the same numbers for the same number of lines, whatever the thread count.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use crate::measure::bias::{self, CorrectedValues};
use crate::measure::channel;
use crate::measure::estimators::EntropyEstimator;
use crate::measure::rows::Rows;
use crate::measure::visibility::{self, ContinuousValues, DiscreteValues};
use crate::measure::Estimate;
use rayon::prelude::*;

use crate::sample::counts::PairCounts;
use crate::sample::environment;
use crate::sample::lines::LineSource;
use crate::sample::tally::{trace_batches, BatchPlan, Tally, TracedBatches, Wanted};
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// The most lines traced in one round (their pair keys are held until the round is counted).
const MAX_ROUND_LINES: u64 = 1 << 25;

/// Default number of independent groups of lines behind every standard error.
pub const DEFAULT_GROUPS: usize = 16;

/// The entropy estimator behind the bias-corrected H_s and I_s, chosen by measurement against the exact
/// I_s of `@cube:N` (README, "Error against run time").
pub const DEFAULT_ESTIMATOR: EntropyEstimator = EntropyEstimator::ChaoWangJost;

/// How the standard errors of the measures built from pair counts (H_s, I_s, H(X, Y), E(MSE), the
/// corrected values and the accuracies) are estimated (README, "Standard errors"). I_s^c, a mean, always
/// gets batch means, which are exact for it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ErrorMethod {
    /// Batch means: the spread of the G groups' own values / sqrt(G). Cheap, and conservative where the
    /// form-factor rows are undersampled (each group has 1/G of the lines).
    #[default]
    Groups,
    /// The delete-a-group jackknife: the spread of the G values with one group left out each. Closer to
    /// the real run-to-run scatter of undersampled measures (still conservative at the extreme), for about
    /// 15% more run time on a 5400-patch scene. Not for `--enclose` nor Chao–Shen: batch means there.
    Jackknife,
}

impl ErrorMethod {
    /// Every method with its name.
    pub const NAMES: [(&'static str, ErrorMethod); 2] = [
        ("groups", ErrorMethod::Groups),
        ("jackknife", ErrorMethod::Jackknife),
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            ErrorMethod::Groups => "groups",
            ErrorMethod::Jackknife => "jackknife",
        }
    }

    /// Parses a name as printed by [`ErrorMethod::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, m)| m)
    }
}

/// What to run.
#[derive(Clone, Copy, Debug)]
pub struct AnalysisConfig {
    /// Global lines to cast (a cap when a budget is set).
    pub lines: u64,
    /// Seed of the line streams.
    pub seed: u64,
    /// Which measures to gather.
    pub wanted: Wanted,
    /// Groups for the standard errors (see [`crate::measure::estimate`]).
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
}

impl AnalysisConfig {
    /// `lines` lines from `seed`, every measure, default groups and estimator, no budget.
    pub fn new(lines: u64, seed: u64) -> Self {
        AnalysisConfig {
            lines,
            seed,
            wanted: Wanted {
                discrete: true,
                continuous: true,
            },
            groups: DEFAULT_GROUPS,
            estimator: DEFAULT_ESTIMATOR,
            errors: ErrorMethod::Groups,
            budget: Budget::default(),
            source: LineSource::Independent,
            enclose: false,
        }
    }
}

/// Limits that end a run before its line count.
#[derive(Clone, Copy, Debug, Default)]
pub struct Budget {
    /// Stop when this much wall-clock time is spent.
    pub seconds: Option<f64>,
    /// Stop when a measure's standard error is this small.
    pub target: Option<Target>,
}

/// A precision target: run until `measure`'s standard error is at most `stderr`.
#[derive(Clone, Copy, Debug)]
pub struct Target {
    /// The measure watched.
    pub measure: TargetMeasure,
    /// The standard error to reach.
    pub stderr: f64,
}

/// A measure a precision target can watch (named as in the JSON report).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetMeasure {
    /// H_s, eq. (17).
    Entropy,
    /// I_s, eq. (21).
    MutualInformation,
    /// I_s^c, eq. (27).
    ContinuousMutualInformation,
    /// I_s / I_s^c.
    Accuracy,
}

impl TargetMeasure {
    /// Every target measure with its name.
    pub const NAMES: [(&'static str, TargetMeasure); 4] = [
        ("entropy", TargetMeasure::Entropy),
        ("mutual_information", TargetMeasure::MutualInformation),
        (
            "continuous_mutual_information",
            TargetMeasure::ContinuousMutualInformation,
        ),
        ("accuracy", TargetMeasure::Accuracy),
    ];

    /// Parses a name as in the JSON report (`mutual_information`).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, m)| m)
    }

    fn of(self, v: &VisibilityEstimates) -> Option<Estimate> {
        match self {
            TargetMeasure::Entropy => v.entropy,
            TargetMeasure::MutualInformation => v.mutual_information,
            TargetMeasure::ContinuousMutualInformation => v.continuous_mutual_information,
            TargetMeasure::Accuracy => v.accuracy,
        }
    }
}

/// Shared between a run and whoever watches it: a stop request (Ctrl-C) and a progress counter.
#[derive(Debug, Default)]
pub struct RunControl {
    stop: AtomicBool,
    lines_started: AtomicU64,
}

impl RunControl {
    /// Asks the run to stop; it finishes the batches under way and reports what it gathered.
    pub fn request_stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Lines whose tracing has started so far (for a progress display).
    pub fn lines_started(&self) -> u64 {
        self.lines_started.load(Ordering::Relaxed)
    }

    fn stop_requested(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }
}

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// All the requested lines were cast.
    Lines,
    /// The time budget was spent.
    Seconds,
    /// The precision target was reached.
    Target,
    /// A stop was requested (Ctrl-C).
    Interrupted,
}

impl StopReason {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            StopReason::Lines => "lines",
            StopReason::Seconds => "seconds",
            StopReason::Target => "target_stderr",
            StopReason::Interrupted => "interrupted",
        }
    }
}

/// The visibility measures of a run, each with its standard error; `None` when not computed.
#[derive(Clone, Debug, Default)]
pub struct VisibilityEstimates {
    /// Eq. (19), exact.
    pub positional_entropy: Option<Estimate>,
    /// Eq. (17), plug-in.
    pub entropy: Option<Estimate>,
    /// Eq. (17) with bias-corrected row entropies ([`crate::measure::bias`]).
    pub entropy_corrected: Option<Estimate>,
    /// H(X, Y).
    pub joint_entropy: Option<Estimate>,
    /// Eq. (21), plug-in.
    pub mutual_information: Option<Estimate>,
    /// Eq. (20) with the bias-corrected H_s.
    pub mutual_information_corrected: Option<Estimate>,
    /// Eq. (27).
    pub continuous_mutual_information: Option<Estimate>,
    /// Sec. 3.3: discretisation accuracy I_s / I_s^c (plug-in I_s).
    pub accuracy: Option<Estimate>,
    /// Sec. 3.3 with the bias-corrected I_s.
    pub accuracy_corrected: Option<Estimate>,
    /// Sec. 3.3: discretisation relative error (I_s^c - I_s) / I_s^c.
    pub relative_error: Option<Estimate>,
    /// Eq. (22), per line.
    pub mse_per_line: Option<Estimate>,
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
    /// The measures.
    pub visibility: VisibilityEstimates,
    /// The full-run counts, for form factors (when counted).
    pub tally: Tally,
}

/// Measures of one group (or of the whole run).
#[derive(Clone, Copy, Debug)]
struct GroupValues {
    discrete: Option<DiscreteValues>,
    corrected: Option<CorrectedValues>,
    continuous: Option<ContinuousValues>,
    /// The environment patch's area (tracing space), when enclosed.
    environment_area: Option<f64>,
}

impl GroupValues {
    /// The values of a tally; of the enclosed scene when `enclose` ([`environment::enclosed`]).
    fn of(scene: &Scene, t: &Tally, estimator: EntropyEstimator, enclose: bool) -> Self {
        if enclose {
            let (enclosed, areas) = environment::enclosed(scene, t);
            return GroupValues {
                environment_area: Some(environment::environment_area(scene, t)),
                ..GroupValues::plain(&areas, &enclosed, estimator)
            };
        }
        let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
        GroupValues::plain(&areas, t, estimator)
    }

    fn plain(areas: &[f64], t: &Tally, estimator: EntropyEstimator) -> Self {
        let counted = t.counts.as_ref().filter(|_| t.lines > 0);
        // One pass over the counts serves both the plug-in and the corrected measures.
        let (discrete, corrected) = counted
            .map(|c| {
                let a = channel::area_distribution(areas);
                let a = a.as_slice().expect("a fresh array is contiguous");
                let rows = Rows::gather(a, c, &t.escapes_by_patch, estimator);
                (
                    visibility::discrete_from_rows(a, &rows.sums),
                    bias::corrected_from_rows(a, &rows, c, &t.escapes_by_patch),
                )
            })
            .unzip();
        GroupValues {
            discrete,
            corrected,
            continuous: ContinuousValues::from_sum(t.cmi_sum, t.cmi_pairs),
            environment_area: None,
        }
    }

    fn accuracy(&self) -> Option<f64> {
        Some(self.discrete?.mutual_information / self.continuous?.mutual_information)
    }

    fn accuracy_corrected(&self) -> Option<f64> {
        Some(self.corrected?.mutual_information / self.continuous?.mutual_information)
    }
}

/// Runs an analysis with no one watching: casts `cfg.lines` global lines (or fewer, by the budget).
pub fn analyze(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &AnalysisConfig,
) -> Result<Analysis, TraceError> {
    analyze_with(scene, tracer, cfg, &RunControl::default())
}

/// Runs an analysis that `control` can watch and stop.
///
/// Uses the current rayon thread pool; results do not depend on its size.
pub fn analyze_with(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &AnalysisConfig,
    control: &RunControl,
) -> Result<Analysis, TraceError> {
    analyze_observed(scene, tracer, cfg, control, &mut |_| {})
}

/// [`analyze_with`], also handing each group's final tally to `each_group` (in group order), for
/// measures that need their own per-group values, such as the radiosity measures ([`crate::radiosity`]).
pub fn analyze_observed(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &AnalysisConfig,
    control: &RunControl,
    each_group: &mut dyn FnMut(&Tally),
) -> Result<Analysis, TraceError> {
    let start = Instant::now();
    let open_ended = cfg.budget.seconds.is_some() || cfg.budget.target.is_some();
    let plan = if open_ended {
        BatchPlan::open_ended(cfg.lines, cfg.source)
    } else {
        BatchPlan::for_source(cfg.lines, cfg.source)
    };
    let deadline = cfg
        .budget
        .seconds
        .map(|s| start + Duration::from_secs_f64(s.max(0.0)));
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
    let mut run = GroupedRun::new(scene, cfg, plan);

    let stop = |b: u64| {
        let late = deadline.is_some_and(|d| Instant::now() >= d);
        if control.stop_requested() || late {
            return true;
        }
        control
            .lines_started
            .fetch_add(plan.batch_len(b) as u64, Ordering::Relaxed);
        false
    };
    // Rounds bound the memory held in pair keys and let a budget run check itself; for a fixed run
    // their sizes depend on the line count only, so the numbers do too.
    let max_round = (MAX_ROUND_LINES / plan.batch_size).max(1);
    let mut round = if open_ended {
        (4 * run.groups()).max(64)
    } else {
        max_round
    };
    // Batches traced so far, and the last round's when it is not counted yet: without a precision target
    // the next round's size does not depend on the counts, so a round is counted while the next one is
    // traced, which keeps both cores busy through the counting's serial parts.
    let mut traced_to = 0;
    let mut pending: Option<TracedBatches> = None;
    let stop_reason = loop {
        let batches = traced_to..(traced_to + round).min(plan.batches());
        let trace = || {
            trace_batches(
                scene,
                tracer,
                &plan,
                cfg.source,
                cfg.seed,
                batches.clone(),
                cfg.wanted,
                &stop,
            )
        };
        let (traced, complete) = match pending.take() {
            Some(previous) => rayon::join(trace, || run.add(previous)).0?,
            None => trace()?,
        };
        traced_to += traced.len() as u64;
        let ended = if !complete {
            Some(if control.stop_requested() {
                StopReason::Interrupted
            } else {
                StopReason::Seconds
            })
        } else if traced_to >= plan.batches() {
            Some(StopReason::Lines)
        } else if deadline.is_some_and(|d| Instant::now() >= d) {
            Some(StopReason::Seconds)
        } else {
            None
        };
        if ended.is_some() || cfg.budget.target.is_some() {
            run.add(traced);
        } else {
            pending = Some(traced);
        }
        if let Some(reason) = ended {
            break reason;
        }
        if let Some(target) = cfg.budget.target {
            let se = run.current_stderr(&areas, cfg, target.measure);
            match se {
                Some(se) if se <= target.stderr => break StopReason::Target,
                // stderr ~ 1/sqrt(lines): aim 10% past the predicted need, at most doubling per round.
                Some(se) => {
                    let need = run.batches_done as f64 * (se / target.stderr).powi(2) * 1.1;
                    round = ((need as u64).saturating_sub(run.batches_done))
                        .clamp(1, run.batches_done.max(1));
                }
                None => round = run.batches_done.max(1),
            }
        } else {
            // Doubling: few rounds, and a time budget is checked before every batch anyway.
            round = traced_to.max(64);
        }
        round = round.min(max_round);
    };

    let Finished {
        total,
        all,
        per_group,
        replicates,
        enclose: enclosed,
    } = run.finish(cfg.estimator, cfg.errors, each_group);
    let jackknifed = replicates.is_some();
    let mut visibility = if total.lines == 0 {
        VisibilityEstimates {
            positional_entropy: Some(Estimate::exact(positional_entropy(&areas))),
            ..VisibilityEstimates::default()
        }
    } else {
        estimates(&areas, &all, &per_group, replicates.as_deref(), cfg.wanted)
    };
    let mut environment_area = None;
    if enclosed {
        // The environment's area is counted, so H_p has a spread over the groups too.
        visibility.positional_entropy = all.discrete.map(|d| {
            let per: Vec<f64> = per_group
                .iter()
                .filter_map(|g| Some(g.discrete?.positional_entropy))
                .collect();
            Estimate::from_groups(d.positional_entropy, &per)
        });
        let scale2 = scene.normalization.scale.powi(2);
        environment_area = all.environment_area.map(|a| {
            let per: Vec<f64> = per_group
                .iter()
                .filter_map(|g| g.environment_area)
                .collect();
            Estimate::from_groups(
                a * scale2,
                &per.iter().map(|a| a * scale2).collect::<Vec<_>>(),
            )
        });
    }
    Ok(Analysis {
        lines: total.lines,
        seed: cfg.seed,
        seconds: start.elapsed().as_secs_f64(),
        stop_reason,
        groups: per_group.len(),
        estimator: cfg.estimator,
        errors: if jackknifed {
            ErrorMethod::Jackknife
        } else {
            ErrorMethod::Groups
        },
        hits: total.hits,
        pairs: total.pairs,
        escapes: total.escapes,
        unpaired: total.unpaired,
        degenerate_pairs: total.degenerate_pairs,
        environment_area,
        distinct_pairs: total.counts.as_ref().map(|c| c.distinct_pairs()),
        unsampled: all
            .discrete
            .map(|d| (d.unsampled_patches, d.unsampled_area_fraction)),
        visibility,
        tally: total,
    })
}

/// The groups of a run as they fill up.
struct GroupedRun<'a> {
    scene: &'a Scene,
    wanted: Wanted,
    enclose: bool,
    groups: Vec<Option<Tally>>,
    /// With sparse counts, those of all the groups together (counted with the groups', so that the
    /// total needs no merging of the groups at the end).
    total_counts: Option<PairCounts>,
    batches_done: u64,
}

impl<'a> GroupedRun<'a> {
    fn new(scene: &'a Scene, cfg: &AnalysisConfig, plan: BatchPlan) -> Self {
        // A short fixed run has fewer batches than groups: one group per batch then.
        let groups = (cfg.groups.max(2) as u64).min(plan.batches().max(2)) as usize;
        GroupedRun {
            scene,
            wanted: cfg.wanted,
            enclose: cfg.enclose,
            groups: vec![None; groups],
            total_counts: None,
            batches_done: 0,
        }
    }

    fn groups(&self) -> u64 {
        self.groups.len() as u64
    }

    /// Adds traced batches (consecutive from `batches_done`) to their groups, counting the groups in
    /// parallel.
    fn add(&mut self, traced: TracedBatches) {
        let batches = traced.len() as u64;
        let (tallies, total_counts) =
            traced.into_group_tallies(self.scene, self.wanted, self.groups());
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

    /// The standard error of `measure` from the groups so far.
    fn current_stderr(
        &self,
        areas: &[f64],
        cfg: &AnalysisConfig,
        measure: TargetMeasure,
    ) -> Option<f64> {
        let filled: Vec<&Tally> = self.groups.iter().flatten().collect();
        let enclose = self.enclose && filled.iter().any(|t| t.escapes > 0);
        let values: Vec<GroupValues> = filled
            .par_iter()
            .map(|t| GroupValues::of(self.scene, t, cfg.estimator, enclose))
            .collect();
        // The total's value does not change the spread of the groups; any stand-in does.
        let stand_in = values.first()?;
        // Batch means while the run goes on (the jackknife needs the total's counts, which a dense run
        // merges only at the end): they are larger where they differ, so a target is never met early.
        measure
            .of(&estimates(areas, stand_in, &values, None, cfg.wanted))?
            .stderr
    }

    /// The merged total and its values, every non-empty group's values, the jackknife's
    /// leave-one-group-out values where it applies ([`jackknife_replicates`]), and whether they are those
    /// of the enclosed scene (`--enclose`, and something escaped).
    fn finish(
        self,
        estimator: EntropyEstimator,
        errors: ErrorMethod,
        each_group: &mut dyn FnMut(&Tally),
    ) -> Finished {
        let filled: Vec<Tally> = self.groups.into_iter().flatten().collect();
        filled.iter().for_each(&mut *each_group);
        let enclose = self.enclose && filled.iter().any(|t| t.escapes > 0);
        let scene = self.scene;
        let values_of = |t: &Tally| GroupValues::of(scene, t, estimator, enclose);
        // The sums merge in a fixed tree; the counts are integers, added in any order: the sparse ones
        // were counted with the groups', the dense ones are added up here.
        let sums = filled.iter().map(Tally::without_counts).collect();
        let mut total = merge_tree(sums).unwrap_or_else(|| Tally::empty(scene, self.wanted));
        total.counts = self.total_counts.or_else(|| dense_total(&filled));
        let (all, per_group) = rayon::join(
            || values_of(&total),
            || filled.par_iter().map(values_of).collect(),
        );
        let replicates = (errors == ErrorMethod::Jackknife)
            .then(|| jackknife_replicates(scene, &total, &filled, estimator, enclose))
            .flatten();
        Finished {
            total,
            all,
            per_group,
            replicates,
            enclose,
        }
    }
}

/// What a run's groups come to (see [`GroupedRun::finish`]).
struct Finished {
    total: Tally,
    all: GroupValues,
    per_group: Vec<GroupValues>,
    replicates: Option<Vec<GroupValues>>,
    enclose: bool,
}

/// The sum of the groups' dense counts (`None` without counts).
fn dense_total(groups: &[Tally]) -> Option<PairCounts> {
    let mut counts = groups.iter().filter_map(|t| t.counts.as_ref());
    let mut total = counts.next()?.clone();
    counts.for_each(|c| total.merge(c));
    Some(total)
}

/// The delete-a-group jackknife's replicates: the run's values with each group's lines left out, from
/// the total's row sums lowered by that group's counts ([`Rows::without_group`]). `None` where they
/// are not formed so: without pair counts, for an enclosed scene (the environment patch's area is itself
/// estimated from the lines), and for Chao–Shen (its second pass needs every count of the replicate).
fn jackknife_replicates(
    scene: &Scene,
    total: &Tally,
    groups: &[Tally],
    estimator: EntropyEstimator,
    enclose: bool,
) -> Option<Vec<GroupValues>> {
    if enclose || estimator == EntropyEstimator::ChaoShen || groups.len() < 2 {
        return None;
    }
    let total_counts = total.counts.as_ref()?;
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
    let a = channel::area_distribution(&areas);
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
                // The counts are read only by Chao–Shen, excluded above.
                corrected: Some(bias::corrected_from_rows(
                    a,
                    &left,
                    counts,
                    &g.escapes_by_patch,
                )),
                continuous: ContinuousValues::from_sum(
                    total.cmi_sum - g.cmi_sum,
                    total.cmi_pairs - g.cmi_pairs,
                ),
                environment_area: None,
            })
        })
        .collect()
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

fn positional_entropy(areas: &[f64]) -> f64 {
    -channel::area_distribution(areas)
        .iter()
        .map(|&x| crate::measure::entropy::xlog2x(x))
        .sum::<f64>()
}

/// Every measure with its standard error: by the delete-a-group jackknife when `replicates` (the values
/// with each group left out) are given, except I_s^c, a mean, whose batch-means error is exact; else,
/// and for I_s^c, by batch means of the `groups`' values.
fn estimates(
    areas: &[f64],
    all: &GroupValues,
    groups: &[GroupValues],
    replicates: Option<&[GroupValues]>,
    wanted: Wanted,
) -> VisibilityEstimates {
    let batch_means = |f: &dyn Fn(&GroupValues) -> Option<f64>| -> Option<Estimate> {
        let value = f(all)?;
        let per: Vec<f64> = groups.iter().filter_map(f).collect();
        Some(if per.len() == groups.len() {
            Estimate::from_groups(value, &per)
        } else {
            Estimate {
                value,
                stderr: None,
            }
        })
    };
    let est = |f: &dyn Fn(&GroupValues) -> Option<f64>| -> Option<Estimate> {
        let value = f(all)?;
        let jackknife = replicates.and_then(|reps| {
            let per: Vec<f64> = reps.iter().filter_map(f).collect();
            (per.len() == reps.len()).then(|| Estimate::from_jackknife(value, &per))
        });
        jackknife.or_else(|| batch_means(f))
    };
    let both = wanted.discrete && wanted.continuous;
    VisibilityEstimates {
        positional_entropy: Some(Estimate::exact(positional_entropy(areas))),
        entropy: est(&|g| Some(g.discrete?.entropy)),
        entropy_corrected: est(&|g| Some(g.corrected?.entropy)),
        joint_entropy: est(&|g| Some(g.discrete?.joint_entropy)),
        mutual_information: est(&|g| Some(g.discrete?.mutual_information)),
        mutual_information_corrected: est(&|g| Some(g.corrected?.mutual_information)),
        continuous_mutual_information: batch_means(&|g| Some(g.continuous?.mutual_information)),
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
