//! The sparse form-factor matrix of a run (`--form-factors`): `F_ij = N_ij / N_i`, the share of patch
//! i's segments that end on patch j (the Monte Carlo estimate of eq. 2 by global lines, sec. 2.3).
//!
//! An enclosed open scene (`--enclose`) has the environment as row and column `patches`: `F_i,env =
//! escapes_i / N_i`, `F_env,j = escapes_j / N_env` and `F_env,env = 2 misses / N_env`, so that every
//! row sums to 1 ([`crate::sample::environment`]).

use rayon::prelude::*;

use crate::analysis::Analysis;
use crate::sample::counts::PairCounts;

/// The non-zero entries of F with their counts, and each row's total.
#[derive(Clone, Debug)]
pub struct FormFactors {
    /// The matrix is `patches x patches` (the scene's patches, and the environment after them when the
    /// run's measures are those of the enclosed scene).
    pub patches: usize,
    /// Every `(i, j, N_ij)` with `N_ij > 0`, both directions of each pair, sorted by `i` then `j`; a
    /// segment from a patch back to itself enters `N_ii` twice (as in the measures).
    pub entries: Vec<(u32, u32, u64)>,
    /// `N_i`: each row's pair counts plus the segments it lost (escapes and segments to back sides),
    /// so that `F_ij` is the geometric form factor whatever else the row loses.
    pub row_totals: Vec<u64>,
}

impl FormFactors {
    /// The matrix of a run of a scene of `patches` patches that counted patch pairs (`None` when it did
    /// not: `--measures` without `discrete`); of the enclosed scene, `patches + 1` square, when the run's
    /// measures are ([`Analysis::enclosed`]).
    pub fn of(a: &Analysis, patches: usize) -> Option<FormFactors> {
        if a.enclosed {
            let counts = a.tally.enclosed_counts(patches)?;
            return Some(FormFactors::of_counts(
                patches + 1,
                &counts,
                &a.tally.enclosed_lost(patches),
            ));
        }
        let counts = a.tally.counts.as_ref()?;
        Some(FormFactors::of_counts(
            patches,
            counts,
            &a.tally.lost_by_patch(),
        ))
    }

    fn of_counts(patches: usize, counts: &PairCounts, lost: &[u64]) -> FormFactors {
        let entries = ordered_entries(counts);
        let row_totals = row_totals(patches, &entries, lost);
        FormFactors {
            patches,
            entries,
            row_totals,
        }
    }

    /// Entry `k`'s `F_ij` and standard error ([`form_factor`]).
    pub fn value(&self, k: usize) -> (f64, f64) {
        let (i, _, c) = self.entries[k];
        form_factor(c, self.row_totals[i as usize])
    }
}

fn ordered_entries(counts: &PairCounts) -> Vec<(u32, u32, u64)> {
    let mut entries = Vec::with_capacity(2 * counts.distinct_pairs());
    counts.for_each(|i, j, c| {
        if i == j {
            entries.push((i, i, 2 * c));
        } else {
            entries.push((i, j, c));
            entries.push((j, i, c));
        }
    });
    entries.par_sort_unstable_by_key(|&(i, j, _)| (i, j));
    entries
}

fn row_totals(patches: usize, entries: &[(u32, u32, u64)], lost: &[u64]) -> Vec<u64> {
    let mut n = lost.to_vec();
    n.resize(patches, 0);
    for &(i, _, c) in entries {
        n[i as usize] += c;
    }
    n
}

/// `F_ij = N_ij / N_i` and its binomial standard error `sqrt(F (1 - F) / N_i)` (the error of a row's
/// share).
pub fn form_factor(count: u64, total: u64) -> (f64, f64) {
    let n = total as f64;
    let f = count as f64 / n;
    (f, (f * (1.0 - f) / n).max(0.0).sqrt())
}
