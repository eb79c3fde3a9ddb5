//! `scx completions` and `scx man`: shell completions and the manual page, generated from the same clap
//! definitions as the program (so they never disagree with it).

use std::path::PathBuf;

use clap_complete::Shell;

use super::exit::{Exit, Failure};
use super::file_kind::text_report;
use super::output::{self, check_all};

/// Arguments of `scx completions`.
#[derive(clap::Args, Debug)]
pub struct CompletionsArgs {
    /// The shell.
    shell: Shell,
    /// Write the script to FILE instead of standard output.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// Arguments of `scx man`.
#[derive(clap::Args, Debug)]
pub struct ManArgs {
    /// The command whose page to print (`analyze`, ...); absent: the page of scx itself.
    command: Option<String>,
    /// Write the page to FILE instead of standard output.
    #[arg(short, long)]
    output: Option<PathBuf>,
}

/// Prints the completion script of a shell for the program `scx` defines.
pub fn completions(args: &CompletionsArgs, mut scx: clap::Command) -> Result<Exit, Failure> {
    text_report("completions", "a shell script", args.output.as_deref(), "")?;
    check_all(args.output.as_deref())?;
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut scx, "scx", &mut script);
    output::emit(args.output.as_deref(), &String::from_utf8_lossy(&script))?;
    Ok(Exit::Ok)
}

/// Prints the manual page of scx, the program `scx` defines (its commands listed), or of one command
/// (`scx-analyze`).
pub fn man(args: &ManArgs, scx: clap::Command) -> Result<Exit, Failure> {
    text_report("man", "roff", args.output.as_deref(), "")?;
    check_all(args.output.as_deref())?;
    let command = match &args.command {
        None => scx,
        Some(name) => {
            let sub = scx.find_subcommand(name).ok_or_else(|| {
                let names: Vec<&str> = scx.get_subcommands().map(|c| c.get_name()).collect();
                Failure::bad_input(format!(
                    "no command `{name}`; the commands are {}",
                    names.join(", ")
                ))
            })?;
            // clap keeps names for the life of the program.
            let page_name: &'static str = Box::leak(format!("scx-{name}").into_boxed_str());
            sub.clone().name(page_name)
        }
    };
    let mut page = Vec::new();
    clap_mangen::Man::new(command)
        .render(&mut page)
        .expect("rendering into memory");
    output::emit(args.output.as_deref(), &String::from_utf8_lossy(&page))?;
    Ok(Exit::Ok)
}
