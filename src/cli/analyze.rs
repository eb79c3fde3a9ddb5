//! `scx analyze`: one analysis, reported as a table, JSON or CSV.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use clap::ValueEnum;
use scene_complexity::Measure;
use scene_complexity::Query;
use scene_complexity::{cast, finish};
use scene_complexity::{
    remaining_lines, start, Budget, CastOptions, Measures, RunControl, RunIdentity, RunSpec,
    RunState, SamplerChoice, SceneRef, Scope, Shard, StopReason, Target,
};
use scene_complexity::{
    sphere_lines, LineBound, LineSource, LinesThrough, Sampler, MAX_BUNDLE_GRID,
};

use super::args::{
    check_target_measure, parse_count, parse_positive, parse_seconds, parse_whole_in,
    target_measure_parser, ReportOutput, RunOptions,
};
use super::exit::{Exit, Failure};
use super::file_kind::report_format;
use super::output::{self, warn};
use super::patch_files::PatchFiles;
use super::report::{self, Format};
use super::runner::Runner;

/// Arguments of `scx analyze`.
#[derive(clap::Args, Debug)]
pub struct AnalyzeArgs {
    /// The scene: a file in OBJ, glTF/GLB, PLY or STL (told by its content), a built-in such as
    /// `@cube:10` (`scx scenes` lists them), or `-` for a scene in any of those formats on standard input. With --resume, the saved run's scene (given again, it must be the same).
    #[arg(required_unless_present = "resume")]
    scene: Option<String>,
    /// Number of global lines (accepts `1e7`; default 1e6, or no limit with a budget), counted as lines
    /// through the bounding sphere, the paper's unit: lines drawn through the box count for what they
    /// are worth, so fewer are drawn (--lines-through).
    #[arg(long, value_parser = parse_count, allow_negative_numbers = true)]
    lines: Option<u64>,
    #[command(flatten)]
    run: RunOptions,
    /// Which measures to compute (comma separated): discrete, continuous, radiosity. Default: all that
    /// apply (radiosity needs an emitting material, and brings the discrete counts along).
    #[arg(long, value_delimiter = ',', value_enum)]
    measures: Option<Vec<MeasureArg>>,
    /// Stop after this long (then --lines is only a cap): seconds (`90`, `1e3`), or with units (`30s`,
    /// `5m`, `2h`, `1h30m`).
    #[arg(long, value_name = "DURATION", value_parser = parse_seconds, allow_negative_numbers = true)]
    seconds: Option<f64>,
    /// Stop when the standard error of --target-measure is at most this AND its reading is reliable
    /// (verdict `ok`); then --lines (and --seconds) only cap the run.
    #[arg(long, value_parser = parse_positive, allow_negative_numbers = true)]
    target_stderr: Option<f64>,
    /// The measure --target-stderr watches (only with --target-stderr) [default:
    /// mutual_information_corrected].
    #[arg(long, value_parser = target_measure_parser())]
    target_measure: Option<Measure>,
    /// Cast the lines in bundles of G x G parallel lines (jittered grid over the disc, traced as adjacent
    /// packets); 0 casts independent lines. The standard errors include the correlation within a bundle.
    #[arg(long, default_value_t = 0, value_parser = parse_bundle)]
    bundle: u32,
    /// How the lines are drawn: `independent` (each line on its own), `sobol` (randomised quasi-Monte
    /// Carlo: one Owen-scrambled Sobol' sequence per standard-error group, 8 groups unless --groups
    /// says otherwise, lines that cover the space of lines more evenly; not with --bundle), or `auto`: `sobol` for a run that counts no patch
    /// pairs (`--measures continuous` without --patches: I_s^c alone, several times tighter at the same
    /// cost), `independent` otherwise (the bias-corrected readings need independent lines to be honest
    /// without a looser debiasing). The report says which. docs/sampling.md says for which measures
    /// `sobol` pays.
    #[arg(long, default_value = "auto", value_parser = parse_sampler)]
    sampler: SamplerChoice,
    /// Where the lines are drawn: `sphere` (the paper's global lines, through the bounding sphere),
    /// `box` (through the scene's bounding box: the sphere's lines that meet it, so no line is spent
    /// missing the box; with --sampler sobol, far smaller errors on scenes whose walls are parallel to
    /// the box's faces), `polytope` (through the box with its edges and corners cut off at 45 degrees:
    /// with --sampler sobol, far smaller errors on solids whose faces it shares, such as the
    /// octahedron), or `auto`: for --sampler sobol the box when it is smaller than the sphere (rooms,
    /// most scenes built along the axes), else the polytope when the scene lies mostly in its faces,
    /// else the sphere; for independent lines the smallest of the three (the same estimates, less
    /// time); the sphere for --bundle and --enclose, with which box and polytope are refused. The
    /// report says which, how many lines were drawn and what they are worth. docs/sampling.md.
    #[arg(long, default_value = "auto", value_parser = parse_bound)]
    lines_through: LinesThrough,
    /// Close an open scene with a virtual, absorbing environment patch (the bounding sphere, facing
    /// inwards): escaping segments become pairs with it, rows of F sum to 1, and every visibility measure
    /// is that of the enclosed scene. Its area is counted: the part of the sphere that sees the scene's
    /// front sides or itself (4 pi R^2 for objects in open space). Changes nothing in a closed scene.
    /// With --patches, --form-factors and --objects, the environment is a row (and object) of its own,
    /// after the scene's patches.
    #[arg(long)]
    enclose: bool,
    /// Output format (default: the one the extension of -o names, `.json` or `.csv`, else `table`; one
    /// that contradicts the extension is refused): `table` (for people), `json` (one document with every
    /// field, units and verdicts), `csv` (one row per measure: scene, lines, seed, tracer, patches,
    /// escape_fraction, seconds, family, measure, unit, value, stderr, reliability, corrected,
    /// corrected_stderr, corrected_reliability, then the bounds each reading breaks and the bias and
    /// lines behind an `undersampled` verdict: flags, corrected_flags, estimated_bias, lines_needed,
    /// corrected_estimated_bias, corrected_lines_needed; last, what the lines drawn are worth through
    /// the sphere and where they were drawn: sphere_lines, lines_through).
    #[arg(long, value_enum)]
    format: Option<Format>,
    #[command(flatten)]
    out: ReportOutput,
    /// Save the run's state to FILE at the end (also when interrupted): `scx merge` reports it,
    /// `--resume` continues it (docs/runs.md, "Runs beyond one machine").
    #[arg(long, value_name = "FILE")]
    save: Option<PathBuf>,
    /// Run only shard K of M of the run's batches (K from 1); needs --save or --checkpoint, and no
    /// --seconds or --target-stderr. `scx merge` joins the shards' states into the report of the whole
    /// run.
    #[arg(long, value_name = "K/M", value_parser = parse_shard,
          conflicts_with_all = ["seconds", "target_stderr"])]
    shard: Option<Shard>,
    /// Save the run's state to FILE every --checkpoint-every seconds and at the end (atomically: a
    /// run killed loses only the work since the last checkpoint).
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Time between checkpoints, with --checkpoint (or --resume, which saves back as it goes):
    /// seconds (`300`, the default), or with units (`30s`, `5m`, `1h30m`).
    #[arg(long, value_name = "DURATION", value_parser = parse_seconds, allow_negative_numbers = true)]
    checkpoint_every: Option<f64>,
    /// Continue the run saved in FILE (by --save or --checkpoint) with its own settings, up to --lines
    /// (more lines than first asked are fine for a run that drew 131072 lines or more; a shorter one is cut
    /// into smaller batches and continues only to a few lines more, as the message says), and save it
    /// back to FILE as it goes. --tracer, --query
    /// and --threads may differ from the first run's: they change no number.
    #[arg(long, value_name = "FILE", conflicts_with_all = [
        "seed", "groups", "estimator", "errors", "measures", "seconds", "target_stderr",
        "target_measure", "bundle", "sampler", "lines_through", "enclose", "shard", "planarity", "strict_planarity",
        "flip_normals", "two_sided"])]
    resume: Option<PathBuf>,
    #[command(flatten)]
    files: PatchFiles,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum MeasureArg {
    Discrete,
    Continuous,
    Radiosity,
}

/// A shard `K/M`, 1 <= K <= M.
fn parse_shard(s: &str) -> Result<Shard, String> {
    let (k, m) = s
        .split_once('/')
        .ok_or_else(|| format!("`{s}`: a shard is K/M, shard K (from 1) of M"))?;
    let parse = |x: &str| {
        x.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{s}`: K and M must be whole numbers"))
    };
    let (k, m) = (parse(k)?, parse(m)?);
    if !(1..=m).contains(&k) {
        return Err(format!("`{s}`: need 1 <= K <= M"));
    }
    Ok(Shard { index: k, count: m })
}

/// Checks the per-patch files before any work: their kinds, that they can be written, and that a new
/// run will have what they need (a resumed one is checked once its state is read).
fn check_patch_files(args: &AnalyzeArgs) -> Result<(), Failure> {
    let f = &args.files;
    f.check()?;
    if !f.form_factors.is_empty()
        && args.measures.as_ref().is_some_and(|m| {
            !m.contains(&MeasureArg::Discrete) && !m.contains(&MeasureArg::Radiosity)
        })
    {
        return Err(Failure::bad_input(
            "--form-factors needs the pair counts: add `discrete` to --measures",
        ));
    }
    Ok(())
}

fn parse_bundle(s: &str) -> Result<u32, String> {
    let g = parse_whole_in(
        s,
        "the bundle grid (0: independent lines)",
        0,
        u64::from(MAX_BUNDLE_GRID),
    )?;
    let g = g as u32;
    LineSource::bundles(g).map(|_| g).map_err(|e| e.to_string())
}

fn parse_sampler(s: &str) -> Result<SamplerChoice, String> {
    SamplerChoice::from_name(s).ok_or_else(|| format!("`{s}`: expected auto, independent or sobol"))
}

fn parse_bound(s: &str) -> Result<LinesThrough, String> {
    LinesThrough::from_name(s)
        .ok_or_else(|| format!("`{s}`: expected auto, sphere, box or polytope"))
}

/// The spec of a new run from the arguments, the command line parsed once, before its scene is read,
/// its sampler settled ([`RunSpec::drawn_by`]): its bound and the lines it draws are settled with the
/// scene ([`RunSpec::through`]).
fn spec_of(args: &AnalyzeArgs) -> Result<RunSpec, Failure> {
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
            measure: args.target_measure.unwrap_or(Measure::DEFAULT_TARGET),
            stderr,
        }),
    };
    if args.sampler == SamplerChoice::Given(Sampler::Sobol) && args.bundle > 0 {
        return Err(Failure::bad_input(format!(
            "--sampler sobol draws single lines (each a point of a randomised Sobol' sequence) and does \
             not take --bundle {}: drop one of them",
            args.bundle
        )));
    }
    let container = match args.lines_through {
        LinesThrough::Bound(b) if b != LineBound::Sphere => Some(b.name()),
        _ => None,
    };
    if let (Some(name), true) = (container, args.bundle > 0) {
        return Err(Failure::bad_input(format!(
            "--lines-through {name} draws single lines, each from a face of the bounding {name}, and \
             does not take --bundle {}: drop one of them",
            args.bundle
        )));
    }
    if let (Some(name), true) = (container, args.enclose) {
        return Err(Failure::bad_input(format!(
            "--enclose makes the bounding sphere the environment patch, whose area is counted from \
             the lines that miss the scene, and --lines-through {name} leaves most of those out: drop \
             one of them"
        )));
    }
    let lines = args.lines.unwrap_or(if budget.is_open_ended() {
        1_000_000_000_000
    } else {
        1_000_000
    });
    Ok(RunSpec {
        measures,
        budget,
        source: LineSource::bundles(args.bundle).map_err(Failure::bad_input)?,
        enclose: args.enclose,
        per_patch: args.files.wants_per_patch(),
        ..args.run.spec(lines, args.run.seed.value)
    }
    .drawn_by(args.sampler)
    .grouped(args.run.groups_asked()))
}

/// A run about to be cast: its runner, identity (with its spec) and state, and the seconds it took
/// before.
struct Prepared {
    runner: Runner,
    identity: RunIdentity,
    state: RunState,
    seconds: f64,
}

/// A new run from the arguments.
fn new_run(args: &AnalyzeArgs, name: &str) -> Result<Prepared, Failure> {
    let spec = spec_of(args)?;
    if name == "-" && (args.save.is_some() || args.checkpoint.is_some()) {
        return Err(Failure::bad_input(
            "a run of a scene read from standard input cannot be saved (a resume or merge could not \
             read it again): save the scene to a file",
        ));
    }
    let reading = args.run.input.options();
    let runner = Runner::with(
        name,
        (&reading, &args.run.input.policy()),
        args.run.tracing(),
        args.run.threads.value,
    )?;
    let spec = spec.through(&runner.scene, args.lines_through);
    let state = start(&runner.scene, &spec).map_err(Failure::bad_input)?;
    let identity = RunIdentity::new(
        SceneRef::of(name, &reading, &runner.scene),
        spec,
        args.shard,
        runner.tracing,
    );
    Ok(Prepared {
        runner,
        identity,
        state,
        seconds: 0.0,
    })
}

/// A saved run to continue, to `--lines` when given, traced as `--tracer`/`--query` ask or else as it
/// was.
fn resumed_run(args: &AnalyzeArgs, file: &Path) -> Result<Prepared, Failure> {
    let stored = scene_complexity::read_state(file).map_err(persist_failure)?;
    let mut identity = stored.identity().clone();
    identity
        .continuable_here()
        .map_err(|problem| Failure::bad_input(format!("{}: {problem}", file.display())))?;
    let name = args
        .scene
        .clone()
        .unwrap_or_else(|| identity.scene.name.clone());
    let tracing = match (args.run.tracer.value, args.run.query) {
        (None, Query::Single) => identity.tracing,
        _ => args.run.tracing(),
    };
    let runner = Runner::with(
        &name,
        (&identity.scene.reading, &args.run.input.policy()),
        tracing,
        args.run.threads.value,
    )?;
    identity.tracing = runner.tracing;
    let shown = file.display().to_string();
    let saved = stored.into_run(&runner.scene).map_err(persist_failure)?;
    // A state keeps the per-patch sums when its first run was asked for --patches, and a resumed run
    // goes on gathering what its state holds: without them from the start, they cannot be had now.
    let wanted = saved.state.wanted();
    let without_sums: Vec<String> = (!wanted.per_patch)
        .then(|| shown.clone())
        .into_iter()
        .collect();
    args.files
        .check_saved(&shown, &identity, wanted, &without_sums)?;
    let mut state = saved.state;
    let asked = args
        .lines
        .map(|n| identity.spec.lines_for(&runner.scene, n));
    if let Some(lines) = asked.filter(|&n| n != identity.spec.lines) {
        identity.spec = identity.spec.extended_to(lines).map_err(|e| {
            let bound = identity.spec.bound;
            let e = e.in_sphere_lines(&runner.scene, bound);
            let unit = drawn_lines_unit(&runner.scene, bound);
            Failure::bad_input(format!("{shown}: {e}{unit}"))
        })?;
        state = state.extend(identity.spec.plan());
    }
    Ok(Prepared {
        runner,
        identity,
        state,
        seconds: saved.seconds,
    })
}

/// For a run drawn through the box or the polytope, what the counts of a message about its lines count:
/// lines through the sphere, as `--lines` does, while its batches hold lines drawn.
fn drawn_lines_unit(scene: &scene_complexity::Scene, bound: LineBound) -> String {
    match bound {
        LineBound::Sphere => String::new(),
        LineBound::Box | LineBound::Polytope => format!(
            " (line counts through the bounding sphere, as --lines counts them; the run draws its lines \
             through the bounding {}, each worth {:.4} through the sphere, and its batches hold lines \
             drawn)",
            bound.name(),
            sphere_lines(scene, bound, 1)
        ),
    }
}

pub use super::output::persist_failure;

/// Saves checkpoints every so often while a run goes on, and remembers a failed save (the run then
/// stops, since its work could no longer be kept).
struct Checkpoints<'a> {
    path: Option<&'a Path>,
    every: Duration,
    last: Instant,
    failed: Option<Failure>,
    /// Seconds of the run before this session, and when this session began.
    before: f64,
    began: Instant,
}

impl Checkpoints<'_> {
    fn seconds(&self) -> f64 {
        self.before + self.began.elapsed().as_secs_f64()
    }

    fn after_round(&mut self, identity: &RunIdentity, state: &RunState, control: &RunControl) {
        let Some(path) = self.path else { return };
        if self.failed.is_some() || self.last.elapsed() < self.every {
            return;
        }
        match scene_complexity::save_state(path, identity, state, self.seconds()) {
            Ok(()) => self.last = Instant::now(),
            Err(e) => {
                self.failed = Some(persist_failure(e));
                control.request_stop();
            }
        }
    }
}

/// Seconds between checkpoints when --checkpoint-every is not given.
const DEFAULT_CHECKPOINT_EVERY: f64 = 300.0;

/// Refuses an option given without the one it tunes: accepted, it would do nothing, and the user would
/// believe it did.
fn check_tuning_options(args: &AnalyzeArgs) -> Result<(), Failure> {
    if args.checkpoint_every.is_some() && args.checkpoint.is_none() && args.resume.is_none() {
        return Err(Failure::bad_input(
            "--checkpoint-every needs --checkpoint FILE (or --resume FILE): it sets how often the \
             run's state is saved to that file, and without one nothing is saved",
        ));
    }
    check_target_measure(args.target_measure, args.target_stderr).map_err(Failure::bad_input)
}

/// A state to resume that is not there is named as one that cannot be read (the resume file is also
/// checked as an output, and a missing folder would read as an output that cannot be written).
fn check_state_exists(file: &Path) -> Result<(), Failure> {
    if file.exists() {
        return Ok(());
    }
    Err(Failure {
        code: Exit::Io,
        message: format!(
            "cannot read {}: there is no such file (--resume continues a run saved by --save or \
             --checkpoint)",
            file.display()
        ),
    })
}

/// Runs `scx analyze`.
pub fn run(args: &AnalyzeArgs) -> Result<Exit, Failure> {
    check_tuning_options(args)?;
    let format = report_format("analyze", args.format, args.out.output.as_deref(), "")?;
    if args.shard.is_some() && args.save.is_none() && args.checkpoint.is_none() {
        return Err(Failure::bad_input(
            "--shard needs --save FILE (or --checkpoint FILE): a shard's work is only of use saved",
        ));
    }
    let checkpoint = args.checkpoint.as_deref().or(args.resume.as_deref());
    // `--resume F --save F` saves F once.
    let same = |a: &Path, b: &Path| {
        a == b
            || std::fs::canonicalize(a)
                .is_ok_and(|x| std::fs::canonicalize(b).is_ok_and(|y| x == y))
    };
    let save = args.save.as_deref().filter(|s| {
        !(args.resume.as_deref().is_some_and(|r| same(s, r))
            && checkpoint == args.resume.as_deref())
    });
    let checkpoint_flag = if args.checkpoint.is_some() {
        "--checkpoint"
    } else {
        "--resume"
    };
    let mut outputs: Vec<(&str, &Path)> = Vec::new();
    outputs.extend(args.out.output.as_deref().map(|p| ("-o", p)));
    outputs.extend(save.map(|p| ("--save", p)));
    outputs.extend(checkpoint.map(|p| (checkpoint_flag, p)));
    outputs.extend(args.files.outputs());
    let mut inputs: Vec<(&str, &Path)> = Vec::new();
    inputs.extend(args.scene.as_deref().map(|s| ("scene", Path::new(s))));
    inputs.extend(args.resume.as_deref().map(|p| ("--resume", p)));
    output::check_distinct(
        &outputs,
        &inputs,
        &[
            ("--resume", "--resume"),
            ("--checkpoint", "--resume"),
            ("--save", "--resume"),
        ],
    )?;
    if let Some(file) = args.resume.as_deref() {
        check_state_exists(file)?;
    }
    output::check_all(args.out.output.as_deref())?;
    for path in save.into_iter().chain(checkpoint) {
        output::check_state(path)?;
    }
    check_patch_files(args)?;
    let _locks = output::lock_states(save.into_iter().chain(checkpoint))?;
    let Prepared {
        mut runner,
        identity,
        mut state,
        seconds: before,
    } = match &args.resume {
        Some(file) => resumed_run(args, file)?,
        None => new_run(args, args.scene.as_deref().unwrap_or("-"))?,
    };
    output::check_not_read_by(&outputs, &runner.scene)?;
    // The per-patch files asked for now decide what is shared out at the end; what is gathered is what
    // the state gathers.
    let cfg = RunSpec {
        per_patch: args.files.wants_per_patch(),
        ..identity.spec.clone()
    };
    let scope = Scope::of(identity.shard);
    let every = args.checkpoint_every.unwrap_or(DEFAULT_CHECKPOINT_EVERY);
    let mut checkpoints = Checkpoints {
        path: checkpoint,
        // Longer than the clock can count (`--checkpoint-every 1e30`): a checkpoint at the end only.
        every: Duration::try_from_secs_f64(every).unwrap_or(Duration::MAX),
        last: Instant::now(),
        failed: None,
        before,
        began: Instant::now(),
    };
    let total = (!cfg.budget.is_open_ended()).then(|| remaining_lines(&state, scope));
    let control = &runner.control;
    let label = super::runner::drawn_label(cfg.bound);
    let stop_reason = runner
        .in_pool(total, label, || {
            cast(
                &runner.scene,
                runner.tracer(),
                &cfg,
                &mut state,
                CastOptions {
                    scope,
                    round_seconds: checkpoint.map(|_| every.min(30.0) / 2.0),
                },
                control,
                &mut |s| checkpoints.after_round(&identity, s, control),
            )
        })
        .map_err(|e| Failure {
            code: Exit::Failed,
            message: e.to_string(),
        })?;
    let seconds = checkpoints.seconds();
    runner.release_tracer();
    // The state's bytes are taken now (the analysis consumes the state) and saved after the report, so
    // that a save that fails never costs the report of the finished work.
    let saves: Vec<&Path> = save.into_iter().chain(checkpoint).collect();
    let bytes =
        (!saves.is_empty()).then(|| scene_complexity::encode_state(&identity, &state, seconds));
    // In the run's pool: the measures use the threads asked for, like the tracing.
    let analysis = runner
        .pool
        .install(|| finish(&runner.scene, &cfg, state, stop_reason, seconds))
        .map_err(Failure::of)?;
    for w in &analysis.warnings {
        warn(&w.message);
    }
    let run = report::RunInfo {
        shard: identity.shard,
        ..runner.info()
    };
    let text = report::render(format, &run, &analysis);
    let mut failures = Vec::new();
    failures.extend(output::emit(args.out.output.as_deref(), &text).err());
    failures.extend(
        runner
            .pool
            .install(|| args.files.write(&runner.scene, &analysis))
            .err(),
    );
    for path in saves {
        let bytes = bytes.as_deref().unwrap_or_default();
        match scene_complexity::save_state_bytes(path, bytes) {
            Ok(()) => output::wrote(path),
            Err(e) => failures.push(persist_failure(e)),
        }
    }
    // A checkpoint that failed during the run stopped it: the report covers the lines cast until then.
    if let Some(mut f) = checkpoints.failed {
        f.message.push_str(
            "; the run stopped there, and the report printed covers the lines cast until then",
        );
        failures.insert(0, f);
    }
    if let Some(first) = failures.into_iter().next() {
        return Err(first);
    }
    Ok(if analysis.stop_reason == StopReason::Interrupted {
        Exit::Interrupted
    } else {
        Exit::Ok
    })
}
