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

    #[test]
    fn stderr_of_known_values() {
        // Sample sd of [1, 2, 3, 4] is sqrt(5/3); divided by 2.
        let s = batch_means_stderr(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert!((s - (5.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-15);
        assert_eq!(batch_means_stderr(&[1.0]), None);
        assert_eq!(batch_means_stderr(&[1.0, f64::NAN]), None);
    }
}
