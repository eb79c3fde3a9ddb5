//! The per-patch results of a run ([`crate::measure::shares`]), each with its standard error.
//!
//! Every group of lines gets its own per-patch terms (and, when the scene emits, its own radiosity
//! solution), and each full-run value gets the batch-means standard error of the group values, as the
//! scene's measures do ([`crate::run::errors`]); like theirs, the errors of the plug-in terms of undersampled
//! rows measure the statistical error only, not the bias.

use rayon::prelude::*;

use super::object_results::{object_weight, patches_by_object, ObjectValues};
use crate::measure::estimators::EntropyEstimator;
use crate::measure::radiosity::{self, FormFactors, PatchMaterials, SolveOptions};
use crate::measure::shares::{patch_values, ContinuousSums, PatchValues};
use crate::measure::{Estimate, PatchMeasure};
use crate::run::FinishedRun;
use crate::sample::tally::Tally;
use crate::scene::Scene;

/// One patch's results (patch `k` of the scene is entry `k`): its segments and, for each per-patch
/// quantity of the catalogue ([`PatchMeasure`]), its value with a standard error. Bits for the entropies
/// and terms; the radiosities in the units of the scene's emissions.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchResult {
    /// `N_i`: segments leaving the patch's front side (to patches, or escaping).
    pub segments: u64,
    /// Of them, the escapes.
    pub escapes: u64,
    /// Of them, the segments to back sides (absorbed).
    pub absorbed: u64,
    /// Each quantity's estimate, by [`PatchMeasure`] (`None`: not computed, e.g. no I_s^c or no light).
    values: [Option<Estimate>; PatchMeasure::COUNT],
}

impl PatchResult {
    /// Whether any segment left the patch (an unsampled patch's terms are 0 and say nothing).
    pub fn sampled(&self) -> bool {
        self.segments > 0
    }

    /// The estimate of `quantity` (`None`: not computed).
    pub fn get(&self, quantity: PatchMeasure) -> Option<Estimate> {
        self.values[quantity as usize]
    }
}

/// The radiosity side of the per-patch results: the scene's materials and how to solve.
#[derive(Clone, Copy, Debug)]
pub struct PatchLight<'a> {
    /// Emission and reflectance per patch.
    pub materials: &'a PatchMaterials,
    /// How the radiosity system is solved.
    pub solve: &'a SolveOptions,
}

/// One tally's per-patch values and, when lit, its radiosities `(B, B^in)`.
struct TallyPatches {
    values: PatchValues,
    /// Escapes per patch.
    escapes: Vec<u64>,
    /// Segments to back sides per patch (empty when none).
    absorbed: Vec<u64>,
    light: Option<(Vec<f64>, Vec<f64>)>,
}

/// Every patch's results from a finished run, and each object's values ([`object_values`]); `None`
/// without pair counts.
pub(crate) fn estimates(
    scene: &Scene,
    run: &FinishedRun,
    estimator: EntropyEstimator,
    light: Option<PatchLight<'_>>,
) -> Option<(Vec<PatchResult>, Vec<ObjectValues>)> {
    let of = |t: &Tally| of_tally(scene, t, estimator, light);
    let (all, groups): (Option<TallyPatches>, Vec<Option<TallyPatches>>) = rayon::join(
        || of(&run.total),
        || run.groups.par_iter().map(of).collect(),
    );
    let all = all?;
    let groups: Vec<TallyPatches> = groups.into_iter().flatten().collect();
    let patches = (0..scene.patch_count())
        .map(|i| patch_estimate(i, &all, &groups))
        .collect();
    Some((patches, object_values(scene, &all, &groups)))
}

fn of_tally(
    scene: &Scene,
    t: &Tally,
    estimator: EntropyEstimator,
    light: Option<PatchLight<'_>>,
) -> Option<TallyPatches> {
    let counts = t.counts.as_ref()?;
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
    let continuous = t.kernel_by_patch.as_ref().map(|sums| ContinuousSums {
        sums,
        total_area: scene.total_area(),
    });
    let lost = t.lost_by_patch();
    let values = patch_values(&areas, counts, &lost, estimator, continuous);
    // A group whose own solve fails (too few lines) only loses the standard errors of B.
    let light = light.and_then(|l| {
        let ff = FormFactors::from_counts(areas.len(), counts, &lost);
        let s = radiosity::solve(&ff, l.materials, l.solve).ok()?;
        Some((s.radiosity, s.incoming))
    });
    Some(TallyPatches {
        values,
        escapes: t.escapes_by_patch.dense().into_owned(),
        absorbed: t.absorbed_by_patch.dense().into_owned(),
        light,
    })
}

/// An estimate from the value of all the lines and the values of the groups (the batch-means standard
/// error; none when a group has no value).
fn estimate_of(
    f: &dyn Fn(&TallyPatches) -> Option<f64>,
    all: &TallyPatches,
    groups: &[TallyPatches],
) -> Option<Estimate> {
    let value = f(all)?;
    let per_group: Option<Vec<f64>> = groups.iter().map(f).collect();
    Some(match per_group {
        Some(g) => Estimate::from_groups(value, &g),
        None => Estimate {
            value,
            stderr: None,
        },
    })
}

/// Patch `i`'s value of `q` in one tally (`None`: not computed).
fn patch_value(q: PatchMeasure, i: usize, t: &TallyPatches) -> Option<f64> {
    let v = &t.values;
    let continuous = || Some(v.continuous_term.as_ref()?[i]);
    match q {
        PatchMeasure::RowEntropy => Some(v.row_entropy[i]),
        PatchMeasure::RowEntropyCorrected => Some(v.row_entropy_corrected[i]),
        PatchMeasure::MutualInformationTerm => Some(v.mutual_information_term[i]),
        PatchMeasure::MutualInformationTermCorrected => {
            Some(v.mutual_information_term_corrected[i])
        }
        PatchMeasure::ContinuousTerm => continuous(),
        PatchMeasure::LostInformation => Some(continuous()? - v.mutual_information_term[i]),
        PatchMeasure::LostInformationCorrected => {
            Some(continuous()? - v.mutual_information_term_corrected[i])
        }
        PatchMeasure::Radiosity => Some(t.light.as_ref()?.0[i]),
        PatchMeasure::IncomingRadiosity => Some(t.light.as_ref()?.1[i]),
    }
}

/// Patch `i`'s values from all the lines, with the batch-means standard errors of the groups'.
fn patch_estimate(i: usize, all: &TallyPatches, groups: &[TallyPatches]) -> PatchResult {
    PatchResult {
        segments: all.values.segments[i],
        escapes: all.escapes[i],
        absorbed: all.absorbed.get(i).copied().unwrap_or(0),
        values: PatchMeasure::ALL.map(|q| estimate_of(&|t| patch_value(q, i, t), all, groups)),
    }
}

/// Each object's values: its patches' values weighted as [`object_weight`] says, summed in each tally,
/// with the batch-means standard error of the groups' sums.
fn object_values(scene: &Scene, all: &TallyPatches, groups: &[TallyPatches]) -> Vec<ObjectValues> {
    let total_area = scene.total_area();
    let fraction = |i: usize| scene.patches[i].area / total_area;
    patches_by_object(scene)
        .iter()
        .map(|members| {
            let object_fraction: f64 = members.iter().map(|&i| fraction(i)).sum();
            PatchMeasure::ALL.map(|q| {
                let sum = |t: &TallyPatches| -> Option<f64> {
                    members.iter().try_fold(0.0, |acc, &i| {
                        let w = object_weight(q, fraction(i), object_fraction);
                        Some(acc + w * patch_value(q, i, t)?)
                    })
                };
                estimate_of(&sum, all, groups)
            })
        })
        .collect()
}
