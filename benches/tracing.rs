//! Lines per second of the ray kernels: all-hits and first-hit queries, for each tracer (Embree single
//! lines and native packets of 4/8/16, the pure-Rust BVH, the brute-force reference on small scenes), on
//! `@cube:30` and on `@cubes512` (a room with 512 small cubes, fixed seed); then the whole analysis on the
//! same lines. Independent global lines, and bundles of 16 x 16 parallel lines (what packets are for).
//!
//! `cargo bench --bench tracing`; CI only builds it (`cargo bench --no-run`).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use rayon::prelude::*;
use scene_complexity::internals::analysis::analyze;
use scene_complexity::internals::run::Measures;
use scene_complexity::internals::run::{RunControl, RunSpec};
use scene_complexity::internals::sample::lines::LineSource;
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::rust::BruteForceTracer;
use scene_complexity::internals::trace::{make_tracer, Backend, Line, LineHits, Query, Tracer};

const LINES: usize = 1 << 16;
const CHUNK: usize = 4096;
const SCENES: [&str; 2] = ["@cube:30", "@cubes512"];

/// The benchmark's lines: independent, or in bundles of 16 x 16 (one bundle per 256 lines).
fn lines(source: LineSource) -> Vec<Line> {
    let mut v = Vec::with_capacity(LINES);
    for b in 0..(LINES / CHUNK) as u64 {
        source.batch_lines(1, b, CHUNK, 1.0, &mut v);
    }
    v
}

fn sources() -> [(&'static str, LineSource); 2] {
    [
        ("independent", LineSource::Independent),
        ("bundle16", LineSource::Bundles { grid: 16 }),
    ]
}

/// Traces `lines` in chunks on the rayon pool; returns the hits found (so nothing is optimised away).
fn all_hits(tracer: &dyn Tracer, lines: &[Line]) -> usize {
    lines
        .par_chunks(CHUNK)
        .map_init(
            || (Vec::new(), LineHits::default()),
            |(raw, hits), chunk| {
                tracer.all_hits(chunk, raw, hits).unwrap();
                hits.hits.len()
            },
        )
        .sum()
}

/// Nearest hits of `lines` in chunks; returns how many lines hit.
fn first_hits(tracer: &dyn Tracer, lines: &[Line]) -> usize {
    lines
        .par_chunks(CHUNK)
        .map_init(Vec::new, |first, chunk| {
            tracer.first_hits(chunk, first).unwrap();
            first.iter().filter(|h| h.is_some()).count()
        })
        .sum()
}

/// Every tracer and query kind this build and machine have for `scene`.
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
    v.push((
        "rust-bvh".into(),
        make_tracer(Backend::Rust, scene, Query::Single).unwrap(),
    ));
    if scene.triangles.len() <= 200 {
        v.push((
            "rust-brute".into(),
            Box::new(BruteForceTracer::new(scene)) as Box<dyn Tracer>,
        ));
    }
    v
}

fn bench_queries(c: &mut Criterion) {
    for spec in SCENES {
        let scene = scenes::load(spec).unwrap();
        let tracers = tracers(&scene);
        for (source_name, source) in sources() {
            let ls = lines(source);
            for (query, f) in [
                ("all_hits", all_hits as fn(&dyn Tracer, &[Line]) -> usize),
                ("first_hit", first_hits),
            ] {
                let mut g = c.benchmark_group(format!("{query}/{spec}/{source_name}"));
                g.throughput(Throughput::Elements(LINES as u64));
                g.sample_size(10);
                for (name, t) in &tracers {
                    g.bench_function(BenchmarkId::from_parameter(name), |b| {
                        b.iter(|| f(t.as_ref(), &ls))
                    });
                }
                g.finish();
            }
        }
    }
}

fn bench_analysis(c: &mut Criterion) {
    for spec in SCENES {
        let scene = scenes::load(spec).unwrap();
        let mut g = c.benchmark_group(format!("analyze/{spec}"));
        g.throughput(Throughput::Elements(LINES as u64));
        g.sample_size(10);
        let cfg = RunSpec {
            measures: Measures {
                discrete: true,
                continuous: true,
                radiosity: false,
            },
            ..RunSpec::new(LINES as u64, 1)
        };
        for (name, t) in tracers(&scene) {
            g.bench_function(BenchmarkId::from_parameter(&name), |b| {
                b.iter(|| analyze(&scene, t.as_ref(), &cfg, &RunControl::default()).unwrap())
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench_queries, bench_analysis);
criterion_main!(benches);
