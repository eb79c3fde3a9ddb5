//! Results per object of the scene (the groups, meshes or nodes the file names): what each object is,
//! how lines met its sides, and, when the run has per-patch results, the sums of its patches' terms,
//! each with the batch-means standard error of the group sums (a sum's error is not the sum of its
//! terms' errors: the terms of one group move together).
//!
//! The per-patch results of an enclosed open scene (`--enclose`) have a row for the environment
//! ([`super::patch_results`]); the objects then have one too, last, named [`ENVIRONMENT`], and every
//! object's area fraction is its share of the enclosed scene's area, so that the objects' values add up
//! to the enclosed scene's measures.

use crate::measure::{Estimate, PatchMeasure};
use crate::sample::tally::{ObjectSides, Tally};
use crate::scene::Scene;

/// The name of the environment's object (and material) in the per-object and per-patch results of an
/// enclosed open scene.
pub const ENVIRONMENT: &str = "environment";

/// An object's value of each quantity of the per-patch catalogue, by [`PatchMeasure`].
pub type ObjectValues = [Option<Estimate>; PatchMeasure::COUNT];

/// One object's results.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectResult {
    /// Its name in the scene file.
    pub name: String,
    /// Its patches.
    pub patches: usize,
    /// Its triangles.
    pub triangles: usize,
    /// Its area, in the scene's units squared.
    pub area: f64,
    /// Its share of the scene's area (of the enclosed scene's, the environment's included, when the
    /// results have the environment's row).
    pub area_fraction: f64,
    /// How lines met its sides: front sides escaping, back sides seen from front sides and from open
    /// space ([`ObjectSides`]).
    pub sides: ObjectSides,
    /// Segments leaving its patches' front sides (to patches, escaping or absorbed), when counted.
    pub segments: Option<u64>,
    /// Of them, the escapes (when counted per patch).
    pub escapes: Option<u64>,
    /// Of them, the segments to back sides (when counted per patch).
    pub absorbed: Option<u64>,
    /// Per quantity of the per-patch catalogue, the object's value ([`object_weight`]), when the run
    /// has per-patch results.
    pub(crate) values: ObjectValues,
}

impl ObjectResult {
    /// The object's value of `quantity`: the sum of its patches' terms for the terms of I_s, I_s^c and
    /// the information lost; its share of H_s (`sum a_i H_i`) for the row entropies; its area-weighted
    /// mean for the radiosities (`None`: not computed).
    pub fn get(&self, quantity: PatchMeasure) -> Option<Estimate> {
        self.values[quantity as usize]
    }

    /// The share of the segments leaving its front sides that escape the scene.
    pub fn escape_fraction(&self) -> Option<f64> {
        let (segments, escapes) = (self.segments?, self.escapes?);
        (segments > 0).then(|| escapes as f64 / segments as f64)
    }
}

/// How patch `i`'s value of `quantity` enters its object's: 1 for the additive terms, the patch's area
/// fraction `a_i` for the row entropies (H_s = sum a_i H_i), and `a_i / a_object` for the radiosities
/// (an area-weighted mean).
pub fn object_weight(quantity: PatchMeasure, area_fraction: f64, object_fraction: f64) -> f64 {
    match quantity {
        PatchMeasure::RowEntropy | PatchMeasure::RowEntropyCorrected => area_fraction,
        PatchMeasure::Radiosity | PatchMeasure::IncomingRadiosity => {
            if object_fraction > 0.0 {
                area_fraction / object_fraction
            } else {
                0.0
            }
        }
        PatchMeasure::MutualInformationTerm
        | PatchMeasure::MutualInformationTermCorrected
        | PatchMeasure::ContinuousTerm
        | PatchMeasure::LostInformation
        | PatchMeasure::LostInformationCorrected => 1.0,
    }
}

/// The patches of each object, in patch order.
pub fn patches_by_object(scene: &Scene) -> Vec<Vec<usize>> {
    let mut members = vec![Vec::new(); scene.objects.len()];
    for (i, p) in scene.patches.iter().enumerate() {
        members[p.object as usize].push(i);
    }
    members
}

/// Every object's results from the run's total tally: what it is, how its sides were met, and its
/// segments and escapes when the pair counts were kept; `values` holds the sums of its patches' terms
/// when the run has per-patch results, and the environment's last when they are an enclosed scene's
/// (`environment`: its area in tracing space); the environment is then the last object.
pub(crate) fn of_run(
    scene: &Scene,
    total: &Tally,
    values: Option<Vec<ObjectValues>>,
    environment: Option<f64>,
) -> Vec<ObjectResult> {
    let members = patches_by_object(scene);
    let total_area = scene.total_area() + environment.unwrap_or(0.0);
    let scale2 = scene.normalization.scale * scene.normalization.scale;
    let lost = total.lost_by_patch();
    let segments = total
        .counts
        .as_ref()
        .map(|counts| crate::measure::channel::row_totals(scene.patch_count(), counts, &lost));
    let mut values = values.map(Vec::into_iter);
    let (escapes, absorbed) = (
        total.escapes_by_patch.dense(),
        total.absorbed_by_patch.dense(),
    );
    members
        .iter()
        .enumerate()
        .map(|(o, patches)| {
            let area: f64 = patches.iter().map(|&i| scene.patches[i].area).sum();
            let sum = |per_patch: &[u64]| -> u64 {
                patches
                    .iter()
                    .map(|&i| per_patch.get(i).copied().unwrap_or(0))
                    .sum()
            };
            let counted = total.counts.is_some();
            ObjectResult {
                name: scene.objects[o].clone(),
                patches: patches.len(),
                triangles: patches
                    .iter()
                    .map(|&i| scene.patches[i].triangle_count as usize)
                    .sum(),
                area: area * scale2,
                area_fraction: area / total_area,
                sides: total.orientation.get(o).copied().unwrap_or_default(),
                segments: segments
                    .as_ref()
                    .map(|s| patches.iter().map(|&i| s[i].round() as u64).sum()),
                escapes: counted.then(|| sum(&escapes)),
                absorbed: counted.then(|| sum(&absorbed)),
                values: values
                    .as_mut()
                    .and_then(Iterator::next)
                    .unwrap_or([None; PatchMeasure::COUNT]),
            }
        })
        .collect::<Vec<_>>()
        .into_iter()
        .chain(environment.map(|area| {
            let c = &total.counters;
            ObjectResult {
                name: ENVIRONMENT.into(),
                patches: 1,
                triangles: 0,
                area: area * scale2,
                area_fraction: area / total_area,
                sides: ObjectSides::default(),
                segments: total.counts.as_ref().map(|_| c.escapes + 2 * c.misses),
                escapes: total.counts.as_ref().map(|_| 0),
                absorbed: total.counts.as_ref().map(|_| 0),
                values: values
                    .as_mut()
                    .and_then(Iterator::next)
                    .unwrap_or([None; PatchMeasure::COUNT]),
            }
        }))
        .collect()
}
