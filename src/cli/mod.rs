//! Command-line arguments and dispatch. Knows the library's public API only (never a backend's types).

mod convergence;
mod plot;
mod progress;
mod report;
mod reproduce;

use std::sync::Arc;

use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use scene_complexity::crosscheck::{self, CrossCheckConfig, Tolerance};
use scene_complexity::measure::estimators::EntropyEstimator;
use scene_complexity::measure::radiosity::SolveOptions;
use scene_complexity::refine::{refine, RefineConfig, RefineRound, Strategy};
use scene_complexity::run::{
    analyze, Analysis, AnalysisConfig, Budget, ErrorMethod, Measures, RunControl, Target,
    TargetMeasure, DEFAULT_ESTIMATOR, DEFAULT_GROUPS,
};
use scene_complexity::sample::lines::LineSource;
use scene_complexity::scene::{self, ObjectSet, Planarity, SceneOptions, DEFAULT_PLANARITY};
use scene_complexity::scenes;
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
    /// Write a scene (built-in or file) as OBJ + MTL, or as glTF (`-o scene.gltf` or `.glb`).
    Export(ExportArgs),
    /// Run a scene at growing line counts: every measure with its error against run time.
    Convergence(ConvergenceArgs),
    /// Refine a scene's patches with a meshing strategy (paper Table 9) and write the mesh as OBJ + MTL.
    Refine(RefineArgs),
    /// Trace the same lines with Embree and the pure-Rust tracer, compare them hit for hit and measure
    /// for measure; exit 1 when a line differs beyond the tolerance.
    Crosscheck(CrosscheckArgs),
    /// Regenerate the paper's Tables 1 to 9 and print each beside the published values (Markdown).
    Reproduce(reproduce::ReproduceArgs),
}

#[derive(clap::Args, Debug)]
struct CrosscheckArgs {
    /// A scene file (OBJ, glTF, PLY, STL), or a built-in scene such as `@cube:10` (see `scx scenes`).
    scene: String,
    #[command(flatten)]
    input: SceneArgs,
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
struct RefineArgs {
    /// A scene file (OBJ, glTF, PLY, STL), or a built-in scene such as `@cornell`.
    scene: String,
    #[command(flatten)]
    input: SceneArgs,
    /// Which patches to split: uniform (all, largest first), power (A_i B_i), smoothness (variation of
    /// received radiosity over the patch), information (loss of information transfer).
    #[arg(long, value_enum)]
    strategy: StrategyArg,
    /// Stop at about this many patches (at most 2 over).
    #[arg(long)]
    patches: usize,
    /// The OBJ file to write; the MTL library goes beside it.
    #[arg(short, long)]
    output: std::path::PathBuf,
    /// Global lines per refinement round (accepts `1e6`).
    #[arg(long, default_value = "1e6", value_parser = parse_count)]
    lines: u64,
    /// Each round grows the mesh by at most this factor.
    #[arg(long, default_value_t = 1.5)]
    growth: f64,
    /// Seed of the first round's lines.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Tracing backend.
    #[arg(long, value_enum)]
    tracer: Option<TracerArg>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum StrategyArg {
    Uniform,
    Power,
    Smoothness,
    Information,
}

#[derive(clap::Args, Debug)]
struct ExportArgs {
    /// A scene file (OBJ, glTF, PLY, STL), or a built-in scene such as `@cube:10`.
    scene: String,
    #[command(flatten)]
    input: SceneArgs,
    /// The file to write: `.gltf` or `.glb` writes glTF 2.0, anything else OBJ with its MTL library
    /// beside it.
    #[arg(short, long)]
    output: std::path::PathBuf,
}

/// How a scene file is read: non-planar polygons, and objects to flip or make two-sided.
#[derive(clap::Args, Debug, Clone)]
struct SceneArgs {
    /// A polygon whose corners leave its plane by at most this fraction of its size is planar (one
    /// patch); a less planar one is split into planar triangles (one warning per file).
    #[arg(long, default_value_t = DEFAULT_PLANARITY, value_parser = parse_tolerance)]
    planarity: f64,
    /// Refuse non-planar polygons (exit 2, naming the first) instead of splitting them.
    #[arg(long)]
    strict_planarity: bool,
    /// Reverse the normals of these objects (comma separated names: OBJ `o`/`g`, glTF node or mesh, the
    /// file name for PLY and STL); without a list, of every object. Put it after the scene.
    #[arg(long, value_name = "OBJECT,...", num_args = 0..=1, value_delimiter = ',', default_missing_value = "")]
    flip_normals: Option<Vec<String>>,
    /// Make these objects two-sided (two patches back to back, one per side, each with the face's area
    /// and material); without a list, every object. Put it after the scene.
    #[arg(long, value_name = "OBJECT,...", num_args = 0..=1, value_delimiter = ',', default_missing_value = "")]
    two_sided: Option<Vec<String>>,
}

impl SceneArgs {
    fn options(&self) -> SceneOptions {
        let set = |names: &Option<Vec<String>>| match names {
            None => ObjectSet::None,
            Some(list) if list.iter().all(|n| n.is_empty()) => ObjectSet::All,
            Some(list) => {
                ObjectSet::Named(list.iter().filter(|n| !n.is_empty()).cloned().collect())
            }
        };
        SceneOptions {
            planarity: Planarity {
                tolerance: self.planarity,
                strict: self.strict_planarity,
            },
            flip_normals: set(&self.flip_normals),
            two_sided: set(&self.two_sided),
        }
    }
}

/// Options shared by every command that casts lines.
#[derive(clap::Args, Debug)]
struct RunOptions {
    #[command(flatten)]
    input: SceneArgs,
    /// Seed of the random line streams.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Tracing backend (default: embree when built in).
    #[arg(long, value_enum)]
    tracer: Option<TracerArg>,
    /// Ray query: `single`, or `packet4`/`packet8`/`packet16` (Embree, native widths only).
    #[arg(long, default_value = "single", value_parser = parse_query)]
    query: Query,
    /// Independent groups of lines behind each standard error.
    #[arg(long, default_value_t = DEFAULT_GROUPS as u16, value_parser = clap::value_parser!(u16).range(2..=1024))]
    groups: u16,
    /// Estimator of the bias-corrected H_s and I_s: plug-in, miller-madow, grassberger, chao-shen,
    /// chao-wang-jost.
    #[arg(long, default_value = DEFAULT_ESTIMATOR.name(), value_parser = parse_estimator)]
    estimator: EntropyEstimator,
    /// Standard errors of the count-based measures: `groups` (batch means, conservative when rows are
    /// undersampled) or `jackknife` (delete-a-group, closer to the real scatter, ~15% slower on large
    /// meshes). I_s^c always gets batch means.
    #[arg(long, default_value = "groups", value_parser = parse_errors)]
    errors: ErrorMethod,
}

#[derive(clap::Args, Debug)]
struct AnalyzeArgs {
    /// A scene file (OBJ, glTF, PLY, STL), or a built-in scene such as `@cube:10` (see `scx scenes`).
    scene: String,
    /// Number of global lines (accepts `1e7`; default 1e6, or no limit with a budget).
    #[arg(long, value_parser = parse_count)]
    lines: Option<u64>,
    #[command(flatten)]
    run: RunOptions,
    /// Which measures to compute (comma separated): discrete, continuous, radiosity. Default: all that
    /// apply (radiosity needs an emitting material, and brings the discrete counts along).
    #[arg(long, value_delimiter = ',', value_enum)]
    measures: Option<Vec<MeasureArg>>,
    /// Stop after this many seconds (then --lines is only a cap).
    #[arg(long, value_parser = parse_positive)]
    seconds: Option<f64>,
    /// Stop when the standard error of --target-measure is at most this (then --lines is only a cap).
    #[arg(long, value_parser = parse_positive)]
    target_stderr: Option<f64>,
    /// The measure --target-stderr watches: mutual_information, entropy, continuous_mutual_information,
    /// accuracy.
    #[arg(long, default_value = "mutual_information", value_parser = parse_target_measure)]
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
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

#[derive(clap::Args, Debug)]
struct ConvergenceArgs {
    /// A scene file (OBJ, glTF, PLY, STL), or a built-in scene such as `@cube:30`.
    scene: String,
    /// The line counts to run, comma separated.
    #[arg(long, value_delimiter = ',', value_parser = parse_count, default_value = "1e4,1e5,1e6,1e7")]
    lines: Vec<u64>,
    /// Runs per line count (seeds seed, seed+1, ...).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000))]
    repeats: u32,
    #[command(flatten)]
    run: RunOptions,
    /// Also write every run's measures as CSV.
    #[arg(long)]
    csv: Option<std::path::PathBuf>,
    /// Also draw error against run time, log-log (.svg or .png).
    #[arg(long)]
    plot: Option<std::path::PathBuf>,
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
    Radiosity,
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

fn parse_tolerance(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "`{s}`: need a number >= 0 (a fraction of the polygon's size)"
        )),
    }
}

fn parse_positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{s}`: need a positive number")),
    }
}

fn parse_estimator(s: &str) -> Result<EntropyEstimator, String> {
    EntropyEstimator::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = EntropyEstimator::ALL.iter().map(|e| e.name()).collect();
        format!("`{s}`: expected one of {}", names.join(", "))
    })
}

fn parse_errors(s: &str) -> Result<ErrorMethod, String> {
    ErrorMethod::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = ErrorMethod::NAMES.iter().map(|(n, _)| *n).collect();
        format!("`{s}`: expected one of {}", names.join(", "))
    })
}

fn parse_target_measure(s: &str) -> Result<TargetMeasure, String> {
    TargetMeasure::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = TargetMeasure::NAMES.iter().map(|(n, _)| *n).collect();
        format!("`{s}`: expected one of {}", names.join(", "))
    })
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
            let list: String = scenes::CATALOGUE
                .iter()
                .map(|b| format!("{:<18} {}\n", b.usage, b.description))
                .collect();
            finish(write_stdout(&list))
        }
        Command::Analyze(args) => finish(try_analyze(&args)),
        Command::Export(args) => finish(try_export(&args)),
        Command::Convergence(args) => finish(convergence::run(&args)),
        Command::Refine(args) => finish(try_refine(&args)),
        Command::Crosscheck(args) => finish(try_crosscheck(&args)),
        Command::Reproduce(args) => finish(reproduce::run(&args)),
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

fn load_scene(spec: &str, input: &SceneArgs) -> Result<scene::Scene, Failure> {
    let scene = scenes::load_with(spec, &input.options()).map_err(bad_input)?;
    for w in &scene.warnings {
        eprintln!("scx: warning: {w}");
    }
    Ok(scene)
}

fn try_export(args: &ExportArgs) -> Result<(), Failure> {
    let scene = load_scene(&args.scene, &args.input)?;
    let gltf = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"));
    let written = if gltf {
        scene::gltf::write(&scene, &args.output)
    } else {
        scene::obj::write(&scene, &args.output)
    };
    written.map_err(|e| Failure {
        code: 1,
        message: e.to_string(),
    })?;
    eprintln!(
        "scx: wrote {} ({} patches){}",
        args.output.display(),
        scene.patch_count(),
        if gltf { "" } else { " and its MTL library" }
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

/// A scene with its tracer and thread pool, ready to run analyses.
struct Runner {
    scene: scene::Scene,
    tracer: Box<dyn scene_complexity::trace::Tracer>,
    pool: rayon::ThreadPool,
    threads: usize,
    query: Query,
    control: Arc<RunControl>,
}

impl Runner {
    fn new(spec: &str, opts: &RunOptions) -> Result<Runner, Failure> {
        let scene = load_scene(spec, &opts.input)?;
        let backend = match opts.tracer {
            Some(TracerArg::Embree) => Backend::Embree,
            Some(TracerArg::Rust) => Backend::Rust,
            None => Backend::default_available(),
        };
        let tracer = make_tracer(backend, &scene, opts.query).map_err(bad_input)?;
        let (threads, pool) = thread_pool(opts.threads)?;
        let control = Arc::new(RunControl::default());
        watch_ctrl_c(&control);
        Ok(Runner {
            scene,
            tracer,
            pool,
            threads,
            query: opts.query,
            control,
        })
    }

    /// Runs one analysis with a progress bar (of `total` lines when known).
    fn analyze(&self, cfg: &AnalysisConfig, total: Option<u64>) -> Result<Analysis, Failure> {
        progress::while_running(&self.control, total, || {
            self.pool
                .install(|| analyze(&self.scene, self.tracer.as_ref(), cfg, &self.control))
        })
        .map_err(|e| Failure {
            code: if e.is_bad_input() { 2 } else { 1 },
            message: e.to_string(),
        })
    }

    fn info(&self) -> report::RunInfo<'_> {
        report::RunInfo {
            scene: &self.scene,
            tracer: self.tracer.name(),
            query: self.query,
            threads: self.threads,
            bundle: 0,
        }
    }

    /// A config for `lines` lines with these options (the visibility measures).
    fn config(&self, opts: &RunOptions, lines: u64, seed: u64) -> AnalysisConfig {
        AnalysisConfig {
            measures: Measures::VISIBILITY,
            groups: usize::from(opts.groups),
            estimator: opts.estimator,
            errors: opts.errors,
            ..AnalysisConfig::new(lines, seed)
        }
    }
}

fn try_analyze(args: &AnalyzeArgs) -> Result<(), Failure> {
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
        source: LineSource::bundles(args.bundle).map_err(bad_input)?,
        enclose: args.enclose,
        ..runner.config(&args.run, lines, args.run.seed)
    };
    let total = (!open_ended).then_some(lines);
    let analysis = runner.analyze(&cfg, total)?;
    for w in &analysis.warnings {
        eprintln!("scx: warning: {w}");
    }
    let run = report::RunInfo {
        bundle: args.bundle,
        ..runner.info()
    };
    let text = match args.format {
        Format::Table => report::table(&run, &analysis),
        Format::Json => report::json(&run, &analysis),
        Format::Csv => report::csv(&analysis),
    };
    write_stdout(&text)
}

fn try_refine(args: &RefineArgs) -> Result<(), Failure> {
    let scene = load_scene(&args.scene, &args.input)?;
    let backend = match args.tracer {
        Some(TracerArg::Embree) => Backend::Embree,
        Some(TracerArg::Rust) => Backend::Rust,
        None => Backend::default_available(),
    };
    // Check the backend once up front, so that an unavailable one is a clear input error.
    make_tracer(backend, &scene, Query::Single).map_err(bad_input)?;
    let strategy = match args.strategy {
        StrategyArg::Uniform => Strategy::Uniform,
        StrategyArg::Power => Strategy::Power,
        StrategyArg::Smoothness => Strategy::Smoothness,
        StrategyArg::Information => Strategy::Information,
    };
    let cfg = RefineConfig {
        strategy,
        target_patches: args.patches,
        lines_per_round: args.lines,
        seed: args.seed,
        growth: args.growth,
        solve: SolveOptions::default(),
    };
    let (_, pool) = thread_pool(args.threads)?;
    let started = std::time::Instant::now();
    let mut log = |r: &RefineRound| {
        let mi = r
            .radiosity_mutual_information
            .map(|x| format!(", radiosity I_s {x:.4} (plug-in, this round's lines only)"))
            .unwrap_or_default();
        eprintln!(
            "scx: refine {strategy}: {} -> {} patches, {} lines, {:.2} s{mi}",
            r.patches_before, r.patches_after, r.lines, r.seconds
        );
    };
    let refined = pool
        .install(|| {
            refine(
                &scene,
                &|s| make_tracer(backend, s, Query::Single),
                &cfg,
                &mut log,
            )
        })
        .map_err(|e| Failure {
            code: if e.is_bad_input() { 2 } else { 1 },
            message: e.to_string(),
        })?;
    scene::obj::write(&refined.scene, &args.output).map_err(|e| Failure {
        code: 1,
        message: e.to_string(),
    })?;
    let lines: u64 = refined.rounds.iter().map(|r| r.lines).sum();
    eprintln!(
        "scx: wrote {} ({} patches) and its MTL library: {} rounds, {lines} lines, {:.2} s",
        args.output.display(),
        refined.scene.patch_count(),
        refined.rounds.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

fn try_crosscheck(args: &CrosscheckArgs) -> Result<(), Failure> {
    if !(args.ulps.is_finite() && args.ulps >= 0.0) {
        return Err(bad_input(format!(
            "--ulps {}: need a finite number >= 0",
            args.ulps
        )));
    }
    let scene = load_scene(&args.scene, &args.input)?;
    let embree = make_tracer(Backend::Embree, &scene, Query::Single).map_err(bad_input)?;
    let rust = make_tracer(Backend::Rust, &scene, Query::Single).map_err(bad_input)?;
    let (_, pool) = thread_pool(args.threads)?;
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
            code: if e.is_bad_input() { 2 } else { 1 },
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

/// The worker threads (default: all cores) and a rayon pool of that size.
fn thread_pool(threads: Option<usize>) -> Result<(usize, rayon::ThreadPool), Failure> {
    let threads = threads.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| bad_input(format!("cannot start {threads} threads: {e}")))?;
    Ok((threads, pool))
}

/// The first Ctrl-C asks the run to stop and report what it gathered; a second one ends the program.
fn watch_ctrl_c(control: &Arc<RunControl>) {
    let control = Arc::clone(control);
    let presses = std::sync::atomic::AtomicU32::new(0);
    // Failing to install the handler only loses the clean stop: Ctrl-C then ends the program as usual.
    let _ = ctrlc::set_handler(move || {
        if presses.fetch_add(1, std::sync::atomic::Ordering::SeqCst) > 0 {
            std::process::exit(130);
        }
        eprintln!("\nscx: stopping after the batches under way (Ctrl-C again to quit now)");
        control.request_stop();
    });
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
