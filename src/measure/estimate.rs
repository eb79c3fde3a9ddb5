//! An estimate with its standard error.
//!
//! Standard errors come from independent groups of lines: a run is cut into G groups of consecutive
//! batches (each batch has its own random stream, so the groups are independent), every measure is also
//! computed on each group alone, and the standard error of the full-run value is the standard deviation
//! of the G group values divided by sqrt(G) ("batch means"). For a mean such as eq. (27) this is exact in
//! expectation; for the plug-in entropies and mutual information it is the usual delta-method
//! approximation and measures the *statistical* error only, not the bias of the plug-in estimate at a
//! finite number of lines.

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

    #[test]
    fn stderr_of_known_values() {
        // Sample sd of [1, 2, 3, 4] is sqrt(5/3); divided by 2.
        let s = batch_means_stderr(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert!((s - (5.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-15);
        assert_eq!(batch_means_stderr(&[1.0]), None);
        assert_eq!(batch_means_stderr(&[1.0, f64::NAN]), None);
    }
}
