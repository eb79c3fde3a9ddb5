use rayon::prelude::*;
use scene_complexity::sample::lines::batch_lines;
use scene_complexity::sample::pairs::{segments, Segment};
use scene_complexity::sample::tally::BatchPlan;
use scene_complexity::scene;
use scene_complexity::trace::{make_tracer, Backend, LineHits, Query};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seed: u64 = args[1].parse().unwrap();
    let sc = scene::load("@labyrinth").unwrap();
    let tracer = make_tracer(Backend::Rust, &sc, Query::Single).unwrap();
    let plan = BatchPlan::new(10_000_000);
    (0..plan.batches()).into_par_iter().for_each(|b| {
        let mut lines = Vec::new();
        batch_lines(seed, b, plan.batch_len(b), 1.0, &mut lines);
        let mut raw = Vec::new();
        let mut hits = LineHits::default();
        tracer.all_hits(&lines, &mut raw, &mut hits).unwrap();
        for (k, l) in lines.iter().enumerate() {
            let h = hits.of_line(k);
            let mut esc = false;
            segments(&sc, l, h, |s| {
                if let Segment::Escape { .. } = s {
                    esc = true
                }
            });
            if esc {
                println!("batch {b} line {k}: {:?}", l);
                for x in h {
                    let p = sc.triangle_patch[x.triangle as usize];
                    let pp = &sc.patches[p as usize];
                    let d: f64 = (0..3).map(|a| pp.normal[a] * l.dir[a] as f64).sum();
                    println!(
                        "   t {:.9} tri {} patch {} normal {:?} cos {:+.3e}",
                        x.t, x.triangle, p, pp.normal, d
                    );
                }
            }
        }
    });
}
