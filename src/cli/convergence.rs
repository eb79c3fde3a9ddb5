//! `scx convergence`: the same scene at growing line counts, every measure with its error against run
//! time, as a table, a CSV file and a log-log plot.

use std::fmt::Write as _;

use scene_complexity::measure::Estimate;
use scene_complexity::run::Analysis;

use super::plot::{self, Curve};
use super::report::{self, Row};
use super::{write_stdout, ConvergenceArgs, Failure, Runner};

/// The measures followed, as (JSON key, short name, corrected?). The plot leaves H_s out: I_s = H_p - H_s
/// with H_p exact, so their errors are the same.
const FOLLOWED: [(&str, &str, bool); 5] = [
    ("mutual_information", "I_s", false),
    ("mutual_information", "I_s corrected", true),
    ("entropy", "H_s", false),
    ("entropy", "H_s corrected", true),
    ("continuous_mutual_information", "I_s^c", false),
];

/// The runs at one line count.
struct Level {
    lines: u64,
    runs: Vec<Analysis>,
}

impl Level {
    fn seconds(&self) -> f64 {
        mean(self.runs.iter().map(|a| a.seconds))
    }

    /// Mean value and mean standard error of a followed measure over the repeats.
    fn measure(&self, key: &str, corrected: bool) -> Option<(f64, f64)> {
        let estimates: Vec<Estimate> = self
            .runs
            .iter()
            .filter_map(|a| pick(a, key, corrected))
            .collect();
        if estimates.len() != self.runs.len() || estimates.is_empty() {
            return None;
        }
        let stderr = mean(estimates.iter().filter_map(|e| e.stderr));
        Some((mean(estimates.iter().map(|e| e.value)), stderr))
    }
}

fn pick(a: &Analysis, key: &str, corrected: bool) -> Option<Estimate> {
    let row: Row = report::measures(a).into_iter().find(|r| r.key == key)?;
    if corrected {
        row.corrected
    } else {
        row.estimate
    }
}

fn mean(xs: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = xs.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 {
        f64::NAN
    } else {
        sum / n as f64
    }
}

/// Runs the command.
pub fn run(args: &ConvergenceArgs) -> Result<(), Failure> {
    let runner = Runner::new(&args.scene, &args.run)?;
    let mut counts = args.lines.clone();
    counts.sort_unstable();
    counts.dedup();
    let mut levels = Vec::new();
    let mut csv =
        String::from("lines,repeat,seed,seconds,measure,value,stderr,corrected,corrected_stderr\n");
    for &lines in &counts {
        let mut runs = Vec::new();
        for r in 0..args.repeats {
            let seed = args.run.seed + u64::from(r);
            let mut a = runner.analyze(&runner.config(&args.run, lines, seed), Some(lines))?;
            append_csv(&mut csv, &a, r);
            // The counts are not needed any more; keep the measures only.
            a.tally.counts = None;
            let interrupted = a.stop_reason != scene_complexity::run::StopReason::Lines;
            runs.push(a);
            if interrupted {
                break;
            }
        }
        let interrupted = runs.last().is_some_and(|a| a.lines < lines);
        levels.push(Level { lines, runs });
        if interrupted {
            eprintln!("scx: interrupted: reporting the line counts gathered so far");
            break;
        }
    }
    if let Some(path) = &args.csv {
        std::fs::write(path, &csv).map_err(|e| Failure {
            code: 1,
            message: format!("{}: cannot write: {e}", path.display()),
        })?;
    }
    if let Some(path) = &args.plot {
        let title = format!(
            "{}: error against run time ({} tracer)",
            runner.scene.name,
            runner.tracer.name()
        );
        plot::write(path, &title, &curves(&levels))
            .map_err(|message| Failure { code: 1, message })?;
    }
    write_stdout(&table(&runner, &levels, args.repeats))
}

fn append_csv(csv: &mut String, a: &Analysis, repeat: u32) {
    for r in report::measures(a) {
        let Some(e) = r.estimate else { continue };
        let num = |x: Option<f64>| x.map(|v| v.to_string()).unwrap_or_default();
        let _ = writeln!(
            csv,
            "{},{repeat},{},{},{},{},{},{},{}",
            a.lines,
            a.seed,
            a.seconds,
            r.key,
            e.value,
            num(e.stderr),
            num(r.corrected.map(|c| c.value)),
            num(r.corrected.and_then(|c| c.stderr)),
        );
    }
}

/// For each followed measure: its standard error (solid) and its distance to the largest run (dashed).
fn curves(levels: &[Level]) -> Vec<Curve> {
    let mut out = Vec::new();
    let Some(last) = levels.last() else {
        return out;
    };
    for (colour, &(key, name, corrected)) in FOLLOWED
        .iter()
        .enumerate()
        .filter(|(_, f)| f.0 != "entropy")
    {
        let Some((reference, _)) = last.measure(key, corrected) else {
            continue;
        };
        let stderr: Vec<(f64, f64)> = levels
            .iter()
            .filter_map(|l| Some((l.seconds(), l.measure(key, corrected)?.1)))
            .filter(|&(s, e)| s > 0.0 && e > 0.0)
            .collect();
        let distance: Vec<(f64, f64)> = levels[..levels.len() - 1]
            .iter()
            .filter_map(|l| {
                Some((
                    l.seconds(),
                    (l.measure(key, corrected)?.0 - reference).abs(),
                ))
            })
            .filter(|&(s, e)| s > 0.0 && e > 0.0)
            .collect();
        out.push(Curve {
            label: format!("{name}: standard error"),
            colour,
            dashed: false,
            points: stderr,
        });
        if !distance.is_empty() {
            out.push(Curve {
                label: format!("{name}: |value - largest run|"),
                colour,
                dashed: true,
                points: distance,
            });
        }
    }
    out
}

fn table(runner: &Runner, levels: &[Level], repeats: u32) -> String {
    let mut s = String::new();
    let info = runner.info();
    let _ = writeln!(
        s,
        "scene {} ({} patches), tracer {}, {} thread(s), {repeats} run(s) per line count (means shown)\n",
        info.scene.name,
        info.scene.patch_count(),
        info.tracer,
        info.threads
    );
    let _ = write!(s, "{:>12} {:>9}", "lines", "seconds");
    for (_, name, _) in FOLLOWED {
        let _ = write!(s, " {:>22}", name);
    }
    let _ = writeln!(s);
    for l in levels {
        let _ = write!(s, "{:>12} {:>9.3}", l.lines, l.seconds());
        for (key, _, corrected) in FOLLOWED {
            let cell = match l.measure(key, corrected) {
                Some((v, e)) => format!("{v:.5} +- {e:.5}"),
                None => "-".into(),
            };
            let _ = write!(s, " {cell:>22}");
        }
        let _ = writeln!(s);
    }
    s
}
