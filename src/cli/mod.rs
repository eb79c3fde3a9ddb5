//! Command-line arguments and dispatch. Knows the library's public API only (never a backend's types).

mod analyze;
mod args;
mod convergence;
mod crosscheck;
mod docs;
mod export;
mod input;
mod merge;
mod output;
mod patch_files;
mod plot;
mod progress;
mod refine;
mod render;
mod report;
mod reproduce;
mod runner;
mod table;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// The exit codes, one scheme for every command (listed in `--help` and the README).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// Success.
    Ok = 0,
    /// A check failed (crosscheck found lines that differ), or the machinery failed (a tracer error).
    Failed = 1,
    /// Bad input or usage: a scene that cannot be read, a nonsense option.
    BadInput = 2,
    /// A file could not be read or written.
    Io = 3,
    /// Interrupted (Ctrl-C): the report printed covers the lines gathered so far.
    Interrupted = 130,
}

/// The exit codes as `--help` lists them.
const EXIT_CODES: &str = "\
Exit codes:
  0    success
  1    a check failed (crosscheck found lines that differ) or the tracer failed
  2    bad input or usage (a scene that cannot be read, a value out of range)
  3    a file could not be read or written (named in the message)
  130  interrupted (Ctrl-C): the report printed covers the lines gathered so far";

/// scx: how hard is a 3D scene to light and to mesh? Information-theoretic scene complexity
/// (Feixas, del Acebo, Bekaert, Sbert, Eurographics 1999) from global lines.
#[derive(Parser, Debug)]
#[command(name = "scx", version, about, long_about = None, after_help = EXIT_CODES)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
    /// No progress bars, warnings or "wrote FILE" lines on stderr; errors still print (a JSON report
    /// keeps its warnings).
    #[arg(short, long, global = true)]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Cast global lines through a scene and report its complexity measures.
    #[command(after_help = concat!(
        "Examples:\n",
        "  scx analyze @cube:10 --lines 1e7\n",
        "  scx analyze room.obj --format json -o room.json\n",
        "  scx analyze @cube:30 --target-stderr 0.002 --lines 1e9\n",
        "  scx analyze @fig2:a --lines 1e7 --patches patches.csv --form-factors ff.mtx\n",
        "  cat room.obj | scx analyze - --lines 1e6\n\n",
        "Exit codes: 0 success, 1 the tracer failed, 2 bad input, 3 a file could not be written, \
         130 interrupted (the report covers the lines gathered)."
    ))]
    Analyze(analyze::AnalyzeArgs),
    /// List the built-in scenes and their parameters.
    #[command(after_help = "Example:\n  scx scenes")]
    Scenes(ScenesArgs),
    /// Write a scene (built-in or file) as OBJ + MTL.
    #[command(after_help = "Example:\n  scx export @cornell -o cornell.obj")]
    Export(export::ExportArgs),
    /// Run a scene at growing line counts: every measure with its error against run time.
    #[command(after_help = concat!(
        "Example:\n",
        "  scx convergence @cube:30 --lines 1e5,1e6,1e7 --repeats 3 --plot conv.png --csv conv.csv"
    ))]
    Convergence(convergence::ConvergenceArgs),
    /// Refine a scene's patches with a meshing strategy (paper Table 9) and write the mesh as OBJ + MTL.
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
        "Exit codes: 0 success, 1 the tracer failed, 2 bad input, 3 a file could not be written, \
         130 interrupted."
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
struct ScenesArgs {
    #[command(flatten)]
    out: args::ReportOutput,
}

/// A failure with its exit code and the sentence that explains it.
#[derive(Debug)]
pub struct Failure {
    code: Exit,
    message: String,
}

/// A library error that tells whether the user's input is at fault.
pub trait InputError: std::fmt::Display {
    /// Whether the input (a scene, materials, settings) is at fault, not the machinery.
    fn is_bad_input(&self) -> bool;
}

macro_rules! input_errors {
    ($($t:ty),*) => {$(
        impl InputError for $t {
            fn is_bad_input(&self) -> bool {
                <$t>::is_bad_input(self)
            }
        }
    )*};
}

input_errors!(
    scene_complexity::analysis::AnalysisError,
    scene_complexity::refine::RefineError,
    scene_complexity::reproduce::ReproduceError
);

impl Failure {
    /// A library error: bad input (2) when the input is at fault, else a failure (1).
    pub fn of(e: impl InputError) -> Self {
        Failure {
            code: if e.is_bad_input() {
                Exit::BadInput
            } else {
                Exit::Failed
            },
            message: e.to_string(),
        }
    }

    /// Bad input (exit code 2).
    pub fn bad_input(message: impl ToString) -> Self {
        Failure {
            code: Exit::BadInput,
            message: message.to_string(),
        }
    }
}

/// Runs the command line.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    output::set_quiet(cli.quiet);
    let result = match cli.command {
        Command::Scenes(args) => scenes(&args),
        Command::Analyze(args) => analyze::run(&args),
        Command::Export(args) => export::run(&args),
        Command::Convergence(args) => convergence::run(&args),
        Command::Refine(args) => refine::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Crosscheck(args) => crosscheck::run(&args),
        Command::Reproduce(args) => reproduce::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Completions(args) => docs::completions(&args),
        Command::Man(args) => docs::man(&args),
    };
    match result {
        Ok(Exit::Interrupted) => {
            eprintln!("scx: interrupted: the report covers the lines gathered so far");
            ExitCode::from(Exit::Interrupted as u8)
        }
        Ok(code) => ExitCode::from(code as u8),
        Err(f) => {
            eprintln!("scx: error: {}", f.message);
            ExitCode::from(f.code as u8)
        }
    }
}

fn scenes(args: &ScenesArgs) -> Result<Exit, Failure> {
    let list: String = scene_complexity::scenes::CATALOGUE
        .iter()
        .map(|b| format!("{:<18} {}\n", b.usage, b.description))
        .collect();
    output::check_all(args.out.output.as_deref())?;
    output::emit(args.out.output.as_deref(), &list)?;
    Ok(Exit::Ok)
}
