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
    let cli = Cli::parse();
    output::set_quiet(cli.quiet);
    let result = match cli.command {
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
