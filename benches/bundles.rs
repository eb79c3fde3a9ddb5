//! Do bundles of parallel lines pay? For each scene, line source (independent lines, bundles of G x G)
//! and query (single lines, Embree packets), runs the whole analysis and prints the throughput and the
//! standard error of I_s^c and I_s per unit of run time: stderr x sqrt(seconds), the error one second of
//! work buys (lower is better; it does not depend on the line count). Both are also given relative to
//! independent single lines. Time is CPU time of all threads (robust when the machine is shared) and
//! wall-clock time; standard errors are averaged (as variances) over a few seeds, each with 64 groups.
//!
//! `cargo bench --bench bundles [-- SCENE... [LINES]]`, default `@cube:30 @cubes512` and 10^6 lines.

mod common;

use std::time::Instant;

use scene_complexity::analysis::{analyze, AnalysisConfig};
use scene_complexity::sample::lines::LineSource;
use scene_complexity::scene::{self, Scene};
use scene_complexity::trace::{make_tracer, Backend, Query, Tracer};

const SEEDS: u64 = 3;
const GROUPS: usize = 64;

fn main() -> anyhow::Result<()> {
    let (specs, lines) = common::scenes_and_lines(1e6)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build()?;
    println!(
        "{lines} lines per run, 2 threads, {SEEDS} seeds x {GROUPS} groups; eff = stderr x sqrt(s), \
         relative to independent single lines (lower is better)"
    );
    println!(
        "{:<10} {:<15} {:>4}  {:>6} {:>6}  {:>10} {:>8} {:>8}  {:>10} {:>8} {:>8}",
        "scene",
        "query",
        "G",
        "Ml/s",
        "Ml/cpu",
        "se(I_s^c)",
        "eff cpu",
        "eff wall",
        "se(I_s)",
        "eff cpu",
        "eff wall"
    );
    for spec in &specs {
        let scene = scene::load(spec)?;
        let mut base: Option<Row> = None;
        for (backend, query) in queries() {
            let Ok(tracer) = make_tracer(backend, &scene, query) else {
                continue;
            };
            for grid in [0, 4, 8, 16, 32] {
                let row = pool.install(|| measure(&scene, tracer.as_ref(), lines, grid));
                let b = *base.get_or_insert(row);
                print_row(spec, &format!("{}-{query}", tracer.name()), grid, &row, &b);
            }
        }
    }
    Ok(())
}

fn queries() -> Vec<(Backend, Query)> {
    vec![
        (Backend::Embree, Query::Single),
        (Backend::Embree, Query::Packet(8)),
        (Backend::Embree, Query::Packet(16)),
        (Backend::Rust, Query::Single),
    ]
}

/// One configuration's totals over the seeds.
#[derive(Clone, Copy, Debug)]
struct Row {
    lines: f64,
    wall: f64,
    cpu: f64,
    /// Mean stderr^2 of I_s^c and of I_s over the seeds.
    var_cmi: f64,
    var_mi: f64,
}

impl Row {
    /// stderr x sqrt(seconds per run).
    fn eff(&self, var: f64, seconds: f64) -> f64 {
        (var * seconds / SEEDS as f64).sqrt()
    }
}

fn measure(scene: &Scene, tracer: &dyn Tracer, lines: u64, grid: u32) -> Row {
    let source = LineSource::bundles(grid).expect("grids from the list are valid");
    let cfg = |seed| AnalysisConfig {
        groups: GROUPS,
        source,
        ..AnalysisConfig::new(lines, seed)
    };
    let mut row = Row {
        lines: 0.0,
        wall: 0.0,
        cpu: 0.0,
        var_cmi: 0.0,
        var_mi: 0.0,
    };
    for seed in 1..=SEEDS {
        let (w0, c0) = (Instant::now(), common::cpu_seconds());
        let a = analyze(scene, tracer, &cfg(seed)).expect("analysis runs");
        row.wall += w0.elapsed().as_secs_f64();
        row.cpu += common::cpu_seconds() - c0;
        row.lines += a.lines as f64;
        let se = |e: Option<scene_complexity::measure::Estimate>| {
            e.and_then(|e| e.stderr).unwrap_or(f64::NAN)
        };
        row.var_cmi += se(a.visibility.continuous_mutual_information).powi(2) / SEEDS as f64;
        row.var_mi += se(a.visibility.mutual_information).powi(2) / SEEDS as f64;
    }
    row
}

fn print_row(spec: &str, query: &str, grid: u32, r: &Row, base: &Row) {
    let rel = |x: f64, y: f64| x / y;
    println!(
        "{spec:<10} {query:<15} {grid:>4}  {:>6.2} {:>6.2}  {:>10.3e} {:>8.2} {:>8.2}  {:>10.3e} {:>8.2} {:>8.2}",
        r.lines / r.wall / 1e6,
        r.lines / r.cpu / 1e6,
        r.var_cmi.sqrt(),
        rel(r.eff(r.var_cmi, r.cpu), base.eff(base.var_cmi, base.cpu)),
        rel(r.eff(r.var_cmi, r.wall), base.eff(base.var_cmi, base.wall)),
        r.var_mi.sqrt(),
        rel(r.eff(r.var_mi, r.cpu), base.eff(base.var_mi, base.cpu)),
        rel(r.eff(r.var_mi, r.wall), base.eff(base.var_mi, base.wall)),
    );
}
