//! `scx reproduce`: the paper's tables regenerated (see [`scene_complexity::reproduce`]), printed as
//! Markdown on stdout as each table finishes; one log line per run on stderr.

use std::time::Instant;

use scene_complexity::reproduce::{reproduce, LinePlan, ReproduceConfig, TableReport, TABLES};
use scene_complexity::Backend;

use super::args::{parse_whole_in, ReportOutput, Seed, Threads, Tracer, TracerArg};
use super::exit::{Exit, Failure};
use super::file_kind::text_report;
use super::output::{self, check_all};
use super::runner::thread_pool;

/// Arguments of `scx reproduce`.
#[derive(clap::Args, Debug)]
pub struct ReproduceArgs {
    /// The tables to regenerate, comma separated (default: all, 1 to 9).
    #[arg(long, value_delimiter = ',', value_parser = parse_table, allow_hyphen_values = true)]
    table: Vec<u8>,
    /// Lines per run: `default` (the paper's counts, at most 1e8 per run), `paper` (the paper's counts,
    /// 1e9 included), a factor on the defaults (`x0.1`), or one count for every run (`1e6`).
    #[arg(long, default_value = "default", value_parser = LinePlan::parse)]
    lines: LinePlan,
    #[command(flatten)]
    seed: Seed,
    #[command(flatten)]
    threads: Threads,
    #[command(flatten)]
    tracer: Tracer,
    #[command(flatten)]
    out: ReportOutput,
}

/// `--table`: a table of the paper, 1 to 9.
fn parse_table(s: &str) -> Result<u8, String> {
    parse_whole_in(s, "a table number", 1, 9).map(|n| n as u8)
}

/// Runs `scx reproduce`: the Markdown goes to standard output as each table finishes, or to `-o FILE`
/// at the end.
pub fn run(args: &ReproduceArgs) -> Result<Exit, Failure> {
    text_report("reproduce", "Markdown", args.out.output.as_deref(), "")?;
    check_all(args.out.output.as_deref())?;
    let tables = if args.table.is_empty() {
        TABLES.collect()
    } else {
        args.table.clone()
    };
    let cfg = ReproduceConfig {
        tables,
        lines: args.lines,
        seed: args.seed.value,
        backend: TracerArg::backend(args.tracer.value),
    };
    let (threads, pool) = thread_pool(args.threads.value)?;
    let start = Instant::now();
    let mut document = String::new();
    let to_file = args.out.output.is_some();
    let mut print = |text: &str| -> Result<(), Failure> {
        if to_file {
            document.push_str(text);
            Ok(())
        } else {
            output::emit(None, text)
        }
    };
    print(&format!(
        "`scx reproduce`: lines {}, seed {}, tracer {}, {threads} \
         threads. Each value is `estimate ± standard error`; `corr.` is the bias-corrected estimate \
         (chao-wang-jost row entropies); `paper` is the published value. `!` marks a reading that \
         breaks a bound of the theory, as `scx analyze` does (the note under the table says which); a \
         finding judged on such readings says `on flagged readings` and names them.\n\n",
        cfg.lines,
        cfg.seed,
        match cfg.backend {
            Backend::Embree => "embree",
            Backend::Rust => "rust",
        }
    ))?;
    let mut printed: Result<(), Failure> = Ok(());
    let mut on_table = |t: &TableReport| {
        if printed.is_ok() {
            printed = print(&t.markdown());
        }
    };
    let mut log = |m: &str| output::note(&format!("reproduce: {m}"));
    pool.install(|| reproduce(&cfg, &mut log, &mut on_table))
        .map_err(Failure::of)?;
    printed?;
    print(&format!(
        "Total: {:.1} s ({:.1} min).\n",
        start.elapsed().as_secs_f64(),
        start.elapsed().as_secs_f64() / 60.0
    ))?;
    if let Some(path) = &args.out.output {
        output::write_file(path, document.as_bytes())?;
    }
    Ok(Exit::Ok)
}
