//! `scx crosscheck`: Embree and the pure-Rust tracer on the same lines, hit for hit.

use scene_complexity::crosscheck::{self, CrossCheckConfig, Tolerance};
use scene_complexity::DEFAULT_GROUPS;
use scene_complexity::{make_tracer, Backend, Query};

use super::args::SceneArgs;
use super::args::{parse_count, ReportOutput, Seed, Threads};
use super::exit::{Exit, Failure};
use super::input::load_scene;
use super::output::{self, check_all};
use super::runner::thread_pool;

/// Arguments of `scx crosscheck`.
#[derive(clap::Args, Debug)]
pub struct CrosscheckArgs {
    /// A scene file (OBJ, glTF, PLY, STL), a built-in scene such as `@cube:10` (see `scx scenes`), or `-` for an OBJ on
    /// standard input.
    scene: String,
    #[command(flatten)]
    input: SceneArgs,
    /// Number of global lines (accepts `1e6`).
    #[arg(long, default_value = "1e6", value_parser = parse_count, allow_negative_numbers = true)]
    lines: u64,
    #[command(flatten)]
    seed: Seed,
    #[command(flatten)]
    threads: Threads,
    /// Distances agree within this many f32 ulps at max(t, 1).
    #[arg(long, default_value_t = Tolerance::default().ulps, allow_negative_numbers = true)]
    ulps: f32,
    /// How many differing lines to print.
    #[arg(long, default_value_t = 5)]
    show: usize,
    #[command(flatten)]
    out: ReportOutput,
}

/// Runs `scx crosscheck`: exit 1 when a line differs.
pub fn run(args: &CrosscheckArgs) -> Result<Exit, Failure> {
    if !(args.ulps.is_finite() && args.ulps >= 0.0) {
        return Err(Failure::bad_input(format!(
            "--ulps {}: need a finite number >= 0",
            args.ulps
        )));
    }
    check_all(args.out.output.as_deref())?;
    let scene = load_scene(&args.scene, &args.input.options(), &args.input.policy())?;
    let embree = make_tracer(Backend::Embree, &scene, Query::Single).map_err(Failure::bad_input)?;
    let rust = make_tracer(Backend::Rust, &scene, Query::Single).map_err(Failure::bad_input)?;
    let (_, pool) = thread_pool(args.threads.value)?;
    let cfg = CrossCheckConfig {
        lines: args.lines,
        seed: args.seed.value,
        tolerance: Tolerance { ulps: args.ulps },
        examples: args.show,
    };
    let check = pool
        .install(|| {
            crosscheck::crosscheck(&scene, embree.as_ref(), rust.as_ref(), &cfg, DEFAULT_GROUPS)
        })
        .map_err(Failure::of)?;
    output::emit(
        args.out.output.as_deref(),
        &crosscheck::report(&check, &scene),
    )?;
    if check.passed() {
        Ok(Exit::Ok)
    } else {
        Err(Failure {
            code: Exit::Failed,
            message: format!(
                "{} of {} lines differ between the tracers",
                check.hits.differing_lines(),
                check.hits.lines
            ),
        })
    }
}
