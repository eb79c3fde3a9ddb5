//! A throughput table for notes and docs/performance.md: million lines per second of the all-hits kernel
//! (canonical hits of lines drawn beforehand), of first-hit queries, of drawing the lines and tracing them (what an
//! analysis does before pairing and counting), and of the whole analysis on the same lines, per tracer
//! (Embree single lines and native packets, the pure-Rust BVH) and thread count. Best of three runs (the
//! machine is shared). Then the analysis's share of the kernel's rate, against the kernel alone and
//! against drawing plus kernel (so that what remains is pairing and counting); last, an analysis of I_s^c
//! alone (`--measures continuous`: no pair counts) and its share of the kernel's rate.
//!
//! `cargo bench --bench throughput [-- SCENE... [LINES]]`, default `@cube:30 @cubes512` and 10^6 lines;
//! `SCX_BENCH_TRACERS=rust,single` keeps only the tracers whose names contain one of the words.

mod common;

use scene_complexity::internals::scenes;
use std::time::Instant;

use rayon::prelude::*;
use scene_complexity::internals::analysis::analyze;
use scene_complexity::internals::run::{BatchPlan, Measures};
use scene_complexity::internals::run::{RunControl, RunSpec, DEFAULT_GROUPS};
use scene_complexity::internals::sample::lines::batch_lines;
use scene_complexity::internals::trace::{make_tracer, Backend, Line, LineHits, Query, Tracer};

const CHUNK: usize = 4096;
const REPEATS: usize = 3;

fn main() -> anyhow::Result<()> {
    let (specs, count) = common::scenes_and_lines(1e6)?;
    println!(
        "M lines/s: wall clock, and per CPU-second of all threads (robust when the machine is shared)"
    );
    println!(
        "{:<11} {:<16} {:>3}  {:>14}  {:>14}  {:>14}  {:>14}  {:>10}  {:>10}  {:>14}  {:>10}",
        "scene",
        "tracer",
        "thr",
        "all-hits",
        "first-hit",
        "draw+all-hits",
        "analyze",
        "an./all",
        "an./draw+all",
        "an. I_s^c",
        "I_s^c/all"
    );
    println!(
        "{:<11} {:<16} {:>3}  {:>6} {:>7}  {:>6} {:>7}  {:>6} {:>7}  {:>6} {:>7}  {:>4} {:>5}  {:>4} {:>5}  {:>6} {:>7}  {:>4} {:>5}",
        "", "", "", "wall", "cpu", "wall", "cpu", "wall", "cpu", "wall", "cpu", "wall", "cpu", "wall", "cpu",
        "wall", "cpu", "wall", "cpu"
    );
    // The pools live for the whole run: a thread that exits during a measurement would take its CPU time
    // out of the sum.
    let pools = [1, 2].map(|n| rayon::ThreadPoolBuilder::new().num_threads(n).build());
    let pools: Vec<rayon::ThreadPool> = pools.into_iter().collect::<Result<_, _>>()?;
    for spec in &specs {
        bench_scene(spec, count, &pools)?;
    }
    Ok(())
}

fn bench_scene(spec: &str, count: u64, pools: &[rayon::ThreadPool]) -> anyhow::Result<()> {
    let scene = scenes::load(spec)?;
    let mut lines = Vec::with_capacity(count as usize);
    for b in 0..count.div_ceil(CHUNK as u64) {
        batch_lines(
            1,
            b,
            CHUNK.min((count - b * CHUNK as u64) as usize),
            1.0,
            &mut lines,
        );
    }
    let cfg = RunSpec {
        groups: DEFAULT_GROUPS,
        ..RunSpec::new(count, 1)
    };
    // `--measures continuous`: I_s^c alone, no pair counts (what a run needs when it wants only eq. 27).
    let continuous = RunSpec {
        measures: Measures {
            discrete: false,
            continuous: true,
            radiosity: false,
        },
        ..cfg
    };
    // `SCX_BENCH_TRACERS=rust,embree single` keeps the tracers whose names contain one of the words.
    let only = std::env::var("SCX_BENCH_TRACERS").unwrap_or_default();
    let wanted = |name: &str| only.is_empty() || only.split(',').any(|w| name.contains(w.trim()));
    for (name, backend, query) in candidates().into_iter().filter(|c| wanted(&c.0)) {
        let Ok(tracer) = make_tracer(backend, &scene, query) else {
            continue;
        };
        for pool in pools {
            let threads = pool.current_num_threads();
            let t = tracer.as_ref();
            let all = pool.install(|| best(|| all_hits_pass(t, &lines)));
            let first = pool.install(|| best(|| first_hit_pass(t, &lines)));
            let drawn = pool.install(|| best(|| draw_and_trace_pass(t, count)));
            let end_to_end = pool.install(|| {
                best(|| {
                    analyze(&scene, t, &cfg, &RunControl::default()).unwrap();
                })
            });
            let continuous_only = pool.install(|| {
                best(|| {
                    analyze(&scene, t, &continuous, &RunControl::default()).unwrap();
                })
            });
            let rate = |s: f64| count as f64 / s / 1e6;
            println!(
                "{spec:<11} {name:<16} {threads:>3}  {:>6.2} {:>7.2}  {:>6.2} {:>7.2}  {:>6.2} {:>7.2}  {:>6.2} {:>7.2}  {:>4.2} {:>5.2}  {:>4.2} {:>5.2}  {:>6.2} {:>7.2}  {:>4.2} {:>5.2}",
                rate(all.wall),
                rate(all.cpu),
                rate(first.wall),
                rate(first.cpu),
                rate(drawn.wall),
                rate(drawn.cpu),
                rate(end_to_end.wall),
                rate(end_to_end.cpu),
                all.wall / end_to_end.wall,
                all.cpu / end_to_end.cpu,
                drawn.wall / end_to_end.wall,
                drawn.cpu / end_to_end.cpu,
                rate(continuous_only.wall),
                rate(continuous_only.cpu),
                all.wall / continuous_only.wall,
                all.cpu / continuous_only.cpu,
            );
        }
    }
    Ok(())
}

fn candidates() -> Vec<(String, Backend, Query)> {
    let mut v = vec![("embree single".to_string(), Backend::Embree, Query::Single)];
    for w in [4, 8, 16] {
        v.push((
            format!("embree packet{w}"),
            Backend::Embree,
            Query::Packet(w),
        ));
    }
    v.push(("rust single".to_string(), Backend::Rust, Query::Single));
    v
}

/// The fastest of a few runs: wall-clock seconds, and CPU seconds of all the process's threads.
#[derive(Clone, Copy, Debug)]
struct Timing {
    wall: f64,
    cpu: f64,
}

/// Best wall time and best CPU time of `REPEATS` runs.
fn best(mut f: impl FnMut()) -> Timing {
    let mut t = Timing {
        wall: f64::INFINITY,
        cpu: f64::INFINITY,
    };
    for _ in 0..REPEATS {
        let (w0, c0) = (Instant::now(), common::cpu_seconds());
        f();
        t.wall = t.wall.min(w0.elapsed().as_secs_f64());
        t.cpu = t.cpu.min(common::cpu_seconds() - c0);
    }
    t
}

fn first_hit_pass(tracer: &dyn Tracer, lines: &[Line]) {
    lines
        .par_chunks(CHUNK)
        .for_each_init(Vec::new, |first, chunk| {
            tracer.first_hits(chunk, first).unwrap()
        });
}

/// Draws the lines of an analysis of `count` lines (seed 1, its batches) and traces them, batch by batch
/// in parallel, as the analysis does before pairing.
fn draw_and_trace_pass(tracer: &dyn Tracer, count: u64) {
    let plan = BatchPlan::new(count);
    (0..plan.batches()).into_par_iter().for_each_init(
        || (Vec::new(), Vec::new(), LineHits::default()),
        |(lines, raw, hits), b| {
            lines.clear();
            batch_lines(1, b, plan.batch_len(b), 1.0, lines);
            tracer.all_hits(lines, raw, hits).unwrap();
        },
    );
}

fn all_hits_pass(tracer: &dyn Tracer, lines: &[Line]) {
    lines.par_chunks(CHUNK).for_each_init(
        || (Vec::new(), LineHits::default()),
        |(raw, hits), chunk| tracer.all_hits(chunk, raw, hits).unwrap(),
    );
}
