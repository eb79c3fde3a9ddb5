//! An estimate with its standard error.
//!
//! Standard errors come from independent groups of lines: a run's batches are dealt into G groups
//! (each batch has its own random stream, so the groups are independent), every measure is also
//! computed on each group alone, and the standard error of the full-run value is the standard deviation
//! of the G group values divided by sqrt(G) ("batch means"). For a mean such as eq. (27) this is exact in
//! expectation; for the plug-in entropies and mutual information it measures the *statistical* error
//! only, not the bias of the plug-in estimate at a finite number of lines, and where form-factor rows are
//! undersampled it can be far off (a group alone is much sparser than the run). The delete-a-group
//! jackknife ([`Estimate::from_jackknife`], `--errors jackknife`) uses the values with one group left out
//! instead, which scatter like the full run's (docs/results.md, "Standard errors" and "The jackknife", for measurements of both).

use serde::Serialize;

/// A value and its standard error (absent when it cannot be estimated, e.g. from fewer than 2 groups).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// The estimate from all lines.
    pub value: f64,
    /// Its standard error.
    pub stderr: Option<f64>,
}

impl Estimate {
    /// An exact value (standard error 0), such as H_p from the areas.
    pub fn exact(value: f64) -> Self {
        Estimate {
            value,
            stderr: Some(0.0),
        }
    }

    /// The full-run `value` with the batch-means standard error of the group values.
    pub fn from_groups(value: f64, groups: &[f64]) -> Self {
        Estimate {
            value,
            stderr: batch_means_stderr(groups),
        }
    }
}

impl Estimate {
    /// The full-run `value` with the delete-a-group jackknife standard error of `replicates`, the values
    /// computed with one group left out each (G of them): `se^2 = (G - 1) / G * sum (x_g - mean)^2`.
    /// Each replicate holds (G - 1) / G of the lines, so for estimates that are nonlinear in the counts,
    /// such as the plug-in and bias-corrected entropies of undersampled rows, it behaves like the full
    /// run's estimate, where a group alone (1 / G of the lines) scatters more than sqrt(G) times as
    /// much, so that batch means overstate the error.
    pub fn from_jackknife(value: f64, replicates: &[f64]) -> Self {
        Estimate {
            value,
            stderr: jackknife_stderr(replicates),
        }
    }
}

impl Estimate {
    /// The interval `value ± quantile × stderr` (`None` without a standard error). With
    /// [`student_t_975`] of the run's degrees of freedom it is the 95% interval a report states.
    pub fn interval(&self, quantile: f64) -> Option<(f64, f64)> {
        let half = quantile * self.stderr?;
        Some((self.value - half, self.value + half))
    }
}

/// Student's t 0.975 quantile for `df` degrees of freedom: the half-width, in standard errors, of a 95%
/// interval whose standard error comes from `df + 1` groups. With 16 groups it is 2.131, not the normal
/// 1.960: the standard error is itself estimated from 16 numbers, and 1.96 of it covers about 93%.
/// Tabulated to 30 degrees of freedom, then the Cornish–Fisher expansion (error below 1e-6 there).
pub fn student_t_975(df: usize) -> f64 {
    const TABLE: [f64; 30] = [
        12.706205, 4.302653, 3.182446, 2.776445, 2.570582, 2.446912, 2.364624, 2.306004, 2.262157,
        2.228139, 2.200985, 2.178813, 2.160369, 2.144787, 2.131450, 2.119905, 2.109816, 2.100922,
        2.093024, 2.085963, 2.079614, 2.073873, 2.068658, 2.063899, 2.059539, 2.055529, 2.051831,
        2.048407, 2.045230, 2.042272,
    ];
    match df {
        0 => f64::INFINITY,
        1..=30 => TABLE[df - 1],
        _ => cornish_fisher_975(df as f64),
    }
}

/// The Cornish–Fisher expansion of Student's t quantile around the normal one (Abramowitz and Stegun
/// 26.7.5), at the 0.975 level.
fn cornish_fisher_975(n: f64) -> f64 {
    let z: f64 = 1.959_963_984_540_054;
    let g1 = (z.powi(3) + z) / 4.0;
    let g2 = (5.0 * z.powi(5) + 16.0 * z.powi(3) + 3.0 * z) / 96.0;
    let g3 = (3.0 * z.powi(7) + 19.0 * z.powi(5) + 17.0 * z.powi(3) - 15.0 * z) / 384.0;
    let g4 = (79.0 * z.powi(9) + 776.0 * z.powi(7) + 1482.0 * z.powi(5)
        - 1920.0 * z.powi(3)
        - 945.0 * z)
        / 92160.0;
    z + g1 / n + g2 / n.powi(2) + g3 / n.powi(3) + g4 / n.powi(4)
}

/// The delete-a-group jackknife standard error of leave-one-group-out values; `None` with fewer than 2
/// values or non-finite ones.
pub fn jackknife_stderr(replicates: &[f64]) -> Option<f64> {
    let g = replicates.len();
    if g < 2 || replicates.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mean = replicates.iter().sum::<f64>() / g as f64;
    let sum_sq = replicates.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
    Some(((g - 1) as f64 / g as f64 * sum_sq).sqrt())
}

/// Standard deviation of `values` divided by sqrt(len); `None` with fewer than 2 values or non-finite ones.
pub fn batch_means_stderr(values: &[f64]) -> Option<f64> {
    let n = values.len();
    if n < 2 || values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    Some((var / n as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For a mean, the jackknife of the leave-one-group-out means equals batch means of the groups.
    #[test]
    fn jackknife_of_a_mean_is_batch_means() {
        let groups = [1.0, 2.5, 3.0, 4.5, 2.0];
        let total: f64 = groups.iter().sum();
        let left_out: Vec<f64> = groups.iter().map(|g| (total - g) / 4.0).collect();
        let jk = jackknife_stderr(&left_out).unwrap();
        let bm = batch_means_stderr(&groups).unwrap();
        assert!((jk - bm).abs() < 1e-12, "{jk} vs {bm}");
        assert_eq!(jackknife_stderr(&[1.0]), None);
        assert_eq!(jackknife_stderr(&[1.0, f64::NAN]), None);
    }

    /// P(|T| <= t) for Student's t with `df` degrees of freedom, by Simpson's rule on its density.
    fn t_coverage(t: f64, df: f64) -> f64 {
        let ln_c = ln_gamma((df + 1.0) / 2.0)
            - ln_gamma(df / 2.0)
            - 0.5 * (df * std::f64::consts::PI).ln();
        let density = |x: f64| (ln_c - (df + 1.0) / 2.0 * (1.0 + x * x / df).ln()).exp();
        let n = 20_000;
        let h = t / n as f64;
        let mut sum = density(0.0) + density(t);
        for k in 1..n {
            sum += density(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        2.0 * sum * h / 3.0
    }

    /// ln Γ(x) by Lanczos (g = 7, 9 terms), enough for the test's 1e-7.
    fn ln_gamma(x: f64) -> f64 {
        const C: [f64; 9] = [
            0.999_999_999_999_809_9,
            676.520_368_121_885_1,
            -1_259.139_216_722_402_8,
            771.323_428_777_653_1,
            -176.615_029_162_140_6,
            12.507_343_278_686_905,
            -0.138_571_095_265_720_12,
            9.984_369_578_019_572e-6,
            1.505_632_735_149_311_6e-7,
        ];
        let x = x - 1.0;
        let mut a = C[0];
        let t = x + 7.5;
        for (i, c) in C.iter().enumerate().skip(1) {
            a += c / (x + i as f64);
        }
        0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
    }

    /// The tabulated and expanded quantiles hold 95% of Student's t, integrated independently.
    #[test]
    fn t_quantiles_hold_95_percent() {
        for df in [1usize, 2, 3, 5, 8, 15, 30, 31, 63, 255, 10_000] {
            let q = student_t_975(df);
            let p = t_coverage(q, df as f64);
            assert!((p - 0.95).abs() < 2e-6, "df {df}: t {q} holds {p}");
        }
        assert!((student_t_975(30) - cornish_fisher_975(30.0)).abs() < 1e-5);
        assert!((student_t_975(100_000) - 1.959964).abs() < 1e-4);
        assert_eq!(student_t_975(0), f64::INFINITY);
        let e = Estimate {
            value: 1.0,
            stderr: Some(0.5),
        };
        assert_eq!(e.interval(2.0), Some((0.0, 2.0)));
    }

    #[test]
    fn stderr_of_known_values() {
        // Sample sd of [1, 2, 3, 4] is sqrt(5/3); divided by 2.
        let s = batch_means_stderr(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert!((s - (5.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-15);
        assert_eq!(batch_means_stderr(&[1.0]), None);
        assert_eq!(batch_means_stderr(&[1.0, f64::NAN]), None);
    }
}
