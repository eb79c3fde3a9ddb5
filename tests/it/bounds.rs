//! Lines through the bounding box (`--lines-through box`) against independent truth: Crofton's formula
//! for the hits per patch through the real tracers (a patch inside the box is met by a share 2 A / S_box
//! of the lines that meet the box), the unit cube's closed-form I_s and I_s^c with both samplers, and the
//! invariants of a run (thread count, shards, resume), with the settings that contradict it refused.

use crate::support;
use scene_complexity::internals::analysis::{analyze, AnalysisError};
use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::run::{LineStream, Measures, RunControl, RunSpec};
use scene_complexity::internals::sample::bounds::{LineBound, LineRegion};
use scene_complexity::internals::sample::lines::{LineSource, Sampler};
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::{make_tracer, Backend, Query};
use support::{hits_per_patch_match, same_on_one_and_two_threads, unit_cube_matches_closed_forms};

fn through_the_box(lines: u64, seed: u64, sampler: Sampler) -> RunSpec {
    RunSpec {
        sampler,
        bound: LineBound::Box,
        measures: Measures::VISIBILITY,
        ..RunSpec::new(lines, seed)
    }
}

const SAMPLERS: [Sampler; 2] = [Sampler::Independent, Sampler::Sobol];

/// The surface of `scene`'s bounding box as the run grows it (a thousandth of the bounding radius, 1 in
/// tracing space, on every side), from the vertices' extent.
fn grown_box_surface(scene: &Scene) -> f64 {
    let side = |k: usize| {
        let (lo, hi) = scene
            .positions
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(f64::from(p[k])), hi.max(f64::from(p[k])))
            });
        hi - lo + 2e-3
    };
    let (x, y, z) = (side(0), side(1), side(2));
    2.0 * (x * y + y * z + z * x)
}

/// Crofton through the tracers: a line meeting the box meets a planar patch of area A inside it with
/// probability 2 A / S_box, so over a run's lines (16 groups) the hits of each patch of `@cube:2` per
/// line match it, to 4.5 standard errors of the groups, with either sampler.
#[test]
fn box_lines_hit_each_patch_as_often_as_crofton_says() {
    let scene: Scene = scenes::load("@cube:2").unwrap();
    let surface = grown_box_surface(&scene);
    for sampler in SAMPLERS {
        let spec = through_the_box(1 << 19, 2024, sampler);
        let stream = LineStream {
            plan: spec.plan(),
            source: LineSource::Independent,
            sampler,
            bound: LineBound::Box,
            groups: spec.group_count() as u64,
            seed: spec.seed,
        };
        hits_per_patch_match(
            &scene,
            &stream,
            &LineRegion::of(&scene, LineBound::Box),
            |p| 2.0 * scene.patches[p].area / surface,
            sampler.name(),
        );
    }
}

/// The unit cube's closed-form I_s (eq. 21 with the exact form factors of its faces) and I_s^c (the
/// calibration's exact value) within 4.5 standard errors of runs of lines through the box, both samplers.
#[test]
fn unit_cube_measures_match_closed_forms_with_box_lines() {
    let scene = scenes::load("@cube").unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    for sampler in SAMPLERS {
        for seed in [3, 4] {
            let spec = through_the_box(200_000, seed, sampler);
            let a = analyze(&scene, tracer.as_ref(), &spec, &RunControl::default()).unwrap();
            unit_cube_matches_closed_forms(&a, &format!("{} seed {seed}", sampler.name()));
        }
    }
}

/// The same seed gives the same numbers on 1 and 2 threads, to the bit, with either sampler.
#[test]
fn box_runs_are_the_same_on_any_thread_count() {
    let scene = scenes::load("@cube:4").unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    for sampler in SAMPLERS {
        let spec = RunSpec {
            measures: Measures::ALL,
            ..through_the_box(150_000, 9, sampler)
        };
        same_on_one_and_two_threads(
            &scene,
            tracer.as_ref(),
            &spec,
            &[
                Measure::ContinuousMutualInformation,
                Measure::MutualInformationCorrected,
                Measure::MsePerLine,
            ],
        );
    }
}

/// Lines through the box with bundles, or with the environment patch (whose area is counted from the
/// lines that miss the scene, most of which the box leaves out), are refused before any line is cast.
#[test]
fn box_lines_with_bundles_or_the_environment_are_refused() {
    let scene = scenes::load("@cube").unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    let bundles = RunSpec {
        source: LineSource::bundles(4).unwrap(),
        ..through_the_box(10_000, 1, Sampler::Independent)
    };
    let enclosed = RunSpec {
        enclose: true,
        ..through_the_box(10_000, 1, Sampler::Independent)
    };
    for (spec, says) in [(bundles, "bundles of 4 x 4"), (enclosed, "--enclose")] {
        let err = analyze(&scene, tracer.as_ref(), &spec, &RunControl::default()).unwrap_err();
        assert!(matches!(err, AnalysisError::Spec(_)), "{err}");
        assert!(err.to_string().contains(says), "{err}");
    }
}

/// A state saved before the bound existed reads as lines through the sphere, and two specs that differ
/// in it cannot be parts of one run, which the difference names.
#[test]
fn specs_without_a_bound_read_as_the_sphere() {
    let spec = RunSpec::new(1000, 1);
    let mut old = serde_json::to_value(&spec).unwrap();
    old.as_object_mut().unwrap().remove("bound").unwrap();
    let read: RunSpec = serde_json::from_value(old).unwrap();
    assert_eq!(read, spec);
    let boxed = RunSpec {
        bound: LineBound::Box,
        ..spec.clone()
    };
    let d = spec.difference(&boxed, true).unwrap();
    assert_eq!(
        (d.setting.as_str(), d.ours.as_str(), d.theirs.as_str()),
        ("bound", "sphere", "box")
    );
}

/// `scx analyze --lines-through box --sampler sobol`: shards merged, a run resumed to more lines and a
/// run on one thread give the report of the run cast at once, bit for bit (session fields aside); the
/// report says where its lines were drawn and what they are worth in lines through the sphere (a cube's
/// box meets 2 / pi of them, less the margin); a part of the same run through the sphere is refused by
/// name, and so are `--bundle` and `--enclose` with the box.
#[cfg(feature = "cli")]
#[test]
fn box_runs_split_resumed_and_merged_are_the_single_run() {
    use support::{json_of, scx, without_session};
    let strip = without_session;
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let run = |more: &[&str]| {
        let mut args = vec![
            "analyze",
            "@cube:6",
            "--lines-through",
            "box",
            "--sampler",
            "sobol",
            "--tracer",
            "rust",
            "--format",
            "json",
        ];
        args.extend(more);
        json_of(&scx(&args))
    };
    let single = run(&["--lines", "7e5"]);
    assert_eq!(single["lines_through"], "box");
    let worth = single["sphere_lines"].as_f64().unwrap() / 7e5;
    let h = 1.0 / 3f64.sqrt() + 1e-3;
    let expected = std::f64::consts::PI / (6.0 * h * h);
    assert!(
        (worth - expected).abs() < 1e-5,
        "{worth} against {expected}"
    );
    assert!(strip(&single) == strip(&run(&["--lines", "7e5", "--threads", "1"])));
    let (p1, p2) = (path("p1.scx"), path("p2.scx"));
    for (k, p) in [("1/2", &p1), ("2/2", &p2)] {
        run(&["--lines", "7e5", "--shard", k, "--save", p]);
    }
    let merged = json_of(&scx(&["merge", &p2, &p1, "--format", "json"]));
    assert!(strip(&single) == strip(&merged), "2 shards merged");
    let short = path("short.scx");
    run(&["--lines", "3e5", "--save", &short]);
    let resumed = json_of(&scx(&[
        "analyze", "--resume", &short, "--lines", "7e5", "--format", "json",
    ]));
    assert!(
        strip(&single) == strip(&resumed),
        "3e5 lines resumed to 7e5"
    );
    // A shard of the same run through the sphere is another run.
    let sphere = path("sphere.scx");
    let out = scx(&[
        "analyze",
        "@cube:6",
        "--sampler",
        "sobol",
        "--tracer",
        "rust",
        "--lines",
        "7e5",
        "--shard",
        "1/2",
        "--save",
        &sphere,
    ]);
    assert!(out.status.success());
    let refused = scx(&["merge", &p1, &sphere]);
    assert_eq!(refused.status.code(), Some(2));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("bound"), "{err}");
    for other in [["--bundle", "4"], ["--enclose", "--seed"]] {
        let mut args = vec![
            "analyze",
            "@cube",
            "--lines-through",
            "box",
            "--lines",
            "1e4",
        ];
        args.extend(other);
        if other[0] == "--enclose" {
            args.push("2");
        }
        let out = scx(&args);
        assert_eq!(out.status.code(), Some(2), "{other:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("--lines-through box"),
            "{other:?}"
        );
    }
}
