//! `scx refine`: a scene's patches refined by a meshing strategy (paper Table 9), written as OBJ + MTL.

use std::path::PathBuf;

use clap::ValueEnum;
use scene_complexity::refine::{refine, RefineConfig, RefineRound, Strategy};
use scene_complexity::RunControl;
use scene_complexity::Scene;
use scene_complexity::SolveOptions;
use scene_complexity::{make_tracer, Query};
use std::sync::Arc;

use super::args::SceneArgs;
use super::args::{parse_count, parse_positive, parse_whole_in, Seed, Threads, Tracer, TracerArg};
use super::exit::{Exit, Failure};
use super::input::load_scene;
use super::output::{self, note};
use super::runner::{thread_pool, watch_ctrl_c};

/// Arguments of `scx refine`.
#[derive(clap::Args, Debug)]
pub struct RefineArgs {
    /// The scene: a file in OBJ, glTF/GLB, PLY or STL (told by its content), a built-in such as
    /// `@cornell` (`scx scenes` lists them), or `-` for a scene on standard input.
    scene: String,
    #[command(flatten)]
    input: SceneArgs,
    /// Which patches to split: uniform (all, largest first), power (A_i B_i), smoothness (variation of
    /// received radiosity over the patch), information (loss of information transfer).
    #[arg(long, value_enum)]
    strategy: StrategyArg,
    /// Stop at about this many patches (at most 2 over). Refine only splits patches, so N below the
    /// scene's patch count is refused; at that count the mesh is written as it is.
    #[arg(long, value_parser = parse_patches, allow_negative_numbers = true)]
    patches: u64,
    /// The file to write the refined mesh to, its format chosen by the extension: `.obj` (OBJ, its MTL
    /// library written beside it), `.ply` (binary PLY), `.stl` (binary STL), `.gltf` or `.glb` (glTF
    /// 2.0); any other extension is refused. Checked writable first. OBJ and PLY keep the patches.
    #[arg(short, long)]
    output: PathBuf,
    /// Global lines per refinement round (accepts `1e6`).
    #[arg(long, default_value = "1e6", value_parser = parse_count, allow_negative_numbers = true)]
    lines: u64,
    /// Each round grows the mesh by at most this factor (above 1).
    #[arg(long, default_value_t = 1.5, value_parser = parse_positive, allow_negative_numbers = true)]
    growth: f64,
    #[command(flatten)]
    seed: Seed,
    #[command(flatten)]
    threads: Threads,
    #[command(flatten)]
    tracer: Tracer,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum StrategyArg {
    Uniform,
    Power,
    Smoothness,
    Information,
}

/// `--patches`: the patch count to refine towards, a whole number from 1 to the most patches a built-in
/// scene may have ([`scene_complexity::MAX_BUILTIN_PATCHES`]): a refined mesh grows by every split, and a
/// target beyond what memory can hold would be found only after hours of rounds.
fn parse_patches(s: &str) -> Result<u64, String> {
    parse_whole_in(
        s,
        "the number of patches to refine towards",
        1,
        scene_complexity::MAX_BUILTIN_PATCHES as u64,
    )
}

/// Refuses a target below the scene's patch count: refine only splits patches, so it would write the
/// scene unchanged and leave the user to find out. At the count itself, says that no round will run.
fn check_target(patches: u64, scene: &Scene) -> Result<(), Failure> {
    let has = scene.patch_count() as u64;
    if patches < has {
        return Err(Failure::bad_input(format!(
            "--patches {patches}: {} already has {has} patches, and refine only splits patches (it \
             never merges them); ask for more than {has}",
            scene.name
        )));
    }
    if patches == has {
        note(&format!(
            "{} already has {has} patches (--patches {patches}): no patch is split, the mesh is \
             written as it is",
            scene.name
        ));
    }
    Ok(())
}

/// Runs `scx refine`.
pub fn run(args: &RefineArgs) -> Result<Exit, Failure> {
    let format = super::export::planned_output(&args.output, &args.scene)?;
    let scene = load_scene(&args.scene, &args.input.options(), &args.input.policy())?;
    check_target(args.patches, &scene)?;
    super::export::check_not_read(&args.output, format, &scene)?;
    let backend = TracerArg::backend(args.tracer.value);
    // Check the backend once up front, so that an unavailable one is a clear input error.
    make_tracer(backend, &scene, Query::Single).map_err(Failure::bad_input)?;
    let strategy = match args.strategy {
        StrategyArg::Uniform => Strategy::Uniform,
        StrategyArg::Power => Strategy::Power,
        StrategyArg::Smoothness => Strategy::Smoothness,
        StrategyArg::Information => Strategy::Information,
    };
    let cfg = RefineConfig {
        strategy,
        target_patches: usize::try_from(args.patches).unwrap_or(usize::MAX),
        lines_per_round: args.lines,
        seed: args.seed.value,
        growth: args.growth,
        solve: SolveOptions::default(),
    };
    let (_, pool) = thread_pool(args.threads.value)?;
    let control = Arc::new(RunControl::default());
    watch_ctrl_c(&control);
    let started = std::time::Instant::now();
    let mut log = |r: &RefineRound| {
        let mi = r
            .radiosity_mutual_information
            .map(|x| format!(", radiosity I_s {x:.4} bits (plug-in, this round's lines only)"))
            .unwrap_or_default();
        note(&format!(
            "refine {strategy}: {} -> {} patches, {} lines, {:.2} s{mi}",
            r.patches_before, r.patches_after, r.lines, r.seconds
        ));
    };
    let refined = pool
        .install(|| {
            refine(
                &scene,
                &|s| make_tracer(backend, s, Query::Single),
                &cfg,
                &control,
                &mut log,
            )
        })
        .map_err(Failure::of)?;
    let beside = super::export::write_scene(&refined.scene, format, &args.output)?;
    let lines: u64 = refined.rounds.iter().map(|r| r.lines).sum();
    output::note(&format!(
        "wrote {} as {}, {}{beside}: {} rounds, {lines} lines, {:.2} s",
        args.output.display(),
        format.name(),
        format.patches_written(&refined.scene),
        refined.rounds.len(),
        started.elapsed().as_secs_f64()
    ));
    if refined.interrupted {
        note("interrupted: the mesh written is that of the last finished round");
        return Ok(Exit::Interrupted);
    }
    Ok(Exit::Ok)
}
