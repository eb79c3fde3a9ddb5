//! A throughput table for notes and the README: million lines per second of the all-hits kernel (raw and
//! canonical hits), of first-hit queries, and of the whole analysis on the same number of lines, per query
//! kind and thread count. Best of three runs (the machine is shared).
//!
//! `cargo bench --bench throughput [-- SCENE [LINES]]`, default `@cube:30` and 10^6 lines.

use std::time::Instant;

use rayon::prelude::*;
use scene_complexity::analysis::{analyze, AnalysisConfig};
use scene_complexity::sample::lines::batch_lines;
use scene_complexity::sample::tally::Wanted;
use scene_complexity::scene;
use scene_complexity::trace::{make_tracer, Backend, Line, LineHits, Query, Tracer};

const CHUNK: usize = 4096;
const REPEATS: usize = 3;

fn main() -> anyhow::Result<()> {
    // `cargo bench` passes `--bench`; keep only our own arguments.
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let spec = args.first().cloned().unwrap_or_else(|| "@cube:30".into());
    let count: u64 = args
        .get(1)
        .map(|a| a.parse::<f64>())
        .transpose()?
        .unwrap_or(1e6) as u64;
    let scene = scene::load(&spec)?;
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
    println!("{spec}: {} triangles, {count} lines", scene.triangles.len());
    println!("tracer          threads  raw Ml/s  all-hits Ml/s  analyze Ml/s  analyze/all-hits");
    for (name, backend, query) in candidates() {
        let Ok(tracer) = make_tracer(backend, &scene, query) else {
            continue;
        };
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()?;
            let raw = pool.install(|| best(|| raw_pass(tracer.as_ref(), &lines)));
            let all = pool.install(|| best(|| all_hits_pass(tracer.as_ref(), &lines)));
            let cfg = AnalysisConfig {
                wanted: Wanted {
                    discrete: true,
                    continuous: true,
                },
                ..AnalysisConfig::new(count, 1)
            };
            let end_to_end = pool.install(|| {
                best(|| {
                    analyze(&scene, tracer.as_ref(), &cfg).unwrap();
                })
            });
            let rate = |s: f64| count as f64 / s / 1e6;
            println!(
                "{name:<15} {threads:>7}  {:>8.2}  {:>13.2}  {:>12.2}  {:>16.2}",
                rate(raw),
                rate(all),
                rate(end_to_end),
                all / end_to_end
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
    v
}

/// Fastest of a few runs, in seconds.
fn best(mut f: impl FnMut()) -> f64 {
    (0..REPEATS)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn raw_pass(tracer: &dyn Tracer, lines: &[Line]) {
    lines
        .par_chunks(CHUNK)
        .for_each_init(Vec::new, |raw, chunk| tracer.raw_hits(chunk, raw).unwrap());
}

fn all_hits_pass(tracer: &dyn Tracer, lines: &[Line]) {
    lines.par_chunks(CHUNK).for_each_init(
        || (Vec::new(), LineHits::default()),
        |(raw, hits), chunk| tracer.all_hits(chunk, raw, hits).unwrap(),
    );
}
