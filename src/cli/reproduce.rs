//! `scx reproduce`: the paper's tables regenerated (see [`scene_complexity::reproduce`]), printed as
//! Markdown on stdout as each table finishes; one log line per run on stderr.

use std::time::Instant;

use scene_complexity::reproduce::{reproduce, LinePlan, ReproduceConfig, TableReport, TABLES};
use scene_complexity::trace::Backend;

use super::{thread_pool, write_stdout, Failure, TracerArg};

/// Arguments of `scx reproduce`.
#[derive(clap::Args, Debug)]
pub struct ReproduceArgs {
    /// The tables to regenerate, comma separated (default: all, 1 to 9).
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u8).range(1..=9))]
    table: Vec<u8>,
    /// Lines per run: `default` (the paper's counts, at most 1e8 per run), `paper` (the paper's counts,
    /// 1e9 included), a factor on the defaults (`x0.1`), or one count for every run (`1e6`).
    #[arg(long, default_value = "default", value_parser = LinePlan::parse)]
    lines: LinePlan,
    /// Seed of every run's lines.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Tracing backend (default: embree when built in).
    #[arg(long, value_enum)]
    tracer: Option<TracerArg>,
}

/// Runs `scx reproduce`.
pub fn run(args: &ReproduceArgs) -> Result<(), Failure> {
    let tables = if args.table.is_empty() {
        TABLES.collect()
    } else {
        args.table.clone()
    };
    let cfg = ReproduceConfig {
        tables,
        lines: args.lines,
        seed: args.seed,
        backend: match args.tracer {
            Some(TracerArg::Embree) => Backend::Embree,
            Some(TracerArg::Rust) => Backend::Rust,
            None => Backend::default_available(),
        },
    };
    let (threads, pool) = thread_pool(args.threads)?;
    let start = Instant::now();
    write_stdout(&format!(
        "`scx reproduce`: lines {}, seed {}, tracer {}, {threads} \
         threads. Each value is `estimate ± standard error`; `corr.` is the bias-corrected estimate \
         (chao-wang-jost row entropies); `paper` is the published value.\n\n",
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
            printed = write_stdout(&t.markdown());
        }
    };
    let mut log = |m: &str| eprintln!("scx reproduce: {m}");
    pool.install(|| reproduce(&cfg, &mut log, &mut on_table))
        .map_err(|e| Failure {
            code: if e.is_bad_input() { 2 } else { 1 },
            message: e.to_string(),
        })?;
    printed?;
    write_stdout(&format!(
        "Total: {:.1} s ({:.1} min).\n",
        start.elapsed().as_secs_f64(),
        start.elapsed().as_secs_f64() / 60.0
    ))
}
