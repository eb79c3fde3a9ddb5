//! Standard errors from the groups of a run (docs/results.md, "Standard errors").
//!
//! Batch `b` of a run belongs to group `b mod G`; every batch has its own random stream, so the groups
//! are independent. Every measure is computed on the whole run, on each group alone, and (for the
//! delete-a-group jackknife) on the run with each group left out; [`Spread`] turns those values into
//! the run's estimates ([`Estimate::from_groups`], [`Estimate::from_jackknife`]).

use crate::measure::Estimate;

/// How the standard errors of the measures built from pair counts (H_s, I_s, H(X, Y), E(MSE), the
/// corrected values, the accuracies and the radiosity measures) are estimated. I_s^c, a mean, always
/// gets batch means, which are exact for it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorMethod {
    /// Batch means: the spread of the G groups' own values / sqrt(G). Cheap, and conservative where the
    /// form-factor rows are undersampled (each group has 1/G of the lines).
    #[default]
    Groups,
    /// The delete-a-group jackknife: the spread of the G values with one group left out each. Closer to
    /// the real run-to-run scatter of undersampled measures (still conservative at the extreme), for about
    /// 15% more run time on a 5400-patch scene. Not for `--enclose` nor Chao–Shen: batch means there.
    Jackknife,
}

impl ErrorMethod {
    /// Every method with its name.
    pub const NAMES: [(&'static str, ErrorMethod); 2] = [
        ("groups", ErrorMethod::Groups),
        ("jackknife", ErrorMethod::Jackknife),
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            ErrorMethod::Groups => "groups",
            ErrorMethod::Jackknife => "jackknife",
        }
    }

    /// Parses a name as printed by [`ErrorMethod::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, m)| m)
    }
}

/// A run's values of some measures: on all its lines, on each group alone, and, for the jackknife, with
/// each group left out.
#[derive(Clone, Copy, Debug)]
pub struct Spread<'a, V> {
    /// The values on all the lines.
    pub all: &'a V,
    /// Each group's values.
    pub groups: &'a [V],
    /// The values with each group left out (`None`: batch means only).
    pub replicates: Option<&'a [V]>,
}

impl<V> Spread<'_, V> {
    /// The estimate of the measure `f` picks, with its batch-means standard error; `None` when the whole
    /// run has no value, no standard error when a group has none.
    pub fn batch_means(&self, f: impl Fn(&V) -> Option<f64>) -> Option<Estimate> {
        let value = f(self.all)?;
        let per: Vec<f64> = self.groups.iter().filter_map(&f).collect();
        Some(if per.len() == self.groups.len() {
            Estimate::from_groups(value, &per)
        } else {
            Estimate {
                value,
                stderr: None,
            }
        })
    }

    /// The delete-a-group jackknife's estimate of the bias of the measure `f` picks: `(G - 1)` times the
    /// mean of the values with one group left out less the value on all the lines, the bias of an
    /// estimator whose bias falls like 1 / lines (the replicates have `(G - 1) / G` of the lines). `None`
    /// without replicates or a value in each.
    pub fn jackknife_bias(&self, f: impl Fn(&V) -> Option<f64>) -> Option<f64> {
        let value = f(self.all)?;
        let reps: Vec<f64> = self.replicates?.iter().filter_map(&f).collect();
        let g = self.replicates?.len();
        if g < 2 || reps.len() != g || reps.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mean = reps.iter().sum::<f64>() / g as f64;
        Some((g - 1) as f64 * (mean - value))
    }

    /// The delete-a-group jackknife's bias-corrected estimate of the measure `f` picks: its value less
    /// [`Spread::jackknife_bias`], with the jackknife standard error (the spread of the pseudo-values
    /// `G x - (G - 1) x_(-g)`, whose mean this estimate is). The jackknife asks only that the groups be
    /// independent replicates of one sampling, so it corrects an estimator's leading 1 / lines bias
    /// however the lines within a group were drawn. `None` without replicates or a value in each.
    pub fn debiased(&self, f: impl Fn(&V) -> Option<f64>) -> Option<Estimate> {
        let bias = self.jackknife_bias(&f)?;
        let per: Vec<f64> = self.replicates?.iter().filter_map(&f).collect();
        let value = f(self.all)?;
        Some(Estimate {
            value: value - bias,
            stderr: Estimate::from_jackknife(value, &per).stderr,
        })
    }

    /// The estimate of the measure `f` picks, with the jackknife standard error when there are
    /// replicates and each has a value, else batch means.
    pub fn estimate(&self, f: impl Fn(&V) -> Option<f64>) -> Option<Estimate> {
        let value = f(self.all)?;
        let jackknife = self.replicates.and_then(|reps| {
            let per: Vec<f64> = reps.iter().filter_map(&f).collect();
            (per.len() == reps.len()).then(|| Estimate::from_jackknife(value, &per))
        });
        jackknife.or_else(|| self.batch_means(f))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An estimator whose bias is `c / k` on `k` of `G` independent groups (the plug-in entropy's leading
    /// term): the debiased estimate is the true value, to rounding, whatever the groups' own values;
    /// its standard error is the jackknife's.
    #[test]
    fn a_bias_falling_like_one_over_the_groups_is_taken_out() {
        let (truth, c, g) = (2.5, 0.3, 16usize);
        let all = truth + c / g as f64;
        // Replicates: G - 1 groups each, scattered about their expectation.
        let replicates: Vec<f64> = (0..g)
            .map(|i| truth + c / (g - 1) as f64 + 1e-3 * (i as f64 - 7.5))
            .collect();
        let groups = vec![0.0; g];
        let spread = Spread {
            all: &all,
            groups: &groups,
            replicates: Some(&replicates),
        };
        let e = spread.debiased(|&v| Some(v)).unwrap();
        assert!((e.value - truth).abs() < 1e-12, "{}", e.value);
        let jackknife = Estimate::from_jackknife(all, &replicates);
        assert_eq!(e.stderr, jackknife.stderr);
        let without = Spread {
            replicates: None,
            ..spread
        };
        assert_eq!(without.debiased(|&v| Some(v)), None);
    }
}
