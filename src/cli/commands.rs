//! The command line: its commands and their arguments (clap's derive), and the listing of the built-in
//! scenes.

use clap::{Parser, Subcommand};

use super::exit::{Exit, Failure};
use super::file_kind::text_report;
use super::{
    analyze, calibrate, convergence, crosscheck, docs, export, merge, refine, render, reproduce,
};
use super::{args, output};

/// The exit codes as `--help` lists them (`scx --help` and the commands that cast lines), one text so
/// that no help says otherwise; docs/cli.md, "Exit codes", has the same words, which a test compares.
macro_rules! exit_codes {
    () => {
        "Exit codes:
  0    success; also a run stopped by --seconds or --target-stderr, the target met or not (the
       report says which)
  1    a check failed (crosscheck found lines that differ), the tracer failed, or scx failed (a
       bug: the message says so)
  2    bad input or usage: an option or value refused, a scene that cannot be read (the message
       names the file and line), bad materials, a run state that is damaged or of another run
  3    a file could not be written (every output is checked before any line is cast), or a run
       state could not be read (--resume, merge: the message gives the system's reason) or is
       held by a live run
  130  interrupted (Ctrl-C): the report printed covers the lines gathered so far"
    };
}

/// scx: how hard is a 3D scene to light and to mesh? Information-theoretic scene complexity
/// (Feixas, del Acebo, Bekaert, Sbert, Eurographics 1999) from global lines.
#[derive(Parser, Debug)]
#[command(name = "scx", version, about, long_about = None, after_help = exit_codes!())]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// No progress bars, warnings or "wrote FILE" lines on stderr; errors still print (a JSON report
    /// keeps its warnings).
    #[arg(short, long, global = true)]
    pub quiet: bool,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Cast global lines through a scene and report its complexity measures.
    #[command(after_help = concat!(
        "Examples:\n",
        "  scx analyze @cube:10 --lines 1e7\n",
        "  scx analyze room.obj --format json -o room.json\n",
        "  scx analyze @cube:30 --target-stderr 0.002 --lines 1e9\n",
        "  scx analyze @fig2:a --lines 1e7 --patches patches.csv --form-factors ff.mtx\n",
        "  cat room.obj | scx analyze - --lines 1e6\n\n",
        exit_codes!()
    ))]
    Analyze(analyze::AnalyzeArgs),
    /// List the built-in scenes and their parameters.
    #[command(after_help = "Example:\n  scx scenes")]
    Scenes(ScenesArgs),
    /// Write a scene (built-in or file) as OBJ + MTL, PLY, STL or glTF/GLB, chosen by the extension of -o.
    #[command(after_help = concat!(
        "Examples:\n",
        "  scx export @cornell -o cornell.obj    (OBJ, and cornell.mtl beside it)\n",
        "  scx export scan.ply -o scan.glb"
    ))]
    Export(export::ExportArgs),
    /// Run a scene at growing line counts: every measure with its error against run time.
    #[command(after_help = concat!(
        "Example:\n",
        "  scx convergence @cube:30 --lines 1e5,1e6,1e7 --repeats 3 --plot conv.png --csv conv.csv"
    ))]
    Convergence(convergence::ConvergenceArgs),
    /// Refine a scene's patches with a meshing strategy (paper Table 9) and write the mesh (OBJ + MTL,
    /// PLY, STL or glTF/GLB, by the extension of -o).
    #[command(after_help = concat!(
        "Example:\n",
        "  scx refine @cornell --strategy information --patches 460 -o cornell_460.obj"
    ))]
    Refine(refine::RefineArgs),
    /// Draw the scene with each patch coloured by a per-patch result of a run (row entropy, lost
    /// information, segments, radiosity, ...), with a labelled colour bar (PNG); optionally the coloured
    /// mesh (PLY).
    #[command(after_help = concat!(
        "Examples:\n",
        "  scx render @fig2:a --color lost-information --per-area --lines 1e7 -o fig2a.png\n",
        "  scx render @cornell --color radiosity -o cornell.png --patches-mesh cornell.ply\n",
        "  scx render @cube:10 --color row-entropy --camera 0.5,0.5,0.02,0.5,0.5,1,0,1,0,70 -o cube.png\n\n",
        exit_codes!()
    ))]
    Render(render::RenderArgs),
    /// Trace the same lines with Embree and the pure-Rust tracer, compare them hit for hit and measure
    /// for measure; exit 1 when a line differs beyond the tolerance.
    #[command(after_help = "Example:\n  scx crosscheck @cubes512 --lines 1e6")]
    Crosscheck(crosscheck::CrosscheckArgs),
    /// Join the saved states of a run's shards (`analyze --shard K/M --save FILE`) into the report of the
    /// whole run, identical to casting it at once.
    #[command(after_help = concat!(
        "Example:\n",
        "  for k in 1 2 3 4; do scx analyze @cube:30 --lines 1e9 --shard $k/4 --save part-$k.scx & done; wait\n",
        "  scx merge part-*.scx --format json -o cube30.json\n",
        "  scx merge part-*.scx --patches patches.csv --form-factors ff.mtx   (shards run with --patches)"
    ))]
    Merge(merge::MergeArgs),
    /// Regenerate the paper's Tables 1 to 9 and print each beside the published values (Markdown).
    #[command(after_help = "Example:\n  scx reproduce --table 4 --lines x0.1 -o table4.md")]
    Reproduce(reproduce::ReproduceArgs),
    /// Run scenes with exact values over many seeds: how often each reading's stated 95% interval
    /// covers the truth, how often readings are ok and ok ones cover, and how far off they are in
    /// standard errors (Markdown, CSV).
    #[command(after_help = concat!(
        "Examples:\n",
        "  scx calibrate --suite small\n",
        "  scx calibrate --scene @cube:10 --lines 1e6,1e7 --seeds 60 --csv cube10.csv"
    ))]
    Calibrate(calibrate::CalibrateArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell).
    #[command(after_help = concat!(
        "Example:\n",
        "  scx completions bash > ~/.local/share/bash-completion/completions/scx"
    ))]
    Completions(docs::CompletionsArgs),
    /// Print the manual page (roff), generated from these definitions.
    #[command(after_help = "Example:\n  scx man -o scx.1 && man ./scx.1")]
    Man(docs::ManArgs),
}

#[derive(clap::Args, Debug)]
pub struct ScenesArgs {
    #[command(flatten)]
    out: args::ReportOutput,
}

/// Runs `scx scenes`.
pub fn scenes(args: &ScenesArgs) -> Result<Exit, Failure> {
    let list: String = scene_complexity::CATALOGUE
        .iter()
        .map(|b| format!("{:<18} {}\n", b.usage, b.description))
        .collect();
    text_report("scenes", "a listing", args.out.output.as_deref(), "")?;
    output::check_all(args.out.output.as_deref())?;
    output::emit(args.out.output.as_deref(), &list)?;
    Ok(Exit::Ok)
}
