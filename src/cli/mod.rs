//! Command-line arguments and dispatch. Knows the library's public API only (never a backend's types).

mod report;

use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use scene_complexity::analysis::{analyze_with, AnalysisConfig, DEFAULT_GROUPS};
use scene_complexity::sample::lines::LineSource;
use scene_complexity::sample::tally::Wanted;
use scene_complexity::scene::{self, builtin};
use scene_complexity::trace::crosscheck::{self, CrossCheckConfig, Tolerance};
use scene_complexity::trace::{make_tracer, Backend, Query};

/// scx: how hard is a 3D scene to light and to mesh? Information-theoretic scene complexity
/// (Feixas, del Acebo, Bekaert, Sbert, Eurographics 1999) from global lines.
#[derive(Parser, Debug)]
#[command(name = "scx", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Cast global lines through a scene and report its complexity measures.
    Analyze(AnalyzeArgs),
    /// List the built-in scenes and their parameters.
    Scenes,
    /// Write a scene (built-in or file) as OBJ + MTL.
    Export(ExportArgs),
    /// Trace the same lines with Embree and the pure-Rust tracer, compare them hit for hit and measure
    /// for measure; exit 1 when a line differs beyond the tolerance.
    Crosscheck(CrosscheckArgs),
}

#[derive(clap::Args, Debug)]
struct CrosscheckArgs {
    /// An OBJ file, or a built-in scene such as `@cube:10` (see `scx scenes`).
    scene: String,
    /// Number of global lines (accepts `1e6`).
    #[arg(long, default_value = "1e6", value_parser = parse_count)]
    lines: u64,
    /// Seed of the random line streams (the lines of `scx analyze` with the same seed).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Distances agree within this many f32 ulps at max(t, 1).
    #[arg(long, default_value_t = Tolerance::default().ulps)]
    ulps: f32,
    /// How many differing lines to print.
    #[arg(long, default_value_t = 5)]
    show: usize,
}

#[derive(clap::Args, Debug)]
struct ExportArgs {
    /// An OBJ file, or a built-in scene such as `@cube:10`.
    scene: String,
    /// The OBJ file to write; the MTL library goes beside it.
    #[arg(short, long)]
    output: std::path::PathBuf,
}

#[derive(clap::Args, Debug)]
struct AnalyzeArgs {
    /// An OBJ file, or a built-in scene such as `@cube:10` (see `scx scenes`).
    scene: String,
    /// Number of global lines (accepts `1e7`).
    #[arg(long, default_value = "1e6", value_parser = parse_count)]
    lines: u64,
    /// Seed of the random line streams.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Tracing backend.
    #[arg(long, value_enum)]
    tracer: Option<TracerArg>,
    /// Ray query: `single`, or `packet4`/`packet8`/`packet16` (Embree, native widths only).
    #[arg(long, default_value = "single", value_parser = parse_query)]
    query: Query,
    /// Cast the lines in bundles of G x G parallel lines (jittered grid over the disc, traced as adjacent
    /// packets); 0 casts independent lines. The standard errors include the correlation within a bundle.
    #[arg(long, default_value_t = 0, value_parser = parse_bundle)]
    bundle: u32,
    /// Which measures to compute (comma separated): discrete, continuous. Default: all.
    #[arg(long, value_delimiter = ',', value_enum)]
    measures: Option<Vec<MeasureArg>>,
    /// Independent groups of lines behind each standard error.
    #[arg(long, default_value_t = DEFAULT_GROUPS as u16, value_parser = clap::value_parser!(u16).range(2..=1024))]
    groups: u16,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum TracerArg {
    Embree,
    Rust,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum MeasureArg {
    Discrete,
    Continuous,
}

/// Output formats of `analyze`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// A readable table.
    Table,
    /// One JSON document.
    Json,
    /// `measure,value,stderr` rows.
    Csv,
}

/// Parses a positive whole count written as `1000000`, `1e6` or `2.5e6`.
fn parse_count(s: &str) -> Result<u64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if !(v.is_finite() && v >= 1.0 && v.fract() == 0.0 && v <= 1e15) {
        return Err(format!("`{s}`: need a whole number from 1 to 1e15"));
    }
    Ok(v as u64)
}

fn parse_bundle(s: &str) -> Result<u32, String> {
    let g: u32 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number"))?;
    LineSource::bundles(g).map(|_| g)
}

fn parse_query(s: &str) -> Result<Query, String> {
    match s {
        "single" => Ok(Query::Single),
        "packet4" => Ok(Query::Packet(4)),
        "packet8" => Ok(Query::Packet(8)),
        "packet16" => Ok(Query::Packet(16)),
        _ => Err(format!(
            "`{s}`: expected single, packet4, packet8 or packet16"
        )),
    }
}

/// Runs the command line; exit code 2 for bad input, 1 for failures while running.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Scenes => {
            let list: String = builtin::BUILTINS
                .iter()
                .map(|b| format!("{:<18} {}\n", b.usage, b.description))
                .collect();
            finish(write_stdout(&list))
        }
        Command::Analyze(args) => finish(try_analyze(&args)),
        Command::Export(args) => finish(try_export(&args)),
        Command::Crosscheck(args) => finish(try_crosscheck(&args)),
    }
}

fn finish(result: Result<(), Failure>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("scx: error: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}

fn load_scene(spec: &str) -> Result<scene::Scene, Failure> {
    let scene = scene::load(spec).map_err(bad_input)?;
    for w in &scene.warnings {
        eprintln!("scx: warning: {w}");
    }
    Ok(scene)
}

fn try_export(args: &ExportArgs) -> Result<(), Failure> {
    let scene = load_scene(&args.scene)?;
    scene::obj::write(&scene, &args.output).map_err(|e| Failure {
        code: 1,
        message: e.to_string(),
    })?;
    eprintln!(
        "scx: wrote {} ({} patches) and its MTL library",
        args.output.display(),
        scene.patch_count()
    );
    Ok(())
}

/// A failure with its exit code.
struct Failure {
    code: u8,
    message: String,
}

fn bad_input(message: impl ToString) -> Failure {
    Failure {
        code: 2,
        message: message.to_string(),
    }
}

/// A rayon pool of `threads` threads (default: all cores).
fn thread_pool(threads: Option<usize>) -> Result<(rayon::ThreadPool, usize), Failure> {
    let threads = threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| bad_input(format!("cannot start {threads} threads: {e}")))?;
    Ok((pool, threads))
}

fn try_crosscheck(args: &CrosscheckArgs) -> Result<(), Failure> {
    if !(args.ulps.is_finite() && args.ulps >= 0.0) {
        return Err(bad_input(format!(
            "--ulps {}: need a finite number >= 0",
            args.ulps
        )));
    }
    let scene = load_scene(&args.scene)?;
    let embree = make_tracer(Backend::Embree, &scene, Query::Single).map_err(bad_input)?;
    let rust = make_tracer(Backend::Rust, &scene, Query::Single).map_err(bad_input)?;
    let (pool, _) = thread_pool(args.threads)?;
    let cfg = CrossCheckConfig {
        lines: args.lines,
        seed: args.seed,
        tolerance: Tolerance { ulps: args.ulps },
        examples: args.show,
    };
    let check = pool
        .install(|| {
            crosscheck::crosscheck(&scene, embree.as_ref(), rust.as_ref(), &cfg, DEFAULT_GROUPS)
        })
        .map_err(|e| Failure {
            code: 1,
            message: e.to_string(),
        })?;
    write_stdout(&crosscheck::report(&check, &scene))?;
    if check.passed() {
        Ok(())
    } else {
        Err(Failure {
            code: 1,
            message: format!(
                "{} of {} lines differ between the tracers",
                check.hits.differing_lines(),
                check.hits.lines
            ),
        })
    }
}

fn try_analyze(args: &AnalyzeArgs) -> Result<(), Failure> {
    let scene = load_scene(&args.scene)?;
    let backend = match args.tracer {
        Some(TracerArg::Embree) => Backend::Embree,
        Some(TracerArg::Rust) => Backend::Rust,
        None => Backend::default_available(),
    };
    let tracer = make_tracer(backend, &scene, args.query).map_err(bad_input)?;
    let wanted = match &args.measures {
        None => Wanted {
            discrete: true,
            continuous: true,
        },
        Some(m) => Wanted {
            discrete: m.contains(&MeasureArg::Discrete),
            continuous: m.contains(&MeasureArg::Continuous),
        },
    };
    let (pool, threads) = thread_pool(args.threads)?;
    let source = LineSource::bundles(args.bundle).map_err(bad_input)?;
    let cfg = AnalysisConfig {
        lines: args.lines,
        seed: args.seed,
        wanted,
        groups: usize::from(args.groups),
    };
    let analysis = pool
        .install(|| analyze_with(&scene, tracer.as_ref(), &cfg, source))
        .map_err(|e| Failure {
            code: 1,
            message: e.to_string(),
        })?;
    let run = report::RunInfo {
        scene: &scene,
        tracer: tracer.name(),
        query: args.query,
        threads,
        bundle: args.bundle,
    };
    for w in report::warnings(&scene, &analysis) {
        eprintln!("scx: warning: {w}");
    }
    let text = match args.format {
        Format::Table => report::table(&run, &analysis),
        Format::Json => report::json(&run, &analysis),
        Format::Csv => report::csv(&run, &analysis),
    };
    write_stdout(&text)
}

/// Writes a report to stdout; a reader that went away (`scx ... | head`) is not an error worth a panic.
fn write_stdout(text: &str) -> Result<(), Failure> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Failure {
            code: 1,
            message: format!("cannot write the report to stdout: {e}"),
        }),
    }
}
