//! Command-line arguments and dispatch. Knows the library's public API only (never a backend's types).

mod analyze;
mod args;
mod calibrate;
mod commands;
mod convergence;
mod crosscheck;
mod docs;
mod exit;
mod export;
mod file_kind;
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

use clap::{CommandFactory, Parser};

use commands::{Cli, Command};
use exit::Exit;

/// Runs the command line.
pub fn main() -> ExitCode {
    let cli = Cli::try_parse().unwrap_or_else(|e| usage_error(e));
    output::set_quiet(cli.quiet);
    // A panic is a bug in scx, never the user's to read as a backtrace: the hook keeps its message
    // quiet (a reader that catches a dependency's panic has already said what went wrong), and one that
    // reaches here, from this thread or a worker's, ends the program with a sentence and exit code 1.
    std::panic::set_hook(Box::new(|info| {
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let place = info
            .location()
            .map(|l| format!(" ({}:{})", l.file(), l.line()))
            .unwrap_or_default();
        if let Ok(mut last) = LAST_PANIC.lock() {
            *last = Some(format!("{message}{place}"));
        }
    }));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| dispatch(cli)))
        .unwrap_or_else(|_| {
            let what = LAST_PANIC
                .lock()
                .ok()
                .and_then(|mut m| m.take())
                .unwrap_or_default();
            Err(exit::Failure {
                code: Exit::Failed,
                message: format!(
                    "internal error, a bug in scx: {what}; please report it with the command line"
                ),
            })
        });
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

/// Ends the program on a command line clap refused (exit 2; help and version exit 0), with a hint
/// when a flag whose list is optional took the scene as its list.
fn usage_error(e: clap::Error) -> ! {
    use clap::error::ErrorKind;
    let swallowed = matches!(
        e.kind(),
        ErrorKind::MissingRequiredArgument | ErrorKind::InvalidValue
    );
    let hint = swallowed
        .then(|| {
            let words: Vec<String> = std::env::args_os()
                .skip(1)
                .map(|w| w.to_string_lossy().into_owned())
                .collect();
            swallowed_scene(&Cli::command(), &words)
        })
        .flatten();
    let Some(hint) = hint else { e.exit() };
    let _ = e.print();
    eprintln!("hint: {hint}");
    std::process::exit(e.exit_code());
}

/// When a flag that takes an optional list (`--two-sided`, `--flip-normals`, `--aimed`) is followed by
/// a word that looks like a scene (an existing file, a built-in `@...`, a scene file's name), the
/// sentence that says so: clap gave that word to the flag, and then found no scene.
fn swallowed_scene(command: &clap::Command, words: &[String]) -> Option<String> {
    let optional_lists: Vec<String> = command
        .get_subcommands()
        .flat_map(|c| c.get_arguments())
        .filter(|a| {
            a.get_num_args()
                .is_some_and(|n| n.min_values() == 0 && n.takes_values())
        })
        .filter_map(|a| a.get_long().map(|l| format!("--{l}")))
        .collect();
    words.windows(2).find_map(|pair| {
        let (flag, value) = (&pair[0], &pair[1]);
        (optional_lists.contains(flag) && looks_like_scene(value)).then(|| {
            format!(
                "{flag} took `{value}` as its list; put the scene first, or write {flag}=NAMES, \
                 or put `--` before the scene"
            )
        })
    })
}

/// Whether a word names a scene rather than objects: a built-in, standard input, a scene file's
/// extension, or an existing file.
fn looks_like_scene(word: &str) -> bool {
    let path = std::path::Path::new(word);
    let scene_extension = path.extension().is_some_and(|e| {
        ["obj", "gltf", "glb", "ply", "stl"].contains(&e.to_string_lossy().to_lowercase().as_str())
    });
    word.starts_with('@') || word == "-" || scene_extension || path.is_file()
}

/// The message and place of the last panic (for the sentence that ends the program).
static LAST_PANIC: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Runs the command.
fn dispatch(cli: Cli) -> Result<Exit, exit::Failure> {
    match cli.command {
        Command::Scenes(args) => commands::scenes(&args),
        Command::Analyze(args) => analyze::run(&args),
        Command::Export(args) => export::run(&args),
        Command::Convergence(args) => convergence::run(&args),
        Command::Refine(args) => refine::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Crosscheck(args) => crosscheck::run(&args),
        Command::Reproduce(args) => reproduce::run(&args),
        Command::Calibrate(args) => calibrate::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Completions(args) => docs::completions(&args, Cli::command()),
        Command::Man(args) => docs::man(&args, Cli::command()),
    }
}
