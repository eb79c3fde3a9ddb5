//! `scx calibrate`: the calibration suite (see [`scene_complexity::calibrate`]), its table printed as
//! Markdown on stdout as each cell finishes; one log line per cell on stderr.

use std::path::PathBuf;
use std::time::Instant;

use scene_complexity::calibrate::{
    self, check_computable, report, suite, CalibrationScene, Cell, CellMeasures, CellReport,
    CellTarget, SuiteLevel,
};
use scene_complexity::{default_groups, LinesThrough, Measure, Sampler};

use super::args::{
    check_target_measure, parse_count, parse_groups, parse_positive, parse_seed, parse_whole_in,
    target_measure_parser, ReportOutput, Threads, Tracer, TracerArg, MAX_WHOLE,
};
use super::exit::{Exit, Failure};
use super::file_kind::{check_csv, text_report};
use super::output::{self, check_all};
use super::runner::thread_pool;

/// Arguments of `scx calibrate`.
#[derive(clap::Args, Debug)]
pub struct CalibrateArgs {
    /// A built-in list of cells: `small` (under a minute on two cores; what CI runs), `standard`
    /// (hours: the cube from 4 to 30 patches a side up to 1e8 lines, the regular solids, open scenes,
    /// a flipped face, a lit cube, precision targets), or `full` (standard and the expensive cells, up
    /// to 2e8 lines and a target capped at 2e9). Default `small`, unless `--scene` names the cells.
    #[arg(long, value_parser = parse_suite, conflicts_with = "scene")]
    suite: Option<SuiteLevel>,
    /// Scenes with exact values, comma separated: @cube[:N], @tetrahedron[:k], @octahedron[:k],
    /// @icosahedron[:k], @dodecahedron[:k], two-squares:parallel[:N[:D]], two-squares:perpendicular[:N],
    /// flipped-cube[:N], lit-cube[:N]. One cell per scene and line count.
    #[arg(long, value_delimiter = ',', value_parser = parse_scene)]
    scene: Vec<CalibrationScene>,
    /// Lines per run, comma separated (with `--scene`; a cap with a target).
    #[arg(long, requires = "scene", value_delimiter = ',', value_parser = parse_count, default_value = "1e5")]
    lines: Vec<u64>,
    /// Runs per cell (with `--scene`), seeds `first-seed..first-seed + seeds`.
    #[arg(long, requires = "scene", value_parser = parse_seed_count, default_value = "200")]
    seeds: u64,
    /// The first seed (with `--scene`).
    #[arg(long, requires = "scene", value_parser = parse_seed, default_value = "1")]
    first_seed: u64,
    /// Measures of the runs (with `--scene`): `all`, or `continuous` (I_s^c alone, as
    /// `scx analyze --measures continuous`).
    #[arg(long, requires = "scene", default_value = "all", value_parser = parse_measures)]
    measures: CellMeasures,
    /// A precision target for every run (with `--scene`): stop when the standard error of
    /// `--target-measure` reaches this on an ok reading, or at `--lines`.
    #[arg(long, requires = "scene", value_parser = parse_positive)]
    target_stderr: Option<f64>,
    /// The measure the target watches (with `--scene` and `--target-stderr`) [default:
    /// mutual_information_corrected].
    #[arg(long, requires = "scene", value_parser = target_measure_parser())]
    target_measure: Option<Measure>,
    /// How the runs draw their lines, for every cell (the suite's or `--scene`'s): `independent` or
    /// `sobol` (`scx analyze --sampler`).
    #[arg(long, default_value = "independent", value_parser = parse_sampler)]
    sampler: Sampler,
    /// Where the runs draw their lines, for every cell: `auto`, `sphere`, `box` or `polytope` (`scx
    /// analyze --lines-through`; `auto` draws independent lines through the smallest container, and
    /// --sampler sobol's through the box or the polytope where it is the tighter container). Line counts
    /// are lines through the sphere, as `scx analyze --lines` counts them.
    #[arg(long, default_value = "auto", value_parser = parse_bound)]
    lines_through: LinesThrough,
    /// Independent groups of lines behind each run's standard errors, for every cell (2 to 1024; `scx
    /// analyze --groups`): the table's `runs` column names the degrees of freedom of any other count
    /// than the default's [default: 16, or 8 with --sampler sobol].
    #[arg(long, value_parser = parse_groups)]
    groups: Option<u16>,
    /// Print the cells and exit.
    #[arg(long)]
    list: bool,
    #[command(flatten)]
    threads: Threads,
    #[command(flatten)]
    tracer: Tracer,
    /// Also write the table as CSV to FILE (.csv; one row per cell, measure and basis).
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Also write every run's readings as CSV to FILE (.csv; one row per run and measure).
    #[arg(long, value_name = "FILE")]
    readings: Option<PathBuf>,
    #[command(flatten)]
    out: ReportOutput,
}

/// `--seeds`: runs per cell, a whole number >= 1.
fn parse_seed_count(s: &str) -> Result<u64, String> {
    parse_whole_in(s, "the number of runs per cell", 1, MAX_WHOLE)
}

fn parse_suite(s: &str) -> Result<SuiteLevel, String> {
    SuiteLevel::parse(s).ok_or_else(|| format!("`{s}`: expected small, standard or full"))
}

fn parse_scene(s: &str) -> Result<CalibrationScene, String> {
    CalibrationScene::parse(s).map_err(|e| e.to_string())
}

fn parse_measures(s: &str) -> Result<CellMeasures, String> {
    match s {
        "all" => Ok(CellMeasures::All),
        "continuous" => Ok(CellMeasures::ContinuousOnly),
        _ => Err(format!("`{s}`: expected all or continuous")),
    }
}

fn parse_sampler(s: &str) -> Result<Sampler, String> {
    Sampler::from_name(s).ok_or_else(|| format!("`{s}`: expected independent or sobol"))
}

fn parse_bound(s: &str) -> Result<LinesThrough, String> {
    LinesThrough::from_name(s)
        .ok_or_else(|| format!("`{s}`: expected auto, sphere, box or polytope"))
}

/// The standard-error groups of every cell's runs: those asked for, or the sampler's default (as `scx
/// analyze` chooses them).
fn groups_of(args: &CalibrateArgs) -> usize {
    args.groups
        .map_or(default_groups(args.sampler), usize::from)
}

/// The cells the arguments ask for.
fn cells(args: &CalibrateArgs) -> Vec<Cell> {
    if args.scene.is_empty() {
        return suite(args.suite.unwrap_or(SuiteLevel::Small))
            .into_iter()
            .map(|c| {
                c.with_sampler(args.sampler)
                    .with_bound(args.lines_through)
                    .with_groups(groups_of(args))
            })
            .collect();
    }
    let target = args.target_stderr.map(|stderr| CellTarget {
        measure: args.target_measure.unwrap_or(Measure::DEFAULT_TARGET),
        stderr,
    });
    args.scene
        .iter()
        .flat_map(|&scene| {
            args.lines.iter().map(move |&lines| Cell {
                scene,
                lines,
                first_seed: args.first_seed,
                seeds: args.seeds,
                measures: args.measures,
                target,
                sampler: args.sampler,
                through: args.lines_through,
                groups: groups_of(args),
            })
        })
        .collect()
}

/// Runs `scx calibrate`.
pub fn run(args: &CalibrateArgs) -> Result<Exit, Failure> {
    check_target_measure(args.target_measure, args.target_stderr).map_err(Failure::bad_input)?;
    text_report(
        "calibrate",
        "Markdown",
        args.out.output.as_deref(),
        " (the table as CSV: --csv FILE; every run's readings: --readings FILE)",
    )?;
    check_csv("--csv", args.csv.as_deref())?;
    check_csv("--readings", args.readings.as_deref())?;
    let named = [
        ("-o", &args.out.output),
        ("--csv", &args.csv),
        ("--readings", &args.readings),
    ];
    let outputs: Vec<(&str, &std::path::Path)> = named
        .iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (*flag, p)))
        .collect();
    output::check_distinct(&outputs, &[], &[])?;
    check_all(outputs.iter().map(|(_, p)| *p))?;
    let cells = cells(args);
    if args.list {
        let list: String = cells
            .iter()
            .map(|c| {
                format!(
                    "{} {} x {} seeds\n",
                    c.scene.name(),
                    c.lines_label(),
                    c.seeds
                )
            })
            .collect();
        output::emit(args.out.output.as_deref(), &list)?;
        return Ok(Exit::Ok);
    }
    // Every scene is built, and its exact values checked to be within reach, before the table starts:
    // one that cannot be (a parameter beyond what the scene allows, a scene too large for its exact
    // values) is refused as the input it is, not after the header.
    let mut built: Vec<String> = Vec::new();
    for cell in &cells {
        let name = cell.scene.name();
        if !built.contains(&name) {
            let scene = cell.scene.build().map_err(Failure::bad_input)?;
            check_computable(&cell.scene, &scene).map_err(Failure::bad_input)?;
            built.push(name);
        }
    }
    let backend = TracerArg::backend(args.tracer.value);
    let (threads, pool) = thread_pool(args.threads.value)?;
    let to_file = args.out.output.is_some();
    let mut document = format!(
        "`scx calibrate`: {} cells, tracer {}, {threads} threads.\n\n",
        cells.len(),
        match backend {
            scene_complexity::Backend::Embree => "embree",
            scene_complexity::Backend::Rust => "rust",
        }
    );
    document.push_str(&report::markdown_header());
    if !to_file {
        output::emit(None, &document)?;
    }
    let start = Instant::now();
    let mut printed: Result<(), Failure> = Ok(());
    let mut on_cell = |r: &CellReport| {
        output::note(&format!(
            "calibrate: {} {} x {} seeds in {:.1} s",
            r.cell.scene.name(),
            r.cell.lines_label(),
            r.cell.seeds,
            r.seconds
        ));
        let rows = report::markdown_rows(r);
        if to_file {
            document.push_str(&rows);
        } else if printed.is_ok() {
            printed = output::emit(None, &rows);
        }
    };
    let reports = pool
        .install(|| calibrate::run_cells(&cells, backend, &mut on_cell))
        .map_err(Failure::of)?;
    printed?;
    output::note(&format!(
        "calibrate: {} cells in {:.1} s",
        reports.len(),
        start.elapsed().as_secs_f64()
    ));
    if let Some(path) = &args.out.output {
        output::write_file(path, document.as_bytes())?;
    }
    if let Some(path) = &args.csv {
        output::write_file(path, report::summary_csv(&reports).as_bytes())?;
    }
    if let Some(path) = &args.readings {
        output::write_file(path, report::readings_csv(&reports).as_bytes())?;
    }
    Ok(Exit::Ok)
}
