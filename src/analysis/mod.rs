//! What is computed from a run: every measure with its standard error and verdict, the radiosity
//! measures, the per-patch results and the warnings.
//!
//! [`analyze`] is the one entry point, for the visibility measures (paper sec. 3) and, when the scene
//! emits, the radiosity measures (sec. 4): it casts the run's lines with the engine ([`crate::run`])
//! and [`finish`]es it, computing every measure on the whole run and on each group
//! ([`crate::run::Spread`]).

pub mod object_results;
mod orientation;
pub mod patch_results;
pub mod radiosity;
pub mod reliability;
mod values;
pub mod warnings;

use std::time::Instant;

pub use object_results::{ObjectResult, ENVIRONMENT};
pub use patch_results::{PatchLight, PatchResult};
pub use radiosity::{RadiosityOutcome, RadiositySolve, SolveFailure, NOTHING_EMITS};
pub use reliability::{
    HalfRun, LinesAdvice, Reliability, SamplingReport, Verdict, ADVICE_SETTLED_GROWTH, COVERAGE_OK,
    COVERAGE_UNUSABLE, MIN_PAIRS,
};
pub use warnings::{RunWarning, RunWarningKind};

use patch_results as per_patch;
use values::{visibility_estimates, Replication, VisibilityOfRun};

use crate::measure::estimators::EntropyEstimator;
use crate::measure::radiosity::{MaterialError, PatchMaterials};
use crate::measure::{student_t_975, ByMeasure, Estimate, Measure};
use crate::run::{
    BatchPlan, BatchSet, CastHooks, CastOptions, ErrorMethod, FinishedRun, RunControl, RunSpec,
    RunState, SpecError, StartError, StopReason, TargetReading,
};
use crate::sample::bounds::{sphere_lines, sphere_lines_for_drawn};
use crate::sample::lines::{LineSource, Sampler};
use crate::sample::tally::{ObjectSides, Tally, Wanted};
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// Why an analysis failed.
#[derive(Debug, thiserror::Error)]
pub enum AnalysisError {
    /// A material outside the physical range (bad input), found before any line is cast.
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// Settings of the run that contradict each other (bad input), found before any line is cast.
    #[error(transparent)]
    Spec(#[from] SpecError),
    /// The radiosity system has no solution, or the solver gave up (bad input: the materials).
    #[error(transparent)]
    Solve(#[from] SolveFailure),
    /// Tracing failed.
    #[error(transparent)]
    Trace(#[from] TraceError),
}

impl From<StartError> for AnalysisError {
    fn from(e: StartError) -> Self {
        match e {
            StartError::Material(e) => AnalysisError::Material(e),
            StartError::Spec(e) => AnalysisError::Spec(e),
        }
    }
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
    /// What the run was asked to be (its seed, measures, estimator, ...).
    pub spec: RunSpec,
    /// Lines cast: those drawn, through the spec's bound (fewer than the sphere's lines asked through a box
    /// or polytope smaller than the sphere; [`crate::sample::bounds::sphere_lines_of_drawn`]).
    pub lines: u64,
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
    /// Of them, segments from a front side to a back side: absorbed, they count in their rows as escapes
    /// do (0 in a consistently oriented closed scene).
    pub absorbed: u64,
    /// Pairs with coincident points, left out of eq. (27).
    pub degenerate_pairs: u64,
    /// Distinct patch pairs seen (when counted).
    pub distinct_pairs: Option<usize>,
    /// Patches no segment left from, and their area fraction (when counted).
    pub unsampled: Option<(usize, f64)>,
    /// With `--enclose` when something escaped: the environment patch's area in scene units (see
    /// [`crate::sample::environment`]); `None` otherwise.
    pub environment_area: Option<Estimate>,
    /// Whether the measures are those of the enclosed scene (`--enclose` on a scene lines escaped):
    /// the environment is then patch `patches` of the per-patch results and of the form factors
    /// ([`Tally::enclosed`]).
    pub enclosed: bool,
    /// Every reading with its standard error, by measure ([`Measure`]): the visibility measures and,
    /// when computed, the radiosity measures; `None` for a measure not computed.
    pub estimates: ByMeasure<Estimate>,
    /// How well the lines sampled the rows of F (when the discrete measures were counted).
    pub sampling: Option<SamplingReport>,
    /// The verdict on every reading that has one (all but the exact ones).
    pub reliability: ByMeasure<Reliability>,
    /// The precision target, when there was one, and whether it was met.
    pub target: Option<TargetOutcome>,
    /// The radiosity solution's figures, or why there are no radiosity measures.
    pub radiosity: RadiosityOutcome,
    /// What the user must know about these numbers (an open scene, unsampled patches, ...).
    pub warnings: Vec<RunWarning>,
    /// Per object of the scene: how lines met its sides (the evidence behind the orientation warnings).
    pub orientation: Vec<ObjectSides>,
    /// The full-run counts, for form factors (when counted).
    pub tally: Tally,
    /// Each patch's results, with standard errors, when [`RunSpec::per_patch`] asked for them; for an
    /// enclosed open scene those of the enclosed scene, the environment's after the scene's patches
    /// ([`patch_results`]).
    pub patches: Option<Vec<PatchResult>>,
    /// Each object's results ([`ObjectResult`]): what it is and how its sides were met always, its
    /// segments when the pairs were counted, and its share of the measures with per-patch results
    /// (with the environment's object last when those are an enclosed scene's).
    pub objects: Vec<ObjectResult>,
}

impl Analysis {
    /// The reading of `measure` with its standard error (`None`: not computed).
    pub fn estimate(&self, measure: Measure) -> Option<Estimate> {
        self.estimates.get(measure).copied()
    }

    /// The verdict on the reading of `measure` (`None`: no reading, or an exact one).
    pub fn verdict(&self, measure: Measure) -> Option<Verdict> {
        self.reliability.get(measure).map(|r| r.verdict)
    }

    /// The half-width of the 95% interval in standard errors: Student's t quantile for the groups less
    /// one degrees of freedom ([`student_t_975`]).
    pub fn interval_quantile(&self) -> f64 {
        student_t_975(self.groups.saturating_sub(1))
    }

    /// The 95% interval of the reading of `measure`: value ± [`Analysis::interval_quantile`] stderr
    /// (`None`: no reading or no standard error). A reading marked ok is one whose interval covers the
    /// exact value in 95% of runs (docs/calibration.md measures it).
    pub fn interval_95(&self, measure: Measure) -> Option<(f64, f64)> {
        self.estimate(measure)?.interval(self.interval_quantile())
    }

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

    /// The fraction of the segments leaving a front side that arrive at a back side and are absorbed
    /// (`None` without segments).
    pub fn absorbed_fraction(&self) -> Option<f64> {
        let c = &self.tally.counters;
        let segments = c.pairs + c.escapes + c.absorbed;
        (segments > 0).then(|| c.absorbed as f64 / segments as f64)
    }
}

/// A precision target at the end of a run: met only when the standard error is small enough *and* the
/// reading is reliable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetOutcome {
    /// The measure watched.
    pub measure: Measure,
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

/// Runs an analysis that `control` can watch and stop: casts `cfg.lines` global lines (or fewer, by the
/// budget) and computes the measures `cfg.measures` asks for, each with its standard error.
///
/// With radiosity asked for, the materials are checked before any line is cast; when nothing emits the
/// radiosity measures are left out with the reason. Uses the current rayon thread pool; results do not
/// depend on its size. [`crate::run::start`], [`cast`] and [`finish`] are its three steps, for runs that are
/// sharded, checkpointed or resumed.
pub fn analyze(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &RunSpec,
    control: &RunControl,
) -> Result<Analysis, AnalysisError> {
    let started = Instant::now();
    let mut state = crate::run::start(scene, cfg)?;
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

/// Casts the batches of `options.scope` not done yet in `state` (the engine's `run::cast`), stopping early
/// when the run's precision target is met; `after_round` sees the state after each round (to save a
/// checkpoint).
pub fn cast(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &RunSpec,
    state: &mut RunState,
    options: CastOptions,
    control: &RunControl,
    after_round: &mut dyn FnMut(&RunState),
) -> Result<StopReason, TraceError> {
    let watch = |state: &RunState| match cfg.budget.target {
        Some(target) => current_reading(scene, state, cfg, target.measure),
        None => TargetReading {
            stderr: None,
            reliable: false,
            floored: false,
        },
    };
    crate::run::cast(
        scene,
        tracer,
        cfg,
        state,
        options,
        control,
        CastHooks {
            target: Some(&watch),
            after_round,
        },
    )
}

/// The measures of a run's state: every reading with its standard error and verdict, the radiosity
/// measures when the scene emits, and the warnings. `seconds` is the run's time before its measures;
/// the report's [`Analysis::seconds`] adds the time they take here (summing the groups into the run's
/// total and estimating from them is part of what a user waits for).
pub fn finish(
    scene: &Scene,
    cfg: &RunSpec,
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
    let (visibility, enclose) = judged_visibility(scene, &run, cfg, wanted);
    let target = cfg.budget.target.map(|t| TargetOutcome {
        measure: t.measure,
        stderr_goal: t.stderr,
        stderr: visibility.estimates.get(t.measure).and_then(|e| e.stderr),
        verdict: visibility.reliability.get(t.measure).map(|r| r.verdict),
    });
    let (radiosity, radiosity_readings) = match &materials {
        None => (RadiosityOutcome::NotRequested, None),
        Some(_) if !lit => (
            RadiosityOutcome::Skipped(radiosity::NOTHING_EMITS.into()),
            None,
        ),
        Some(m) => radiosity::estimates(
            scene,
            m,
            &run,
            &cfg.solve,
            cfg.estimator,
            (visibility.jackknifed, visibility.debiased),
            visibility
                .sampling
                .as_ref()
                .expect("radiosity counts the pairs"),
        )?,
    };
    let patches = cfg
        .per_patch
        .then(|| {
            let light = materials.as_ref().filter(|_| lit).map(|m| PatchLight {
                materials: m,
                solve: &cfg.solve,
            });
            per_patch::estimates(scene, &run, cfg.estimator, light, enclose)
        })
        .flatten();
    let (patches, object_values) = patches.unzip();
    let FinishedRun { total, .. } = run;
    // The environment is an object of its own beside the enclosed scene's per-patch results.
    let environment = (enclose && patches.is_some()).then(|| total.environment_area(scene));
    let objects = object_results::of_run(scene, &total, object_values, environment);
    let mut warnings = warnings::of_run(
        &scene.name,
        &total.counters,
        visibility.unsampled,
        visibility.environment_area,
    );
    warnings.extend(orientation::warnings(scene, &total, enclose));
    warnings.extend(warnings::fewer_groups(
        &scene.name,
        (cfg.groups.max(2), visibility.groups),
        covered.len(),
        || {
            let drawn = BatchPlan::lines_for_batches(
                cfg.groups.max(2) as u64,
                cfg.source,
                cfg.budget.is_open_ended(),
            );
            sphere_lines_for_drawn(scene, cfg.bound, drawn)
        },
    ));
    let closed = total.counters.escapes == 0 && total.counters.pairs > 0;
    warnings.extend(
        patches
            .as_deref()
            .and_then(|p| warnings::negative_lost_information(&scene.name, p, closed)),
    );
    let mut visibility = visibility;
    if total.counters.pairs == 0 && !enclose {
        // No pair: only H_p (exact, from the areas) is defined; zeros would read as measurements.
        let kept = visibility
            .estimates
            .get(Measure::PositionalEntropy)
            .copied();
        visibility.estimates = ByMeasure::default();
        visibility.estimates.set(Measure::PositionalEntropy, kept);
        // Nor has an undefined reading a verdict, nor lines to advise.
        let exact = visibility
            .reliability
            .get(Measure::PositionalEntropy)
            .cloned();
        visibility.reliability = ByMeasure::default();
        visibility
            .reliability
            .set(Measure::PositionalEntropy, exact);
    }
    let (mut estimates, mut reliability) = (visibility.estimates, visibility.reliability);
    if let Some(r) = &radiosity_readings {
        for (m, e) in r.estimates.iter() {
            estimates.set(m, Some(*e));
        }
        let mut verdicts = r.reliability.clone();
        if cfg.sampler == Sampler::Sobol && !visibility.debiased {
            reliability::flag_dependent_lines(&mut verdicts);
        }
        for (m, v) in verdicts.iter() {
            reliability.set(m, Some(v.clone()));
        }
    }
    Ok(Analysis {
        spec: cfg.clone(),
        lines: total.counters.lines,
        seconds: seconds + began.elapsed().as_secs_f64(),
        stop_reason,
        plan,
        covered,
        groups: visibility.groups,
        errors: if visibility.jackknifed {
            ErrorMethod::Jackknife
        } else {
            ErrorMethod::Groups
        },
        hits: total.counters.hits,
        pairs: total.counters.pairs,
        escapes: total.counters.escapes,
        unpaired: total.counters.unpaired,
        absorbed: total.counters.absorbed,
        degenerate_pairs: total.counters.degenerate_pairs,
        environment_area: visibility.environment_area,
        enclosed: enclose,
        distinct_pairs: total.counts.as_ref().map(|c| c.distinct_pairs()),
        unsampled: visibility.unsampled,
        estimates,
        sampling: visibility.sampling,
        reliability,
        target,
        radiosity,
        warnings,
        orientation: total.orientation.clone(),
        tally: total,
        patches,
        objects,
    })
}

/// The visibility measures of a run and their verdicts, as both the finished run and a precision
/// target's checks judge them; and whether the run is enclosed (`--enclose` on a scene lines escaped).
fn judged_visibility(
    scene: &Scene,
    run: &FinishedRun,
    cfg: &RunSpec,
    wanted: Wanted,
) -> (VisibilityOfRun, bool) {
    let enclose = cfg.enclose && run.groups.iter().any(|t| t.counters.escapes > 0);
    let replication = replication(cfg, run, enclose);
    let worth = sphere_lines(scene, cfg.bound, 1);
    let v = visibility_estimates(
        scene,
        run,
        cfg.estimator,
        enclose,
        replication,
        wanted,
        worth,
    );
    (v, enclose)
}

/// Whether a run's delete-a-group replicates can be computed (for the bias estimates behind the
/// verdicts), whether they also give the standard errors (`--errors jackknife`), and whether they
/// debias the readings on corrected rows (the Sobol' sampler). Not with `--enclose` nor Chao–Shen (its
/// second pass needs every count of the replicate), and not with fewer than 2 groups.
fn replication(cfg: &RunSpec, run: &FinishedRun, enclose: bool) -> Replication {
    let replicable =
        !enclose && cfg.estimator != EntropyEstimator::ChaoShen && run.groups.len() >= 2;
    Replication {
        replicable,
        jackknife: replicable && cfg.errors == ErrorMethod::Jackknife,
        debias: cfg.sampler == Sampler::Sobol,
        dependent_lines: cfg.sampler == Sampler::Sobol
            || matches!(cfg.source, LineSource::Bundles { .. }),
    }
}

/// The standard error of `measure` and the verdict on its reading, from the run so far, judged as the
/// finished run's will be (the same errors and bias estimates).
fn current_reading(
    scene: &Scene,
    state: &RunState,
    cfg: &RunSpec,
    measure: Measure,
) -> TargetReading {
    let run = state.snapshot(scene);
    let (v, _) = judged_visibility(scene, &run, cfg, state.wanted());
    let stderr = v.estimates.get(measure).and_then(|e| e.stderr);
    let c = &run.total.counters;
    let floor = reliability::f32_floor(c.pairs, c.short_chords);
    TargetReading {
        stderr,
        reliable: v.reliability.get(measure).map(|r| r.verdict) == Some(Verdict::Ok),
        floored: measure == Measure::ContinuousMutualInformation
            && stderr.is_some_and(|se| reliability::below_f32_floor(floor, se)),
    }
}
