//! Where the complexity is: the scene's measures shared out among its patches.
//!
//! Every visibility measure of sec. 3 is a sum over the patches, so each patch has its own term:
//!
//! * eq. (17): `H_s = sum_i a_i H_i`, with `H_i = -sum_j F_ij log2 F_ij` the patch's row entropy
//!   (plug-in, or bias-corrected by the run's estimator, [`super::bias`]);
//! * eq. (21): `I_s = sum_i I_i`, with `I_i = a_i sum_j F_ij log2(F_ij / a_j)`, the patch's term of the
//!   discrete mutual information (corrected: `a_i (X_i - H_i)`, with `H_i` corrected and the linear
//!   cross term `X_i = -sum_j F_ij log2 a_j` as it is);
//! * eq. (27): `I_s^c = sum_i I_i^c`. Eq. (27) integrates `F(x,y) log2(A_T F(x,y))` over x uniform on
//!   the scene, so it is `sum_i a_i m_i`, with `m_i` the mean of that log over x uniform on patch i and y
//!   the point x sees in a cosine-distributed direction. The pairs with an end on patch i sample
//!   exactly that (a global line crosses i at a uniform point, in a cosine-distributed direction, and
//!   leaves its front side along one segment), so `m_i` is estimated by the mean term of those pairs,
//!   and `I_i^c = a_i (m_i + delta)`. The estimates `sum_i a_i m_i` and the run's I_s^c (the mean over
//!   all its pairs) agree in expectation but not sample by sample; `delta` shares their difference out
//!   in proportion to area (a few 1e-4 bits), so that the shares add up to the run's I_s^c exactly (to
//!   rounding). Splitting each pair's term half and half between its ends would add up too, but weighs
//!   a patch by its share of the run's pairs, whose sampling noise then swamps the lost information
//!   below (5 times the scatter per patch on `@fig2:a` at 10^7 lines);
//! * the information the discretisation loses at patch i (sec. 3.3): `I_i^c - I_i`, which adds up to
//!   `I_s^c - I_s`.
//!
//! [`information_loss`] scores the same loss for the `information` meshing strategy, per pair of
//! patches and weighted by their radiosities; see its documentation for how the two estimates differ.

use super::bias::row_corrections;
use super::channel::{area_distribution, row_totals};
use super::estimators::EntropyEstimator;
use super::rows::Rows;
use crate::sample::counts::PairCounts;
use crate::sample::kernel_sums::PatchKernelSums;

/// The per-patch terms of one set of lines (a run, or one of its groups), one entry per patch in every
/// vector.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchValues {
    /// `N_i`: segments leaving the patch's front side (to patches, or escaping).
    pub segments: Vec<u64>,
    /// Of them, the escapes.
    pub escapes: Vec<u64>,
    /// `H_i`, the plug-in row entropy (bits); 0 for an unsampled patch.
    pub row_entropy: Vec<f64>,
    /// `H_i` by the bias-correcting estimator (bits).
    pub row_entropy_corrected: Vec<f64>,
    /// `I_i = a_i sum_j F_ij log2(F_ij / a_j)`, the patch's term of eq. (21) (bits).
    pub mutual_information_term: Vec<f64>,
    /// `a_i (X_i - H_i)` with the corrected `H_i` (bits).
    pub mutual_information_term_corrected: Vec<f64>,
    /// `I_i^c`, the patch's share of eq. (27) (bits); `None` without the per-patch sums of eq. (27).
    pub continuous_term: Option<Vec<f64>>,
}

impl PatchValues {
    /// The information lost at each patch, `I_i^c - I_i` (bits), plug-in or with the corrected `I_i`.
    pub fn lost_information(&self, corrected: bool) -> Option<Vec<f64>> {
        let discrete = if corrected {
            &self.mutual_information_term_corrected
        } else {
            &self.mutual_information_term
        };
        let continuous = self.continuous_term.as_ref()?;
        Some(
            continuous
                .iter()
                .zip(discrete)
                .map(|(c, d)| c - d)
                .collect(),
        )
    }
}

/// What eq. (27)'s per-patch shares are computed from: the per-patch sums of the log kernel and the
/// total area `A_T` in the units the kernel was measured in.
#[derive(Clone, Copy, Debug)]
pub struct ContinuousSums<'a> {
    /// Per-patch sums of `log2(cos_x cos_y / d^2)` over the pair ends (every usable pair of the run
    /// has its two ends there).
    pub sums: &'a PatchKernelSums,
    /// `A_T`, in the units of the distances `d`.
    pub total_area: f64,
}

/// Every patch's terms from the patch areas, the pair counts and escapes, and (for eq. (27)) the
/// per-patch kernel sums; the corrected values by `estimator`.
pub fn patch_values(
    areas: &[f64],
    counts: &PairCounts,
    escapes: &[u64],
    estimator: EntropyEstimator,
    continuous: Option<ContinuousSums<'_>>,
) -> PatchValues {
    let a = area_distribution(areas);
    let a = a.as_slice().expect("a fresh array is contiguous");
    let gathered = Rows::gather(a, counts, escapes, estimator);
    let rows = &gathered.sums;
    let row_entropy: Vec<f64> = rows.iter().map(|r| r.plug_in_entropy()).collect();
    // One pass serves every estimator but Chao–Shen, which needs a second one over the counts.
    let row_entropy_corrected = gathered.corrected_entropies().unwrap_or_else(|| {
        let corrections = row_corrections(counts, escapes, estimator);
        row_entropy
            .iter()
            .enumerate()
            .map(|(i, h)| h + corrections.get(i).copied().unwrap_or(0.0))
            .collect()
    });
    let term = |i: usize, h: f64| a[i] * (rows[i].cross_entropy_with_areas() - h);
    PatchValues {
        segments: rows.iter().map(|r| r.segments).collect(),
        escapes: rows.iter().map(|r| r.escapes).collect(),
        mutual_information_term: (0..a.len()).map(|i| term(i, row_entropy[i])).collect(),
        mutual_information_term_corrected: (0..a.len())
            .map(|i| term(i, row_entropy_corrected[i]))
            .collect(),
        row_entropy,
        row_entropy_corrected,
        continuous_term: continuous.and_then(|c| continuous_shares(c, a)),
    }
}

/// Eq. (27)'s share of every patch, `a_i (m_i + delta)` (module documentation), from the area
/// fractions `a_i`; 0 for a patch no pair reached; `None` without pairs.
pub fn continuous_shares(c: ContinuousSums<'_>, area_fractions: &[f64]) -> Option<Vec<f64>> {
    let ends: u64 = c.sums.ends.iter().sum();
    if ends == 0 {
        return None;
    }
    let offset = (c.total_area / std::f64::consts::PI).log2();
    // Every term of the run once per end: their sum over the ends is twice the sum over the pairs.
    let terms = |i: usize| c.sums.log2_kernel[i].value() + c.sums.ends[i] as f64 * offset;
    let whole = (0..area_fractions.len()).map(terms).sum::<f64>() / ends as f64;
    let reached = |i: &usize| c.sums.ends[*i] > 0;
    let mean = |i: usize| terms(i) / c.sums.ends[i] as f64;
    let stratified: f64 = (0..area_fractions.len())
        .filter(reached)
        .map(|i| area_fractions[i] * mean(i))
        .sum();
    let reached_area: f64 = (0..area_fractions.len())
        .filter(reached)
        .map(|i| area_fractions[i])
        .sum();
    let delta = (whole - stratified) / reached_area;
    Some(
        (0..area_fractions.len())
            .map(|i| {
                if reached(&i) {
                    area_fractions[i] * (mean(i) + delta)
                } else {
                    0.0
                }
            })
            .collect(),
    )
}

/// Per unordered patch pair, what the `information` meshing strategy reads: the pair counts, and beside
/// each entry (in [`PairCounts::for_each`] order) the sum of `log2 F(x, y)` over its sampled pairs of
/// points, `F(x, y) = cos_x cos_y / (pi d^2)` (eq. (25)), and how many pairs entered it.
#[derive(Clone, Debug)]
pub struct PairKernelSums {
    /// Pair counts `N_ij`.
    pub counts: PairCounts,
    /// Per entry of `counts`: the sum of `log2 F(x, y)` over its pairs of points.
    pub log_kernel_sums: Vec<f64>,
    /// Per entry: how many pairs entered the sum (pairs of coincident points are left out).
    pub log_kernel_pairs: Vec<u64>,
    /// Escapes per patch.
    pub escapes: Vec<u64>,
}

/// The `information` meshing strategy's score of every patch: its share of the information transfer
/// the discretisation loses, weighted by the radiosities `B` (all 1 when `radiosity` is `None`).
///
/// For the transformed scene of sec. 4 with the patch radiosities held constant over each patch, the
/// loss `𝓘^c - 𝓘_s` (eq. (25) against eq. (35)) is a sum over ordered patch pairs of
///
/// ```text
///   (B_i B_j / 𝒜_T) [ ∫_i ∫_j F(x,y) log F(x,y) dx dy  -  A_i F_ij log(F_ij / A_j) ],
/// ```
///
/// the radiosity-weighted visibility loss of the pair; each bracket is >= 0 (log-sum inequality; 0 when
/// F(x, y) is constant over the pair). Patch i's score is its row of the sum (𝒜_T dropped: a common
/// factor). The integral is `A_i F_ij` times the mean of `log2 F(x, y)` over the sampled pairs of
/// points between i and j.
///
/// With `B = 1` and a closed scene the score divided by `A_T` is [`PatchValues::lost_information`]
/// (`I_i^c - I_i`) but for its common correction `a_i delta` (module documentation), which keeps the
/// per-patch table adding up exactly: both weigh a pair by the estimated `A_i F_ij`. (In an open scene
/// the escapes count in `N_i` here and not in `m_i` there.)
pub fn information_loss(
    areas: &[f64],
    sample: &PairKernelSums,
    radiosity: Option<&[f64]>,
) -> Vec<f64> {
    let n = areas.len();
    let totals = row_totals(n, &sample.counts, &sample.escapes);
    let b = |i: usize| radiosity.map_or(1.0, |r| r[i]);
    let mut score = vec![0.0; n];
    // Both layouts visit their entries in pair-key order, the order of the sums.
    let mut k = 0;
    sample.counts.for_each(|i, j, count| {
        let entry = k;
        k += 1;
        let (i, j) = (i as usize, j as usize);
        let used = sample.log_kernel_pairs[entry];
        if i == j || used == 0 {
            return; // A planar patch cannot see itself; no usable pair of points.
        }
        let mean_log = sample.log_kernel_sums[entry] / used as f64;
        let weight = b(i) * b(j);
        for (p, q) in [(i, j), (j, i)] {
            let f = count as f64 / totals[p];
            score[p] += weight * areas[p] * f * (mean_log - (f / areas[q]).log2());
        }
    });
    score
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::visibility::discrete;
    use crate::sample::counts::pair_key;

    /// The per-patch terms add up to the scene's H_s and I_s, in an open scene with an unsampled patch.
    #[test]
    fn terms_add_up_to_the_scene_measures() {
        let areas = [1.0, 2.0, 0.5, 3.0, 0.7];
        let mut keys = Vec::new();
        for (i, j, c) in [(0, 1, 3), (0, 2, 1500), (1, 3, 2), (2, 3, 40), (0, 3, 9)] {
            keys.extend(std::iter::repeat_n(pair_key(i, j), c));
        }
        let counts = PairCounts::from_keys(5, &mut keys);
        let escapes = [0, 5, 0, 2, 0];
        let v = patch_values(&areas, &counts, &escapes, EntropyEstimator::PlugIn, None);
        let scene = discrete(&areas, &counts, &escapes);
        let a = area_distribution(&areas);
        let h: f64 = a.iter().zip(&v.row_entropy).map(|(a, h)| a * h).sum();
        let is: f64 = v.mutual_information_term.iter().sum();
        assert!(
            (h - scene.entropy).abs() < 1e-13,
            "{h} vs {}",
            scene.entropy
        );
        assert!((is - scene.mutual_information).abs() < 1e-13);
        assert_eq!(v.segments[4], 0);
        assert_eq!(v.row_entropy[4], 0.0);
        assert_eq!(v.mutual_information_term[4], 0.0);
        // The plug-in estimator corrects nothing.
        assert_eq!(v.row_entropy, v.row_entropy_corrected);
    }

    /// Known terms: each patch gets its area fraction times the mean term of its pairs, plus its share
    /// of the difference to the mean over all pairs, so the shares add up to that mean; a patch no pair
    /// reached gets nothing (never 0/0).
    #[test]
    fn continuous_shares_are_area_times_mean_term_and_add_up() {
        let mut sums = PatchKernelSums::new(4);
        sums.add_pairs(
            &[pair_key(0, 1), pair_key(1, 2), pair_key(0, 2)],
            &[1.0, 3.0, 2.0],
        );
        let total_area = std::f64::consts::PI; // offset log2(A_T / pi) = 0
        let a = [0.25, 0.25, 0.25, 0.25];
        let s = continuous_shares(
            ContinuousSums {
                sums: &sums,
                total_area,
            },
            &a,
        )
        .unwrap();
        // Means 1.5, 2, 2.5 over a_i = 1/4 give 1.5; the pairs' mean is 2: delta = 0.5 / 0.75.
        let delta = 0.5 / 0.75;
        let expected = [1.5, 2.0, 2.5].map(|m| 0.25 * (m + delta));
        for (x, e) in s.iter().zip(expected) {
            assert!((x - e).abs() < 1e-15, "{s:?}");
        }
        assert_eq!(s[3], 0.0);
        assert!((s.iter().sum::<f64>() - 2.0).abs() < 1e-15);
        let none = continuous_shares(
            ContinuousSums {
                sums: &PatchKernelSums::new(4),
                total_area,
            },
            &a,
        );
        assert!(none.is_none(), "no pairs, no shares");
    }
}
