//! The cross-check: two tracers that agree pass on small scenes (Embree against the pure-Rust BVH when
//! Embree is built in, the BVH against brute force always); a tracer with planted faults is caught on
//! exactly the lines it spoils, by the right kind; the `scx crosscheck` command exits accordingly.

use crate::support;
use scene_complexity::internals::scenes;
#[cfg(feature = "cli")]
use support::scx;

use scene_complexity::crosscheck::{
    compare_hits, crosscheck, CrossCheckConfig, DifferenceKind, Tolerance,
};
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::trace::rust::{BruteForceTracer, BvhTracer};
use scene_complexity::internals::trace::{HitRules, Line, RawHit, TraceError, Tracer};

fn config(lines: u64) -> CrossCheckConfig {
    CrossCheckConfig {
        lines,
        seed: 5,
        tolerance: Tolerance::default(),
        examples: 3,
    }
}

/// The brute-force tracer with faults planted on chosen lines of each batch: line 3 loses its last hit,
/// line 5 reports its first hit on another patch's triangle, line 7 has its first hit moved by 64 ulps.
struct Faulty {
    inner: BruteForceTracer,
    other_patch_triangle: u32,
}

impl Tracer for Faulty {
    fn name(&self) -> &'static str {
        "faulty"
    }

    fn rules(&self) -> &HitRules {
        self.inner.rules()
    }

    fn raw_hits(&self, lines: &[Line], out: &mut Vec<RawHit>) -> Result<(), TraceError> {
        self.inner.raw_hits(lines, out)?;
        let of = |out: &Vec<RawHit>, line: u32| -> Vec<usize> {
            let mut idx: Vec<usize> = (0..out.len()).filter(|&i| out[i].line == line).collect();
            idx.sort_by(|&a, &b| out[a].t.total_cmp(&out[b].t));
            idx
        };
        if let Some(&last) = of(out, 3).last() {
            out.remove(last);
        }
        if let Some(&first) = of(out, 5).first() {
            out[first].triangle = self.other_patch_triangle;
        }
        if let Some(&first) = of(out, 7).first() {
            out[first].t += 64.0 * f32::EPSILON * out[first].t.max(1.0);
        }
        Ok(())
    }
}

#[test]
fn planted_faults_are_found_on_their_lines_and_by_kind() {
    // @cube:1: one patch per face; every line through the cube hits it twice, so every fault is visible.
    let scene = scenes::load("@cube").unwrap();
    let faulty = Faulty {
        inner: BruteForceTracer::new(&scene),
        other_patch_triangle: 2,
    };
    let reference = BruteForceTracer::new(&scene);
    let lines = 2000;
    let c = compare_hits(&scene, &reference, &faulty, &config(lines)).unwrap();
    assert_eq!(c.lines, lines);
    assert!(!c.agrees());
    // 2000 lines are at most a few batches; each batch holds lines 3, 5 and 7 of its own.
    let batches = scene_complexity::internals::run::BatchPlan::new(lines).batches();
    // A line that misses the cube (about 1 in 4 within the unit sphere) has nothing to spoil.
    let [count, patch, distance] = c.differing;
    assert!(count <= batches && patch <= batches && distance <= batches);
    assert!(count + patch + distance >= batches, "{:?}", c.differing);
    let kinds: Vec<DifferenceKind> = c.examples.iter().map(|d| d.kind).collect();
    let indices: Vec<u64> = c.examples.iter().map(|d| d.index).collect();
    // Line 5's first hit was on patch 0 or 1 or ...; triangle 2 is patch 1: it differs unless it was
    // already there, so check the examples are among the planted lines, in order, with their kinds.
    for (i, k) in indices.iter().zip(&kinds) {
        let expected = match i % BatchPlanSize::of(lines) {
            3 => DifferenceKind::Count,
            5 => DifferenceKind::Patch,
            7 => DifferenceKind::Distance,
            other => panic!("line {i} (position {other} in its batch) was not spoiled"),
        };
        assert_eq!(*k, expected, "line {i}");
    }
    assert!(indices.windows(2).all(|w| w[0] < w[1]));
}

/// The batch size of a run's plan.
struct BatchPlanSize;

impl BatchPlanSize {
    fn of(lines: u64) -> u64 {
        scene_complexity::internals::run::BatchPlan::new(lines).batch_size
    }
}

#[test]
fn the_bvh_and_brute_force_agree_line_for_line() {
    for spec in ["@cube:3", "@sphere:1", "@dodecahedron"] {
        let scene: Scene = scenes::load(spec).unwrap();
        let check = crosscheck(
            &scene,
            &BruteForceTracer::new(&scene),
            &BvhTracer::new(&scene).unwrap(),
            &config(20_000),
            4,
        )
        .unwrap();
        assert!(check.passed(), "{spec}: {:?}", check.hits.examples);
        assert_eq!(check.hits.max_ulps, 0.0, "{spec}: the same arithmetic");
        assert!(!check.measures.is_empty());
        for m in &check.measures {
            assert_eq!(m.a.value, m.b.value, "{spec}: {}", m.name);
        }
    }
}

#[cfg(feature = "embree")]
#[test]
fn embree_and_the_rust_bvh_agree_on_small_scenes() {
    use scene_complexity::internals::trace::{make_tracer, Backend, Query};
    let dir = tempfile::tempdir().unwrap();
    let room = dir.path().join("room.obj");
    std::fs::write(&room, support::room_with_box_obj(1.0)).unwrap();
    for spec in [
        "@cube:4",
        "@sphere:2",
        "@tetrahedron",
        "@icosahedron:2",
        room.to_str().unwrap(),
    ] {
        let scene = scenes::load(spec).unwrap();
        let embree = make_tracer(Backend::Embree, &scene, Query::Single).unwrap();
        let rust = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
        let check = crosscheck(&scene, embree.as_ref(), rust.as_ref(), &config(50_000), 4).unwrap();
        assert_eq!(check.hits.lines, 50_000);
        assert!(
            check.hits.hits.0 > 20_000,
            "{spec}: the lines hit the scene"
        );
        assert!(check.passed(), "{spec}: {:?}", check.hits.examples);
        for m in &check.measures {
            assert!(m.gap_in_stderrs() < 1e-6, "{spec}: {}", m.name);
        }
    }
}

#[cfg(all(feature = "embree", feature = "cli"))]
#[test]
fn the_command_passes_and_reports() {
    let out = scx(&["crosscheck", "@cube:3", "--lines", "2e4", "--threads", "2"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("differing lines: 0"), "{text}");
    assert!(text.contains("PASS"), "{text}");
    assert!(text.contains("I_s^c"), "{text}");
}

#[cfg(all(not(feature = "embree"), feature = "cli"))]
#[test]
fn without_embree_the_command_says_so() {
    let out = scx(&["crosscheck", "@cube:3", "--lines", "1e3"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("without Embree"));
}

#[cfg(feature = "cli")]
#[test]
fn bad_arguments_are_clear_errors() {
    let out = scx(&["crosscheck", "@nothing", "--lines", "1e3"]);
    assert_eq!(out.status.code(), Some(2));
    let out = scx(&["crosscheck", "@cube", "--lines", "-3"]);
    assert_eq!(out.status.code(), Some(2));
}
