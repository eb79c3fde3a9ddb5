//! The calibration table as Markdown, and as CSV (one row per cell, measure and basis; and the raw
//! readings, one row per run and measure).

use std::fmt::Write as _;

use super::driver::GROUPS;
use super::summary::{Summary, NORMAL_95};
use super::truth::Basis;
use super::CellReport;
use crate::measure::{student_t_975, Measure};

/// `x` with `digits` significant digits, without an exponent for the magnitudes of the measures.
fn significant(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let magnitude = x.abs().log10().floor() as i64;
    let decimals = (digits as i64 - 1 - magnitude).clamp(0, 12) as usize;
    format!("{x:.decimals$}")
}

fn percent(share: Option<f64>) -> String {
    share.map_or("-".into(), |s| format!("{:.1}%", 100.0 * s))
}

fn signed(x: f64) -> String {
    if x.is_finite() {
        format!("{x:+.2}")
    } else {
        "-".into()
    }
}

/// A measure's name in the CSV files: its key, prefixed by `radiosity_` for sec. 4's (the catalogue's
/// keys are unique within a family only).
pub fn measure_name(m: Measure) -> String {
    let info = m.info();
    match info.family {
        crate::measure::Family::Visibility => info.key.to_string(),
        family => format!("{}_{}", family.name(), info.key),
    }
}

/// The measure's symbol, with the basis when the scene has two.
fn measure_label(s: &Summary) -> String {
    let symbol = s.measure.info().symbol;
    match s.basis {
        Basis::Closed => symbol.to_string(),
        basis => format!("{symbol} ({})", basis.name()),
    }
}

/// The header of the Markdown table, naming the multipliers.
pub fn markdown_header() -> String {
    let dof = GROUPS - 1;
    format!(
        "Each row: the runs of one cell (scene, lines, seeds 1..=n) against one exact value. `cover`: \
         share of readings whose stated 95% interval, value ± t se, holds the exact value, with t \
         Student's 97.5% quantile for the run's groups with lines less one ({:.3} for the default {GROUPS} \
         groups of independent lines, {dof} degrees of freedom; `runs` names the degrees of freedom of \
         runs with other group counts: sobol's 8, --groups, or too few lines); `cover 1.96`: the same with the normal {:.2}; `ok`: share of readings marked ok; \
         `cover if ok`: share of the ok readings that cover; `z`: (value - exact) / se, its mean and \
         standard deviation (near 1 when the standard errors are right: {:.2} for t with {dof} degrees of \
         freedom; below 1 when too wide); `met`: runs declaring their precision target met, and the share \
         of those that cover.\n\n\
         | scene | lines | runs | measure | exact | mean value | mean se | cover | cover 1.96 | ok | cover if ok | mean z | sd z | met |\n\
         |---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
        student_t_975(dof),
        NORMAL_95,
        (dof as f64 / (dof as f64 - 2.0)).sqrt(),
    )
}

/// The `runs` cell: the judged runs, with their degrees of freedom when they are not the default's.
fn runs_label(s: &Summary) -> String {
    let default = GROUPS - 1;
    match s.degrees_of_freedom {
        (lo, hi) if lo == default && hi == default => s.runs.to_string(),
        (lo, hi) if lo == hi => format!("{} ({lo} dof)", s.runs),
        (lo, hi) => format!("{} ({lo}-{hi} dof)", s.runs),
    }
}

/// The Markdown rows of one cell.
pub fn markdown_rows(report: &CellReport) -> String {
    let mut out = String::new();
    for s in &report.summaries {
        let lines = if report.cell.target.is_some() {
            format!("{} (mean {:.3e})", s.lines, s.mean_lines)
        } else {
            s.lines.clone()
        };
        let met = s.met.map_or("-".into(), |(met, _)| {
            format!("{met}/{}, {} cover", s.runs, percent(s.met_coverage()))
        });
        let _ = writeln!(
            out,
            "| `{}` | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            s.scene,
            lines,
            runs_label(s),
            measure_label(s),
            significant(s.exact, 7),
            significant(s.mean_value, 7),
            significant(s.mean_stderr, 3),
            percent(s.coverage()),
            percent(s.coverage_normal()),
            percent(s.ok_share()),
            percent(s.ok_coverage()),
            signed(s.mean_z),
            if s.sd_z.is_finite() {
                format!("{:.2}", s.sd_z)
            } else {
                "-".into()
            },
            met
        );
    }
    out
}

/// The whole table.
pub fn markdown(reports: &[CellReport]) -> String {
    let mut out = markdown_header();
    for r in reports {
        out.push_str(&markdown_rows(r));
    }
    out
}

/// Quotes a CSV field when it holds a comma, a quote or a line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// One CSV row per cell, measure and basis: counts, not only shares, so that cells can be pooled.
pub fn summary_csv(reports: &[CellReport]) -> String {
    let mut out = String::from(
        "scene,lines,target_measure,target_stderr,seeds,mean_lines,measure,basis,exact,runs,\
         without_stderr,dof_min,dof_max,mean_value,mean_stderr,covered,covered_normal,with_verdict,ok,\
         ok_covered,mean_z,sd_z,met,met_covered\n",
    );
    for r in reports {
        let (tm, ts) = r.cell.target.map_or((String::new(), String::new()), |t| {
            (t.measure.key().to_string(), t.stderr.to_string())
        });
        for s in &r.summaries {
            let (met, met_covered) = s.met.map_or((String::new(), String::new()), |(a, b)| {
                (a.to_string(), b.to_string())
            });
            let _ = writeln!(
                out,
                "{},{},{},{},{},{},{},{},{:e},{},{},{},{},{:e},{:e},{},{},{},{},{},{},{},{},{}",
                field(&s.scene),
                r.cell.lines,
                tm,
                ts,
                s.seeds,
                s.mean_lines,
                measure_name(s.measure),
                s.basis.name(),
                s.exact,
                s.runs,
                s.without_stderr,
                s.degrees_of_freedom.0,
                s.degrees_of_freedom.1,
                s.mean_value,
                s.mean_stderr,
                s.covered,
                s.covered_normal,
                s.with_verdict,
                s.ok,
                s.ok_covered,
                s.mean_z,
                s.sd_z,
                met,
                met_covered
            );
        }
    }
    out
}

/// One CSV row per run and reading: the raw material, for pooling cells or trying other multipliers
/// without running again.
pub fn readings_csv(reports: &[CellReport]) -> String {
    let mut out = String::from(
        "scene,cell_lines,seed,lines,groups,target_met,measure,value,stderr,verdict\n",
    );
    for r in reports {
        let scene = r.cell.scene.name();
        for run in &r.runs {
            for (measure, reading) in run.readings.iter() {
                let _ = writeln!(
                    out,
                    "{},{},{},{},{},{},{},{:e},{},{}",
                    field(&scene),
                    r.cell.lines,
                    run.seed,
                    run.lines,
                    run.groups,
                    run.target_met.map_or(String::new(), |m| m.to_string()),
                    measure_name(measure),
                    reading.estimate.value,
                    reading
                        .estimate
                        .stderr
                        .map_or(String::new(), |s| format!("{s:e}")),
                    reading.verdict.map_or("", |v| v.name())
                );
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_their_significant_digits() {
        assert_eq!(significant(1.609_312_345, 7), "1.609312");
        assert_eq!(significant(5_394.123_456, 7), "5394.123");
        assert_eq!(significant(0.001_234_56, 3), "0.00123");
        assert_eq!(field("a,b"), "\"a,b\"");
    }

    /// CSV names are unique across the families (the catalogue's keys are unique within one).
    #[test]
    fn measure_names_are_unique() {
        let names: std::collections::BTreeSet<String> =
            Measure::ALL.into_iter().map(measure_name).collect();
        assert_eq!(names.len(), Measure::COUNT);
        assert_eq!(measure_name(Measure::RadiosityEntropy), "radiosity_entropy");
    }
}
