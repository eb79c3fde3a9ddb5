//! The radiosity measures of a run (paper sec. 4), each with a standard error.
//!
//! The radiosity system is solved on the form factors estimated from the run's own pair counts, so the
//! radiosity measures carry the statistical error of those counts. As for the visibility measures
//! ([`crate::run::errors`]), every group's counts give their own form factors, their own solution `B` and
//! their own eqs. (33)-(35), and so do the counts with each group left out for the jackknife.

use rayon::prelude::*;

use super::reliability::{self, Reliability, RunFacts, SamplingReport};
use crate::measure::bias::row_corrections;
use crate::measure::estimators::EntropyEstimator;
use crate::measure::radiosity::{
    self, FormFactors, PatchMaterials, RadiosityValues, SolveError, SolveOptions,
};
use crate::measure::{ByMeasure, Estimate, Measure};
use crate::run::FinishedRun;
use crate::run::Spread;
use crate::sample::tally::Tally;
use crate::scene::Scene;

/// The figures of a run's radiosity solution (its measures are among the run's readings,
/// [`crate::analysis::Analysis::estimates`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RadiositySolve {
    /// Relative residual `max |B - E - R F B| / max B` of the full-run solution.
    pub solver_residual: f64,
    /// The tolerance it was solved to.
    pub solver_tolerance: f64,
    /// Gauss-Seidel sweeps of the full-run solution.
    pub solver_sweeps: usize,
    /// Patches outside the channel (transformed area 𝒜_i = 0, eq. (30)).
    pub excluded_patches: usize,
    /// Their share of the scene's area.
    pub excluded_area_fraction: f64,
}

/// The radiosity readings of a run and their verdicts (as for the visibility measures: the rows are
/// those of F, reweighted by the radiosities).
pub(crate) struct RadiosityReadings {
    pub(crate) estimates: ByMeasure<Estimate>,
    pub(crate) reliability: ByMeasure<Reliability>,
}

/// Whether the radiosity measures were computed (with the solution's figures), or why not.
#[derive(Clone, Debug, PartialEq)]
pub enum RadiosityOutcome {
    /// Computed.
    Computed(RadiositySolve),
    /// Not asked for.
    NotRequested,
    /// Left out, with the reason for the report.
    Skipped(String),
}

/// The reason given when nothing in the scene emits.
pub const NOTHING_EMITS: &str =
    "nothing emits: no material has an emission (Ke) above 0, so every radiosity is 0";

/// A radiosity system without a solution, or one the solver gave up on: the scene's materials are at
/// fault.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{scene}: {message}")]
pub struct SolveFailure {
    /// The scene.
    pub scene: String,
    /// What went wrong, naming the material concerned.
    pub message: String,
}

/// Solves the radiosity system of the whole run, of every group, and with each group left out when
/// `jackknife` (then the replicates give the standard errors) or `debias` (then they debias the
/// readings on corrected rows, as for the visibility measures of a run of Sobol' lines), and measures
/// each.
pub(crate) fn estimates(
    scene: &Scene,
    materials: &PatchMaterials,
    run: &FinishedRun,
    opts: &SolveOptions,
    estimator: EntropyEstimator,
    (jackknife, debias): (bool, bool),
    sampling: &SamplingReport,
) -> Result<(RadiosityOutcome, Option<RadiosityReadings>), SolveFailure> {
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
    let solve = |t: &Tally| solve_tally(&areas, materials, t, opts, estimator);
    // A group whose own solve fails (too few lines) only loses the standard error.
    let per_group: Vec<Option<RadiosityValues>> = run
        .groups
        .par_iter()
        .map(|g| solve(g).ok().flatten().map(|r| r.0))
        .collect();
    let replicates: Option<Vec<Option<RadiosityValues>>> = (jackknife || debias).then(|| {
        run.groups
            .par_iter()
            .map(|g| {
                solve(&run.total.without_part(g))
                    .ok()
                    .flatten()
                    .map(|r| r.0)
            })
            .collect()
    });
    let (all, solution) = match solve(&run.total) {
        Err(e) => return Err(solve_failure(scene, materials, e)),
        Ok(None) => {
            return Ok((
                RadiosityOutcome::Skipped(
                    "no patch both receives and sends light: every transformed area A_i B_i^in B_i (eq. 30) is 0"
                        .into(),
                ),
                None,
            ))
        }
        Ok(Some(solved)) => solved,
    };
    let all = Some(all);
    let with_replicates = Spread {
        all: &all,
        groups: &per_group,
        replicates: replicates.as_deref(),
    };
    let spread = Spread {
        replicates: replicates.as_deref().filter(|_| jackknife),
        ..with_replicates
    };
    let all = all.as_ref().expect("solved above");
    let estimates = ByMeasure::from_fn(|m| {
        let pick = value_of(m)?;
        let value = |v: &Option<RadiosityValues>| v.as_ref().map(pick);
        if debias && m.rests_on_corrected_rows() {
            with_replicates
                .debiased(value)
                .or_else(|| spread.estimate(value))
        } else {
            spread.estimate(value)
        }
    });
    let c = &run.total.counters;
    let facts = RunFacts {
        lines: c.lines,
        pairs: c.pairs,
        open: c.escapes + c.absorbed > 0,
        short_chords: c.short_chords,
        // Radiosity readings take their errors from the groups (`spread`), whatever `--errors` says.
        jackknifed: false,
    };
    let reliability = reliability::verdicts(&estimates, Some(sampling), None, facts);
    let solve = RadiositySolve {
        solver_residual: solution.residual,
        solver_tolerance: opts.tolerance,
        solver_sweeps: solution.sweeps,
        excluded_patches: all.excluded_patches,
        excluded_area_fraction: all.excluded_area_fraction,
    };
    Ok((
        RadiosityOutcome::Computed(solve),
        Some(RadiosityReadings {
            estimates,
            reliability,
        }),
    ))
}

/// The estimator behind each radiosity entry of the catalogue ([`crate::measure::catalogue`]): its
/// value in a solution's measures.
fn value_of(m: Measure) -> Option<fn(&RadiosityValues) -> f64> {
    Some(match m {
        Measure::RadiosityPositionalEntropy => |v| v.positional_entropy,
        Measure::RadiosityEntropy => |v| v.entropy,
        Measure::RadiosityEntropyCorrected => |v| v.entropy_corrected,
        Measure::RadiosityMutualInformation => |v| v.mutual_information,
        Measure::RadiosityMutualInformationCorrected => |v| v.mutual_information_corrected,
        _ => return None,
    })
}

/// Solves the radiosity system on a tally's form factors and measures it; `Ok(None)` when no patch is
/// in the channel.
fn solve_tally(
    areas: &[f64],
    materials: &PatchMaterials,
    t: &Tally,
    opts: &SolveOptions,
    estimator: EntropyEstimator,
) -> Result<Option<(RadiosityValues, radiosity::Solution)>, SolveError> {
    let Some(counts) = &t.counts else {
        return Ok(None);
    };
    let lost = t.lost_by_patch();
    let ff = FormFactors::from_counts(areas.len(), counts, &lost);
    let solution = radiosity::solve(&ff, materials, opts)?;
    let Some(mut values) = radiosity::measures(areas, &ff, &solution) else {
        return Ok(None);
    };
    let deltas = row_corrections(counts, &lost, estimator);
    radiosity::corrected(
        &mut values,
        areas,
        &solution,
        deltas.as_slice().unwrap_or(&[]),
    );
    Ok(Some((values, solution)))
}

/// A solver failure as an error naming the scene and the material concerned.
fn solve_failure(scene: &Scene, materials: &PatchMaterials, e: SolveError) -> SolveFailure {
    let message = match &e {
        SolveError::NoAbsorption {
            example_emitter, ..
        } => {
            let m = &scene.materials[scene.patches[*example_emitter].material as usize];
            format!(
                "{e}; emitting material `{}` (E = {}), lit by reflectance-1 materials only",
                m.name, materials.emission[*example_emitter]
            )
        }
        SolveError::NoConvergence { .. } => {
            let worst = scene
                .patches
                .iter()
                .map(|p| &scene.materials[p.material as usize])
                .filter(|m| m.reflectance < 1.0)
                .max_by(|a, b| a.reflectance.total_cmp(&b.reflectance));
            match worst {
                Some(m) => format!(
                    "{e}; most reflective absorbing material: `{}` (R = {})",
                    m.name, m.reflectance
                ),
                None => e.to_string(),
            }
        }
    };
    SolveFailure {
        scene: scene.name.clone(),
        message,
    }
}
