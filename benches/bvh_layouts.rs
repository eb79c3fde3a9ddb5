//! The evaluation behind the pure-Rust tracer's choice of BVH (see `src/trace/rust/bvh.rs`): obvhs's
//! compressed 8-wide BVH (CWBVH) against its binary BVH (`Bvh2`), leaves of at most 1 or 3 triangles, on
//! the same inflated boxes and 10^6 global lines, each candidate decided by the watertight test. Prints
//! lines per second on one thread and candidates per line.
//!
//! `cargo bench --bench bvh_layouts [-- SCENE...]`, default `@cube:30 @cubes512`.

use std::time::{Duration, Instant};

use glam::Vec3A;
use obvhs::{aabb::Aabb, ray::Ray, BvhBuildParams};
use scene_complexity::sample::lines::batch_lines;
use scene_complexity::scene::{self, Scene};
use scene_complexity::trace::rust::{bvh::margin, watertight::ShearedRay};
use scene_complexity::trace::Line;

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
    for spec in &specs {
        let scene = scene::load(spec)?;
        let tris: Vec<[[f32; 3]; 3]> = scene
            .triangles
            .iter()
            .map(|t| t.map(|v| scene.positions[v as usize]))
            .collect();
        let boxes = inflated_boxes(&scene, &tris);
        for leaf in [1u32, 3] {
            let params = BvhBuildParams {
                pre_split: false,
                max_prims_per_leaf: leaf,
                ..BvhBuildParams::medium_build()
            };
            let cw = obvhs::cwbvh::builder::build_cwbvh(&boxes, params, &mut Duration::default());
            let b2 = obvhs::bvh2::builder::build_bvh2(&boxes, params, &mut Duration::default());
            for layout in ["cwbvh", "bvh2"] {
                let t0 = Instant::now();
                let (mut hits, mut candidates) = (0usize, 0usize);
                for l in &lines {
                    let sheared = ShearedRay::new(l.origin, l.dir);
                    let mut decide = |slot: usize, ids: &[u32]| {
                        candidates += 1;
                        let [a, b, c] = tris[ids[slot] as usize];
                        hits += usize::from(sheared.intersect(a, b, c, 0.0, l.t_max).is_some());
                    };
                    if layout == "cwbvh" {
                        cw.ray_traverse_anyhit(ray(l), |_, id| decide(id, &cw.primitive_indices));
                    } else {
                        b2.ray_traverse_anyhit(ray(l), |_, id| decide(id, &b2.primitive_indices));
                    }
                }
                let rate = lines.len() as f64 / t0.elapsed().as_secs_f64() / 1e6;
                println!(
                    "{spec:<10} leaves <= {leaf}  {layout:<5}  {rate:5.2} M lines/s  {hits} raw hits  {:.2} candidates/line",
                    candidates as f64 / lines.len() as f64
                );
            }
        }
    }
    Ok(())
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
