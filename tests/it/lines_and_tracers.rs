//! Global lines and tracers against truth computed by hand: hits on chosen lines of `@cube:N`, even parity
//! through edges and vertices of a closed mesh, and Crofton's formula for the uniformity of the lines.

use crate::support;
use scene_complexity::internals::scenes;

use rand::{Rng, SeedableRng};
use scene_complexity::internals::sample::lines::batch_lines;
use scene_complexity::internals::sample::pairs::{segments, Segment};
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::trace::{Line, LineHits, Tracer};
use support::all_tracers;

fn trace(tracer: &dyn Tracer, lines: &[Line]) -> LineHits {
    let mut raw = Vec::new();
    let mut hits = LineHits::default();
    tracer
        .all_hits(lines, &mut raw, &mut hits)
        .expect("tracing works");
    hits
}

/// Scene-unit coordinate of the unit cube -> tracing space (centre 0.5, radius sqrt(3)/2).
fn tr(x: f64) -> f64 {
    (x - 0.5) / (3f64.sqrt() / 2.0)
}

#[test]
fn axis_lines_through_patch_centres_hit_the_expected_patches() {
    let n = 5usize;
    let scene = scenes::load(&format!("@cube:{n}")).unwrap();
    let h = tr(1.0);
    for tracer in all_tracers(&scene) {
        for (i, j) in [(0usize, 0usize), (2, 3), (4, 1)] {
            let (x, y) = (
                tr((i as f64 + 0.5) / n as f64),
                tr((j as f64 + 0.5) / n as f64),
            );
            // Up the z axis: enters through face 4 (z = 0, u = x, v = y), leaves through face 5 (z = 1,
            // u = y, v = x), see `CUBE_FACES`.
            let line = Line {
                origin: [x as f32, y as f32, -1.5],
                dir: [0.0, 0.0, 1.0],
                t_max: 3.0,
            };
            let hits = trace(tracer.as_ref(), &[line]);
            let row = hits.of_line(0);
            assert_eq!(row.len(), 2, "{}: {row:?}", tracer.name());
            let patch = |k: usize| scene.triangle_patch[row[k].triangle as usize] as usize;
            assert_eq!(patch(0), 4 * n * n + i * n + j);
            assert_eq!(patch(1), 5 * n * n + j * n + i);
            assert!((row[0].t as f64 - (1.5 - h)).abs() < 1e-6);
            assert!((row[1].t as f64 - (1.5 + h)).abs() < 1e-6);

            let mut seen = Vec::new();
            segments(&scene, &line, row, |s| seen.push(s));
            match seen.as_slice() {
                [Segment::Pair {
                    from,
                    to,
                    distance,
                    cos_from,
                    cos_to,
                }] => {
                    assert_eq!((*from as usize, *to as usize), (patch(0), patch(1)));
                    assert!(
                        (distance - 2.0 * h).abs() < 1e-12,
                        "f64 distance from the planes"
                    );
                    assert!((cos_from - 1.0).abs() < 1e-12 && (cos_to - 1.0).abs() < 1e-12);
                }
                other => panic!("expected one pair, got {other:?}"),
            }
        }
        // An oblique line along (1,1,1) entering the z = 0 face at (0.01, 0.02) (scene units), in
        // patch (0, 0) of face 4, two tracing units from its origin.
        let d = [1.0f64, 1.0, 1.0].map(|c| c / 3f64.sqrt());
        let start = [0.01, 0.02, 0.0].map(tr);
        let o = [0, 1, 2].map(|a| start[a] - 2.0 * d[a]);
        let line = Line {
            origin: o.map(|c| c as f32),
            dir: d.map(|c| c as f32),
            t_max: 4.0,
        };
        let hits = trace(tracer.as_ref(), &[line]);
        let row = hits.of_line(0);
        assert_eq!(row.len(), 2, "{}: {row:?}", tracer.name());
        assert_eq!(
            scene.triangle_patch[row[0].triangle as usize] as usize,
            4 * n * n
        );
        assert!((row[0].t as f64 - 2.0).abs() < 1e-5);
        // Leaves where x or y reaches 1 first: y does (it starts further along); travel in scene units
        // (1 - 0.02) * sqrt(3), then tracing units divide by sqrt(3)/2.
        let exit_t = 2.0 + (1.0 - 0.02) * 3f64.sqrt() / (3f64.sqrt() / 2.0);
        assert!(
            (row[1].t as f64 - exit_t).abs() < 1e-5,
            "{} vs {exit_t}",
            row[1].t
        );
        // y = 1 face is face 3 (u = x, v = z): x = 0.99, z = 0.98 at exit -> patch (4, 4).
        assert_eq!(
            scene.triangle_patch[row[1].triangle as usize] as usize,
            3 * n * n + 4 * n + 4
        );
    }
}

/// Lines through (f32) vertices of the closed cube mesh, in random directions: every line crosses the
/// closed surface an even number of times.
#[test]
fn lines_through_edges_and_vertices_have_even_parity() {
    let scene = scenes::load("@cube:4").unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(17);
    let mut lines = Vec::new();
    for k in 0..20_000 {
        let v = scene.positions[rng.gen_range(0..scene.positions.len())].map(f64::from);
        let through = if k % 2 == 0 {
            v
        } else {
            // The midpoint of an edge between two grid vertices of one face.
            let w = scene.positions
                [scene.triangles[rng.gen_range(0..scene.triangles.len())][1] as usize]
                .map(f64::from);
            [0, 1, 2].map(|a| 0.5 * (v[a] + w[a]))
        };
        let d =
            scene_complexity::internals::geom::uniform_direction(rng.gen(), rng.gen()).to_array();
        lines.push(Line {
            origin: [0, 1, 2].map(|a| (through[a] - 2.0 * d[a]) as f32),
            dir: d.map(|c| c as f32),
            t_max: 4.0,
        });
    }
    // Axis-parallel lines exactly through grid vertices (shared by up to six triangles).
    for &p in scene.positions.iter().filter(|p| p[2] < 0.0) {
        lines.push(Line {
            origin: [p[0], p[1], -2.0],
            dir: [0.0, 0.0, 1.0],
            t_max: 4.0,
        });
    }
    let axis_parallel = lines.len() - 20_000;
    assert!(axis_parallel > 20, "{axis_parallel} axis-parallel lines");
    for tracer in all_tracers(&scene) {
        let hits = trace(tracer.as_ref(), &lines);
        // An axis-parallel line exactly through an inner grid vertex enters and leaves the cube through
        // a vertex of four or six triangles each time: exactly one of them reports each crossing (the
        // test decides a line exactly on an edge as if it passed beside it), before any canonicalisation.
        // One through a vertex on the cube's edge lies in a side face: it touches the cube, or crosses it
        // as a line beside it would.
        let mut raw = Vec::new();
        tracer.raw_hits(&lines[20_000..], &mut raw).unwrap();
        let mut per_line = vec![0usize; axis_parallel];
        for h in &raw {
            per_line[h.line as usize] += 1;
        }
        assert!(
            per_line.iter().all(|&n| n == 0 || n == 2)
                && per_line.iter().filter(|&&n| n == 2).count() > axis_parallel / 3,
            "{}: raw hits of lines through vertices {per_line:?}",
            tracer.name()
        );
        let mut through_interior = 0;
        for (k, line) in lines.iter().enumerate() {
            let n = hits.of_line(k).len();
            assert_eq!(
                n % 2,
                0,
                "{}: line {k} {:?} has {n} hits: {:?}",
                tracer.name(),
                line,
                hits.of_line(k)
            );
            through_interior += usize::from(n == 2);
        }
        assert!(
            through_interior > lines.len() / 3,
            "most such lines cross the cube"
        );
    }
}

/// Crofton: a uniform global line meets a planar patch of area A with probability A / (2 pi R^2).
#[test]
fn hits_per_patch_follow_crofton() {
    let scene: Scene = scenes::load("@cube:2").unwrap();
    let lines_n = 1_000_000usize;
    for tracer in all_tracers(&scene) {
        let mut per_patch = vec![0u64; scene.patch_count()];
        let mut lines = Vec::new();
        for b in 0..(lines_n / 10_000) as u64 {
            lines.clear();
            batch_lines(2024, b, 10_000, 1.0, &mut lines);
            let hits = trace(tracer.as_ref(), &lines);
            for h in &hits.hits {
                per_patch[scene.triangle_patch[h.triangle as usize] as usize] += 1;
            }
        }
        let mut chi2 = 0.0;
        for (i, &c) in per_patch.iter().enumerate() {
            let p = scene.patches[i].area / (2.0 * std::f64::consts::PI);
            let mean = lines_n as f64 * p;
            let sd = (mean * (1.0 - p)).sqrt();
            assert!(
                (c as f64 - mean).abs() < 4.5 * sd,
                "{}: patch {i}: {c} hits, expected {mean:.0} +- {sd:.0}",
                tracer.name()
            );
            chi2 += ((c as f64 - mean) / sd).powi(2);
        }
        // 24 patches: chi-square with ~24 degrees of freedom; 60 is far in the tail.
        assert!(chi2 < 60.0, "{}: chi2 = {chi2}", tracer.name());
    }
}

/// Pairing from the run's plane table ([`PatchPlanes`], shared planes behind an index on a large mesh of
/// walls, one plane per patch on a curved mesh) gives the segments of pairing from the patch records
/// themselves, to the bit, line by line.
#[test]
fn the_plane_table_pairs_every_line_as_the_patch_records_do() {
    use scene_complexity::internals::sample::pairs::{segments_and_ends, PatchPlanes};
    for name in ["@cube:60", "@sphere:5", "@cornell"] {
        let scene = scenes::load(name).unwrap();
        let planes = PatchPlanes::of(&scene);
        // The walls of a fine cube share six planes; a sphere's patches have a plane each; the Cornell
        // box is small enough for the full table.
        assert_eq!(planes.shares_planes(), name == "@cube:60", "{name}");
        let tracer = &all_tracers(&scene)[0];
        let mut lines = Vec::new();
        batch_lines(11, 0, 20_000, scene.bounding_radius(), &mut lines);
        let hits = trace(tracer.as_ref(), &lines);
        let mut pairs = 0;
        for (k, line) in lines.iter().enumerate() {
            let (mut direct, mut tabled) = (Vec::new(), Vec::new());
            let ends = segments_and_ends(&scene, line, hits.of_line(k), |s| direct.push(s));
            let ends_tabled =
                planes.segments_and_ends(&scene, line, hits.of_line(k), |s| tabled.push(s));
            assert_eq!(direct, tabled, "{name}, line {k}");
            assert_eq!(ends, ends_tabled, "{name}, line {k}");
            pairs += direct
                .iter()
                .filter(|s| matches!(s, Segment::Pair { .. }))
                .count();
        }
        assert!(pairs > 1000, "{name}: {pairs} pairs");
    }
}
