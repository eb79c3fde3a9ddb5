//! Bias-corrected H_s and I_s for undersampled form-factor rows.
//!
//! The plug-in H_s (eq. 17) puts the estimated `F_ij = N_ij / N_i` into `-F log F`. Row i is a multinomial
//! sample of its `N_i` segments over the patches it sees, and the plug-in entropy of an undersampled
//! multinomial is biased low (unseen patches count as impossible), so H_s reads low and I_s = H_p - H_s
//! high: on the 30 x 30 cube at 10^7 lines each row holds ~2400 segments spread over ~1800 effectively
//! visible patches, and the plug-in I_s is 70% too high (paper Table 2 shows the same).
//!
//! Each estimator here replaces the plug-in entropy of every row by a less biased one; H_s is their
//! area-weighted sum, and `I_s = X - H_s` where `X = -sum_i a_i sum_j F_ij log a_j` is linear in F (so its
//! ratio estimate is nearly unbiased; `X = H_p` in a closed scene). Escapes of an open scene are one more
//! outcome of the row, whose own plug-in term is removed again, since eq. (17) sums over patches only.
//!
//! * Miller–Madow (1955): plug-in + (m - 1) / (2N) nats, m the outcomes seen. First order only.
//! * Grassberger (2003): ln N - (1/N) sum_k n_k G(n_k), G(n) = psi(n) + (-1)^n / 2 (psi((n+1)/2) - psi(n/2)).
//! * Chao–Shen (2003): coverage-adjusted Horvitz–Thompson, C = 1 - f1/N, p = C n/N,
//!   H = -sum p ln p / (1 - (1 - p)^N).
//! * Chao–Wang–Jost (2013): sum over seen outcomes of (n_k/N)(psi(N) - psi(n_k)) plus a term for the
//!   unseen ones from the singletons f1 and doubletons f2; nearly unbiased even when most outcomes are
//!   unseen.

use ndarray::Array1;

use super::channel::{area_distribution, row_totals};
use super::estimators::{chao_wang_jost_unseen, digamma, grassberger_g, EntropyEstimator};
use super::rows::Rows;
use crate::sample::counts::PairCounts;

/// Bias-corrected discrete measures (bits).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CorrectedValues {
    /// Eq. (17) with every row's entropy estimated by the chosen estimator.
    pub entropy: f64,
    /// `X - H_s` (eq. 20 in a closed scene).
    pub mutual_information: f64,
    /// Eq. (22) per line, `n_p - sum_ij F_ij^2`, with each row's `sum_j F_ij^2` estimated without bias
    /// ([`super::rows::RowSums::unbiased_sum_of_squares`]): the plug-in reads it low by
    /// `sum_i sum_j F_ij (1 - F_ij) / N_i`.
    pub mse_per_line: f64,
}

/// Per-row statistics gathered in a first pass over the counts.
struct RowStats {
    total: Array1<f64>,
    singletons: Array1<f64>,
    doubletons: Array1<f64>,
    seen: Array1<f64>,
}

/// Visits every outcome count of every row: `(row, count)` for each patch pair in both directions, and
/// each row's escapes as one more outcome.
fn for_each_outcome(counts: &PairCounts, escapes: &[u64], mut f: impl FnMut(usize, f64)) {
    counts.for_each(|i, j, c| {
        if i == j {
            f(i as usize, 2.0 * c as f64);
        } else {
            f(i as usize, c as f64);
            f(j as usize, c as f64);
        }
    });
    for (i, &e) in escapes.iter().enumerate() {
        if e > 0 {
            f(i, e as f64);
        }
    }
}

fn row_stats(patches: usize, counts: &PairCounts, escapes: &[u64]) -> RowStats {
    let mut s = RowStats {
        total: row_totals(patches, counts, escapes),
        singletons: Array1::zeros(patches),
        doubletons: Array1::zeros(patches),
        seen: Array1::zeros(patches),
    };
    for_each_outcome(counts, escapes, |i, x| {
        s.seen[i] += 1.0;
        if x == 1.0 {
            s.singletons[i] += 1.0;
        } else if x == 2.0 {
            s.doubletons[i] += 1.0;
        }
    });
    s
}

/// The bias-corrected H_s and I_s from the patch areas, pair counts and escapes.
pub fn corrected(
    areas: &[f64],
    counts: &PairCounts,
    escapes: &[u64],
    estimator: EntropyEstimator,
) -> CorrectedValues {
    let a = area_distribution(areas);
    let a = a.as_slice().expect("a fresh array is contiguous");
    corrected_from_rows(
        a,
        &Rows::gather(a, counts, escapes, estimator),
        counts,
        escapes,
    )
}

/// The bias-corrected H_s and I_s from the area fractions `a_i` and the rows' sums; the counts and
/// escapes they were gathered from are read again only by Chao–Shen.
pub fn corrected_from_rows(
    a: &[f64],
    rows: &Rows,
    counts: &PairCounts,
    escapes: &[u64],
) -> CorrectedValues {
    let entropies = rows.corrected_entropies().unwrap_or_else(|| {
        let stats = row_stats(rows.sums.len(), counts, escapes);
        row_entropies(counts, escapes, rows.estimator, &stats).to_vec()
    });
    let entropy: f64 = a.iter().zip(&entropies).map(|(a, h)| a * h).sum();
    let cross: f64 = a
        .iter()
        .zip(&rows.sums)
        .map(|(a, r)| a * r.cross_entropy_with_areas())
        .sum();
    // Summed as the plug-in's `sum F^2` is ([`super::visibility::discrete_from_rows`]): rows without
    // segments add nothing.
    let sum_f2: f64 = a
        .iter()
        .zip(&rows.sums)
        .filter(|(_, r)| r.segments > 0)
        .map(|(_, r)| r.unbiased_sum_of_squares())
        .sum();
    CorrectedValues {
        entropy,
        mutual_information: cross - entropy,
        mse_per_line: a.len() as f64 - sum_f2,
    }
}

/// Each row's entropy over the patches (bits) by `estimator`: `-sum_j F_ij log2 F_ij` corrected for
/// undersampling; 0 for a row without samples.
fn row_entropies(
    counts: &PairCounts,
    escapes: &[u64],
    estimator: EntropyEstimator,
    stats: &RowStats,
) -> Array1<f64> {
    let n_p = stats.total.len();
    let coverage = stats_coverage(stats);
    let mut nats = Array1::<f64>::zeros(n_p);
    for_each_outcome(counts, escapes, |i, x| {
        nats[i] += outcome_term(estimator, x, stats.total[i], coverage[i]);
    });
    for i in 0..n_p {
        let n = stats.total[i];
        if n == 0.0 {
            continue;
        }
        nats[i] += row_term(
            estimator,
            n,
            stats.seen[i],
            stats.singletons[i],
            stats.doubletons[i],
        );
        // Eq. (17) sums over patches: take the escapes' own (plug-in) term out again.
        let q = escapes.get(i).map_or(0.0, |&e| e as f64 / n);
        if q > 0.0 {
            nats[i] += q * q.ln();
        }
    }
    nats / std::f64::consts::LN_2
}

/// How much `estimator` raises each row's entropy above the plug-in value (bits): the per-row bias
/// correction, which [`crate::measure::radiosity`] applies to the rows of the radiosity channel.
pub fn row_corrections(
    counts: &PairCounts,
    escapes: &[u64],
    estimator: EntropyEstimator,
) -> Array1<f64> {
    let n = escapes.len().max(row_count(counts));
    // The areas do not enter a row's entropy.
    let rows = Rows::gather(&vec![0.0; n], counts, escapes, estimator);
    let corrected = rows.corrected_entropies().map_or_else(
        || {
            let stats = row_stats(n, counts, escapes);
            row_entropies(counts, escapes, estimator, &stats)
        },
        Array1::from,
    );
    let plug_in: Array1<f64> = rows.sums.iter().map(|r| r.plug_in_entropy()).collect();
    corrected - plug_in
}

/// The number of rows the counts need (largest patch index + 1).
fn row_count(counts: &PairCounts) -> usize {
    let mut n = 0;
    counts.for_each(|_, j, _| n = n.max(j as usize + 1));
    n
}

/// Chao–Shen sample coverage per row, `1 - f1/N` (kept above 1/N so that no probability vanishes).
fn stats_coverage(s: &RowStats) -> Array1<f64> {
    ndarray::Zip::from(&s.total)
        .and(&s.singletons)
        .map_collect(|&n, &f1| {
            if n <= 0.0 {
                1.0
            } else {
                (1.0 - f1.min(n - 1.0) / n).max(1.0 / n)
            }
        })
}

/// The contribution (nats) of one outcome seen `x` times in a row of `n` samples.
fn outcome_term(estimator: EntropyEstimator, x: f64, n: f64, coverage: f64) -> f64 {
    match estimator {
        EntropyEstimator::PlugIn | EntropyEstimator::MillerMadow => {
            let p = x / n;
            -p * p.ln()
        }
        EntropyEstimator::Grassberger => -x / n * grassberger_g(x),
        EntropyEstimator::ChaoShen => {
            let p = coverage * x / n;
            let seen_probability = 1.0 - (1.0 - p).powf(n);
            -p * p.ln() / seen_probability
        }
        EntropyEstimator::ChaoWangJost => {
            if x < n {
                x / n * (digamma(n) - digamma(x))
            } else {
                0.0
            }
        }
    }
}

/// The per-row part (nats) of an estimator, given the row's size, outcomes seen, singletons, doubletons.
fn row_term(estimator: EntropyEstimator, n: f64, seen: f64, f1: f64, f2: f64) -> f64 {
    match estimator {
        EntropyEstimator::PlugIn | EntropyEstimator::ChaoShen => 0.0,
        EntropyEstimator::MillerMadow => (seen - 1.0) / (2.0 * n),
        EntropyEstimator::Grassberger => n.ln(),
        EntropyEstimator::ChaoWangJost => chao_wang_jost_unseen(n, f1, f2),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::counts::pair_key;

    /// The one-pass row sums ([`Rows`]) give every estimator's row entropies as the per-outcome
    /// definitions do, on rows of every size (singletons, doubletons, counts beyond the tables, self
    /// pairs, escapes, an empty row).
    #[test]
    fn row_sums_equal_the_per_outcome_definitions() {
        use rand::{Rng, SeedableRng};
        let patches = 60;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
        let mut keys = Vec::new();
        for _ in 0..3000 {
            let i = rng.gen_range(0..patches - 1);
            // Skewed partners: some pairs gather thousands of counts, most a few.
            let j = (i + rng.gen_range(0..patches - 1) * rng.gen_range(0..2)) % (patches - 1);
            keys.push(pair_key(i as u32, j as u32));
        }
        keys.extend(std::iter::repeat_n(pair_key(3, 4), 1500));
        let counts = PairCounts::from_keys(patches, &mut keys);
        let mut escapes = vec![0u64; patches];
        escapes[2] = 1;
        escapes[5] = 2;
        escapes[7] = 2000;
        for estimator in EntropyEstimator::ALL {
            let rows = Rows::gather(&vec![0.0; patches], &counts, &escapes, estimator);
            let stats = row_stats(patches, &counts, &escapes);
            let reference = row_entropies(&counts, &escapes, estimator, &stats);
            let ours = rows.corrected_entropies();
            if estimator == EntropyEstimator::ChaoShen {
                assert!(ours.is_none(), "Chao-Shen needs its second pass");
                continue;
            }
            for (i, (a, b)) in ours.unwrap().iter().zip(&reference).enumerate() {
                assert!((a - b).abs() < 1e-12, "{estimator:?} row {i}: {a} vs {b}");
            }
        }
    }

    /// With every outcome seen many times the corrections vanish: all estimators agree with the plug-in.
    #[test]
    fn well_sampled_rows_need_no_correction() {
        let mut keys = Vec::new();
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            keys.extend(std::iter::repeat_n(pair_key(i, j), 100_000));
        }
        let counts = PairCounts::from_keys(3, &mut keys);
        let plug = corrected(&[1.0; 3], &counts, &[0; 3], EntropyEstimator::PlugIn);
        assert!((plug.entropy - 1.0).abs() < 1e-12, "{plug:?}");
        for e in EntropyEstimator::ALL {
            let c = corrected(&[1.0; 3], &counts, &[0; 3], e);
            assert!((c.entropy - plug.entropy).abs() < 1e-4, "{e:?}: {c:?}");
            assert!((c.mutual_information - (3f64.log2() - c.entropy)).abs() < 1e-12);
        }
    }

    /// Undersampled uniform rows: a row over 400 equally likely patches sampled 400 times. The plug-in
    /// reads far below log2(400); the corrected estimators come much closer.
    #[test]
    fn corrections_reduce_the_bias_of_an_undersampled_uniform_row() {
        use rand::{Rng, SeedableRng};
        let n = 401usize;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let mut keys = Vec::new();
        // Patch 0 sends 400 segments uniformly to patches 1..=400 (only row 0 is of interest).
        for _ in 0..400 {
            keys.push(pair_key(0, rng.gen_range(1..n as u32)));
        }
        let counts = PairCounts::from_keys(n, &mut keys);
        // Only patch 0 has area, so H_s is row 0's entropy.
        let mut areas = vec![1e-300; n];
        areas[0] = 1.0;
        let truth = 400f64.log2();
        let err = |e| (corrected(&areas, &counts, &[0; 401], e).entropy - truth).abs();
        let plug = err(EntropyEstimator::PlugIn);
        assert!(plug > 0.4, "plug-in error {plug}");
        for e in [
            EntropyEstimator::Grassberger,
            EntropyEstimator::ChaoShen,
            EntropyEstimator::ChaoWangJost,
        ] {
            assert!(err(e) < 0.5 * plug, "{e:?}: {} vs plug-in {plug}", err(e));
        }
    }
}
