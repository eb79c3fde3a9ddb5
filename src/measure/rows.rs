//! Per-row sums of the form-factor channel, gathered in one pass over the pair counts.
//!
//! Every discrete measure of sec. 3.1 and every bias-corrected row entropy but Chao–Shen's is a function
//! of a few sums over each row's outcome counts `x` (a pair count seen from one end; a patch's escapes are
//! one more outcome): with `N` the row's segments and `F = x / N`,
//!
//! * `-sum F log2 F = (P / N) log2 N - (1 / N) sum x log2 x` (P: the row's segments to patches),
//! * `-sum_j F_ij log2 a_j = -(1 / N) sum_j x_j log2 a_j`, `sum F^2 = (1 / N^2) sum x^2`,
//! * the unbiased part of Chao–Wang–Jost, `sum (x / N)(psi(N) - psi(x)) = psi(N) - (1 / N) sum x psi(x)`,
//!   and Grassberger's `ln N - (1 / N) sum x G(x)`.
//!
//! None of these sums needs `N` while it is gathered, so one streaming pass over the counts (each entry
//! feeding its two rows) replaces the six passes the definitions took: this runs for every
//! standard-error group and for the whole run, over every distinct visible pair, and those passes were
//! about a third of what an analysis of the 30 x 30 cube spent besides tracing (27 + 21 ms of 10^6
//! lines' 150 ms; 12 + 6 ms with one pass).

use super::estimators::{chao_wang_jost_unseen, digamma, grassberger_g, EntropyEstimator};
use crate::sample::counts::PairCounts;
use rayon::prelude::*;

/// The sums of one row (see the module documentation). Outcome counts are whole numbers, so the
/// integer parts are kept as integers: the segments as 64-bit, the outcomes (at most one per patch and
/// one for the escapes, and patches are numbered in 32 bits) as 32-bit. That makes a row 64 bytes, one
/// cache line when aligned: the pass over the counts reads a row for each end of each entry, mostly
/// at random, and a 72-byte row spanned two lines every time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(align(64))]
pub struct RowSums {
    /// `N_i`: segments leaving the patch's front side, to patches or escaping.
    pub segments: u64,
    /// Of them, the escapes.
    pub escapes: u64,
    /// Distinct outcomes seen (patches, and the escapes as one outcome).
    pub seen: u32,
    /// Outcomes seen exactly once (f1).
    pub singletons: u32,
    /// Outcomes seen exactly twice (f2).
    pub doubletons: u32,
    /// `sum x log2 x` over the patches seen.
    pub x_log2_x: f64,
    /// `sum x^2` over the patches seen.
    pub x_squared: f64,
    /// `sum_j x_j log2 a_j` over the patches seen (`a_j`: area fraction; `log2 0` read as 0).
    pub x_log2_area: f64,
    /// `sum x k(x)` over every outcome, escapes included, for the estimator's kernel `k`: `psi` for
    /// Chao–Wang–Jost, Grassberger's `G`, nothing (0) for the others.
    pub x_kernel: f64,
}

// One cache line a row (see [`RowSums`]).
const _: () = assert!(std::mem::size_of::<RowSums>() == 64);

/// Which per-outcome kernel [`RowSums::x_kernel`] sums for an estimator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kernel {
    None,
    Digamma,
    Grassberger,
}

impl Kernel {
    fn of(estimator: EntropyEstimator) -> Self {
        match estimator {
            EntropyEstimator::ChaoWangJost => Kernel::Digamma,
            EntropyEstimator::Grassberger => Kernel::Grassberger,
            _ => Kernel::None,
        }
    }

    fn eval(self, x: f64) -> f64 {
        match self {
            Kernel::None => 0.0,
            Kernel::Digamma => x * digamma(x),
            Kernel::Grassberger => x * grassberger_g(x),
        }
    }
}

/// `x log2 x` and `x k(x)` of small whole numbers from a table: pair counts are mostly small.
struct OutcomeTable {
    kernel: Kernel,
    x_log2_x: Vec<f64>,
    x_kernel: Vec<f64>,
}

impl OutcomeTable {
    const SIZE: u64 = 1024;

    fn new(kernel: Kernel) -> Self {
        let xs = (0..Self::SIZE).map(|x| x as f64);
        OutcomeTable {
            kernel,
            x_log2_x: xs.clone().map(super::entropy::xlog2x).collect(),
            x_kernel: xs
                .map(|x| if x > 0.0 { kernel.eval(x) } else { 0.0 })
                .collect(),
        }
    }

    /// `(x log2 x, x k(x))`.
    fn of(&self, x: u64) -> (f64, f64) {
        if x < Self::SIZE {
            (self.x_log2_x[x as usize], self.x_kernel[x as usize])
        } else {
            let xf = x as f64;
            (xf * xf.log2(), self.kernel.eval(xf))
        }
    }
}

impl RowSums {
    /// Counts one outcome seen `x` times in the integer sums only.
    fn count_outcome(&mut self, x: u64) {
        self.segments += x;
        self.seen += 1;
        self.singletons += u32::from(x == 1);
        self.doubletons += u32::from(x == 2);
    }

    fn add_patch_outcome(&mut self, x: u64, log2_area: f64, table: &OutcomeTable) {
        let (x_log2_x, x_kernel) = table.of(x);
        let xf = x as f64;
        self.count_outcome(x);
        self.x_log2_x += x_log2_x;
        self.x_squared += xf * xf;
        self.x_log2_area += xf * log2_area;
        self.x_kernel += x_kernel;
    }

    /// Takes one patch outcome seen `x` times out of the row again (the inverse of
    /// [`RowSums::add_patch_outcome`]).
    fn remove_patch_outcome(&mut self, x: u64, log2_area: f64, table: &OutcomeTable) {
        let (x_log2_x, x_kernel) = table.of(x);
        let xf = x as f64;
        self.segments -= x;
        self.seen -= 1;
        self.singletons -= u32::from(x == 1);
        self.doubletons -= u32::from(x == 2);
        self.x_log2_x -= x_log2_x;
        self.x_squared -= xf * xf;
        self.x_log2_area -= xf * log2_area;
        self.x_kernel -= x_kernel;
    }

    /// The row with one patch outcome seen `x` times seen `x - c` times instead.
    fn lower_patch_outcome(&mut self, x: u64, c: u64, log2_area: f64, table: &OutcomeTable) {
        self.remove_patch_outcome(x, log2_area, table);
        if x > c {
            self.add_patch_outcome(x - c, log2_area, table);
        }
    }

    fn add_escapes(&mut self, e: u64, table: &OutcomeTable) {
        if e == 0 {
            return;
        }
        self.count_outcome(e);
        self.escapes += e;
        self.x_kernel += table.of(e).1;
    }

    fn remove_escapes(&mut self, e: u64, table: &OutcomeTable) {
        if e == 0 {
            return;
        }
        self.segments -= e;
        self.escapes -= e;
        self.seen -= 1;
        self.singletons -= u32::from(e == 1);
        self.doubletons -= u32::from(e == 2);
        self.x_kernel -= table.of(e).1;
    }

    /// `N_i` as a float.
    pub fn n(&self) -> f64 {
        self.segments as f64
    }

    /// The plug-in entropy of the row over the patches, eq. (17)'s inner sum, in bits; 0 for an empty
    /// row.
    pub fn plug_in_entropy(&self) -> f64 {
        if self.segments == 0 {
            return 0.0;
        }
        let n = self.n();
        let to_patches = (self.segments - self.escapes) as f64;
        (to_patches * n.log2() - self.x_log2_x) / n
    }

    /// `-sum_j F_ij log2 a_j`, the row's part of the cross term `X` of [`super::bias`].
    pub fn cross_entropy_with_areas(&self) -> f64 {
        if self.segments == 0 {
            0.0
        } else {
            -self.x_log2_area / self.n()
        }
    }

    /// `sum_j F_ij^2`.
    pub fn sum_of_squares(&self) -> f64 {
        if self.segments == 0 {
            0.0
        } else {
            self.x_squared / (self.n() * self.n())
        }
    }

    /// The unbiased estimate of `sum_j F_ij^2` over the patches (escapes are an outcome, not a patch):
    /// `sum_j x_j (x_j - 1) / (N (N - 1))`, since a row's counts are a multinomial sample of its `N`
    /// segments and `E[x (x - 1)] = N (N - 1) F^2`. A row of fewer than two segments has none; its
    /// plug-in value stands in.
    pub fn unbiased_sum_of_squares(&self) -> f64 {
        let n = self.n();
        if n < 2.0 {
            return self.sum_of_squares();
        }
        let to_patches = (self.segments - self.escapes) as f64;
        (self.x_squared - to_patches) / (n * (n - 1.0))
    }

    /// The row's entropy over the patches, in bits, by `estimator` (which must be the one the sums were
    /// gathered for, see [`Rows`]); `None` for Chao–Shen, which needs each outcome with its row's size
    /// ([`super::bias`] computes it in a second pass).
    fn corrected_entropy(&self, estimator: EntropyEstimator) -> Option<f64> {
        if self.segments == 0 {
            return Some(0.0);
        }
        let n = self.n();
        let plug_in = self.plug_in_entropy();
        // Eq. (17) sums over patches: the escapes, an outcome of the estimators, take their own
        // (plug-in) term out again.
        let q = self.escapes as f64 / n;
        let escape_term = if q > 0.0 { q * q.ln() } else { 0.0 };
        let nats = match estimator {
            EntropyEstimator::PlugIn => return Some(plug_in),
            EntropyEstimator::ChaoShen => return None,
            EntropyEstimator::MillerMadow => {
                return Some(
                    plug_in + (self.seen as f64 - 1.0) / (2.0 * n) / std::f64::consts::LN_2,
                )
            }
            EntropyEstimator::Grassberger => n.ln() - self.x_kernel / n + escape_term,
            EntropyEstimator::ChaoWangJost => {
                digamma(n) - self.x_kernel / n
                    + chao_wang_jost_unseen(n, self.singletons as f64, self.doubletons as f64)
                    + escape_term
            }
        };
        Some(nats / std::f64::consts::LN_2)
    }
}

/// Every row's sums, and the estimator whose kernel [`RowSums::x_kernel`] holds.
#[derive(Clone, Debug)]
pub struct Rows {
    /// The estimator the rows were gathered for.
    pub estimator: EntropyEstimator,
    /// One per patch.
    pub sums: Vec<RowSums>,
}

impl Rows {
    /// Every row's sums in one pass over `counts` and the escapes per patch; `area_fractions` are the
    /// `a_i` (their logs enter [`RowSums::x_log2_area`]), `estimator` chooses the kernel summed in
    /// [`RowSums::x_kernel`].
    pub fn gather(
        area_fractions: &[f64],
        counts: &PairCounts,
        escapes: &[u64],
        estimator: EntropyEstimator,
    ) -> Self {
        let table = OutcomeTable::new(Kernel::of(estimator));
        let log2_area = log2_areas(area_fractions);
        let mut sums = vec![RowSums::default(); area_fractions.len().max(escapes.len())];
        counts.for_each(|i, j, c| {
            let (i, j) = (i as usize, j as usize);
            if i == j {
                // One segment from a patch back to itself enters N_ii twice (i -> j and j -> i).
                sums[i].add_patch_outcome(2 * c, log2_area[i], &table);
            } else {
                sums[i].add_patch_outcome(c, log2_area[j], &table);
                sums[j].add_patch_outcome(c, log2_area[i], &table);
            }
        });
        for (row, &e) in sums.iter_mut().zip(escapes) {
            row.add_escapes(e, &table);
        }
        Rows { estimator, sums }
    }

    /// Every row's integer sums alone (segments, escapes, outcomes seen, seen once, seen twice; the
    /// floating-point sums left 0) over `rows` patches: as many as [`Rows::gather`]'s and all that a
    /// row's coverage reads ([`crate::measure::sampling::lines_factor_for_coverage`]), at a fraction of
    /// its cost.
    pub fn outcome_frequencies(rows: usize, counts: &PairCounts, escapes: &[u64]) -> Vec<RowSums> {
        let mut sums = vec![RowSums::default(); rows.max(escapes.len())];
        counts.for_each(|i, j, c| {
            let (i, j) = (i as usize, j as usize);
            if i == j {
                sums[i].count_outcome(2 * c);
            } else {
                sums[i].count_outcome(c);
                sums[j].count_outcome(c);
            }
        });
        for (row, &e) in sums.iter_mut().zip(escapes) {
            if e > 0 {
                row.count_outcome(e);
                row.escapes += e;
            }
        }
        sums
    }

    /// The rows of `total` without one group's share of it (`group` with its escapes, a part of
    /// `total`): each of the group's outcomes is lowered by its count. This is a leave-one-group-out
    /// replicate of the delete-a-group jackknife ([`crate::measure::estimate::Estimate::from_jackknife`]),
    /// from one pass over the group's counts instead of a gather over all the others'.
    pub fn without_group(
        &self,
        area_fractions: &[f64],
        total: (&PairCounts, &[u64]),
        group: (&PairCounts, &[u64]),
    ) -> Rows {
        let table = OutcomeTable::new(Kernel::of(self.estimator));
        let log2_area = log2_areas(area_fractions);
        let mut sums = self.sums.clone();
        group.0.for_each_with_total(total.0, |i, j, c, x| {
            let (i, j) = (i as usize, j as usize);
            if i == j {
                sums[i].lower_patch_outcome(2 * x, 2 * c, log2_area[i], &table);
            } else {
                sums[i].lower_patch_outcome(x, c, log2_area[j], &table);
                sums[j].lower_patch_outcome(x, c, log2_area[i], &table);
            }
        });
        for ((row, &e), &g) in sums.iter_mut().zip(total.1).zip(group.1) {
            if g > 0 {
                row.remove_escapes(e, &table);
                row.add_escapes(e - g, &table);
            }
        }
        Rows {
            estimator: self.estimator,
            sums,
        }
    }

    /// Each row's entropy over the patches (bits) by the rows' estimator; `None` for Chao–Shen.
    pub fn corrected_entropies(&self) -> Option<Vec<f64>> {
        let of = |r: &RowSums| r.corrected_entropy(self.estimator);
        // A row's unseen-outcome sum takes up to thousands of terms: many rows are shared out (each row
        // on its own, so the values do not depend on the threads).
        if self.sums.len() >= PARALLEL_ROWS {
            return self.sums.par_iter().map(of).collect();
        }
        self.sums.iter().map(of).collect()
    }
}

/// From this many rows on, [`Rows::corrected_entropies`] shares them out among threads.
const PARALLEL_ROWS: usize = 1024;

/// `log2 a_i`, read as 0 for a patch without area (it meets no line, so no count needs it).
fn log2_areas(area_fractions: &[f64]) -> Vec<f64> {
    area_fractions
        .iter()
        .map(|&a| if a > 0.0 { a.log2() } else { 0.0 })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::counts::pair_key;

    /// Keys of pairs among `patches` patches, skewed so that counts range from 1 to thousands, with
    /// self pairs.
    fn keys(seed: u64, n: usize, patches: u32) -> Vec<u64> {
        let mut rng = seed;
        (0..n)
            .map(|_| {
                rng = rng
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let i = ((rng >> 33) % u64::from(patches)) as u32;
                let j = if (rng >> 20) % 7 == 0 {
                    i
                } else {
                    ((rng >> 45) % 4) as u32 * (i % 3)
                };
                pair_key(i, j)
            })
            .collect()
    }

    /// The unbiased `sum_j F_ij^2` has the row's exact `sum_j F_ij^2` as its expectation over every
    /// multinomial sample of 2 to 7 segments (three patches and the escapes as a fourth outcome, which
    /// is no patch), where the plug-in's is higher by `sum_j F_ij (1 - F_ij) / N`.
    #[test]
    fn the_unbiased_sum_of_squares_has_the_exact_expectation() {
        let p = [0.5, 0.3, 0.15, 0.05];
        let exact: f64 = p[..3].iter().map(|q| q * q).sum();
        let spread: f64 = p[..3].iter().map(|q| q * (1.0 - q)).sum();
        let factorial = |k: u64| (1..=k).map(|v| v as f64).product::<f64>();
        for n in 2u64..=7 {
            let (mut unbiased, mut plug_in, mut total) = (0.0, 0.0, 0.0);
            for x0 in 0..=n {
                for x1 in 0..=n - x0 {
                    for x2 in 0..=n - x0 - x1 {
                        let xs = [x0, x1, x2, n - x0 - x1 - x2];
                        let prob = factorial(n)
                            * xs.iter()
                                .zip(p)
                                .map(|(&x, q)| q.powi(x as i32) / factorial(x))
                                .product::<f64>();
                        let row = RowSums {
                            segments: n,
                            escapes: xs[3],
                            x_squared: xs[..3].iter().map(|&x| (x * x) as f64).sum(),
                            ..RowSums::default()
                        };
                        unbiased += prob * row.unbiased_sum_of_squares();
                        plug_in += prob * row.sum_of_squares();
                        total += prob;
                    }
                }
            }
            assert!((total - 1.0).abs() < 1e-12, "{n}: {total}");
            assert!(
                (unbiased - exact).abs() < 1e-12,
                "{n}: {unbiased} vs {exact}"
            );
            let expected = exact + spread / n as f64;
            assert!(
                (plug_in - expected).abs() < 1e-12,
                "{n}: {plug_in} vs {expected}"
            );
        }
    }

    /// A row's integer sums counted straight from the keys (a map of outcomes per row, a segment from a
    /// patch to itself twice), in both count layouts, with escapes; and the same as a full gather's.
    #[test]
    fn outcome_frequencies_count_each_rows_outcomes() {
        use std::collections::BTreeMap;
        for patches in [40u32, 3000] {
            let n = patches as usize;
            let mut ks = keys(3, 20_000, patches);
            let counts = PairCounts::from_keys(n, &mut ks.clone());
            let escapes: Vec<u64> = (0..n as u64)
                .map(|i| [0, 1, 2, 5][(i % 4) as usize])
                .collect();
            let mut outcomes = vec![BTreeMap::<u64, u64>::new(); n];
            for k in ks.drain(..) {
                let (i, j) = crate::sample::counts::split_key(k);
                let (i, j) = (i as usize, j as usize);
                *outcomes[i].entry(j as u64).or_default() += 1;
                *outcomes[j].entry(i as u64).or_default() += 1;
            }
            let rows = Rows::outcome_frequencies(n, &counts, &escapes);
            let a = vec![1.0 / n as f64; n];
            let gathered = Rows::gather(&a, &counts, &escapes, EntropyEstimator::ChaoWangJost);
            for i in 0..n {
                let mut xs: Vec<u64> = outcomes[i].values().copied().collect();
                if escapes[i] > 0 {
                    xs.push(escapes[i]);
                }
                let expected = (
                    xs.iter().sum::<u64>(),
                    escapes[i],
                    xs.len() as u32,
                    xs.iter().filter(|&&x| x == 1).count() as u32,
                    xs.iter().filter(|&&x| x == 2).count() as u32,
                );
                let of = |r: &RowSums| (r.segments, r.escapes, r.seen, r.singletons, r.doubletons);
                assert_eq!(of(&rows[i]), expected, "{patches} patches, row {i}");
                assert_eq!(
                    of(&gathered.sums[i]),
                    expected,
                    "{patches} patches, row {i}"
                );
            }
        }
    }

    /// Lowering the total's rows by a group's counts gives the rows of the other groups' counts, for every
    /// estimator with a one-pass kernel, in both count layouts.
    #[test]
    fn rows_without_a_group_are_the_rows_of_the_rest() {
        for patches in [40u32, 3000] {
            let (rest_keys, group_keys) = (keys(1, 20_000, patches), keys(2, 3_000, patches));
            let n = patches as usize;
            let areas: Vec<f64> = (0..n).map(|i| 1.0 + (i % 5) as f64).collect();
            let a: Vec<f64> = areas
                .iter()
                .map(|x| x / areas.iter().sum::<f64>())
                .collect();
            let rest = PairCounts::from_keys(n, &mut rest_keys.clone());
            let group = PairCounts::from_keys(n, &mut group_keys.clone());
            let mut all = [rest_keys, group_keys.clone()].concat();
            let total = PairCounts::from_keys(n, &mut all);
            let mut rest_escapes = vec![0u64; n];
            let mut group_escapes = vec![0u64; n];
            (
                rest_escapes[1],
                rest_escapes[2],
                group_escapes[2],
                group_escapes[3],
            ) = (5, 1, 1, 7);
            let total_escapes: Vec<u64> = rest_escapes
                .iter()
                .zip(&group_escapes)
                .map(|(r, g)| r + g)
                .collect();
            for estimator in [
                EntropyEstimator::PlugIn,
                EntropyEstimator::MillerMadow,
                EntropyEstimator::Grassberger,
                EntropyEstimator::ChaoWangJost,
            ] {
                let direct = Rows::gather(&a, &rest, &rest_escapes, estimator);
                let lowered = Rows::gather(&a, &total, &total_escapes, estimator).without_group(
                    &a,
                    (&total, &total_escapes),
                    (&group, &group_escapes),
                );
                for (i, (d, l)) in direct.sums.iter().zip(&lowered.sums).enumerate() {
                    let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * x.abs().max(1.0);
                    assert_eq!(
                        (d.segments, d.escapes, d.seen, d.singletons, d.doubletons),
                        (l.segments, l.escapes, l.seen, l.singletons, l.doubletons),
                        "{estimator:?}, {patches} patches, row {i}"
                    );
                    assert!(
                        close(d.x_log2_x, l.x_log2_x)
                            && close(d.x_squared, l.x_squared)
                            && close(d.x_log2_area, l.x_log2_area)
                            && close(d.x_kernel, l.x_kernel),
                        "{estimator:?}, {patches} patches, row {i}: {d:?} vs {l:?}"
                    );
                }
                let (hd, hl) = (
                    direct.corrected_entropies().unwrap(),
                    lowered.corrected_entropies().unwrap(),
                );
                for (x, y) in hd.iter().zip(&hl) {
                    assert!((x - y).abs() < 1e-9, "{estimator:?}: {x} vs {y}");
                }
            }
        }
    }
}
