//! The per-patch results of a run ([`crate::measure::shares`]), each with its standard error.
//!
//! Every group of lines gets its own per-patch terms (and, when the scene emits, its own radiosity
//! solution), and each full-run value gets the batch-means standard error of the group values, as the
//! scene's measures do ([`crate::run::errors`]); like theirs, the errors of the plug-in terms of undersampled
//! rows measure the statistical error only, not the bias.
//!
//! An enclosed open scene (`--enclose`, [`crate::sample::environment`]) has one more row, the
//! environment's, after the scene's patches: the per-patch terms are those of the enclosed scene, whose
//! measures the run reports, so that they add up to them. Each tally's terms are taken on its own
//! enclosed scene ([`Tally::enclosed`]), with the environment's area counted from its own lines, as the
//! scene's measures are. The radiosities are the open scene's (the environment is black and emits
//! nothing: what escapes is lost, enclosed or not), and the environment has none.

use rayon::prelude::*;

use super::object_results::{object_weight, patches_by_object, ObjectValues};
use crate::measure::estimators::EntropyEstimator;
use crate::measure::radiosity::{self, FormFactors, PatchMaterials, SolveOptions};
use crate::measure::shares::{patch_values, ContinuousSums, PatchValues};
use crate::measure::{Estimate, PatchMeasure};
use crate::run::FinishedRun;
use crate::sample::tally::Tally;
use crate::scene::Scene;

/// One patch's results (patch `k` of the scene is entry `k`; the environment of an enclosed scene is
/// the entry after the scene's patches): its segments and, for each per-patch quantity of the catalogue
/// ([`PatchMeasure`]), its value with a standard error. Bits for the entropies and terms; the
/// radiosities in the units of the scene's emissions.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchResult {
    /// The patch's area in the scene's units squared (the environment's: its counted area, the
    /// full run's reading of [`crate::analysis::Analysis::environment_area`]).
    pub area: f64,
    /// `a_i`, the weight of the patch's row: its share of the area of the scene whose measures are
    /// reported (of the enclosed scene, the environment's area included, when enclosed).
    pub area_fraction: f64,
    /// `N_i`: segments leaving the patch's front side (to patches, or escaping). The environment's:
    /// the escapes (its pairs with the patches) and twice the lines that met nothing (its pairs with
    /// itself).
    pub segments: u64,
    /// Of them, the escapes (with `--enclose`, the pairs with the environment; 0 for the environment).
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
    /// Each row's area in tracing space (the environment's last when enclosed).
    areas: Vec<f64>,
    /// Each row's area fraction `a_i`.
    fractions: Vec<f64>,
    values: PatchValues,
    /// Escapes per patch.
    escapes: Vec<u64>,
    /// Segments to back sides per patch (empty when none).
    absorbed: Vec<u64>,
    light: Option<(Vec<f64>, Vec<f64>)>,
}

/// Every patch's results from a finished run, and each object's values ([`object_values`]); `None`
/// without pair counts. With `enclose` (an enclosed open scene) the results are the enclosed scene's,
/// the environment's row last, and so are the objects' values, the environment's last.
pub(crate) fn estimates(
    scene: &Scene,
    run: &FinishedRun,
    estimator: EntropyEstimator,
    light: Option<PatchLight<'_>>,
    enclose: bool,
) -> Option<(Vec<PatchResult>, Vec<ObjectValues>)> {
    let of = |t: &Tally| of_tally(scene, t, estimator, light, enclose);
    let (all, groups): (Option<TallyPatches>, Vec<Option<TallyPatches>>) = rayon::join(
        || of(&run.total),
        || run.groups.par_iter().map(of).collect(),
    );
    let all = all?;
    let groups: Vec<TallyPatches> = groups.into_iter().flatten().collect();
    let scale = scene.normalization.scale;
    let patches = (0..all.fractions.len())
        .map(|i| patch_estimate(i, &all, &groups, scale, scene.patch_count()))
        .collect();
    Some((patches, object_values(scene, &all, &groups)))
}

fn of_tally(
    scene: &Scene,
    t: &Tally,
    estimator: EntropyEstimator,
    light: Option<PatchLight<'_>>,
    enclose: bool,
) -> Option<TallyPatches> {
    t.counts.as_ref()?;
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
    // A group whose own solve fails (too few lines) only loses the standard errors of B.
    let light = light.and_then(|l| {
        let ff = FormFactors::from_counts(areas.len(), t.counts.as_ref()?, &t.lost_by_patch());
        let s = radiosity::solve(&ff, l.materials, l.solve).ok()?;
        Some((s.radiosity, s.incoming))
    });
    let (channel, areas) = if enclose {
        let (enclosed, areas) = t.enclosed(scene);
        (std::borrow::Cow::Owned(enclosed), areas)
    } else {
        (std::borrow::Cow::Borrowed(t), areas)
    };
    let counts = channel.counts.as_ref()?;
    let continuous = channel.kernel_by_patch.as_ref().map(|sums| ContinuousSums {
        sums,
        total_area: areas.iter().sum(),
    });
    let lost = channel.lost_by_patch();
    let values = patch_values(&areas, counts, &lost, estimator, continuous);
    let mut escapes = t.escapes_by_patch.dense().into_owned();
    escapes.resize(areas.len(), 0);
    Some(TallyPatches {
        fractions: fractions(&areas),
        areas,
        values,
        escapes,
        absorbed: t.absorbed_by_patch.dense().into_owned(),
        light,
    })
}

/// Each area's share of their total, as the per-patch files have always written them (the scene's
/// total summed in patch order).
fn fractions(areas: &[f64]) -> Vec<f64> {
    let total: f64 = areas.iter().sum();
    areas.iter().map(|a| a / total).collect()
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
        // The environment (after the scene's patches) has no radiosity.
        PatchMeasure::Radiosity => t.light.as_ref()?.0.get(i).copied(),
        PatchMeasure::IncomingRadiosity => t.light.as_ref()?.1.get(i).copied(),
    }
}

/// Patch `i`'s values from all the lines, with the batch-means standard errors of the groups' (`scale`:
/// the scene's units per tracing unit; `own`: the scene's patches, the environment's row after them).
fn patch_estimate(
    i: usize,
    all: &TallyPatches,
    groups: &[TallyPatches],
    scale: f64,
    own: usize,
) -> PatchResult {
    // The patches' areas to the bit as the files have always written them; the environment's as the
    // report's `environment_area`.
    let area = if i < own {
        all.areas[i] * scale * scale
    } else {
        all.areas[i] * (scale * scale)
    };
    PatchResult {
        area,
        area_fraction: all.fractions[i],
        segments: all.values.segments[i],
        escapes: all.escapes[i],
        absorbed: all.absorbed.get(i).copied().unwrap_or(0),
        values: PatchMeasure::ALL.map(|q| estimate_of(&|t| patch_value(q, i, t), all, groups)),
    }
}

/// Each object's values: its patches' values weighted as [`object_weight`] says (with each tally's own
/// area fractions), summed in each tally, with the batch-means standard error of the groups' sums. The
/// environment of an enclosed scene is an object of its own, last.
fn object_values(scene: &Scene, all: &TallyPatches, groups: &[TallyPatches]) -> Vec<ObjectValues> {
    let mut members = patches_by_object(scene);
    if all.fractions.len() > scene.patch_count() {
        members.push(vec![scene.patch_count()]);
    }
    members
        .iter()
        .map(|members| {
            PatchMeasure::ALL.map(|q| {
                let sum = |t: &TallyPatches| -> Option<f64> {
                    let object_fraction: f64 = members.iter().map(|&i| t.fractions[i]).sum();
                    members.iter().try_fold(0.0, |acc, &i| {
                        let w = object_weight(q, t.fractions[i], object_fraction);
                        Some(acc + w * patch_value(q, i, t)?)
                    })
                };
                estimate_of(&sum, all, groups)
            })
        })
        .collect()
}
