//! The radiosity measures of a run (paper sec. 4), each with a standard error.
//!
//! The radiosity system is solved on the form factors estimated from the run's own pair counts, so the
//! radiosity measures carry the statistical error of those counts. As for the visibility measures
//! ([`crate::measure::estimate`]), the run is cut into independent groups of lines: every group's
//! counts give their own form factors, their own solution `B` and their own eqs. (33)-(35); the spread of
//! the group values gives the batch-means standard error of the full-run values.

use crate::analysis::{analyze_observed, analyze_with, Analysis, AnalysisConfig, RunControl};
use crate::measure::bias::row_corrections;
use crate::measure::estimators::EntropyEstimator;
use crate::measure::radiosity::{
    self, FormFactors, MaterialError, PatchMaterials, RadiosityValues, SolveError, SolveOptions,
};
use crate::measure::Estimate;
use crate::sample::tally::Tally;
use crate::scene::Scene;
use crate::trace::{TraceError, Tracer};

/// The radiosity measures of a run, with the full-run solver's figures.
#[derive(Clone, Debug, PartialEq)]
pub struct RadiosityEstimates {
    /// Eq. (33).
    pub positional_entropy: Estimate,
    /// Eq. (34).
    pub entropy: Estimate,
    /// Eq. (35).
    pub mutual_information: Estimate,
    /// Eq. (34) with bias-corrected rows ([`radiosity::corrected`]).
    pub entropy_corrected: Estimate,
    /// Eq. (35) with bias-corrected rows.
    pub mutual_information_corrected: Estimate,
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

/// The radiosity measures, or why there are none.
#[derive(Clone, Debug, PartialEq)]
pub enum RadiosityOutcome {
    /// Computed.
    Computed(RadiosityEstimates),
    /// Left out, with the reason for the report.
    Skipped(String),
}

/// Why a run with radiosity failed.
#[derive(Debug, thiserror::Error)]
pub enum RadiosityError {
    /// A material outside the physical range (bad input).
    #[error(transparent)]
    Material(#[from] MaterialError),
    /// The radiosity system has no solution, or the solver gave up (bad input: the materials).
    #[error("{scene}: {message}")]
    Solve {
        /// The scene.
        scene: String,
        /// What went wrong, naming the material concerned.
        message: String,
    },
    /// Tracing failed.
    #[error(transparent)]
    Trace(#[from] TraceError),
}

impl RadiosityError {
    /// Whether the scene's own data are at fault (materials), not the machinery.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, RadiosityError::Trace(_))
    }
}

/// The reason given when nothing in the scene emits.
pub const NOTHING_EMITS: &str =
    "nothing emits: no material has an emission (Ke) above 0, so every radiosity is 0";

/// [`analyze`] plus the radiosity measures: validates the materials first (before any line is cast), then
/// solves the radiosity system of every group and of the whole run. Discrete counts are gathered whatever
/// `cfg.wanted` says, since the form factors come from them.
pub fn analyze_with_radiosity(
    scene: &Scene,
    tracer: &dyn Tracer,
    cfg: &AnalysisConfig,
    opts: &SolveOptions,
    control: &RunControl,
) -> Result<(Analysis, RadiosityOutcome), RadiosityError> {
    let materials = PatchMaterials::of_scene(scene)?;
    if !materials.any_emission() {
        let a = analyze_with(scene, tracer, cfg, control)?;
        return Ok((a, RadiosityOutcome::Skipped(NOTHING_EMITS.into())));
    }
    let mut cfg = *cfg;
    cfg.wanted.discrete = true;
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
    let mut per_group: Vec<Option<RadiosityValues>> = Vec::new();
    let a = analyze_observed(scene, tracer, &cfg, control, &mut |t| {
        // A group whose own solve fails (too few lines) only loses the standard error.
        per_group.push(
            solve_tally(&areas, &materials, t, opts, cfg.estimator)
                .ok()
                .flatten()
                .map(|r| r.0),
        );
    })?;
    let outcome = match solve_tally(&areas, &materials, &a.tally, opts, cfg.estimator) {
        Err(e) => return Err(solve_error(scene, &materials, e)),
        Ok(None) => RadiosityOutcome::Skipped(
            "no patch both receives and sends light: every transformed area A_i B_i^in B_i (eq. 30) is 0"
                .into(),
        ),
        Ok(Some((values, solution))) => {
            RadiosityOutcome::Computed(estimates(&values, &solution, &per_group, opts))
        }
    };
    Ok((a, outcome))
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
    let ff = FormFactors::from_counts(areas.len(), counts, &t.escapes_by_patch);
    let solution = radiosity::solve(&ff, materials, opts)?;
    let Some(mut values) = radiosity::measures(areas, &ff, &solution) else {
        return Ok(None);
    };
    let deltas = row_corrections(counts, &t.escapes_by_patch, estimator);
    radiosity::corrected(
        &mut values,
        areas,
        &solution,
        deltas.as_slice().unwrap_or(&[]),
    );
    Ok(Some((values, solution)))
}

fn estimates(
    all: &RadiosityValues,
    solution: &radiosity::Solution,
    groups: &[Option<RadiosityValues>],
    opts: &SolveOptions,
) -> RadiosityEstimates {
    let est = |f: fn(&RadiosityValues) -> f64| -> Estimate {
        let per: Vec<f64> = groups.iter().flatten().map(f).collect();
        if per.len() == groups.len() {
            Estimate::from_groups(f(all), &per)
        } else {
            Estimate {
                value: f(all),
                stderr: None,
            }
        }
    };
    RadiosityEstimates {
        positional_entropy: est(|v| v.positional_entropy),
        entropy: est(|v| v.entropy),
        mutual_information: est(|v| v.mutual_information),
        entropy_corrected: est(|v| v.entropy_corrected),
        mutual_information_corrected: est(|v| v.mutual_information_corrected),
        solver_residual: solution.residual,
        solver_tolerance: opts.tolerance,
        solver_sweeps: solution.sweeps,
        excluded_patches: all.excluded_patches,
        excluded_area_fraction: all.excluded_area_fraction,
    }
}

/// A solver failure as an error naming the scene and the material concerned.
fn solve_error(scene: &Scene, materials: &PatchMaterials, e: SolveError) -> RadiosityError {
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
    RadiosityError::Solve {
        scene: scene.name.clone(),
        message,
    }
}
