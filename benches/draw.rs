//! Drawing alone: nanoseconds per independent global line, of `batch_lines` (blocks of draws from
//! interleaved PCG lanes) and of the straightforward path it must equal bit for bit (`global_line` on
//! `batch_rng`, line after line), and per randomised quasi-Monte Carlo line (`sobol_lines`, batches dealt
//! to 16 groups as a run deals them), and per independent line through `@cube:30`'s bounding box and
//! the octahedron's bounding polytope (`batch_lines_through`, what `--lines-through auto` draws), on one
//! thread, over the batches of an analysis (seed 1, radius 1).
//! Runs alternate between the three; medians of the runs (the machine is shared).
//!
//! `cargo bench --bench draw [-- LINES [RUNS]]`, default 3e7 lines and 5 runs.

use std::hint::black_box;
use std::time::Instant;

use scene_complexity::internals::run::BatchPlan;
use scene_complexity::internals::sample::bounds::{batch_lines_through, BoundingBox};
use scene_complexity::internals::sample::lines::{
    batch_lines, batch_rng, global_line, sobol_lines,
};
use scene_complexity::internals::sample::polytope::BoundingPolytope;
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::Line;

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let lines = args
        .first()
        .map_or(3e7, |a| a.parse::<f64>().expect("LINES")) as u64;
    let runs = args.get(1).map_or(5, |a| a.parse::<usize>().expect("RUNS"));
    let plan = BatchPlan::new(lines);
    let cube_box = BoundingBox::of(&scenes::load("@cube:30").expect("@cube:30"));
    let octahedron = BoundingPolytope::of(&scenes::load("@octahedron").expect("@octahedron"));
    let (mut blocks, mut reference, mut sobol) = (Vec::new(), Vec::new(), Vec::new());
    let (mut boxed, mut polytope) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        boxed.push(time_pass(&plan, |b, n, out| {
            batch_lines_through(1, b, n, &cube_box, out)
        }));
        polytope.push(time_pass(&plan, |b, n, out| {
            batch_lines_through(1, b, n, &octahedron, out)
        }));
        sobol.push(time_pass(&plan, |b, n, out| {
            sobol_lines(1, b % 16, b / 16 * plan.batch_size, n, 1.0, out)
        }));
        blocks.push(time_pass(&plan, |b, n, out| batch_lines(1, b, n, 1.0, out)));
        reference.push(time_pass(&plan, |b, n, out| {
            let mut rng = batch_rng(1, b);
            out.extend((0..n).map(|_| global_line(&mut rng, 1.0)));
        }));
    }
    let per_line = |runs: &mut Vec<f64>| median(runs) * 1e9 / lines as f64;
    println!("{lines} lines, {runs} runs, median ns/line (one thread):");
    println!(
        "  global_line on batch_rng  {:6.2}",
        per_line(&mut reference)
    );
    println!("  batch_lines               {:6.2}", per_line(&mut blocks));
    println!("  sobol_lines               {:6.2}", per_line(&mut sobol));
    println!("  through @cube:30's box    {:6.2}", per_line(&mut boxed));
    println!(
        "  through the octahedron    {:6.2}",
        per_line(&mut polytope)
    );
}

/// Seconds to draw every batch of `plan` with `draw(batch, count, out)`, into a reused buffer.
fn time_pass(plan: &BatchPlan, draw: impl Fn(u64, usize, &mut Vec<Line>)) -> f64 {
    let mut out = Vec::with_capacity(plan.batch_size as usize);
    let start = Instant::now();
    for b in 0..plan.batches() {
        out.clear();
        draw(b, plan.batch_len(b), &mut out);
        black_box(&out);
    }
    start.elapsed().as_secs_f64()
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}
