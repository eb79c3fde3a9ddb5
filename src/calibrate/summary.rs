//! What the runs of a cell say about each measure's standard error and verdict, against the exact value:
//! how often the stated 95% interval covers the truth, how often the reading is marked `ok` and how often
//! an `ok` reading covers, and how far off the readings are in standard errors.
//!
//! The stated interval is the one each run reports ([`crate::Analysis::interval_95`]): `value ± t se`, with
//! `t` Student's 97.5% quantile for the run's groups with lines less one degree of freedom (a standard
//! error from G groups is itself estimated from G values: 2.131 for the default 16 groups). The normal
//! 1.96 is counted beside it, to show what the multiplier alone changes.

use super::driver::SeedReadings;
use super::suite::Cell;
use super::truth::{Basis, ExactValue, Truth};
use crate::analysis::Verdict;
use crate::measure::Measure;

/// The normal 97.5% quantile: `value ± 1.96 se`, the interval of a standard error known exactly.
pub const NORMAL_95: f64 = 1.959_963_984_540_054;

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
pub fn summarize(cell: &Cell, truth: &Truth, runs: &[SeedReadings]) -> Vec<Summary> {
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
                    covered: r
                        .interval_95
                        .is_some_and(|(lo, hi)| lo <= exact.value && exact.value <= hi),
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
    use crate::calibrate::quadrature::Rule;
    use crate::measure::student_t_975;

    /// The `p` quantile (`p` in (0.5, 1)) of Student's t distribution with `dof` degrees of freedom, by
    /// bisection on its distribution function, itself a tanh–sinh quadrature of the density: a second
    /// way to the multiplier of the stated intervals.
    fn student_t_quantile(p: f64, dof: f64) -> f64 {
        let rule = Rule::tanh_sinh(6);
        let density = |t: f64| (1.0 + t * t / dof).powf(-(dof + 1.0) / 2.0);
        // The half line by t = s / (1 - s).
        let half = rule.integrate(0.0, 1.0, |s| {
            let t = s / (1.0 - s);
            density(t) / ((1.0 - s) * (1.0 - s))
        });
        let (mut lo, mut hi) = (0.0, 1000.0);
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            let tail = 0.5 * (1.0 - rule.integrate(0.0, mid, density) / half);
            if tail > 1.0 - p {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// The multiplier of the stated intervals, the library's table and expansion, against the quantile
    /// by quadrature for every degree of freedom a run of up to 1024 groups can have, and the tables'
    /// 2.131 for 15.
    #[test]
    fn the_stated_intervals_multiplier_is_students_quantile() {
        assert!((student_t_quantile(0.975, 15.0) - 2.131_449_546).abs() < 1e-6);
        assert!((student_t_quantile(0.975, 1.0) - 12.706_204_736).abs() < 1e-6);
        for dof in (1..=64).chain([100, 255, 1023]) {
            let (table, quadrature) = (student_t_975(dof), student_t_quantile(0.975, dof as f64));
            assert!(
                (table - quadrature).abs() < 2e-6,
                "{dof} degrees of freedom: {table} vs {quadrature}"
            );
        }
    }
}
