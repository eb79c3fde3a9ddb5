//! The pure-Rust BVH tracer against the brute-force watertight tracer (every line against every triangle,
//! no acceleration structure: the reference): the same canonical hits to the bit, on random lines, on lines
//! through vertices and edges, on lines in the planes of walls, and on lines that start on a surface; and
//! first hits equal to the first of the reference's hit lists.

use crate::support;
use scene_complexity::internals::scenes;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use scene_complexity::internals::geom::uniform_direction;
use scene_complexity::internals::sample::lines::batch_lines;
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::trace::rust::{BruteForceTracer, BvhTracer};
use scene_complexity::internals::trace::{
    make_tracer, Backend, Line, LineHits, Query, TraceError, Tracer,
};

fn trace(tracer: &dyn Tracer, lines: &[Line]) -> LineHits {
    let mut raw = Vec::new();
    let mut hits = LineHits::default();
    tracer.all_hits(lines, &mut raw, &mut hits).unwrap();
    hits
}

/// Lines through vertices, or through points on the segment between two vertices (edges and diagonals
/// of patches), nudged by up to 1e-7, in random directions.
fn vertex_and_edge_lines(scene: &Scene, rng: &mut Pcg64, count: usize) -> Vec<Line> {
    (0..count)
        .map(|k| {
            let v = scene.positions[rng.gen_range(0..scene.positions.len())].map(f64::from);
            let w = scene.positions[rng.gen_range(0..scene.positions.len())].map(f64::from);
            let f = if k % 2 == 0 {
                0.0
            } else {
                rng.gen_range(0.0..1.0)
            };
            let nudge = if k % 4 < 2 { 0.0 } else { 1e-7 };
            let p = [0, 1, 2].map(|a| v[a] + f * (w[a] - v[a]) + rng.gen_range(-1.0..=1.0) * nudge);
            let d = uniform_direction(rng.gen(), rng.gen()).to_array();
            Line {
                origin: [0, 1, 2].map(|a| (p[a] - 2.0 * d[a]) as f32),
                dir: d.map(|c| c as f32),
                t_max: 4.0,
            }
        })
        .collect()
}

/// Lines lying in the plane of a patch (through two of its vertices), and lines that start exactly on a
/// vertex (t = 0 at a surface).
fn in_plane_and_starting_lines(scene: &Scene, rng: &mut Pcg64, count: usize) -> Vec<Line> {
    (0..count)
        .map(|k| {
            let tri = scene.triangles[rng.gen_range(0..scene.triangles.len())];
            let a = scene.positions[tri[0] as usize];
            let b = scene.positions[tri[1] as usize];
            if k % 2 == 0 {
                let d = [0, 1, 2].map(|i| b[i] - a[i]);
                let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let d = d.map(|c| c / len);
                Line {
                    origin: [0, 1, 2].map(|i| a[i] - 2.0 * d[i]),
                    dir: d,
                    t_max: 4.0,
                }
            } else {
                let d = uniform_direction(rng.gen(), rng.gen()).to_array();
                Line {
                    origin: a,
                    dir: d.map(|c| c as f32),
                    t_max: 3.0,
                }
            }
        })
        .collect()
}

fn test_lines(scene: &Scene, seed: u64) -> Vec<Line> {
    let mut lines = Vec::new();
    batch_lines(seed, 0, 3000, 1.0, &mut lines);
    let mut rng = Pcg64::seed_from_u64(seed);
    lines.extend(vertex_and_edge_lines(scene, &mut rng, 3000));
    lines.extend(in_plane_and_starting_lines(scene, &mut rng, 1000));
    lines
}

fn room_with_box() -> Scene {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("room.obj");
    std::fs::write(&path, support::room_with_box_obj(1.0)).unwrap();
    scenes::load(path.to_str().unwrap()).unwrap()
}

#[test]
fn all_hits_equal_the_brute_force_tracer_to_the_bit() {
    let mut scenes: Vec<Scene> = ["@cube:3", "@sphere:2", "@dodecahedron:2", "@tetrahedron"]
        .iter()
        .map(|s| scenes::load(s).unwrap())
        .collect();
    scenes.push(room_with_box());
    for (k, scene) in scenes.iter().enumerate() {
        let lines = test_lines(scene, 40 + k as u64);
        let reference = trace(&BruteForceTracer::new(scene), &lines);
        let bvh = BvhTracer::new(scene).unwrap();
        let got = trace(&bvh, &lines);
        for (l, line) in lines.iter().enumerate() {
            assert_eq!(
                got.of_line(l),
                reference.of_line(l),
                "{}: line {l} {line:?}",
                scene.name,
            );
        }
        // The check means something: lines did hit, and some hits were at t = 0.
        assert!(reference.hits.len() > lines.len());
        assert!(reference.hits.iter().any(|h| h.t == 0.0), "{}", scene.name);
    }
}

#[test]
fn first_hits_are_the_nearest_of_the_reference() {
    let scene = scenes::load("@cube:4").unwrap();
    let lines = test_lines(&scene, 7);
    let reference = trace(&BruteForceTracer::new(&scene), &lines);
    let bvh = BvhTracer::new(&scene).unwrap();
    let mut first = Vec::new();
    bvh.first_hits(&lines, &mut first).unwrap();
    assert_eq!(first.len(), lines.len());
    for (k, f) in first.iter().enumerate() {
        assert_eq!(*f, reference.of_line(k).first().copied(), "line {k}");
    }
    assert!(first.iter().filter(|f| f.is_none()).count() < lines.len() / 2);
}

#[test]
fn make_tracer_gives_the_bvh_and_refuses_packets() {
    let scene = scenes::load("@cube:2").unwrap();
    let t = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    assert_eq!(t.name(), "rust");
    assert!(matches!(
        make_tracer(Backend::Rust, &scene, Query::Packet(8)),
        Err(TraceError::Unsupported(_))
    ));
}

#[test]
fn bad_lines_are_errors_not_panics() {
    let scene = scenes::load("@cube:2").unwrap();
    let bvh = BvhTracer::new(&scene).unwrap();
    let bad = Line {
        origin: [f32::NAN, 0.0, 0.0],
        dir: [0.0, 0.0, 1.0],
        t_max: 1.0,
    };
    let mut raw = Vec::new();
    let e = bvh.raw_hits(&[bad], &mut raw).unwrap_err().to_string();
    assert!(e.contains("line 0"), "{e}");
    let mut first = Vec::new();
    assert!(bvh.first_hits(&[bad], &mut first).is_err());
}
