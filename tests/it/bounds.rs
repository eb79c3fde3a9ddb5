//! Lines through the bounding box (`--lines-through box`) against independent truth: Crofton's formula
//! for the hits per patch through the real tracers (a patch inside the box is met by a share 2 A / S_box
//! of the lines that meet the box), the unit cube's closed-form I_s and I_s^c with both samplers, and the
//! invariants of a run (thread count, shards, resume), with the settings that contradict it refused.

use crate::support;
use scene_complexity::internals::analysis::{analyze, AnalysisError};
use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::run::{LinesThrough, Measures, RunControl, RunSpec};
use scene_complexity::internals::sample::bounds::{sphere_lines, LineBound};
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

/// The surface of `scene`'s bounding box as the run grows it (a millionth of the bounding radius, 1 in
/// tracing space, on every side), from the vertices' extent.
fn grown_box_surface(scene: &Scene) -> f64 {
    let side = |k: usize| {
        let (lo, hi) = scene
            .positions
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(f64::from(p[k])), hi.max(f64::from(p[k])))
            });
        hi - lo + 2e-6
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
        hits_per_patch_match(
            &scene,
            &spec,
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

/// `--lines-through auto` draws the Sobol' sampler's lines through the box on a scene whose box is the
/// smaller container (its surface below the unit sphere's 4 pi, Cauchy: fewer lines meet it), through
/// the polytope for the octahedron (its box reaches out of its sphere; its faces are its polytope's),
/// and through the sphere for the icosahedron (whose faces lie in none of the polytope's planes);
/// independent lines through the smallest container (the icosahedron's polytope too: their estimates'
/// distribution does not depend on it); bundles and the environment patch keep the sphere; a bound
/// asked for is kept.
#[test]
fn auto_draws_through_the_container_the_sampler_gains_from() {
    let four_pi = 4.0 * std::f64::consts::PI;
    let (cube, cornell, octahedron) = (
        scenes::load("@cube:4").unwrap(),
        scenes::load("@cornell").unwrap(),
        scenes::load("@octahedron").unwrap(),
    );
    assert!(grown_box_surface(&cube) < four_pi && grown_box_surface(&cornell) < four_pi);
    assert!(grown_box_surface(&octahedron) > four_pi);
    let sobol = RunSpec {
        sampler: Sampler::Sobol,
        ..RunSpec::new(1_000_000, 1)
    };
    let auto =
        |spec: &RunSpec, scene: &Scene| spec.clone().through(scene, LinesThrough::Auto).bound;
    assert_eq!(auto(&sobol, &cube), LineBound::Box);
    assert_eq!(auto(&sobol, &cornell), LineBound::Box);
    assert_eq!(auto(&sobol, &octahedron), LineBound::Polytope);
    let icosahedron = scenes::load("@icosahedron").unwrap();
    assert_eq!(auto(&sobol, &icosahedron), LineBound::Sphere);
    let independent = RunSpec::new(1_000_000, 1);
    assert_eq!(auto(&independent, &cube), LineBound::Box);
    assert_eq!(auto(&independent, &cornell), LineBound::Box);
    assert_eq!(auto(&independent, &octahedron), LineBound::Polytope);
    assert_eq!(auto(&independent, &icosahedron), LineBound::Polytope);
    let bundles = RunSpec {
        source: LineSource::bundles(4).unwrap(),
        ..independent.clone()
    };
    assert_eq!(auto(&bundles, &cube), LineBound::Sphere);
    for spec in [&sobol, &independent] {
        let enclosed = RunSpec {
            enclose: true,
            ..spec.clone()
        };
        assert_eq!(auto(&enclosed, &cube), LineBound::Sphere);
    }
    for bound in [LineBound::Sphere, LineBound::Box] {
        let kept = sobol
            .clone()
            .through(&octahedron, LinesThrough::Bound(bound));
        assert_eq!(kept.bound, bound);
    }
}

/// A line count is read as lines through the sphere: through the box the fewest lines worth as many
/// are drawn, `ceil(n S_box / (4 pi))` (a share S_box / 4 pi of the sphere's lines meet the box, from
/// the vertices' extent here), never worth fewer than asked; through the sphere, `n` itself.
#[test]
fn a_line_count_through_the_box_is_worth_as_many_through_the_sphere() {
    for name in ["@cube:4", "@cornell", "@octahedron"] {
        let scene = scenes::load(name).unwrap();
        let share = grown_box_surface(&scene) / (4.0 * std::f64::consts::PI);
        for n in [1u64, 7, 1000, 999_999, 1_000_000, 123_456_789] {
            let boxed = RunSpec::new(n, 1).through(&scene, LinesThrough::Bound(LineBound::Box));
            let ideal = n as f64 * share;
            let drawn = boxed.lines as f64;
            assert!(
                drawn >= ideal - 1e-6 * ideal && drawn < ideal + 1.0 + 1e-6 * ideal,
                "{name}: {n} -> {drawn} drawn, {ideal} ideal"
            );
            let worth = sphere_lines(&scene, LineBound::Box, boxed.lines);
            assert!(
                worth >= n as f64 * (1.0 - 1e-12),
                "{name}: {n} -> worth {worth}"
            );
            let sphere = RunSpec::new(n, 1).through(&scene, LinesThrough::Bound(LineBound::Sphere));
            assert_eq!(sphere.lines, n);
        }
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
    // --lines counts lines through the sphere: the fewest through the box worth as many are drawn.
    let h = 1.0 / 3f64.sqrt() + 1e-6;
    let share = 6.0 * h * h / std::f64::consts::PI;
    let drawn = single["lines"].as_f64().unwrap();
    assert!(
        (drawn - 7e5 * share).abs() < 1.0 + 1e-3,
        "{drawn} lines drawn"
    );
    // What they are worth is reported as the round count asked (they are worth 7e5 and a fraction).
    assert_eq!(single["sphere_lines"], 700_000);
    assert!(strip(&single) == strip(&run(&["--lines", "7e5", "--threads", "1"])));
    let (p1, p2) = (path("p1.scx"), path("p2.scx"));
    for (k, p) in [("1/2", &p1), ("2/2", &p2)] {
        run(&["--lines", "7e5", "--shard", k, "--save", p]);
    }
    let merged = json_of(&scx(&["merge", &p2, &p1, "--format", "json"]));
    assert!(strip(&single) == strip(&merged), "2 shards merged");
    // 4.5e5 through the sphere: over 2^18 drawn, full batches already.
    let short = path("short.scx");
    run(&["--lines", "4.5e5", "--save", &short]);
    let resumed = json_of(&scx(&[
        "analyze", "--resume", &short, "--lines", "7e5", "--format", "json",
    ]));
    assert!(
        strip(&single) == strip(&resumed),
        "4.5e5 lines resumed to 7e5"
    );
    // A shard of the same run through the sphere is another run.
    let sphere = path("sphere.scx");
    let out = scx(&[
        "analyze",
        "@cube:6",
        "--sampler",
        "sobol",
        "--lines-through",
        "sphere",
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

/// `scx analyze`: without `--lines-through`, `--sampler sobol` draws through the box of a cube (fewer
/// lines, worth the `--lines` asked), through the polytope of the octahedron and through the sphere of
/// the icosahedron; independent lines (the default with every measure) through the cube's box, and
/// bundles through the sphere, `--lines` of them.
#[cfg(feature = "cli")]
#[test]
fn the_cli_chooses_the_bound_by_sampler_and_scene() {
    use support::{json_of, scx};
    let run = |scene: &str, more: &[&str]| {
        let mut args = vec![
            "analyze", scene, "--lines", "2e5", "--tracer", "rust", "--format", "json",
        ];
        args.extend(more);
        json_of(&scx(&args))
    };
    let field = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    let cube = run("@cube:6", &["--sampler", "sobol"]);
    assert_eq!(cube["lines_through"], "box");
    assert!(field(&cube, "lines") < 2e5 * 0.7, "{}", cube["lines"]);
    assert_eq!(field(&cube, "sphere_lines"), 2e5);
    let octahedron = run("@octahedron", &["--sampler", "sobol"]);
    assert_eq!(octahedron["lines_through"], "polytope");
    assert!(
        field(&octahedron, "lines") < 2e5 * 0.6,
        "{}",
        octahedron["lines"]
    );
    let independent = run("@cube:6", &[]);
    assert_eq!(independent["lines_through"], "box");
    assert_eq!(field(&independent, "lines"), field(&cube, "lines"));
    assert_eq!(field(&independent, "sphere_lines"), 2e5);
    for (scene, more) in [
        ("@icosahedron", &["--sampler", "sobol"][..]),
        ("@cube:6", &["--bundle", "4"][..]),
    ] {
        let v = run(scene, more);
        assert_eq!(v["lines_through"], "sphere", "{scene} {more:?}");
        assert_eq!((field(&v, "lines"), field(&v, "sphere_lines")), (2e5, 2e5));
    }
}

/// The lines advice of a run through the box counts lines as `--lines` does, through the sphere: a run
/// of `@cube:10` short of a coverage of 0.99 is advised about as many lines through either bound (the
/// same distribution of counts per line that meets the scene), where advice in the lines drawn would
/// be the box's share of it, 0.64.
#[test]
fn the_lines_advice_of_a_box_run_counts_the_spheres_lines() {
    let scene = scenes::load("@cube:10").unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    let advice = |bound: LineBound| -> f64 {
        (1..=3)
            .map(|seed| {
                let spec = RunSpec {
                    measures: Measures::VISIBILITY,
                    ..RunSpec::new(200_000, seed)
                }
                .through(&scene, LinesThrough::Bound(bound));
                let a = analyze(&scene, tracer.as_ref(), &spec, &RunControl::default()).unwrap();
                a.sampling.unwrap().lines_for_coverage.unwrap() as f64
            })
            .sum()
    };
    let ratio = advice(LineBound::Box) / advice(LineBound::Sphere);
    assert!((0.85..1.15).contains(&ratio), "box / sphere advice {ratio}");
}

/// Lines through the bounding polytope: the octahedron's is itself grown by the margin (its surface
/// between the octahedron's, 8 equilateral triangles of side sqrt 2, and that of the octahedron whose
/// face planes are moved out by 1e-6, 4 sqrt 3 (1 + sqrt 3 10^-6)^2, which the planes of the axes and
/// the diagonals trim at its corners and edges), each of its faces is met by a share 2 A / S of the
/// lines (Crofton) through every tracer with both samplers, and its exact I_s^c (the calibration's) is
/// met within 4.5 standard errors; on 1 and 2 threads the same.
#[test]
fn polytope_lines_meet_crofton_and_the_octahedrons_exact_measure() {
    use scene_complexity::calibrate::{truth, Basis, CalibrationScene};
    let scene: Scene = scenes::load("@octahedron").unwrap();
    let share =
        scene_complexity::internals::sample::bounds::share_of_sphere(&scene, LineBound::Polytope);
    let surface = share * 4.0 * std::f64::consts::PI;
    let octahedron = 4.0 * 3f64.sqrt();
    assert!(
        surface > octahedron && surface < octahedron * (1.0 + 3f64.sqrt() * 1e-6).powi(2),
        "{surface}"
    );
    let exact = truth::truth(&CalibrationScene::parse("@octahedron").unwrap())
        .unwrap()
        .value(Measure::ContinuousMutualInformation, Basis::Closed)
        .unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    for sampler in SAMPLERS {
        let spec = RunSpec {
            sampler,
            bound: LineBound::Polytope,
            measures: Measures::VISIBILITY,
            ..RunSpec::new(1 << 18, 2024)
        };
        hits_per_patch_match(
            &scene,
            &spec,
            |p| 2.0 * scene.patches[p].area / surface,
            sampler.name(),
        );
        for seed in [5, 6] {
            let spec = RunSpec {
                seed,
                ..spec.clone()
            };
            let a = analyze(&scene, tracer.as_ref(), &spec, &RunControl::default()).unwrap();
            let e = a.estimate(Measure::ContinuousMutualInformation).unwrap();
            let se = e.stderr.unwrap();
            assert!(
                (e.value - exact).abs() < 4.5 * se,
                "{} seed {seed}: I_s^c {} +- {se}, exact {exact}",
                sampler.name(),
                e.value
            );
        }
        same_on_one_and_two_threads(
            &scene,
            tracer.as_ref(),
            &spec,
            &[
                Measure::ContinuousMutualInformation,
                Measure::MutualInformation,
            ],
        );
    }
}

/// The unit cube's closed forms through its polytope (the cube itself), both samplers.
#[test]
fn unit_cube_measures_match_closed_forms_with_polytope_lines() {
    let scene = scenes::load("@cube").unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    for sampler in SAMPLERS {
        let spec = RunSpec {
            sampler,
            bound: LineBound::Polytope,
            measures: Measures::VISIBILITY,
            ..RunSpec::new(200_000, 3)
        };
        let a = analyze(&scene, tracer.as_ref(), &spec, &RunControl::default()).unwrap();
        unit_cube_matches_closed_forms(&a, sampler.name());
    }
}
