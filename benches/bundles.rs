//! Do bundles of parallel lines pay? For each scene, line source (independent lines, bundles of G x G)
//! and query (single lines, Embree packets), runs the whole analysis and prints the throughput and the
//! standard error of I_s^c and I_s per unit of run time: stderr x sqrt(seconds), the error one second of
//! work buys (lower is better; it does not depend on the line count). Both are also given relative to
//! independent single lines. Time is CPU time of all threads (robust when the machine is shared) and
//! wall-clock time; standard errors are averaged (as variances) over a few seeds, each with 64 groups.
//!
//! `cargo bench --bench bundles [-- SCENE... [LINES]]`, default `@cube:30 @cubes512` and 10^6 lines.
//!
//! Group standard errors are noisy and, for the plug-in and corrected I_s, not the real error in an
//! undersampled regime, so with `SCX_BUNDLE_SEEDS=N` the bench instead runs N seeds of each line source
//! (independent, 4 x 4 and 8 x 8 bundles; Embree single lines, 16 groups) and judges them by the spread
//! of the estimates over the seeds, the direct measure of their error ([`spread`]).

mod common;

use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::scenes;
use std::time::Instant;

use scene_complexity::internals::analysis::analyze;
use scene_complexity::internals::measure::Estimate;
use scene_complexity::internals::run::{RunControl, RunSpec};
use scene_complexity::internals::sample::lines::LineSource;
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::trace::{make_tracer, Backend, Query, Tracer};

const SEEDS: u64 = 3;
const GROUPS: usize = 64;

fn main() -> anyhow::Result<()> {
    let (specs, lines) = common::scenes_and_lines(1e6)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build()?;
    if let Ok(seeds) = std::env::var("SCX_BUNDLE_SEEDS") {
        return pool.install(|| spread(&specs, lines, seeds.parse()?));
    }
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
        let scene = scenes::load(spec)?;
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
    let cfg = |seed| RunSpec {
        groups: GROUPS,
        source,
        ..RunSpec::new(lines, seed)
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
        let a = analyze(scene, tracer, &cfg(seed), &RunControl::default()).expect("analysis runs");
        row.wall += w0.elapsed().as_secs_f64();
        row.cpu += common::cpu_seconds() - c0;
        row.lines += a.lines as f64;
        let se = |e: Option<scene_complexity::internals::measure::Estimate>| {
            e.and_then(|e| e.stderr).unwrap_or(f64::NAN)
        };
        row.var_cmi += se(a.estimate(Measure::ContinuousMutualInformation)).powi(2) / SEEDS as f64;
        row.var_mi += se(a.estimate(Measure::MutualInformation)).powi(2) / SEEDS as f64;
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

/// The measures the seed-spread mode follows: name, and the measure.
const FOLLOWED: [(&str, Measure); 4] = [
    ("I_s^c", Measure::ContinuousMutualInformation),
    ("I_s", Measure::MutualInformation),
    ("I_s corr.", Measure::MutualInformationCorrected),
    ("E(MSE)", Measure::MsePerLine),
];

/// Independent lines against 4 x 4 and 8 x 8 bundles over `seeds` seeds each (seed outermost, so that
/// a drift of the machine's speed falls on every source alike). Per source and measure: the spread
/// (sample standard deviation) of the estimate over the seeds with its own relative uncertainty
/// 1/sqrt(2(n-1)), the rms reported standard error, the mean, and the figure of merit spread x
/// sqrt(CPU seconds per run) relative to independent lines. A mean that moves between sources by more
/// than a few of its standard errors (spread/sqrt(n)) is a change of the estimator's bias: the
/// bias-corrected entropies depend on how the lines were drawn, not only on how many.
fn spread(specs: &[String], lines: u64, seeds: u64) -> anyhow::Result<()> {
    const GRIDS: [u32; 3] = [0, 4, 8];
    println!("{lines} lines per run, 2 threads, Embree single lines, {seeds} seeds per source");
    for spec in specs {
        let scene = scenes::load(spec)?;
        let tracer = make_tracer(Backend::Embree, &scene, Query::Single)
            .or_else(|_| make_tracer(Backend::Rust, &scene, Query::Single))?;
        // values[grid][measure][seed], cpu seconds per grid.
        let mut values = vec![vec![Vec::new(); FOLLOWED.len()]; GRIDS.len()];
        let mut stderrs = vec![vec![Vec::new(); FOLLOWED.len()]; GRIDS.len()];
        let mut cpu = [0.0; GRIDS.len()];
        for seed in 1..=seeds {
            for (g, &grid) in GRIDS.iter().enumerate() {
                let cfg = RunSpec {
                    source: LineSource::bundles(grid).expect("grids from the list are valid"),
                    ..RunSpec::new(lines, seed)
                };
                let c0 = common::cpu_seconds();
                let a = analyze(&scene, tracer.as_ref(), &cfg, &RunControl::default())?;
                cpu[g] += common::cpu_seconds() - c0;
                for (m, (_, of)) in FOLLOWED.iter().enumerate() {
                    let e = a.estimate(*of).unwrap_or(Estimate {
                        value: f64::NAN,
                        stderr: None,
                    });
                    values[g][m].push(e.value);
                    stderrs[g][m].push(e.stderr.unwrap_or(f64::NAN));
                }
            }
        }
        println!(
            "{:<10} {:<10} {:>4} {:>7} {:>16} {:>10} {:>22} {:>6}",
            "scene", "measure", "G", "cpu s", "spread (+-)", "rms se", "mean +- se", "merit"
        );
        for (m, (name, _)) in FOLLOWED.iter().enumerate() {
            let base = sample_sd(&values[0][m]) * (cpu[0] / seeds as f64).sqrt();
            for (g, &grid) in GRIDS.iter().enumerate() {
                let v = &values[g][m];
                let sd = sample_sd(v);
                let n = v.len() as f64;
                let rms = (stderrs[g][m].iter().map(|s| s * s).sum::<f64>() / n).sqrt();
                let mean = v.iter().sum::<f64>() / n;
                let seconds = cpu[g] / seeds as f64;
                println!(
                    "{spec:<10} {name:<10} {grid:>4} {seconds:>7.3} {:>10.3e} {:>4.0}% {rms:>10.3e} {:>12.6} {:>9.2e} {:>6.2}",
                    sd,
                    100.0 / (2.0 * (n - 1.0)).sqrt(),
                    mean,
                    sd / n.sqrt(),
                    sd * seconds.sqrt() / base,
                );
            }
        }
    }
    Ok(())
}

fn sample_sd(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}
