//! The pure-Rust BVH tracer against the brute-force watertight tracer (every line against every triangle,
//! no acceleration structure: the reference): the same canonical hits to the bit, on random lines, on lines
//! through vertices and edges, on lines in the planes of walls, and on lines that start on a surface; and
//! first hits equal to the first of the reference's hit lists.

use crate::meshed_room::turned_meshed_room;
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
        let hit = (0..lines.len())
            .filter(|&l| !reference.of_line(l).is_empty())
            .count();
        assert!(hit > lines.len() / 4, "{}: {hit} lines hit", scene.name);
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

/// Lines within 1e-6 of a wall's plane, at angles of 1e-6 to 1e-2 to it: the grids' slabs and cell
/// ranges at their widest.
fn grazing_lines(scene: &Scene, rng: &mut Pcg64, count: usize) -> Vec<Line> {
    (0..count)
        .map(|k| {
            let tri = scene.triangles[rng.gen_range(0..scene.triangles.len())];
            let [a, b, c] = tri.map(|v| scene.positions[v as usize].map(f64::from));
            let e1 = [0, 1, 2].map(|i| b[i] - a[i]);
            let e2 = [0, 1, 2].map(|i| c[i] - a[i]);
            let n = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            let unit = |v: [f64; 3]| {
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                v.map(|x| x / l)
            };
            let (n, e1) = (unit(n), unit(e1));
            let angle = 10f64.powi(-2 - (k % 5) as i32);
            let offset = rng.gen_range(-1e-6..1e-6);
            let f: f64 = rng.gen_range(0.0..1.0);
            let p = [0, 1, 2].map(|i| a[i] + f * (c[i] - a[i]) + offset * n[i]);
            let d = unit([0, 1, 2].map(|i| e1[i] + angle * n[i]));
            Line {
                origin: [0, 1, 2].map(|i| (p[i] - 2.0 * d[i]) as f32),
                dir: d.map(|x| x as f32),
                t_max: 4.0,
            }
        })
        .collect()
}

/// The room of [`turned_meshed_room`] loaded as a scene, through an OBJ file as a user's would be.
fn turned_room_scene(cells: usize, turn: f64, inner_box: bool, grading: f64) -> Scene {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("turned.obj");
    std::fs::write(&path, turned_meshed_room(cells, turn, inner_box, grading)).unwrap();
    scenes::load(path.to_str().unwrap()).unwrap()
}

/// A wall turned off the axes and meshed finely: its small triangles' normals carry the rounding of
/// their f32 vertices, and their rounded planes fall on both sides of a rounding boundary; the grids
/// still take each wall whole (before neighbouring plane keys were joined, this room had 12 grids).
#[test]
fn a_finely_meshed_turned_wall_is_one_grid() {
    let scene = turned_room_scene(40, 0.2, false, 1.0);
    assert_eq!(BvhTracer::new(&scene).unwrap().planes_in_grids(), 6);
}

/// Rooms whose walls are meshed finely enough for grids (`src/trace/rust/grids.rs`), axis-aligned and
/// turned off the axes, empty and holding a box the tree keeps, meshed regularly and graded: the same canonical hits as the
/// brute-force tracer and as the tracer with every triangle in its tree, to the bit, and the same first
/// hits, on random lines, lines through vertices and edges, in a wall's plane, starting on a surface
/// and grazing a wall.
#[test]
fn grids_find_the_brute_force_tracers_hits_to_the_bit() {
    let mut scenes = vec![scenes::load("@cube:10").unwrap()];
    let rooms = [
        (0.0, true, 1.0),
        (0.3, false, 1.0),
        (0.05, true, 1.0),
        (0.2, true, 1.05),
    ];
    for &(turn, inner_box, grading) in &rooms {
        scenes.push(turned_room_scene(12, turn, inner_box, grading));
    }
    for (k, scene) in scenes.iter().enumerate() {
        let tracer = BvhTracer::new(scene).unwrap();
        assert_eq!(
            tracer.planes_in_grids(),
            6,
            "{}: every wall in a grid",
            scene.name
        );
        let mut lines = test_lines(scene, 60 + k as u64);
        lines.extend(grazing_lines(
            scene,
            &mut Pcg64::seed_from_u64(k as u64),
            3000,
        ));
        let reference = trace(&BruteForceTracer::new(scene), &lines);
        let got = trace(&tracer, &lines);
        let tree = trace(&BvhTracer::tree_only(scene).unwrap(), &lines);
        for (l, line) in lines.iter().enumerate() {
            assert_eq!(
                got.of_line(l),
                reference.of_line(l),
                "{}: line {l} {line:?}",
                scene.name
            );
            assert_eq!(
                tree.of_line(l),
                reference.of_line(l),
                "{}: line {l}",
                scene.name
            );
        }
        let mut first = Vec::new();
        tracer.first_hits(&lines, &mut first).unwrap();
        for (l, f) in first.iter().enumerate() {
            assert_eq!(
                *f,
                reference.of_line(l).first().copied(),
                "{}: line {l}",
                scene.name
            );
        }
        assert!(reference.hits.len() > lines.len(), "{}", scene.name);
        assert!(reference.hits.iter().any(|h| h.t == 0.0), "{}", scene.name);
    }
}

/// Slivers crossed at grazing angles (the crossings whose f32 distance the watertight test recomputes in
/// f64): the tree and the brute-force tracer give the same hits to the bit, and the first hit of each
/// line is the first of its hits (fuzzing found lines where it was not, while such distances were
/// percents off and the first-hit traversal culled the box of a crossing reported before it).
#[test]
fn grazing_crossings_of_slivers_match_the_brute_force_tracer_and_first_hits() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slivers.obj");
    std::fs::write(&path, support::slivers_obj()).unwrap();
    let scene = scenes::load(path.to_str().unwrap()).unwrap();
    let mut rng = Pcg64::seed_from_u64(5);
    let lines = support::lines_grazing_triangles(&scene, &mut rng, 20_000);
    let reference = trace(&BruteForceTracer::new(&scene), &lines);
    let tracer = BvhTracer::new(&scene).unwrap();
    let got = trace(&tracer, &lines);
    assert_eq!(got.start, reference.start);
    assert_eq!(got.hits, reference.hits);
    let mut first = Vec::new();
    tracer.first_hits(&lines, &mut first).unwrap();
    let differing: Vec<usize> = (0..lines.len())
        .filter(|&k| first[k] != reference.of_line(k).first().copied())
        .collect();
    assert!(
        differing.is_empty(),
        "{} of {} lines' first hits differ, e.g. line {:?}: {:?}, the first of {:?}",
        differing.len(),
        lines.len(),
        differing.first().map(|&k| lines[k]),
        differing.first().map(|&k| first[k]),
        differing.first().map(|&k| reference.of_line(k)),
    );
    let crossing_several = (0..lines.len())
        .filter(|&k| reference.of_line(k).len() >= 3)
        .count();
    assert!(
        crossing_several > 1_000,
        "{crossing_several} lines cross 3 slivers or more"
    );
}

/// `all_hits` finds the grid cells of a chunk of lines, and reads their packets, before it tests any of
/// them: on meshes of walls in grids (`@cube:60`, the turned meshed room) its rows are those of the
/// line-by-line raw hits canonicalised, to the bit, over batches that end inside a chunk; and a line that
/// cannot be traced in a later chunk is named by its index in the batch, with nothing returned.
#[test]
fn chunked_grid_lookups_give_the_line_by_line_hits() {
    let room = turned_room_scene(12, 0.2, true, 1.0);
    for scene in [scenes::load("@cube:60").unwrap(), room] {
        let bvh = BvhTracer::new(&scene).unwrap();
        assert!(bvh.planes_in_grids() > 0, "{}", scene.name);
        let lines = test_lines(&scene, 5);
        for count in [1, 31, 33, 100, lines.len()] {
            let got = trace(&bvh, &lines[..count]);
            let mut raw = Vec::new();
            bvh.raw_hits(&lines[..count], &mut raw).unwrap();
            let mut expected = LineHits::default();
            expected.fill_from_raw(count, &raw);
            bvh.rules().canonicalize(&lines[..count], &mut expected);
            assert_eq!(got.start, expected.start, "{} {count}", scene.name);
            assert_eq!(got.hits, expected.hits, "{} {count}", scene.name);
        }
        let mut bad = lines[..100].to_vec();
        bad[70].t_max = -1.0;
        let (mut raw, mut hits) = (Vec::new(), LineHits::default());
        let err = bvh.all_hits(&bad, &mut raw, &mut hits).unwrap_err();
        assert!(err.to_string().contains("line 70 "), "{err}");
        assert!(hits.hits.is_empty() && hits.start.is_empty());
    }
}
