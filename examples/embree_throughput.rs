//! All-hits (and first-hit) throughput of the Embree backend, single lines against native packets, on 1
//! and 2 threads.
//!
//! `cargo run --release --example embree_throughput [-- SCENE [LINES]]`, default `@cube:30` and 10^6
//! lines: uniformly distributed global lines through the unit bounding sphere, from a fixed seed.

#[cfg(not(feature = "embree"))]
fn main() {
    eprintln!("embree_throughput needs the `embree` feature (on by default)");
}

#[cfg(feature = "embree")]
fn main() -> anyhow::Result<()> {
    bench::run()
}

#[cfg(feature = "embree")]
mod bench {
    use std::time::Instant;

    use rayon::prelude::*;
    use scene_complexity::scene;
    use scene_complexity::trace::embree::EmbreeTracer;
    use scene_complexity::trace::{Line, LineHits, Query, TraceError, Tracer};

    /// Lines per task: big enough to amortise the per-call costs, small enough to balance 2 threads.
    const CHUNK: usize = 4096;
    /// Each measurement is repeated and the fastest run kept (the machine is shared).
    const REPEATS: usize = 3;

    pub fn run() -> anyhow::Result<()> {
        let mut args = std::env::args().skip(1);
        let spec = args.next().unwrap_or_else(|| "@cube:30".into());
        let count: usize = args
            .next()
            .map(|a| a.parse())
            .transpose()?
            .unwrap_or(1_000_000);
        let scene = scene::load(&spec)?;
        let lines = global_lines(count, 0x5eed);
        let probe = EmbreeTracer::new(&scene, Query::Single)?;
        println!(
            "{spec}: {} triangles; {count} lines; Embree {}; native packet widths {:?}",
            scene.triangles.len(),
            probe.version(),
            probe.native_packet_widths()
        );
        let mut queries = vec![Query::Single];
        queries.extend(probe.native_packet_widths().into_iter().map(Query::Packet));
        println!("query     threads  raw hits Mlines/s  all_hits Mlines/s  first hit Mlines/s  hits/line");
        for query in queries {
            let tracer = EmbreeTracer::new(&scene, query)?;
            for threads in [1, 2] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()?;
                let (raw, hits) = pool.install(|| best(|| raw_pass(&tracer, &lines)))?;
                let (all, canonical) = pool.install(|| best(|| all_hits_pass(&tracer, &lines)))?;
                let (first, _) = pool.install(|| best(|| first_hit_pass(&tracer, &lines)))?;
                let rate = |secs: f64| count as f64 / secs / 1e6;
                println!(
                    "{:<9} {threads:>7}  {:>17.2}  {:>17.2}  {:>18.2}  {:.3} raw, {:.3} canonical",
                    query.to_string(),
                    rate(raw),
                    rate(all),
                    rate(first),
                    hits as f64 / count as f64,
                    canonical as f64 / count as f64
                );
            }
        }
        Ok(())
    }

    /// The fastest of `REPEATS` runs: (seconds, what the run counted).
    fn best(
        mut pass: impl FnMut() -> Result<usize, TraceError>,
    ) -> Result<(f64, usize), TraceError> {
        let mut fastest = (f64::INFINITY, 0);
        for _ in 0..REPEATS {
            let start = Instant::now();
            let counted = pass()?;
            fastest = fastest.min_by_time(start.elapsed().as_secs_f64(), counted);
        }
        Ok(fastest)
    }

    trait MinByTime {
        fn min_by_time(self, secs: f64, counted: usize) -> Self;
    }

    impl MinByTime for (f64, usize) {
        fn min_by_time(self, secs: f64, counted: usize) -> Self {
            if secs < self.0 {
                (secs, counted)
            } else {
                self
            }
        }
    }

    /// The backend alone: raw hits, no sorting or merging.
    fn raw_pass(tracer: &EmbreeTracer, lines: &[Line]) -> Result<usize, TraceError> {
        lines
            .par_chunks(CHUNK)
            .map_init(Vec::new, |raw, chunk| {
                tracer.raw_hits(chunk, raw)?;
                Ok(raw.len())
            })
            .sum()
    }

    /// What consumers get: canonical hits per line.
    fn all_hits_pass(tracer: &EmbreeTracer, lines: &[Line]) -> Result<usize, TraceError> {
        lines
            .par_chunks(CHUNK)
            .map_init(
                || (Vec::new(), LineHits::default()),
                |(scratch, out), chunk| {
                    tracer.all_hits(chunk, scratch, out)?;
                    Ok(out.hits.len())
                },
            )
            .sum()
    }

    fn first_hit_pass(tracer: &EmbreeTracer, lines: &[Line]) -> Result<usize, TraceError> {
        lines
            .par_chunks(CHUNK)
            .map_init(Vec::new, |out, chunk| {
                tracer.first_hits(chunk, out)?;
                Ok(out.iter().flatten().count())
            })
            .sum()
    }

    /// SplitMix64: a tiny fixed-seed generator, so the lines are the same on every machine.
    struct SplitMix64(u64);

    impl SplitMix64 {
        fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }

        /// Uniform in [-1, 1).
        fn symmetric(&mut self) -> f64 {
            (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// Uniformly distributed lines through the unit sphere: a uniform direction, and a uniform point on
    /// the unit disk across it; each traced from outside the sphere over its whole chord.
    fn global_lines(count: usize, seed: u64) -> Vec<Line> {
        let mut rng = SplitMix64(seed);
        (0..count)
            .map(|_| {
                let dir = loop {
                    let v = [rng.symmetric(), rng.symmetric(), rng.symmetric()];
                    let len = norm(v);
                    if len > 1e-3 && len <= 1.0 {
                        break v.map(|c| c / len);
                    }
                };
                let (a, b) = loop {
                    let (a, b) = (rng.symmetric(), rng.symmetric());
                    if a * a + b * b <= 1.0 {
                        break (a, b);
                    }
                };
                let (u, v) = basis(dir);
                let p = [0, 1, 2].map(|k| a * u[k] + b * v[k]);
                Line {
                    // |origin|^2 = |p|^2 + 1.01^2: outside the sphere; t_max reaches past the far side.
                    origin: [0, 1, 2].map(|k| (p[k] - 1.01 * dir[k]) as f32),
                    dir: dir.map(|c| c as f32),
                    t_max: 2.02,
                }
            })
            .collect()
    }

    fn norm(v: [f64; 3]) -> f64 {
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }

    /// Two unit vectors orthogonal to unit `d` and to each other.
    fn basis(d: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let helper = if d[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let u = cross(d, helper);
        let len = norm(u);
        let u = u.map(|c| c / len);
        (u, cross(d, u))
    }
}
