//! The evaluation behind the pure-Rust tracer's BVH (see `src/trace/rust/bvh.rs`), on the same inflated
//! boxes and 10^6 global lines, each candidate decided by the watertight test, one thread:
//!
//! * obvhs's own traversals (`ray_traverse`, with a callback that never reports a hit, so that every
//!   candidate within the line's span is offered) of its compressed 8-wide BVH (CWBVH) and of its binary
//!   BVH (`Bvh2`), leaves of at most 1 or 3 triangles;
//! * our tracer ([`BvhTracer::raw_hits`]: obvhs's CWBVH topology with exact f32 boxes, unordered
//!   traversal) from several obvhs build presets and leaf sizes.
//!
//! First, per scene, the tracer as runs build it (large planes in grids: `src/trace/rust/grids.rs`)
//! against the same tracer with every triangle in the BVH, and whether their hits agree
//! (`SCX_GRIDS_ONLY=1` stops there).
//!
//! Prints M lines per CPU-second of this thread (robust when the machine is shared) and, for obvhs's
//! traversals, candidates per line.
//!
//! `cargo bench --bench bvh_layouts [-- SCENE...]`, default `@cube:30 @cubes512`. A SCENE may also be
//! `room:N:TURN:GRADING`: the cube [-1, 1]^3 as an OBJ room, each wall meshed into N x N quads whose
//! sides grow by GRADING a step across it (1: a regular mesh), turned TURN radians about x and then z
//! (the rooms of docs/performance.md's "Walls in grids").

mod common;
#[path = "../tests/common/meshed_room.rs"]
mod meshed_room;

use meshed_room::turned_meshed_room;

use scene_complexity::internals::scenes;
use std::time::Duration;

use glam::Vec3A;
use obvhs::{
    aabb::Aabb,
    ray::{Ray, RayHit},
    BvhBuildParams,
};
use scene_complexity::internals::sample::lines::batch_lines;
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::trace::rust::{bvh::margin, watertight::ShearedRay, BvhTracer};
use scene_complexity::internals::trace::{Line, LineHits, Tracer};

/// A built-in scene or file, or a `room:N:TURN:GRADING` written as an OBJ into `scratch`.
fn load(spec: &str, scratch: &std::path::Path) -> anyhow::Result<Scene> {
    let Some(room) = spec.strip_prefix("room:") else {
        return Ok(scenes::load(spec)?);
    };
    let numbers: Vec<f64> = room.split(':').map(str::parse).collect::<Result<_, _>>()?;
    let [n, turn, grading] = numbers[..] else {
        anyhow::bail!("{spec}: expected room:N:TURN:GRADING");
    };
    let path = scratch.join(format!("{}.obj", spec.replace(':', "_")));
    std::fs::write(&path, turned_meshed_room(n as usize, turn, false, grading))?;
    Ok(scenes::load(path.to_str().expect("a UTF-8 scratch path"))?)
}

fn main() -> anyhow::Result<()> {
    let mut specs: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    if specs.is_empty() {
        specs = vec!["@cube:30".into(), "@cubes512".into()];
    }
    let mut lines = Vec::new();
    for b in 0..245 {
        batch_lines(1, b, 4096, 1.0, &mut lines);
    }
    let scratch = tempfile::tempdir()?;
    for spec in &specs {
        let scene = load(spec, scratch.path())?;
        grids_against_tree(spec, &scene, &lines)?;
        if std::env::var_os("SCX_GRIDS_ONLY").is_some() {
            continue;
        }
        obvhs_traversals(spec, &scene, &lines);
        let presets = [
            ("fast", BvhBuildParams::fast_build()),
            ("medium", BvhBuildParams::medium_build()),
            ("slow", BvhBuildParams::slow_build()),
        ];
        for (preset, params) in presets {
            for leaf in [1u32, 2, 3] {
                let params = BvhBuildParams {
                    max_prims_per_leaf: leaf,
                    ..params
                };
                let tracer = BvhTracer::with_params(&scene, params)?;
                let mut raw = Vec::new();
                let mut hits = 0;
                let seconds = best_cpu_seconds(|| {
                    for chunk in lines.chunks(4096) {
                        tracer.raw_hits(chunk, &mut raw).unwrap();
                        hits += raw.len();
                    }
                });
                println!(
                    "{spec:<10} leaves <= {leaf}  ours, {preset:<6} build  {:5.2} M lines/s  {} raw hits",
                    lines.len() as f64 / seconds / 1e6,
                    hits / 3
                );
            }
        }
    }
    Ok(())
}

/// The tracer as runs build it (planes of many triangles in grids, the rest in the tree) against every
/// triangle in the tree, interleaved, 3 rounds: M lines per CPU-second of each (the best round), and
/// whether they found the same canonical hits and first hits.
fn grids_against_tree(spec: &str, scene: &Scene, lines: &[Line]) -> anyhow::Result<()> {
    let with_grids = BvhTracer::new(scene)?;
    let tree = BvhTracer::tree_only(scene)?;
    let tracers = [&tree, &with_grids];
    let mut rates = [0.0f64; 2];
    let mut rows = [LineHits::default(), LineHits::default()];
    for _ in 0..3 {
        for (k, tracer) in tracers.into_iter().enumerate() {
            let mut scratch = Vec::new();
            let mut hits = 0usize;
            let seconds = cpu_seconds(|| {
                for chunk in lines.chunks(4096) {
                    tracer.all_hits(chunk, &mut scratch, &mut rows[k]).unwrap();
                    hits += rows[k].hits.len();
                }
            });
            std::hint::black_box(hits);
            rates[k] = rates[k].max(lines.len() as f64 / seconds / 1e6);
        }
    }
    let (mut same, mut first) = (true, [Vec::new(), Vec::new()]);
    for chunk in lines.chunks(4096) {
        for (k, tracer) in tracers.into_iter().enumerate() {
            tracer
                .all_hits(chunk, &mut Vec::new(), &mut rows[k])
                .unwrap();
            tracer.first_hits(chunk, &mut first[k]).unwrap();
        }
        same &= rows[0].hits == rows[1].hits && rows[0].start == rows[1].start;
        same &= first[0] == first[1];
    }
    println!(
        "{spec:<10} all hits: tree only {:5.2}, with grids {:5.2} M lines/s ({:.2}x; {} planes in grids); same hits: {same}",
        rates[0],
        rates[1],
        rates[1] / rates[0],
        with_grids.planes_in_grids()
    );
    Ok(())
}

fn cpu_seconds(f: impl FnOnce()) -> f64 {
    let t0 = common::thread_cpu_seconds();
    f();
    common::thread_cpu_seconds() - t0
}

/// obvhs's `ray_traverse` on its CWBVH and Bvh2 (medium build), as an all-hits traversal: the callback
/// returns an infinite distance, so the line's span never shrinks and every crossed leaf is offered.
fn obvhs_traversals(spec: &str, scene: &Scene, lines: &[Line]) {
    let tris: Vec<[[f32; 3]; 3]> = scene
        .triangles
        .iter()
        .map(|t| t.map(|v| scene.positions[v as usize]))
        .collect();
    let boxes = inflated_boxes(scene, &tris);
    for leaf in [1u32, 3] {
        // A function, not a value: obvhs 0.2's parameters are neither Copy nor Clone.
        let params = || BvhBuildParams {
            pre_split: false,
            max_prims_per_leaf: leaf,
            ..BvhBuildParams::medium_build()
        };
        let cw = obvhs::cwbvh::builder::build_cwbvh(&boxes, params(), &mut Duration::default());
        let b2 = obvhs::bvh2::builder::build_bvh2(&boxes, params(), &mut Duration::default());
        for layout in ["cwbvh", "bvh2"] {
            let (mut hits, mut candidates) = (0usize, 0usize);
            let seconds = best_cpu_seconds(|| {
                for l in lines {
                    let sheared = ShearedRay::new(l.origin, l.dir);
                    let mut decide = |slot: usize, ids: &[u32]| {
                        candidates += 1;
                        let [a, b, c] = tris[ids[slot] as usize];
                        hits += usize::from(sheared.intersect(a, b, c, 0.0, l.t_max).is_some());
                    };
                    let mut no_hit = RayHit::none();
                    if layout == "cwbvh" {
                        cw.ray_traverse(ray(l), &mut no_hit, |_, id| {
                            decide(id, &cw.primitive_indices);
                            f32::INFINITY
                        });
                    } else {
                        b2.ray_traverse(ray(l), &mut no_hit, |_, id| {
                            decide(id, &b2.primitive_indices);
                            f32::INFINITY
                        });
                    }
                }
            });
            println!(
                "{spec:<10} leaves <= {leaf}  obvhs {layout:<5} anyhit  {:5.2} M lines/s  {} raw hits  {:.2} candidates/line",
                lines.len() as f64 / seconds / 1e6,
                hits / 3,
                candidates as f64 / lines.len() as f64 / 3.0
            );
        }
    }
}

/// The least CPU time of this thread over 3 runs of `f`.
fn best_cpu_seconds(mut f: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let t0 = common::thread_cpu_seconds();
            f();
            common::thread_cpu_seconds() - t0
        })
        .fold(f64::INFINITY, f64::min)
}

fn inflated_boxes(scene: &Scene, tris: &[[[f32; 3]; 3]]) -> Vec<Aabb> {
    let m = Vec3A::splat(margin(scene));
    tris.iter()
        .map(|t| {
            let v = t.map(Vec3A::from_array);
            Aabb::new(v[0].min(v[1]).min(v[2]) - m, v[0].max(v[1]).max(v[2]) + m)
        })
        .collect()
}

fn ray(l: &Line) -> Ray {
    let (o, d) = (Vec3A::from_array(l.origin), Vec3A::from_array(l.dir));
    Ray::new(o - d, d, 0.0, l.t_max + 1.0)
}
