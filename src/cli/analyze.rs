//! `scx analyze`: one analysis, reported as a table, JSON or CSV.

use std::path::PathBuf;

use clap::ValueEnum;
use scene_complexity::run::{AnalysisConfig, Budget, Measures, StopReason, Target, TargetMeasure};
use scene_complexity::sample::lines::LineSource;

use super::args::{parse_count, parse_positive, parse_target_measure, ReportOutput, RunOptions};
use super::output::{self, warn};
use super::runner::Runner;
use super::{patches, report, Exit, Failure};

/// Arguments of `scx analyze`.
#[derive(clap::Args, Debug)]
pub struct AnalyzeArgs {
    /// A scene file (OBJ), a built-in scene such as `@cube:10` (see `scx scenes`), or `-` to read an OBJ
    /// from standard input.
    scene: String,
    /// Number of global lines (accepts `1e7`; default 1e6, or no limit with a budget).
    #[arg(long, value_parser = parse_count, allow_negative_numbers = true)]
    lines: Option<u64>,
    #[command(flatten)]
    run: RunOptions,
    /// Which measures to compute (comma separated): discrete, continuous, radiosity. Default: all that
    /// apply (radiosity needs an emitting material, and brings the discrete counts along).
    #[arg(long, value_delimiter = ',', value_enum)]
    measures: Option<Vec<MeasureArg>>,
    /// Stop after this many seconds (then --lines is only a cap).
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    seconds: Option<f64>,
    /// Stop when the standard error of --target-measure is at most this AND its reading is reliable
    /// (verdict `ok`); then --lines (and --seconds) only cap the run.
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    target_stderr: Option<f64>,
    /// The measure --target-stderr watches: mutual_information_corrected (default), mutual_information,
    /// entropy, entropy_corrected, continuous_mutual_information, accuracy, accuracy_corrected.
    #[arg(long, default_value = "mutual_information_corrected", value_parser = parse_target_measure)]
    target_measure: TargetMeasure,
    /// Cast the lines in bundles of G x G parallel lines (jittered grid over the disc, traced as adjacent
    /// packets); 0 casts independent lines. The standard errors include the correlation within a bundle.
    #[arg(long, default_value_t = 0, value_parser = parse_bundle)]
    bundle: u32,
    /// Close an open scene with a virtual, absorbing environment patch (the bounding sphere, facing
    /// inwards): escaping segments become pairs with it, rows of F sum to 1, and every visibility measure
    /// is that of the enclosed scene. Its area is counted: the part of the sphere that sees the scene's
    /// front sides or itself (4 pi R^2 for objects in open space). Changes nothing in a closed scene.
    #[arg(long)]
    enclose: bool,
    /// Output format: `table` (for people), `json` (one document with every field, units and verdicts),
    /// `csv` (one row per measure: scene, lines, seed, tracer, family, measure, unit, value, stderr,
    /// reliability, corrected, corrected_stderr, corrected_reliability).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    #[command(flatten)]
    out: ReportOutput,
    #[command(flatten)]
    files: PatchFiles,
}

/// The per-patch files of `scx analyze`.
#[derive(clap::Args, Debug)]
struct PatchFiles {
    /// Also write one row per patch to FILE (.csv): id (the order `scx export` writes faces), material,
    /// area, centroid and normal in the scene's units, segments N_i, row entropy, its terms of I_s and
    /// I_s^c, the information it loses, radiosity when lit, each with its standard error. Repeat to
    /// write several files.
    #[arg(long, value_name = "FILE")]
    patches: Vec<PathBuf>,
    /// Also write the sparse form-factor matrix to FILE: `.csv` (i, j, n_ij, n_i, f_ij, f_ij_stderr) or
    /// `.mtx` (Matrix Market, for scipy.io.mmread). Repeat to write both.
    #[arg(long, value_name = "FILE")]
    form_factors: Vec<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum MeasureArg {
    Discrete,
    Continuous,
    Radiosity,
}

/// Output formats of a report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// A readable table.
    Table,
    /// One JSON document.
    Json,
    /// CSV rows with a header.
    Csv,
}

/// Checks the per-patch files before any work: their kinds, that they can be written, and that the run
/// will have what they need.
fn check_patch_files(args: &AnalyzeArgs) -> Result<(), Failure> {
    let f = &args.files;
    if f.patches.is_empty() && f.form_factors.is_empty() {
        return Ok(());
    }
    patches::check_patch_files(&f.patches)?;
    patches::check_matrix_files(&f.form_factors)?;
    if args.enclose {
        return Err(Failure::bad_input(
            "--patches and --form-factors describe the scene's own patches; they do not take --enclose",
        ));
    }
    if !f.form_factors.is_empty()
        && args.measures.as_ref().is_some_and(|m| {
            !m.contains(&MeasureArg::Discrete) && !m.contains(&MeasureArg::Radiosity)
        })
    {
        return Err(Failure::bad_input(
            "--form-factors needs the pair counts: add `discrete` to --measures",
        ));
    }
    output::check_all(
        f.patches
            .iter()
            .chain(&f.form_factors)
            .map(PathBuf::as_path),
    )
}

fn parse_bundle(s: &str) -> Result<u32, String> {
    let g: u32 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number"))?;
    LineSource::bundles(g).map(|_| g)
}

/// Runs `scx analyze`.
pub fn run(args: &AnalyzeArgs) -> Result<Exit, Failure> {
    output::check_all(args.out.output.as_deref())?;
    check_patch_files(args)?;
    let runner = Runner::new(&args.scene, &args.run)?;
    let measures = match &args.measures {
        None => Measures::ALL,
        Some(m) => Measures {
            discrete: m.contains(&MeasureArg::Discrete),
            continuous: m.contains(&MeasureArg::Continuous),
            radiosity: m.contains(&MeasureArg::Radiosity),
        },
    };
    let budget = Budget {
        seconds: args.seconds,
        target: args.target_stderr.map(|stderr| Target {
            measure: args.target_measure,
            stderr,
        }),
    };
    let open_ended = budget.is_open_ended();
    let lines = args.lines.unwrap_or(if open_ended {
        1_000_000_000_000
    } else {
        1_000_000
    });
    let cfg = AnalysisConfig {
        measures,
        budget,
        source: LineSource::bundles(args.bundle).map_err(Failure::bad_input)?,
        enclose: args.enclose,
        per_patch: !args.files.patches.is_empty(),
        ..runner.config(&args.run, lines, args.run.seed)
    };
    let total = (!open_ended).then_some(lines);
    let analysis = runner.analyze(&cfg, total, "")?;
    for w in &analysis.warnings {
        warn(&w.message);
    }
    let run = report::RunInfo {
        bundle: args.bundle,
        ..runner.info()
    };
    runner.pool.install(|| {
        patches::write_patches(&args.files.patches, &runner.scene, &analysis)?;
        patches::write_form_factors(&args.files.form_factors, &runner.scene, &analysis)
    })?;
    let text = match args.format {
        Format::Table => report::table(&run, &analysis),
        Format::Json => report::json(&run, &analysis),
        Format::Csv => report::csv(&run, &analysis),
    };
    output::emit(args.out.output.as_deref(), &text)?;
    Ok(if analysis.stop_reason == StopReason::Interrupted {
        Exit::Interrupted
    } else {
        Exit::Ok
    })
}
