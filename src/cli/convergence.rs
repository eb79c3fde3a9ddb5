//! `scx convergence`: the same scene at growing line counts, every measure with its error against run
//! time, as a table or JSON, a CSV file and a log-log plot.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::ValueEnum;
use scene_complexity::report::reliability_json;
use scene_complexity::Analysis;
use scene_complexity::RunWarningKind;
use scene_complexity::StopReason;
use scene_complexity::Verdict;
use scene_complexity::{Estimate, Measure};
use serde_json::json;

use super::args::{parse_count, parse_whole_in, ReportOutput, RunOptions};
use super::exit::{Exit, Failure};
use super::file_kind::{check_csv, report_format, Kind, ReportFormat};
use super::output::{self, check_all, note, warn};
use super::plot::{self, Curve, Series};
use super::report;
use super::runner::Runner;
use super::table::{fixed, Align, Table};

/// Arguments of `scx convergence`.
#[derive(clap::Args, Debug)]
pub struct ConvergenceArgs {
    /// The scene: a file in OBJ, glTF/GLB, PLY or STL (told by its content), a built-in such as
    /// `@cube:30` (`scx scenes` lists them), or `-` for a scene on standard input.
    scene: String,
    /// The line counts to run, comma separated (accepts `1e6`), counted through the bounding sphere as
    /// `scx analyze --lines` counts them.
    #[arg(long, value_delimiter = ',', value_parser = parse_count, default_value = "1e4,1e5,1e6,1e7",
          allow_hyphen_values = true)]
    lines: Vec<u64>,
    /// Runs per line count (seeds seed, seed+1, ...).
    #[arg(long, default_value_t = 1, value_parser = parse_repeats, allow_negative_numbers = true)]
    repeats: u32,
    #[command(flatten)]
    run: RunOptions,
    /// Output format of the report: `table` or `json` (every run's measures with units and verdicts);
    /// default: `json` when -o names a .json file, else `table`.
    #[arg(long, value_enum)]
    format: Option<ConvergenceFormat>,
    #[command(flatten)]
    out: ReportOutput,
    /// Also write every run's measures as CSV to FILE (.csv; the rows of `analyze --format csv`, with
    /// the run's repeat and seconds).
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Also draw error against run time, log-log, to FILE (.svg or .png).
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ConvergenceFormat {
    Table,
    Json,
}

impl ReportFormat for ConvergenceFormat {
    fn kind(self) -> Kind {
        match self {
            ConvergenceFormat::Table => Kind::Text,
            ConvergenceFormat::Json => Kind::Json,
        }
    }
}

/// The measures followed (the catalogue's, in their column order).
/// `--repeats`: runs per line count, 1 to 1000.
fn parse_repeats(s: &str) -> Result<u32, String> {
    parse_whole_in(s, "the number of runs per line count", 1, 1000).map(|n| n as u32)
}

fn followed() -> Vec<Measure> {
    let mut all: Vec<Measure> = Measure::ALL
        .into_iter()
        .filter(|m| m.info().followed.is_some())
        .collect();
    all.sort_by_key(|m| m.info().followed);
    all
}

/// Whether the plot shows `m`: not the entropies, since I_s = H_p - H_s with H_p exact, so their errors
/// are I_s's.
fn plotted(m: Measure) -> bool {
    let (plain, corrected) = m.info().family.entropies();
    m != plain && m != corrected
}

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
    fn measure(&self, m: Measure) -> Option<(f64, f64)> {
        let estimates: Vec<Estimate> = self.runs.iter().filter_map(|a| a.estimate(m)).collect();
        if estimates.len() != self.runs.len() || estimates.is_empty() {
            return None;
        }
        let stderr = mean(estimates.iter().filter_map(|e| e.stderr));
        Some((mean(estimates.iter().map(|e| e.value)), stderr))
    }

    /// Whether a repeat's reading of `m` breaks a bound of the theory: their mean is then marked, as
    /// `analyze` marks the reading.
    fn flagged(&self, m: Measure) -> bool {
        self.runs
            .iter()
            .any(|a| report::flagged(a.reliability.get(m)))
    }

    /// The worst verdict of the repeats' readings of `m` (`None`: no verdict, as for the exact H_p).
    fn worst_verdict(&self, m: Measure) -> Option<Verdict> {
        self.runs
            .iter()
            .filter_map(|a| a.reliability.get(m).map(|r| r.verdict))
            .max()
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

/// Runs `scx convergence`.
pub fn run(args: &ConvergenceArgs) -> Result<Exit, Failure> {
    let format = report_format(
        "convergence",
        args.format,
        args.out.output.as_deref(),
        " (the runs as CSV: --csv FILE)",
    )?;
    check_csv("--csv", args.csv.as_deref())?;
    let mut outputs: Vec<(&str, &std::path::Path)> = Vec::new();
    outputs.extend(args.out.output.as_deref().map(|p| ("-o", p)));
    outputs.extend(args.csv.as_deref().map(|p| ("--csv", p)));
    outputs.extend(args.plot.as_deref().map(|p| ("--plot", p)));
    let scene = std::path::Path::new(&args.scene);
    output::check_distinct(&outputs, &[("scene", scene)], &[])?;
    check_all(outputs.iter().map(|(_, p)| *p))?;
    if let Some(p) = &args.plot {
        plot::check_target(p).map_err(Failure::bad_input)?;
    }
    let runner = Runner::new(&args.scene, &args.run)?;
    output::check_not_read_by(&outputs, &runner.scene)?;
    let mut counts = args.lines.clone();
    counts.sort_unstable();
    counts.dedup();
    let mut levels = Vec::new();
    let mut interrupted = false;
    // Each run's warnings, as `analyze` prints them, once each (the scene's own recur in every run).
    let mut warned: Vec<String> = Vec::new();
    let total_runs = counts.len() as u32 * args.repeats;
    'counts: for (k, &lines) in counts.iter().enumerate() {
        let mut runs = Vec::new();
        for r in 0..args.repeats {
            let seed = args.run.seed.value + u64::from(r);
            let label = format!(
                "run {} of {total_runs}: {lines:.0e} lines, seed {seed}",
                k as u32 * args.repeats + r + 1
            );
            let mut a = runner.analyze(args.run.spec(lines, seed), &label)?;
            for w in &a.warnings {
                if !warned.contains(&w.message) {
                    warn(&format!("{lines} lines, seed {seed}: {}", w.message));
                    warned.push(w.message.clone());
                }
            }
            // The counts are not needed any more; keep the measures only.
            a.tally.counts = None;
            let stopped = a.stop_reason != StopReason::Lines;
            runs.push(a);
            if stopped {
                interrupted = true;
                levels.push(Level { lines, runs });
                break 'counts;
            }
        }
        levels.push(Level { lines, runs });
    }
    if interrupted {
        note("interrupted: reporting the runs finished so far");
    }
    let info = runner.info();
    if let Some(message) = undefined_measures(&runner.scene.name, &levels) {
        warn(&message);
    }
    if let Some(path) = &args.csv {
        output::write_file(path, csv(&info, &levels).as_bytes())?;
    }
    let mut plot_written = false;
    if let Some(path) = &args.plot {
        let title = format!(
            "{}: error against run time ({} tracer, {} thread(s))",
            runner.scene.name,
            runner.tracer().name(),
            runner.threads
        );
        let curves = curves(&levels);
        if let Some(why) = empty_plot(&levels, &curves) {
            note(&format!("no plot written: {}: {why}", path.display()));
        } else {
            plot::write(path, &title, &curves).map_err(|message| Failure {
                code: Exit::Io,
                message,
            })?;
            output::wrote(path);
            plot_written = true;
        }
    }
    let text = match format {
        ConvergenceFormat::Table => table(&info, &levels, args.repeats, plot_written),
        ConvergenceFormat::Json => json_report(&info, &levels, args.repeats),
    };
    output::emit(args.out.output.as_deref(), &text)?;
    Ok(if interrupted {
        Exit::Interrupted
    } else {
        Exit::Ok
    })
}

/// The followed measures no run estimated.
fn undefined(levels: &[Level]) -> Vec<Measure> {
    followed()
        .into_iter()
        .filter(|&m| {
            levels
                .iter()
                .flat_map(|l| l.runs.iter())
                .all(|a| a.estimate(m).is_none())
        })
        .collect()
}

/// Which measures no run estimated, and why (the runs' `no-pairs` warning when they gave one);
/// `None` when every measure has a value somewhere.
fn undefined_measures(scene: &str, levels: &[Level]) -> Option<String> {
    let undefined = undefined(levels);
    if undefined.is_empty() || levels.is_empty() {
        return None;
    }
    let symbols: Vec<&str> = undefined.iter().map(|m| m.info().symbol).collect();
    let prefix = format!("{scene}: ");
    let why = levels
        .iter()
        .flat_map(|l| l.runs.iter())
        .flat_map(|a| a.warnings.iter())
        .find(|w| w.kind == RunWarningKind::NoPairs)
        .map(|w| {
            w.message
                .strip_prefix(&prefix)
                .unwrap_or(&w.message)
                .to_string()
        })
        .unwrap_or_else(|| "no run could estimate them".to_string());
    Some(format!(
        "{prefix}{} undefined at every line count: {why}",
        symbols.join(", ")
    ))
}

/// Why the plot would be empty (`None`: it has points).
fn empty_plot(levels: &[Level], curves: &[Curve]) -> Option<&'static str> {
    if curves.iter().any(|c| !c.points.is_empty()) {
        return None;
    }
    let undefined = undefined(levels);
    Some(
        if followed()
            .into_iter()
            .filter(|&m| plotted(m))
            .all(|m| undefined.contains(&m))
        {
            "every measure it would show is undefined"
        } else {
            "no measure it shows has a positive error at any line count"
        },
    )
}

/// Every run's `analyze --format csv` rows (which hold its seconds), with the repeat in front.
fn csv(info: &report::RunInfo, levels: &[Level]) -> String {
    let mut out = String::new();
    for (k, l) in levels.iter().enumerate() {
        for (r, a) in l.runs.iter().enumerate() {
            let rows = report::csv(info, a);
            for (n, line) in rows.lines().enumerate() {
                if n == 0 {
                    if k == 0 && r == 0 {
                        let _ = writeln!(out, "repeat,{line}");
                    }
                    continue;
                }
                let _ = writeln!(out, "{r},{line}");
            }
        }
    }
    out
}

/// Every run as JSON: the settings, then each run's lines (drawn, and the lines through the bounding
/// sphere they are worth, the count asked, as `analyze` gives them), seed, seconds and followed measures.
fn json_report(info: &report::RunInfo, levels: &[Level], repeats: u32) -> String {
    let runs: Vec<serde_json::Value> = levels
        .iter()
        .flat_map(|l| l.runs.iter().map(move |a| (l.lines, a)))
        .map(|(sphere_lines, a)| {
            let mut measures = serde_json::Map::new();
            for m in followed() {
                if let Some(e) = a.estimate(m) {
                    let info = m.info();
                    measures.insert(
                        info.symbol.replace(' ', "_"),
                        json!({
                            "value": e.value,
                            "stderr": e.stderr,
                            "unit": info.unit.name(),
                            "reliability": reliability_json(a.reliability.get(m)),
                        }),
                    );
                }
            }
            json!({
                "lines": a.lines,
                "sphere_lines": sphere_lines,
                "lines_through": a.spec.bound.name(),
                "seed": a.spec.seed,
                "seconds": a.seconds,
                "stop_reason": a.stop_reason.name(),
                "measures": measures,
            })
        })
        .collect();
    let doc = json!({
        "scx_version": env!("CARGO_PKG_VERSION"),
        "command_line": std::env::args().collect::<Vec<_>>(),
        "unit": "bit",
        "scene": info.scene.name,
        "patches": info.scene.patch_count(),
        "tracer": info.tracing.backend.name(),
        "threads": info.threads,
        "repeats": repeats,
        "runs": runs,
    });
    let mut s = serde_json::to_string_pretty(&doc).expect("a JSON value always serialises");
    s.push('\n');
    s
}

/// For each followed measure: its standard error (solid) and its distance to the largest run (dashed),
/// each point labelled with its line count.
fn curves(levels: &[Level]) -> Vec<Curve> {
    let mut out = Vec::new();
    let Some(last) = levels.last() else {
        return out;
    };
    for (series, m) in followed().into_iter().filter(|&m| plotted(m)).enumerate() {
        let Some((reference, _)) = last.measure(m) else {
            continue;
        };
        let label_of = |l: &Level| format!("{:.0e}", l.lines as f64);
        let stderr: Vec<(f64, f64, String)> = levels
            .iter()
            .filter_map(|l| Some((l.seconds(), l.measure(m)?.1, label_of(l))))
            .filter(|&(s, e, _)| s > 0.0 && e > 0.0)
            .collect();
        let distance: Vec<(f64, f64, String)> = levels[..levels.len() - 1]
            .iter()
            .filter_map(|l| {
                let d = (l.measure(m)?.0 - reference).abs();
                Some((l.seconds(), d, label_of(l)))
            })
            .filter(|&(s, e, _)| s > 0.0 && e > 0.0)
            .collect();
        let name = m.info().label;
        out.push(Curve {
            label: format!("{name}: standard error"),
            series: Series(series),
            dashed: false,
            points: stderr,
        });
        if !distance.is_empty() {
            out.push(Curve {
                label: format!("{name}: distance to the largest run"),
                series: Series(series),
                dashed: true,
                points: distance,
            });
        }
    }
    out
}

/// The notes under the table: for every repeat's reading that breaks a bound of the theory, the bound,
/// in `analyze`'s words, after the run's lines and seed (each repeat's reading has its own numbers).
fn flag_notes(levels: &[Level]) -> Vec<String> {
    let mut notes = Vec::new();
    for l in levels {
        for a in &l.runs {
            let whose = format!("{} lines, seed {}: ", l.lines, a.spec.seed);
            for m in followed() {
                for f in a.reliability.get(m).iter().flat_map(|r| r.flags.iter()) {
                    let note = report::flag_note(&whose, f);
                    if !notes.contains(&note) {
                        notes.push(note);
                    }
                }
            }
        }
    }
    notes
}

/// One line per line count whose readings are not all `ok`: each such reading with the worst verdict of
/// its repeats, so that the means in the table are not taken for more than they are worth.
fn verdict_lines(levels: &[Level]) -> Vec<String> {
    levels
        .iter()
        .filter_map(|l| {
            let poor: Vec<String> = followed()
                .into_iter()
                .filter_map(|m| {
                    let v = l.worst_verdict(m).filter(|&v| v != Verdict::Ok)?;
                    Some(format!("{} {}", m.info().symbol, v.name()))
                })
                .collect();
            (!poor.is_empty()).then(|| format!("  {} lines: {}", l.lines, poor.join(", ")))
        })
        .collect()
}

/// The table: the means of every line count's repeats, each marked `!` when a repeat's reading breaks
/// a bound of the theory, then the notes that say which, and the readings that are not `ok`.
/// `plot_written`: a plot was drawn, whose points carry no mark.
fn table(info: &report::RunInfo, levels: &[Level], repeats: u32, plot_written: bool) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "scene {} ({} patches), tracer {}, {} thread(s), {repeats} run(s) per line count (means shown); \
         measures in bits\n",
        info.scene.name,
        info.scene.patch_count(),
        info.tracing.backend.name(),
        info.threads
    );
    let mut header = vec!["lines", "seconds"];
    header.extend(followed().into_iter().map(|m| m.info().symbol));
    let mut t = Table::new(&header, &vec![Align::Right; header.len()]);
    for l in levels {
        let mut row = vec![l.lines.to_string(), format!("{:.3}", l.seconds())];
        for m in followed() {
            row.push(match l.measure(m) {
                Some((v, e)) => format!(
                    "{} +- {}{}",
                    fixed(v),
                    fixed(e),
                    if l.flagged(m) { " !" } else { "  " }
                ),
                None => "-".into(),
            });
        }
        t.row(row);
    }
    s += &t.render();
    let notes = flag_notes(levels);
    for n in &notes {
        let _ = writeln!(s, "{n}");
    }
    let poor = verdict_lines(levels);
    if !notes.is_empty() {
        let _ = writeln!(
            s,
            "\nmarked !: a repeat's reading breaks a bound of the theory (the notes above say which); \
             every reading's verdict is in --format json and --csv."
        );
    }
    if !poor.is_empty() {
        if notes.is_empty() {
            s.push('\n');
        }
        let _ = writeln!(
            s,
            "readings not ok (the worst verdict of the repeats; docs/results.md, \"Reading the \
             reliability verdict\"):"
        );
        for p in &poor {
            let _ = writeln!(s, "{p}");
        }
    }
    if plot_written
        && levels
            .iter()
            .any(|l| followed().into_iter().any(|m| plotted(m) && l.flagged(m)))
    {
        let _ = writeln!(
            s,
            "the plot draws the errors of the readings marked ! like any other: their standard errors \
             do not cover their bias."
        );
    }
    s
}
