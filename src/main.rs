//! `scx`: the command-line front end of the scene complexity analyser.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
