//! `scx reproduce`: the paper's Tables 1 to 9 regenerated with scx, each printed beside the paper's
//! values ([`published`]) with the lines and seconds used, plug-in and bias-corrected estimates with their
//! standard errors, and a check of the paper's qualitative findings on our numbers ([`Finding`]).
//!
//! The scenes are the built-ins of the paper's figures (`scx scenes`): `@fig2:a|b|c` (Tables 1 and 3),
//! `@cube:10|20|30` (Table 2), the regular solids, an icosphere and `@cornell` (Table 4), `@fig4:a..f`
//! (Table 5), `@fig5:a..f` and `@fig6:a..f` (Tables 6 and 7), `@labyrinth` (Table 8), and `@cornell`
//! refined by [`crate::refine()`] (Table 9). Runs are cached within one call: a scene run twice at the same
//! line count (Tables 1 and 3 share fig. 2a) is traced once, with identical numbers since the seed is the
//! same.

pub mod published;
mod tables;

use crate::scenes;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::time::Instant;

use crate::analysis::Reliability;
use crate::analysis::{analyze, AnalysisError, RadiosityOutcome};
use crate::measure::{ByMeasure, Estimate, Measure};
use crate::refine::RefineError;
use crate::run::{LinesThrough, Measures, RunControl, RunSpec};
use crate::scene::{Scene, SceneError};
use crate::trace::{make_tracer, Backend, Query, TraceError};

/// The tables there are.
pub const TABLES: std::ops::RangeInclusive<u8> = 1..=9;

/// The most lines one run casts by default: the paper's 10^9-line runs (Table 2) are cast with 10^8
/// (`--lines paper` lifts the cap), which keeps `scx reproduce` well under an hour on two cores.
pub const DEFAULT_CAP: u64 = 100_000_000;

/// Lines of a run the paper gives no count for (Table 8).
pub const UNSTATED_LINES: u64 = 10_000_000;

/// Lines per refinement round of Table 9's meshes (the `scx refine` default).
pub const REFINE_LINES: u64 = 1_000_000;

/// What to run.
#[derive(Clone, Debug)]
pub struct ReproduceConfig {
    /// The tables, each in 1..=9, in the order to run them.
    pub tables: Vec<u8>,
    /// How many lines each run casts.
    pub lines: LinePlan,
    /// Seed of every run's lines (and of the first refinement round).
    pub seed: u64,
    /// The tracer.
    pub backend: Backend,
}

/// How many lines each run casts, from the count the paper used for it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LinePlan {
    /// The paper's counts, at most [`DEFAULT_CAP`].
    Default,
    /// The paper's counts exactly (10^9 for Table 2's last rows).
    Paper,
    /// The default counts times a factor (at least 1 line).
    Scale(f64),
    /// Every run this many lines (refinement rounds too).
    Fixed(u64),
}

/// A `--lines` of `scx reproduce` that is not one ([`LinePlan::parse`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LinePlanError {
    /// A factor out of range.
    #[error("`{0}`: a factor must be a number above 0 and at most 1e6, as in x0.1")]
    Factor(String),
    /// Neither a name, a factor nor a count.
    #[error(
        "`{0}`: expected default, paper, a factor such as x0.1, or a whole line count such as 1e6"
    )]
    Unknown(String),
}

impl LinePlan {
    /// Reads `default`, `paper`, `xF` (a factor on the defaults, `x0.1`) or a count (`1e6`).
    pub fn parse(s: &str) -> Result<Self, LinePlanError> {
        let s = s.trim();
        let positive = |v: f64| v.is_finite() && v > 0.0;
        match s {
            "default" => Ok(LinePlan::Default),
            "paper" => Ok(LinePlan::Paper),
            _ if s.starts_with('x') => match s[1..].parse::<f64>() {
                Ok(f) if positive(f) && f <= 1e6 => Ok(LinePlan::Scale(f)),
                _ => Err(LinePlanError::Factor(s.into())),
            },
            _ => match s.parse::<f64>() {
                Ok(n) if (1.0..=1e15).contains(&n) && n.fract() == 0.0 => {
                    Ok(LinePlan::Fixed(n as u64))
                }
                _ => Err(LinePlanError::Unknown(s.into())),
            },
        }
    }

    /// The lines of a run the paper cast with `paper` lines.
    pub fn lines(&self, paper: u64) -> u64 {
        match *self {
            LinePlan::Default => paper.min(DEFAULT_CAP),
            LinePlan::Paper => paper,
            LinePlan::Scale(f) => ((paper.min(DEFAULT_CAP) as f64 * f).round() as u64).max(1),
            LinePlan::Fixed(n) => n,
        }
    }
}

impl std::fmt::Display for LinePlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LinePlan::Default => write!(
                f,
                "default (the paper's counts, at most {})",
                lines_text(DEFAULT_CAP)
            ),
            LinePlan::Paper => write!(f, "paper (the paper's counts)"),
            LinePlan::Scale(x) => write!(f, "x{x} (the default counts times {x})"),
            LinePlan::Fixed(n) => write!(f, "{} for every run", lines_text(*n)),
        }
    }
}

/// One of the paper's claims, checked on our numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    /// What the paper says.
    pub claim: String,
    /// Whether our numbers agree (for every estimate the detail names).
    pub holds: bool,
    /// The numbers behind the verdict.
    pub detail: String,
    /// The readings it was judged on that break a bound of the theory (`@fig2:a 1e5 I_s`), marked `!` in
    /// the table: a verdict resting on them is no evidence either way, and the report says so.
    pub flagged: Vec<String>,
}

impl Finding {
    /// The verdict as the report prints it: `holds` or `does NOT hold`, and `on flagged readings` when it
    /// rests on readings that break a bound of the theory.
    pub fn verdict(&self) -> String {
        let verdict = if self.holds { "holds" } else { "does NOT hold" };
        if self.flagged.is_empty() {
            verdict.into()
        } else {
            format!("{verdict} on flagged readings")
        }
    }
}

/// A regenerated table.
#[derive(Clone, Debug)]
pub struct TableReport {
    /// 1..=9.
    pub number: u8,
    /// What it shows and on which scenes.
    pub title: String,
    /// Column names.
    pub header: Vec<String>,
    /// Cells, row by row.
    pub rows: Vec<Vec<String>>,
    /// Remarks printed under the table.
    pub notes: Vec<String>,
    /// The paper's qualitative claims about the table, checked.
    pub findings: Vec<Finding>,
    /// Lines cast for this table, counted through the bounding sphere (refinement rounds included; runs
    /// reused from the cache count 0).
    pub lines: u64,
    /// Runs taken from an earlier table instead of being cast again.
    pub reused: usize,
    /// Runs this table asks for twice (the same scene and lines), cast once.
    pub repeated: usize,
    /// Wall-clock seconds spent on this table.
    pub seconds: f64,
}

impl TableReport {
    /// The table as Markdown: a heading, the table, its notes and findings.
    pub fn markdown(&self) -> String {
        let mut s = format!("### Table {}: {}\n\n", self.number, self.title);
        let _ = writeln!(s, "| {} |", self.header.join(" | "));
        let _ = writeln!(s, "|{}|", vec!["---"; self.header.len()].join("|"));
        for r in &self.rows {
            let _ = writeln!(s, "| {} |", r.join(" | "));
        }
        s.push('\n');
        for n in &self.notes {
            let _ = writeln!(s, "{n}  ");
        }
        for f in &self.findings {
            let flagged = if f.flagged.is_empty() {
                String::new()
            } else {
                // One entry per run, its readings comma separated: the runs apart by `;`.
                format!("flagged: {}. ", f.flagged.join("; "))
            };
            let _ = writeln!(
                s,
                "- *{}*: **{}** ({flagged}{})",
                f.claim,
                f.verdict(),
                f.detail
            );
        }
        let mut shared = Vec::new();
        if self.reused > 0 {
            shared.push(format!(
                "{} run(s) shared with an earlier table",
                self.reused
            ));
        }
        if self.repeated > 0 {
            shared.push(format!("{} run(s) repeated within it", self.repeated));
        }
        let reused = if shared.is_empty() {
            String::new()
        } else {
            format!(" ({}, not cast again)", shared.join(", "))
        };
        let _ = writeln!(
            s,
            "\n{} lines cast for this table in {:.1} s{reused}.\n",
            self.lines, self.seconds
        );
        s
    }
}

/// Why a reproduction failed.
#[derive(Debug, thiserror::Error)]
pub enum ReproduceError {
    /// A built-in scene could not be built (a bug: they are fixed).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Tracing failed, or the backend is not available.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// An analysis failed (bad materials, a radiosity system without solution, tracing).
    #[error(transparent)]
    Analysis(#[from] AnalysisError),
    /// A refinement failed.
    #[error(transparent)]
    Refine(#[from] RefineError),
    /// A table number outside 1..=9.
    #[error("there is no table {0}: the paper's tables are 1 to 9")]
    NoSuchTable(u8),
}

impl ReproduceError {
    /// Whether the request was at fault (an unknown table, an unavailable tracer).
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            ReproduceError::NoSuchTable(_) | ReproduceError::Trace(TraceError::Unsupported(_))
        )
    }
}

/// Regenerates the tables of `cfg` in order, handing each to `on_table` when done; `log` hears of
/// every run (scene, lines, seconds).
pub fn reproduce(
    cfg: &ReproduceConfig,
    log: &mut dyn FnMut(&str),
    on_table: &mut dyn FnMut(&TableReport),
) -> Result<Vec<TableReport>, ReproduceError> {
    if let Some(&t) = cfg.tables.iter().find(|t| !TABLES.contains(t)) {
        return Err(ReproduceError::NoSuchTable(t));
    }
    let mut session = Session {
        cfg,
        cache: HashMap::new(),
        lines_cast: 0,
        reused: 0,
        repeated: 0,
        table: 0,
        log,
    };
    let mut reports = Vec::new();
    for (position, &t) in cfg.tables.iter().enumerate() {
        let start = Instant::now();
        let (before, reused, repeated) = (session.lines_cast, session.reused, session.repeated);
        session.table = position;
        let mut report = tables::table(&mut session, t)?;
        report.lines = session.lines_cast - before;
        report.reused = session.reused - reused;
        report.repeated = session.repeated - repeated;
        report.seconds = start.elapsed().as_secs_f64();
        on_table(&report);
        reports.push(report);
    }
    Ok(reports)
}

/// Which measures a run gathers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Want {
    /// I_s^c only (Tables 4 and 5): no pair counts.
    Continuous,
    /// Every visibility measure.
    Visibility,
    /// Every visibility measure and the radiosity measures.
    Radiosity,
}

/// What one run found, kept for the tables.
#[derive(Clone, Debug)]
struct Run {
    /// The scene's name (`@fig2:a`), which names the run in the notes and findings.
    name: String,
    patches: usize,
    /// Lines through the bounding sphere, as the paper counts them (drawn through the scene's box or
    /// polytope when `auto` chooses it, fewer and worth as many).
    lines: u64,
    seconds: f64,
    /// The visibility readings.
    v: ByMeasure<Estimate>,
    /// The radiosity readings, when computed.
    radiosity: Option<ByMeasure<Estimate>>,
    /// The verdicts on the readings of both families, with the bounds of the theory each breaks.
    reliability: ByMeasure<Reliability>,
    /// Segments leaving a front side out of the scene (0 in a closed scene but for grazing hits).
    escapes: u64,
    /// Segments joining two patches.
    pairs: u64,
    /// `2 pi R^2 / A_T` (tracing space, R = 1): eq. (22)'s `n_p - sum F^2` times this is the area-weighted
    /// form-factor MSE per line, `sum_i a_i sum_j Var(F_ij) N`.
    area_weight: f64,
}

/// The state of one `reproduce` call: its configuration, the runs so far, the log.
struct Session<'a> {
    cfg: &'a ReproduceConfig,
    /// The runs so far, each with the table that cast it (its place in the list asked for: a table
    /// asked for twice reuses the runs of its first time).
    cache: HashMap<(String, u64, Want), (Run, usize)>,
    lines_cast: u64,
    /// Runs taken from an earlier table.
    reused: usize,
    /// Runs the current table had cast already.
    repeated: usize,
    /// The place of the table being made in the list asked for.
    table: usize,
    log: &'a mut dyn FnMut(&str),
}

impl Session<'_> {
    /// The lines of a run the paper cast with `paper` lines.
    fn lines(&self, paper: u64) -> u64 {
        self.cfg.lines.lines(paper)
    }

    /// Runs `spec` with the lines for a paper count of `paper`, or reuses an identical earlier run.
    fn run(&mut self, spec: &str, paper: u64, want: Want) -> Result<Run, ReproduceError> {
        let lines = self.lines(paper);
        let key = (spec.to_string(), lines, want);
        if let Some((r, table)) = self.cache.get(&key) {
            if *table == self.table {
                self.repeated += 1;
            } else {
                self.reused += 1;
            }
            return Ok(r.clone());
        }
        let scene = scenes::load(spec)?;
        let run = self.run_scene(&scene, lines, want)?;
        self.cache.insert(key, (run.clone(), self.table));
        Ok(run)
    }

    /// Runs a scene (built here or refined) with `lines` lines.
    fn run_scene(&mut self, scene: &Scene, lines: u64, want: Want) -> Result<Run, ReproduceError> {
        let start = Instant::now();
        let tracer = make_tracer(self.cfg.backend, scene, Query::Single)?;
        let cfg = RunSpec {
            measures: Measures {
                discrete: want != Want::Continuous,
                continuous: true,
                radiosity: want == Want::Radiosity,
            },
            ..RunSpec::new(lines, self.cfg.seed)
        }
        .through(scene, LinesThrough::Auto);
        let a = analyze(scene, tracer.as_ref(), &cfg, &RunControl::default())?;
        let radiosity = match &a.radiosity {
            RadiosityOutcome::Computed(_) => Some(a.estimates.clone()),
            _ => None,
        };
        let seconds = start.elapsed().as_secs_f64();
        // Lines through the sphere, the paper's unit and `--lines`'s, however they were drawn (a run
        // here always casts them all).
        self.lines_cast += lines;
        (self.log)(&format!(
            "{}: {} lines, {seconds:.1} s",
            scene.name,
            lines_text(lines)
        ));
        Ok(Run {
            name: scene.name.clone(),
            patches: scene.patch_count(),
            lines,
            seconds,
            v: a.estimates,
            radiosity,
            reliability: a.reliability,
            escapes: a.escapes,
            pairs: a.pairs,
            area_weight: 2.0 * std::f64::consts::PI / scene.total_area(),
        })
    }
}

impl Run {
    /// The bounds of the theory the reading of `m` breaks, in `analyze`'s words (none when it breaks
    /// none or was not made).
    fn flags(&self, m: Measure) -> &[String] {
        self.reliability.get(m).map_or(&[], |r| r.flags.as_slice())
    }

    /// The run as the notes and findings name it: `@fig2:a 1e5`.
    fn label(&self) -> String {
        format!("{} {}", self.name, lines_text(self.lines))
    }
}

/// A line count as `1e7`, `1.65e7` (`0` for none).
pub fn lines_text(n: u64) -> String {
    if n == 0 {
        return "0".into();
    }
    format!("{:e}", n as f64)
}

/// An estimate as `value ± stderr` with `digits` decimals (one more for the error); an exact value
/// (standard error 0, such as H_p) without the error.
fn est(e: Option<Estimate>, digits: usize) -> String {
    match e {
        Some(Estimate {
            value,
            stderr: Some(se),
        }) if se > 0.0 => format!("{value:.digits$} ± {se:.0$}", digits + 1),
        Some(Estimate { value, .. }) => format!("{value:.digits$}"),
        None => "n/a".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_plans_parse_and_scale() {
        assert_eq!(LinePlan::parse("default").unwrap(), LinePlan::Default);
        assert_eq!(LinePlan::parse("paper").unwrap(), LinePlan::Paper);
        assert_eq!(LinePlan::parse("x0.1").unwrap(), LinePlan::Scale(0.1));
        assert_eq!(LinePlan::parse("1e6").unwrap(), LinePlan::Fixed(1_000_000));
        for bad in ["x0", "x-1", "xx", "0", "1.5", "-3", "lots", "x", "1e16"] {
            assert!(LinePlan::parse(bad).is_err(), "{bad}");
        }
        let billion = 1_000_000_000;
        assert_eq!(LinePlan::Default.lines(billion), DEFAULT_CAP);
        assert_eq!(LinePlan::Paper.lines(billion), billion);
        assert_eq!(LinePlan::Scale(0.01).lines(billion), DEFAULT_CAP / 100);
        assert_eq!(LinePlan::Scale(1e-9).lines(10), 1);
        assert_eq!(LinePlan::Fixed(5).lines(billion), 5);
    }

    #[test]
    fn estimates_print_with_their_errors() {
        let e = Estimate {
            value: 1.23456,
            stderr: Some(0.00123),
        };
        assert_eq!(est(Some(e), 3), "1.235 ± 0.0012");
        assert_eq!(est(None, 3), "n/a");
        assert_eq!(est(Some(Estimate::exact(2.0)), 2), "2.00");
        assert_eq!(lines_text(0), "0");
        assert_eq!(lines_text(16_500_000), "1.65e7");
        assert_eq!(lines_text(10_000), "1e4");
    }
}
