//! Lines per second: all-hits queries per tracer and query kind, and the whole analysis on the same lines.
//!
//! `cargo bench --bench tracing`; CI only builds it (`cargo bench --no-run`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use scene_complexity::analysis::{analyze, AnalysisConfig};
use scene_complexity::sample::lines::batch_lines;
use scene_complexity::sample::tally::Wanted;
use scene_complexity::scene::{self, Scene};
use scene_complexity::trace::{make_tracer, Backend, LineHits, Query, Tracer};

const LINES: usize = 1 << 16;

fn lines(seed: u64) -> Vec<scene_complexity::trace::Line> {
    let mut v = Vec::with_capacity(LINES);
    for b in 0..(LINES / 4096) as u64 {
        batch_lines(seed, b, 4096, 1.0, &mut v);
    }
    v
}

/// Traces `lines` in chunks of 4096 on the rayon pool.
fn all_hits(tracer: &dyn Tracer, lines: &[scene_complexity::trace::Line]) -> usize {
    use rayon::prelude::*;
    lines
        .par_chunks(4096)
        .map_init(
            || (Vec::new(), LineHits::default()),
            |(raw, hits), chunk| {
                tracer.all_hits(chunk, raw, hits).unwrap();
                hits.hits.len()
            },
        )
        .sum()
}

fn tracers(scene: &Scene) -> Vec<(String, Box<dyn Tracer>)> {
    let mut v = Vec::new();
    for q in [
        Query::Single,
        Query::Packet(4),
        Query::Packet(8),
        Query::Packet(16),
    ] {
        if let Ok(t) = make_tracer(Backend::Embree, scene, q) {
            v.push((format!("embree-{q}"), t));
        }
    }
    if scene.triangles.len() <= 2000 {
        v.push((
            "rust-brute".into(),
            make_tracer(Backend::Rust, scene, Query::Single).unwrap(),
        ));
    }
    v
}

fn bench_all_hits(c: &mut Criterion) {
    let ls = lines(1);
    for spec in ["@cube:30", "@cube:4"] {
        let scene = scene::load(spec).unwrap();
        let mut g = c.benchmark_group(format!("all_hits/{spec}"));
        g.throughput(Throughput::Elements(LINES as u64));
        g.sample_size(10);
        for (name, t) in tracers(&scene) {
            g.bench_function(BenchmarkId::from_parameter(&name), |b| {
                b.iter(|| all_hits(t.as_ref(), &ls))
            });
        }
        g.finish();
    }
}

fn bench_analysis(c: &mut Criterion) {
    let scene = scene::load("@cube:30").unwrap();
    let mut g = c.benchmark_group("analyze/@cube:30");
    g.throughput(Throughput::Elements(LINES as u64));
    g.sample_size(10);
    for (name, t) in tracers(&scene) {
        let cfg = AnalysisConfig {
            wanted: Wanted {
                discrete: true,
                continuous: true,
            },
            ..AnalysisConfig::new(LINES as u64, 1)
        };
        g.bench_function(BenchmarkId::from_parameter(&name), |b| {
            b.iter(|| analyze(&scene, t.as_ref(), &cfg).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench_all_hits, bench_analysis);
criterion_main!(benches);
