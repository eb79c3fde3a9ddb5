//! `scx crosscheck`: Embree and the pure-Rust tracer on the same lines, hit for hit.

use scene_complexity::crosscheck::aimed::AimKind;
use scene_complexity::crosscheck::{self, AimedConfig, CrossCheckConfig, Tolerance};
use scene_complexity::{make_tracer, AnalysisError, Backend, Query, Scene, Tracer, DEFAULT_GROUPS};

use super::args::SceneArgs;
use super::args::{parse_count, parse_whole_in, ReportOutput, Seed, Threads};
use super::exit::{Exit, Failure};
use super::file_kind::text_report;
use super::input::load_scene;
use super::output::{self, check_all};
use super::runner::thread_pool;

/// Random lines when `--lines` is not given.
const DEFAULT_RANDOM_LINES: u64 = 1_000_000;

/// Lines of each kind when `--aimed` is given without `--lines`.
const DEFAULT_AIMED_LINES: u64 = 100_000;

/// Arguments of `scx crosscheck`.
#[derive(clap::Args, Debug)]
pub struct CrosscheckArgs {
    /// The scene: a file in OBJ, glTF/GLB, PLY or STL (told by its content), a built-in such as
    /// `@cube:10` (`scx scenes` lists them), or `-` for a scene on standard input.
    scene: String,
    #[command(flatten)]
    input: SceneArgs,
    /// Number of global lines (accepts `1e6`), random ones counted through the bounding sphere as `scx
    /// analyze --lines` counts them [default: 1e6; with --aimed: 1e5 of each kind].
    #[arg(long, value_parser = parse_count, allow_negative_numbers = true)]
    lines: Option<u64>,
    /// Instead of random lines, lines aimed where tracers could differ: at vertices, along and across
    /// edges, in and near faces' planes; these kinds (comma separated), or all without a list. `--lines`
    /// lines of each, their directions and points drawn from the seed; the report gives the lines and
    /// differing lines per kind. Put it after the scene.
    #[arg(long, value_enum, value_name = "KIND,...", num_args = 0..=1, value_delimiter = ',',
          default_missing_value = "all")]
    aimed: Option<Vec<AimArg>>,
    #[command(flatten)]
    seed: Seed,
    #[command(flatten)]
    threads: Threads,
    /// Distances agree within this many f32 ulps at max(t, 1).
    #[arg(long, default_value_t = Tolerance::default().ulps, value_parser = parse_ulps,
          allow_negative_numbers = true)]
    ulps: f32,
    /// How many differing lines to print.
    #[arg(long, default_value_t = 5, value_parser = parse_show, allow_negative_numbers = true)]
    show: usize,
    #[command(flatten)]
    out: ReportOutput,
}

/// The kinds of aimed lines (`--aimed`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum AimArg {
    /// Every kind below.
    All,
    /// Through a vertex, in a random direction (every vertex in turn).
    Vertex,
    /// Through a vertex along a coordinate axis: exactly through it in f32.
    VertexAxis,
    /// Through a vertex along a face or space diagonal (tied components).
    VertexDiagonal,
    /// Through the tenth of the vertices shared by the most triangles (fans, poles), random directions.
    Fan,
    /// Through a random point of an edge, in a random direction.
    Edge,
    /// Through a point of an edge, in the plane of one of its triangles.
    EdgeInFace,
    /// Along an edge, through both its ends.
    AlongEdge,
    /// In a triangle's plane, through a random point of it.
    InFace,
    /// Through a triangle's centroid at 1e-7 to 1e-3 rad (log-uniform) to its plane.
    Grazing,
    /// Through a vertex at 1e-7 to 1e-3 rad to the plane of one of its triangles.
    GrazingVertex,
}

impl AimArg {
    /// The library's kinds this value names.
    fn kinds(self) -> Vec<AimKind> {
        let one = match self {
            AimArg::All => return AimKind::ALL.to_vec(),
            AimArg::Vertex => AimKind::Vertex,
            AimArg::VertexAxis => AimKind::VertexAxis,
            AimArg::VertexDiagonal => AimKind::VertexDiagonal,
            AimArg::Fan => AimKind::Fan,
            AimArg::Edge => AimKind::Edge,
            AimArg::EdgeInFace => AimKind::EdgeInFace,
            AimArg::AlongEdge => AimKind::AlongEdge,
            AimArg::InFace => AimKind::InFace,
            AimArg::Grazing => AimKind::Grazing,
            AimArg::GrazingVertex => AimKind::GrazingVertex,
        };
        vec![one]
    }
}

/// The kinds asked for, each once, in the order of [`AimKind::ALL`].
/// `--ulps`: a tolerance in f32 ulps, a number >= 0.
fn parse_ulps(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "`{s}`: the tolerance must be a number of f32 ulps >= 0 (such as 4 or 0.5)"
        )),
    }
}

/// `--show`: how many differing lines to print, a whole number >= 0.
fn parse_show(s: &str) -> Result<usize, String> {
    parse_whole_in(s, "the number of lines to show", 0, 1_000_000).map(|n| n as usize)
}

fn aimed_kinds(args: &[AimArg]) -> Vec<AimKind> {
    let asked: Vec<AimKind> = args.iter().flat_map(|a| a.kinds()).collect();
    AimKind::ALL
        .into_iter()
        .filter(|k| asked.contains(k))
        .collect()
}

/// Runs `scx crosscheck`: exit 1 when a line differs.
pub fn run(args: &CrosscheckArgs) -> Result<Exit, Failure> {
    if !(args.ulps.is_finite() && args.ulps >= 0.0) {
        return Err(Failure::bad_input(format!(
            "--ulps {}: need a finite number >= 0",
            args.ulps
        )));
    }
    text_report("crosscheck", "text", args.out.output.as_deref(), "")?;
    check_all(args.out.output.as_deref())?;
    let scene = load_scene(&args.scene, &args.input.options(), &args.input.policy())?;
    let embree = make_tracer(Backend::Embree, &scene, Query::Single).map_err(Failure::bad_input)?;
    let rust = make_tracer(Backend::Rust, &scene, Query::Single).map_err(Failure::bad_input)?;
    let tracers = (embree.as_ref(), rust.as_ref());
    match &args.aimed {
        Some(kinds) => run_aimed(args, &scene, tracers, aimed_kinds(kinds)),
        None => run_random(args, &scene, tracers),
    }
}

/// Random lines: hits line by line, then the measures of an analysis with each tracer.
fn run_random(
    args: &CrosscheckArgs,
    scene: &Scene,
    (embree, rust): (&dyn Tracer, &dyn Tracer),
) -> Result<Exit, Failure> {
    let (_, pool) = thread_pool(args.threads.value)?;
    let cfg = CrossCheckConfig {
        lines: args.lines.unwrap_or(DEFAULT_RANDOM_LINES),
        seed: args.seed.value,
        tolerance: Tolerance { ulps: args.ulps },
        examples: args.show,
    };
    let check = pool
        .install(|| crosscheck::crosscheck(scene, embree, rust, &cfg, DEFAULT_GROUPS))
        .map_err(Failure::of)?;
    output::emit(
        args.out.output.as_deref(),
        &crosscheck::report(&check, scene),
    )?;
    verdict(check.hits.differing_lines(), check.hits.lines)
}

/// Aimed lines: hits line by line, kind by kind.
fn run_aimed(
    args: &CrosscheckArgs,
    scene: &Scene,
    (embree, rust): (&dyn Tracer, &dyn Tracer),
    kinds: Vec<AimKind>,
) -> Result<Exit, Failure> {
    let (_, pool) = thread_pool(args.threads.value)?;
    let cfg = AimedConfig {
        lines_per_kind: args.lines.unwrap_or(DEFAULT_AIMED_LINES),
        kinds,
        seed: args.seed.value,
        tolerance: Tolerance { ulps: args.ulps },
        examples: args.show,
    };
    let check = pool
        .install(|| crosscheck::compare_aimed(scene, embree, rust, &cfg))
        .map_err(|e| Failure::of(AnalysisError::from(e)))?;
    output::emit(
        args.out.output.as_deref(),
        &crosscheck::report_aimed(&check, scene, args.show),
    )?;
    verdict(check.differing_lines(), check.lines())
}

/// Exit 0 when no line differs, else 1 with the count.
fn verdict(differing: u64, lines: u64) -> Result<Exit, Failure> {
    if differing == 0 {
        Ok(Exit::Ok)
    } else {
        Err(Failure {
            code: Exit::Failed,
            message: format!("{differing} of {lines} lines differ between the tracers"),
        })
    }
}
