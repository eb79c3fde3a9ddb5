//! What the runs of a cell say about each measure's standard error and verdict, against the exact value:
//! how often the stated 95% interval covers the truth, how often the reading is marked `ok` and how often
//! an `ok` reading covers, and how far off the readings are in standard errors.
//!
//! The stated interval is `value ± t se`, with `t` Student's 97.5% quantile for the run's groups with
//! lines less one degree of freedom (a standard error from G groups is itself estimated from G values:
//! 2.131 for the default 16 groups). The normal 1.96 is counted beside it, to show what the multiplier
//! alone changes.

use std::collections::HashMap;

use super::driver::SeedReadings;
use super::quadrature::Rule;
use super::suite::Cell;
use super::truth::{Basis, ExactValue, Truth};
use crate::analysis::Verdict;
use crate::measure::Measure;

/// The normal 97.5% quantile: `value ± 1.96 se`, the interval of a standard error known exactly.
pub const NORMAL_95: f64 = 1.959_963_984_540_054;

/// The `p` quantile (`p` in (0.5, 1)) of Student's t distribution with `dof` degrees of freedom, by
/// bisection on its distribution function, itself a quadrature of the density (no special-function
/// crate needed for one number per degree of freedom).
pub fn student_t_quantile(p: f64, dof: f64) -> f64 {
    let rule = Rule::tanh_sinh(6);
    let density = |t: f64| (1.0 + t * t / dof).powf(-(dof + 1.0) / 2.0);
    // The half line by t = s / (1 - s).
    let half = rule.integrate(0.0, 1.0, |s| {
        let t = s / (1.0 - s);
        density(t) / ((1.0 - s) * (1.0 - s))
    });
    let upper_tail = 1.0 - p;
    // 64 halvings of [0, 1000] reach below the f64 spacing near the quantiles asked for (2 to 13).
    let (mut lo, mut hi) = (0.0, 1000.0);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        let inner = rule.integrate(0.0, mid, density);
        let tail = 0.5 * (1.0 - inner / half);
        if tail > upper_tail {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Student's 97.5% quantiles by degrees of freedom, each computed once (a cell's runs share a few).
#[derive(Clone, Debug, Default)]
pub struct StudentQuantiles {
    known: HashMap<usize, f64>,
}

impl StudentQuantiles {
    /// The multiplier of the stated 95% interval of a standard error from `groups` groups:
    /// Student's t with `groups - 1` degrees of freedom (at least 1).
    pub fn multiplier(&mut self, groups: usize) -> f64 {
        let dof = groups.saturating_sub(1).max(1);
        *self
            .known
            .entry(dof)
            .or_insert_with(|| student_t_quantile(0.975, dof as f64))
    }
}

/// The judgement of one measure of one cell against one exact value.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The scene's name.
    pub scene: String,
    /// The cell's lines ([`Cell::lines_label`]).
    pub lines: String,
    /// Runs in the cell.
    pub seeds: u64,
    /// Mean lines cast per run (differs from the cell's lines with a target).
    pub mean_lines: f64,
    /// The measure.
    pub measure: Measure,
    /// The reading of the exact value.
    pub basis: Basis,
    /// The exact value.
    pub exact: f64,
    /// Runs that gave the reading with a positive standard error (the judged ones).
    pub runs: usize,
    /// Runs that gave the reading without one (a group without a value): never judged, so counted
    /// apart rather than silently dropped.
    pub without_stderr: usize,
    /// The fewest and the most degrees of freedom of the judged runs' intervals (groups with lines
    /// less one).
    pub degrees_of_freedom: (usize, usize),
    /// Mean of the readings.
    pub mean_value: f64,
    /// Mean of their standard errors.
    pub mean_stderr: f64,
    /// Readings whose stated interval, `value ± t se`, holds the exact value.
    pub covered: usize,
    /// Readings whose `value ± 1.96 se` holds it.
    pub covered_normal: usize,
    /// Readings with a verdict (none for the radiosity H_p).
    pub with_verdict: usize,
    /// Readings marked `ok`.
    pub ok: usize,
    /// `ok` readings whose stated interval covers.
    pub ok_covered: usize,
    /// Mean of `(value - exact) / se`.
    pub mean_z: f64,
    /// Standard deviation of `(value - exact) / se` (about 1 when the standard errors are right, a
    /// little more from 16 groups: Student's t with 15 degrees of freedom has sd 1.07; below 1 they are
    /// too wide).
    pub sd_z: f64,
    /// For the measure a target watches: runs that declared the target met, and of those, how many
    /// cover (stated interval).
    pub met: Option<(usize, usize)>,
}

impl Summary {
    /// Share of judged readings covered by the stated interval.
    pub fn coverage(&self) -> Option<f64> {
        share(self.covered, self.runs)
    }

    /// Share of judged readings covered by `value ± 1.96 se`.
    pub fn coverage_normal(&self) -> Option<f64> {
        share(self.covered_normal, self.runs)
    }

    /// Share of the readings with a verdict marked ok.
    pub fn ok_share(&self) -> Option<f64> {
        share(self.ok, self.with_verdict)
    }

    /// Share of ok readings that cover.
    pub fn ok_coverage(&self) -> Option<f64> {
        share(self.ok_covered, self.ok)
    }

    /// Share of the runs declaring their target met that cover.
    pub fn met_coverage(&self) -> Option<f64> {
        self.met.and_then(|(met, covered)| share(covered, met))
    }
}

fn share(part: usize, whole: usize) -> Option<f64> {
    (whole > 0).then(|| part as f64 / whole as f64)
}

/// One reading against the truth: its error in standard errors, and whether each interval covers.
struct Judged {
    z: f64,
    value: f64,
    stderr: f64,
    dof: usize,
    covered: bool,
    covered_normal: bool,
    verdict: Option<Verdict>,
    met: Option<bool>,
}

impl Judged {
    fn ok(&self) -> bool {
        self.verdict == Some(Verdict::Ok)
    }
}

/// Every measure of a cell's runs against every exact value the truth has for it, in catalogue order.
pub fn summarize(
    cell: &Cell,
    truth: &Truth,
    runs: &[SeedReadings],
    quantiles: &mut StudentQuantiles,
) -> Vec<Summary> {
    let mean_lines = runs.iter().map(|r| r.lines as f64).sum::<f64>() / runs.len().max(1) as f64;
    let target_measure = cell.target.map(|t| t.measure);
    let mut out = Vec::new();
    for measure in Measure::ALL {
        for exact in truth.of(measure) {
            let mut without_stderr = 0;
            let mut judged = Vec::new();
            for run in runs {
                let Some(r) = run.of(measure) else { continue };
                let Some(se) = r.estimate.stderr.filter(|s| s.is_finite() && *s > 0.0) else {
                    without_stderr += 1;
                    continue;
                };
                let error = r.estimate.value - exact.value;
                judged.push(Judged {
                    z: error / se,
                    value: r.estimate.value,
                    stderr: se,
                    dof: run.groups.saturating_sub(1),
                    covered: error.abs() <= quantiles.multiplier(run.groups) * se,
                    covered_normal: error.abs() <= NORMAL_95 * se,
                    verdict: r.verdict,
                    met: run.target_met.filter(|_| target_measure == Some(measure)),
                });
            }
            if judged.is_empty() {
                continue;
            }
            out.push(summary_of(
                cell,
                truth,
                exact,
                &judged,
                without_stderr,
                mean_lines,
            ));
        }
    }
    out
}

fn summary_of(
    cell: &Cell,
    truth: &Truth,
    exact: &ExactValue,
    judged: &[Judged],
    without_stderr: usize,
    mean_lines: f64,
) -> Summary {
    let count = |f: &dyn Fn(&Judged) -> bool| judged.iter().filter(|j| f(j)).count();
    let n = judged.len() as f64;
    let mean = |f: &dyn Fn(&Judged) -> f64| judged.iter().map(f).sum::<f64>() / n;
    let mean_z = mean(&|j| j.z);
    let sd_z = if judged.len() > 1 {
        (judged.iter().map(|j| (j.z - mean_z).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        f64::NAN
    };
    let met = judged.iter().any(|j| j.met.is_some()).then(|| {
        (
            count(&|j| j.met == Some(true)),
            count(&|j| j.met == Some(true) && j.covered),
        )
    });
    let dofs = judged.iter().map(|j| j.dof);
    Summary {
        scene: truth.scene.clone(),
        lines: cell.lines_label(),
        seeds: cell.seeds,
        mean_lines,
        measure: exact.measure,
        basis: exact.basis,
        exact: exact.value,
        runs: judged.len(),
        without_stderr,
        degrees_of_freedom: (dofs.clone().min().unwrap_or(0), dofs.max().unwrap_or(0)),
        mean_value: mean(&|j| j.value),
        mean_stderr: mean(&|j| j.stderr),
        covered: count(&|j| j.covered),
        covered_normal: count(&|j| j.covered_normal),
        with_verdict: count(&|j| j.verdict.is_some()),
        ok: count(&|j| j.ok()),
        ok_covered: count(&|j| j.ok() && j.covered),
        mean_z,
        sd_z,
        met,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Student's t quantiles against the tables, and the first term of the Cornish–Fisher expansion
    /// `z + (z^3 + z) / (4 dof)` for many degrees of freedom.
    #[test]
    fn student_quantiles_match_the_tables() {
        let z = NORMAL_95;
        let large = 1e6;
        for (dof, q) in [
            (1.0, 12.706_204_736),
            (15.0, 2.131_449_546),
            (large, z + (z.powi(3) + z) / (4.0 * large)),
        ] {
            let got = student_t_quantile(0.975, dof);
            assert!((got - q).abs() < 1e-6, "dof {dof}: {got} vs {q}");
        }
        let mut cache = StudentQuantiles::default();
        assert!((cache.multiplier(16) - 2.131_449_546).abs() < 1e-6);
        assert_eq!(cache.multiplier(1), cache.multiplier(2), "at least 1 dof");
    }
}
