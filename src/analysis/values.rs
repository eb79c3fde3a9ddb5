//! The values of every measure on a run's whole lines, on each of its groups and, for the jackknife, on
//! its lines with each group left out; and the estimates with standard errors made from them.

use rayon::prelude::*;

use super::reliability::{self, HalfRun, Reliability, RunFacts, SamplingReport, COVERAGE_OK};
use crate::measure::bias::{self, CorrectedValues};
use crate::measure::catalogue::VerdictRule;
use crate::measure::channel;
use crate::measure::entropy::xlog2x;
use crate::measure::estimators::EntropyEstimator;
use crate::measure::rows::Rows;
use crate::measure::sampling::{lines_factor_for_coverage, Sampling};
use crate::measure::visibility::{self, ContinuousValues, DiscreteValues};
use crate::measure::{ByMeasure, Estimate, Family, Measure};
use crate::run::{FinishedRun, Spread};
use crate::sample::tally::{Counters, Tally, Wanted};
use crate::scene::Scene;

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
                ..GroupValues::plain(
                    &areas,
                    &enclosed,
                    estimator,
                    extrapolate,
                    scene.patch_count(),
                )
            };
        }
        GroupValues::plain(
            &areas(scene),
            t,
            estimator,
            extrapolate,
            scene.patch_count(),
        )
    }

    /// The values of a tally over patches of `areas`, of which the first `scene_rows` are the scene's
    /// own (the rest, the environment of an enclosed scene, is left out of the sampling report: its
    /// row, huge in area and segments, would stand for the scene's rows in the area-weighted means).
    fn plain(
        areas: &[f64],
        t: &Tally,
        estimator: EntropyEstimator,
        extrapolate: bool,
        scene_rows: usize,
    ) -> Self {
        let mut values = GroupValues {
            discrete: None,
            corrected: None,
            continuous: ContinuousValues::from_sum(
                t.counters.cmi_sum.value(),
                t.counters.cmi_pairs,
                lost(&t.counters),
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
        let lost = t.lost_by_patch();
        let rows = Rows::gather(a, c, &lost, estimator);
        values.discrete = Some(visibility::discrete_from_rows(a, &rows.sums));
        values.corrected = Some(bias::corrected_from_rows(a, &rows, c, &lost));
        let own = scene_rows.min(a.len());
        values.sampling = Some(Sampling::of_rows(&a[..own], &rows.sums[..own]));
        if extrapolate {
            values.lines_factor =
                lines_factor_for_coverage(&a[..own], &rows.sums[..own], COVERAGE_OK);
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

/// The segments that left a front side and arrived at no front side: escapes, and segments absorbed at
/// back sides (eq. (27)'s estimate counts them, [`ContinuousValues::from_sum`]).
fn lost(c: &Counters) -> u64 {
    c.escapes + c.absorbed
}

fn areas(scene: &Scene) -> Vec<f64> {
    scene.patches.iter().map(|p| p.area).collect()
}

/// The visibility side of a finished run.
pub(super) struct VisibilityOfRun {
    pub(super) estimates: ByMeasure<Estimate>,
    /// The groups with lines.
    pub(super) groups: usize,
    /// Patches no segment left, and their area fraction (when counted).
    pub(super) unsampled: Option<(usize, f64)>,
    /// The environment's area in scene units, when enclosed.
    pub(super) environment_area: Option<Estimate>,
    /// Whether the standard errors came from the jackknife.
    pub(super) jackknifed: bool,
    /// Whether the readings on corrected rows are the jackknife's debiased ones (Sobol' lines).
    pub(super) debiased: bool,
    /// How the rows were sampled (when counted).
    pub(super) sampling: Option<SamplingReport>,
    /// The verdict on every reading.
    pub(super) reliability: ByMeasure<Reliability>,
}

/// How a run uses its delete-a-group replicates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Replication {
    /// They can be computed (not with `--enclose`, Chao–Shen or fewer than 2 groups).
    pub(super) replicable: bool,
    /// They give the standard errors (`--errors jackknife`).
    pub(super) jackknife: bool,
    /// The lines within a group are not independent (the Sobol' sampler): the readings that rest on
    /// corrected rows ([`Measure::rests_on_corrected_rows`]) are the jackknife's bias-corrected ones
    /// ([`Spread::debiased`]), since the entropy estimators' corrections assume independent lines.
    pub(super) debias: bool,
    /// The lines within a group are not independent (Sobol' lines, or bundles): the plug-in E(MSE)'s
    /// bias is the jackknife's estimate when there are replicates, not the multinomial formula's
    /// (with 8 x 8 bundles on `@cube:4` at 1e5 lines that formula made 37 readings of 100 `ok`, of
    /// which 30 covered).
    pub(super) dependent_lines: bool,
}

/// Every visibility measure of a finished run with its standard error (by the jackknife when asked and
/// possible), and the environment's area when enclosed. The delete-a-group replicates are computed
/// whenever they can be (`replicable`) and the rows are covered well enough for an `ok` corrected
/// reading, for the bias estimates behind its verdict, or the readings on corrected rows are to be
/// debiased; `jackknife` says whether they also give the standard errors (and are then always
/// computed).
pub(super) fn visibility_estimates(
    scene: &Scene,
    run: &FinishedRun,
    estimator: EntropyEstimator,
    enclose: bool,
    rep: Replication,
    wanted: Wanted,
    worth: f64,
) -> VisibilityOfRun {
    let Replication {
        replicable,
        jackknife,
        debias,
        dependent_lines,
    } = rep;
    let values_of = |t: &Tally| GroupValues::of(scene, t, estimator, enclose, false);
    let (all, per_group): (GroupValues, Vec<GroupValues>) = if rows_in_parallel(scene) {
        rayon::join(
            || GroupValues::of(scene, &run.total, estimator, enclose, true),
            || run.groups.par_iter().map(values_of).collect(),
        )
    } else {
        (
            GroupValues::of(scene, &run.total, estimator, enclose, true),
            run.groups.iter().map(values_of).collect(),
        )
    };
    // Below the coverage of an ok verdict the bias changes no verdict: the replicates cost only then.
    let covered = all.sampling.is_some_and(|s| s.coverage >= COVERAGE_OK);
    let replicates = (jackknife || (replicable && (covered || debias)))
        .then(|| jackknife_replicates(scene, &run.total, &run.groups, estimator))
        .flatten();
    let debiased = |m: Measure| debias && replicates.is_some() && m.rests_on_corrected_rows();
    let areas = areas(scene);
    let with_replicates = Spread {
        all: &all,
        groups: &per_group,
        replicates: replicates.as_deref(),
    };
    let spread = Spread {
        replicates: replicates.as_deref().filter(|_| jackknife),
        ..with_replicates
    };
    // The bias estimate behind a corrected reading's verdict: the jackknife's estimate of its bias; for a
    // debiased reading, whose first-order bias is gone, its distance to the debiased plug-in reading
    // (both free of the 1 / lines term, they part where the higher terms are not small: rows sampled too
    // thinly for either to be trusted). With Sobol' lines the jackknife also estimates E(MSE)'s bias,
    // which the multinomial formula overstates.
    let bias = ByMeasure::from_fn(|m| {
        let info = m.info();
        if info.family != Family::Visibility {
            return None;
        }
        let jackknife = |m: Measure| with_replicates.jackknife_bias(|g| value_of(m, g));
        match info.verdict {
            VerdictRule::Corrected | VerdictRule::UnbiasedEstimate if debiased(m) => {
                let debiased_value = |m: Measure| with_replicates.debiased(|g| value_of(m, g));
                Some(debiased_value(m)?.value - debiased_value(plug_in_of(m)?)?.value)
            }
            VerdictRule::Corrected | VerdictRule::UnbiasedEstimate => jackknife(m),
            VerdictRule::Unbiased if dependent_lines => jackknife(m),
            _ => None,
        }
    });
    let mut estimates = if run.total.counters.lines == 0 {
        exact_only(&areas)
    } else {
        estimates(&areas, &spread, wanted)
    };
    for m in Measure::of_family(Family::Visibility).filter(|&m| debiased(m)) {
        if let Some(e) = with_replicates.debiased(|g| value_of(m, g)) {
            estimates.set(m, Some(e));
        }
    }
    let mut environment_area = None;
    if enclose {
        // The environment's area is counted, so H_p has a spread over the groups too.
        estimates.set(
            Measure::PositionalEntropy,
            spread.batch_means(|g| Some(g.discrete?.positional_entropy)),
        );
        let scale2 = scene.normalization.scale.powi(2);
        environment_area = spread.batch_means(|g| Some(g.environment_area? * scale2));
    }
    // The lines advice counts lines as `--lines` does, through the sphere: `worth` of them per line drawn.
    let lines = run.total.counters.lines;
    let sphere_lines = (lines as f64 * worth).round() as u64;
    let sampling = all.sampling.map(|sampling| {
        let lines_for_coverage = all.lines_factor.map(|k| lines_for(k, lines, worth));
        // From half the lines only when there is advice to check.
        let half = match all.lines_factor {
            Some(k) if k > 1.0 => {
                half_run_lines_for_coverage(scene, run, estimator, enclose, worth)
            }
            _ => HalfRun::NotComputed,
        };
        SamplingReport::new(sampling, sphere_lines, lines_for_coverage, half)
    });
    let c = &run.total.counters;
    let facts = RunFacts {
        lines: sphere_lines,
        // Enclosed, the escapes are pairs with the environment (I_s^c has their terms too), and only back
        // sides still lose segments.
        pairs: if enclose {
            c.pairs + c.escapes
        } else {
            c.pairs
        },
        open: c.absorbed > 0 || (c.escapes > 0 && !enclose),
        short_chords: c.short_chords,
        jackknifed: spread.replicates.is_some(),
    };
    let mut reliability = reliability::verdicts(&estimates, sampling.as_ref(), Some(&bias), facts);
    if debias && replicates.is_none() {
        reliability::flag_dependent_lines(&mut reliability);
    }
    VisibilityOfRun {
        estimates,
        sampling,
        reliability,
        groups: per_group.len(),
        unsampled: all
            .discrete
            .map(|d| (d.unsampled_patches, d.unsampled_area_fraction)),
        environment_area,
        jackknifed: spread.replicates.is_some(),
        debiased: debias && replicates.is_some(),
    }
}

/// The plug-in reading a corrected visibility reading corrects.
fn plug_in_of(m: Measure) -> Option<Measure> {
    match m {
        Measure::EntropyCorrected => Some(Measure::Entropy),
        Measure::MutualInformationCorrected => Some(Measure::MutualInformation),
        _ => None,
    }
}

/// The lines in all for a factor `k` on a run of `lines` lines drawn, each worth `worth` lines through
/// the sphere (1 for the sphere's own), in the sphere's lines.
fn lines_for(k: f64, lines: u64, worth: f64) -> u64 {
    (k * lines as f64 * worth).ceil() as u64
}

/// The lines for a coverage of [`COVERAGE_OK`] extrapolated from the first half of the groups alone (a
/// run of about half the lines: the groups are independent replicates, and the first half of them is
/// the same whatever the threads, shards or resumes), to see whether the whole run's extrapolation has
/// settled ([`SamplingReport::advice`]). Not computed with fewer than 2 groups or without pair counts.
fn half_run_lines_for_coverage(
    scene: &Scene,
    run: &FinishedRun,
    estimator: EntropyEstimator,
    enclose: bool,
    worth: f64,
) -> HalfRun {
    let (Some(counts), Some((first, rest))) = (
        run.first_half.as_ref(),
        run.groups[..run.groups.len() / 2].split_first(),
    ) else {
        return HalfRun::NotComputed;
    };
    // The per-patch sums of eq. (27) play no part in the coverage.
    let mut half = Tally {
        counters: first.counters,
        orientation: first.orientation.clone(),
        escapes_by_patch: first.escapes_by_patch.clone(),
        absorbed_by_patch: first.absorbed_by_patch.clone(),
        counts: None,
        kernel_by_patch: None,
    };
    for g in rest {
        half.merge(g);
    }
    let factor = if enclose {
        half.counts = Some(counts.clone());
        GroupValues::of(scene, &half, estimator, enclose, true).lines_factor
    } else {
        // Only the rows' integer sums: the same coverage as every sum's, read from the half's counts
        // where they are.
        let a = channel::area_distribution(&areas(scene));
        let a = a.as_slice().expect("a fresh array is contiguous");
        let rows = Rows::outcome_frequencies(a.len(), counts, &half.lost_by_patch());
        lines_factor_for_coverage(a, &rows, COVERAGE_OK)
    };
    match factor {
        Some(k) => HalfRun::Lines(lines_for(k, half.counters.lines, worth)),
        None => HalfRun::BeyondReach,
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
    let total_lost = total.lost_by_patch();
    let rows = Rows::gather(a, total_counts, &total_lost, estimator);
    let replicate = |g: &Tally| {
        let counts = g.counts.as_ref()?;
        let group_lost = g.lost_by_patch();
        let left = rows.without_group(a, (total_counts, &total_lost), (counts, &group_lost));
        Some(GroupValues {
            discrete: Some(visibility::discrete_from_rows(a, &left.sums)),
            // The counts are read only by Chao–Shen, excluded by the caller.
            corrected: Some(bias::corrected_from_rows(a, &left, counts, &group_lost)),
            continuous: ContinuousValues::from_sum(
                total.counters.cmi_sum.minus(g.counters.cmi_sum).value(),
                total.counters.cmi_pairs - g.counters.cmi_pairs,
                lost(&total.counters) - lost(&g.counters),
            ),
            environment_area: None,
            sampling: None,
            lines_factor: None,
        })
    };
    if rows_in_parallel(scene) {
        groups.par_iter().map(replicate).collect()
    } else {
        groups.iter().map(replicate).collect()
    }
}

/// Scenes with at most this many patches evaluate their groups' rows in parallel. Each evaluation holds
/// a row of sums per patch (about a hundred bytes each, with its vectors): one evaluation per thread at
/// once would make a scene of millions of patches need that many times the memory, more than its scene
/// and run together.
const PARALLEL_ROWS_MAX_PATCHES: usize = 1 << 16;

/// Whether the groups' rows of `scene` are evaluated in parallel ([`PARALLEL_ROWS_MAX_PATCHES`]); the
/// values are the same either way.
fn rows_in_parallel(scene: &Scene) -> bool {
    scene.patch_count() <= PARALLEL_ROWS_MAX_PATCHES
}

/// The estimates of a run in which no segment joined two patches: only the positional entropy (exact,
/// from the areas) is defined; every visibility measure has no pair to be computed from, and zeros would
/// read as measurements.
pub(super) fn exact_only(areas: &[f64]) -> ByMeasure<Estimate> {
    let mut out = ByMeasure::default();
    out.set(
        Measure::PositionalEntropy,
        Some(Estimate::exact(positional_entropy(areas))),
    );
    out
}

/// Eq. (19), exact from the areas.
fn positional_entropy(areas: &[f64]) -> f64 {
    -channel::area_distribution(areas)
        .iter()
        .map(|&x| xlog2x(x))
        .sum::<f64>()
}

/// The value of the visibility measure `m` in a group's (or the run's) values: the estimator behind each
/// entry of the catalogue ([`crate::measure::catalogue`]). `None` when the values do not have it.
fn value_of(m: Measure, g: &GroupValues) -> Option<f64> {
    match m {
        Measure::Entropy => Some(g.discrete?.entropy),
        Measure::EntropyCorrected => Some(g.corrected?.entropy),
        Measure::JointEntropy => Some(g.discrete?.joint_entropy),
        Measure::MutualInformation => Some(g.discrete?.mutual_information),
        Measure::MutualInformationCorrected => Some(g.corrected?.mutual_information),
        Measure::ContinuousMutualInformation => Some(g.continuous?.mutual_information),
        Measure::Accuracy => g.accuracy(),
        Measure::AccuracyCorrected => g.accuracy_corrected(),
        Measure::RelativeError => Some(1.0 - g.accuracy()?),
        Measure::MsePerLine => Some(g.discrete?.mse_per_line),
        Measure::MsePerLineCorrected => Some(g.corrected?.mse_per_line),
        Measure::PositionalEntropy
        | Measure::RadiosityPositionalEntropy
        | Measure::RadiosityEntropy
        | Measure::RadiosityEntropyCorrected
        | Measure::RadiosityMutualInformation
        | Measure::RadiosityMutualInformationCorrected => None,
    }
}

/// Every visibility measure the run gathered what it needs for, with its standard error: exact for
/// H_p (from the areas); by batch means for a mean (I_s^c), whose batch-means error is exact; else by
/// the delete-a-group jackknife when the spread has replicates, or batch means.
fn estimates(areas: &[f64], spread: &Spread<GroupValues>, wanted: Wanted) -> ByMeasure<Estimate> {
    ByMeasure::from_fn(|m| {
        let info = m.info();
        if info.family != Family::Visibility
            || !info.needs.met_by(wanted.discrete, wanted.continuous)
        {
            return None;
        }
        match info.verdict {
            VerdictRule::Exact => Some(Estimate::exact(positional_entropy(areas))),
            VerdictRule::Mean => spread.batch_means(|g| value_of(m, g)),
            _ => spread.estimate(|g| value_of(m, g)),
        }
    })
}
