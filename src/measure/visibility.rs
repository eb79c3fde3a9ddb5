//! Scene visibility complexity (paper sec. 3): entropies and mutual information of the form-factor channel.
//!
//! The channel's input and output are patches, with the area distribution `a_i = A_i / A_T` and the
//! form factors as transition matrix. Form factors are estimated from global-line pair counts as
//! `F_ij = N_ij / N_i`, where `N_i` counts the segments leaving patch i's front side (to another patch, or
//! escaping an open scene), so a row sums to 1 in a closed scene and reciprocity `A_i F_ij = A_j F_ji`
//! holds up to sampling error.

use super::channel::area_distribution;
use super::entropy::xlog2x;
use super::estimators::EntropyEstimator;
use super::rows::{RowSums, Rows};
use crate::sample::counts::PairCounts;

/// The discrete measures of one set of counts (paper sec. 3.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteValues {
    /// Eq. (19): H_p = -sum a_i log a_i, exact from the areas.
    pub positional_entropy: f64,
    /// Eq. (17): H_s = -sum_i a_i sum_j F_ij log F_ij.
    pub entropy: f64,
    /// H(X, Y) = -sum_ij a_i F_ij log(a_i F_ij) (= H_p + H_s in a closed scene).
    pub joint_entropy: f64,
    /// Eq. (21): I_s = sum_ij a_i F_ij log(F_ij / a_j) (= H_p - H_s, eq. (20), in a closed scene).
    pub mutual_information: f64,
    /// Eq. (22) times N: n_p - sum_ij F_ij^2, the expected form-factor MSE of a single line.
    pub mse_per_line: f64,
    /// Patches no line left from (their rows are empty and contribute nothing).
    pub unsampled_patches: usize,
    /// Their share of the total area.
    pub unsampled_area_fraction: f64,
}

/// The continuous measure of one set of pairs (paper sec. 3.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContinuousValues {
    /// Eq. (27): I_s^c, the mean of log2(A_T cos_x cos_y / (pi d^2)) over the segments leaving front
    /// sides (every pair is two of them, one from each end; a segment that arrives at no front side
    /// adds 0).
    pub mutual_information: f64,
}

impl ContinuousValues {
    /// Eq. (27) from the sum of its terms over `pairs` pairs and the `lost` segments that left a front
    /// side and arrived at no front side (escapes, segments to back sides); `None` without pairs.
    ///
    /// Eq. (25) integrates `F(x, y) log(A_T F(x, y)) / A_T` over every x and y; global lines sample x
    /// (area-uniform) and the direction (cosine-distributed) of each segment leaving a front side, and a
    /// direction in which x sees no front side has `F = 0` there. So the estimate is the sum over the
    /// pairs, each counted from both ends, over all those segments: `2 S / (2 P + L)`. In a closed scene
    /// `L = 0` and this is eq. (27)'s mean over pairs; in an open one it is on the same footing as the
    /// discrete measures, whose rows count the lost segments in `N_i` (Proposition 2 holds between the
    /// two).
    pub fn from_sum(sum: f64, pairs: u64, lost: u64) -> Option<Self> {
        (pairs > 0).then(|| ContinuousValues {
            mutual_information: 2.0 * sum / (2 * pairs + lost) as f64,
        })
    }
}

/// The discrete measures from the patch areas, the pair counts and the escapes per patch.
pub fn discrete(areas: &[f64], counts: &PairCounts, escapes: &[u64]) -> DiscreteValues {
    let a = area_distribution(areas);
    let a = a.as_slice().expect("a fresh array is contiguous");
    discrete_from_rows(
        a,
        &Rows::gather(a, counts, escapes, EntropyEstimator::PlugIn).sums,
    )
}

/// The discrete measures from the area fractions `a_i` and the rows' sums ([`Rows::gather`], any
/// estimator).
pub fn discrete_from_rows(a: &[f64], rows: &[RowSums]) -> DiscreteValues {
    let positional_entropy = -a.iter().map(|&x| xlog2x(x)).sum::<f64>();
    let (mut entropy, mut cross, mut area_term, mut sum_f2) = (0.0, 0.0, 0.0, 0.0);
    let mut unsampled_patches = 0;
    let mut unsampled_area_fraction = 0.0;
    for (&a_i, row) in a.iter().zip(rows) {
        if row.segments == 0 {
            unsampled_patches += 1;
            unsampled_area_fraction += a_i;
            continue;
        }
        entropy += a_i * row.plug_in_entropy();
        cross += a_i * row.cross_entropy_with_areas();
        // -sum_j a_i F_ij log2 a_i: the rows' mass on patches (escapes are no patch of eq. 17).
        area_term -= xlog2x(a_i) * (row.segments - row.escapes) as f64 / row.n();
        sum_f2 += row.sum_of_squares();
    }
    DiscreteValues {
        positional_entropy,
        entropy,
        joint_entropy: entropy + area_term,
        mutual_information: cross - entropy,
        mse_per_line: a.len() as f64 - sum_f2,
        unsampled_patches,
        unsampled_area_fraction,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::channel::{for_each_form_factor, row_totals};
    use crate::sample::counts::pair_key;

    /// Two facing patches of equal area that only see each other: F_01 = F_10 = 1, so H_s = 0 and
    /// I_s = H_p = 1 bit.
    #[test]
    fn two_patches_seeing_only_each_other() {
        let counts = PairCounts::from_keys(2, &mut [pair_key(0, 1); 10]);
        let v = discrete(&[1.0, 1.0], &counts, &[0, 0]);
        assert!((v.positional_entropy - 1.0).abs() < 1e-15);
        assert!(v.entropy.abs() < 1e-15);
        assert!((v.mutual_information - 1.0).abs() < 1e-15);
        assert!((v.joint_entropy - 1.0).abs() < 1e-15);
        assert!((v.mse_per_line - 0.0).abs() < 1e-15);
        assert_eq!(v.unsampled_patches, 0);
    }

    /// Independence: F_ij = a_j gives I_s = 0 and H_s = H_p (the sphere of sec. 3.1.2).
    #[test]
    fn independent_channel_has_zero_mutual_information() {
        // Three equal patches with rows (1/3, 1/3, 1/3): a self pair enters N_ii twice and an
        // off-diagonal pair once per direction, so off-diagonal pairs are drawn twice as often.
        let mut keys = Vec::new();
        for (i, j, c) in [
            (0, 0, 1),
            (1, 1, 1),
            (2, 2, 1),
            (0, 1, 2),
            (0, 2, 2),
            (1, 2, 2),
        ] {
            keys.extend(std::iter::repeat_n(pair_key(i, j), c));
        }
        let counts = PairCounts::from_keys(3, &mut keys);
        let v = discrete(&[1.0, 1.0, 1.0], &counts, &[0, 0, 0]);
        assert!(v.mutual_information.abs() < 1e-12, "{v:?}");
        assert!((v.entropy - 3f64.log2()).abs() < 1e-12);
    }

    /// The table-driven sums equal the definitions (eqs. 17, 21 and H(X,Y)) computed form factor by
    /// form factor, with counts below and above the table's size.
    #[test]
    fn measures_equal_their_definitions() {
        let areas = [1.0, 2.0, 0.5, 3.0];
        let mut keys = Vec::new();
        for (i, j, c) in [
            (0, 1, 3),
            (0, 2, 1500),
            (1, 1, 7),
            (1, 3, 2),
            (2, 3, 40),
            (3, 3, 1),
        ] {
            keys.extend(std::iter::repeat_n(pair_key(i, j), c));
        }
        let counts = PairCounts::from_keys(4, &mut keys);
        let escapes = [0, 5, 0, 2];
        let v = discrete(&areas, &counts, &escapes);
        let a = area_distribution(&areas);
        let n = row_totals(4, &counts, &escapes);
        let (mut h, mut joint, mut mi) = (0.0, 0.0, 0.0);
        for_each_form_factor(&counts, &n, |i, j, f| {
            h -= a[i] * xlog2x(f);
            joint -= xlog2x(a[i] * f);
            mi += a[i] * f * (f / a[j]).log2();
        });
        assert!((v.entropy - h).abs() < 1e-13, "{} vs {h}", v.entropy);
        assert!((v.joint_entropy - joint).abs() < 1e-13);
        assert!((v.mutual_information - mi).abs() < 1e-13);
    }

    #[test]
    fn unsampled_patches_are_reported_not_nan() {
        let counts = PairCounts::from_keys(3, &mut [pair_key(0, 1)]);
        let v = discrete(&[1.0, 1.0, 2.0], &counts, &[0, 0, 0]);
        assert_eq!(v.unsampled_patches, 1);
        assert!((v.unsampled_area_fraction - 0.5).abs() < 1e-15);
        assert!(v.entropy.is_finite() && v.mutual_information.is_finite());
    }
}
