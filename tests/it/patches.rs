//! The per-patch results against invariants: the per-patch terms add up to the scene's measures, and
//! the radiosity columns solve eq. (2). (`cli_patches` checks the files `scx analyze` writes.)

use scene_complexity::internals::analysis::{analyze, Analysis};
use scene_complexity::internals::measure::shares::information_loss;
use scene_complexity::internals::measure::{Measure, PatchMeasure};
use scene_complexity::internals::run::{RunControl, RunSpec};
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::{make_tracer, Backend, Query};
use scene_complexity::refine::oracle;
use scene_complexity::EntropyEstimator;

fn run_with_patches(
    spec: &str,
    lines: u64,
    estimator: EntropyEstimator,
) -> (scene_complexity::Scene, Analysis) {
    let scene = scenes::load(spec).unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    let cfg = RunSpec {
        per_patch: true,
        estimator,
        ..RunSpec::new(lines, 7)
    };
    let a = analyze(&scene, tracer.as_ref(), &cfg, &RunControl::default()).unwrap();
    (scene, a)
}

fn close(x: f64, y: f64) -> bool {
    (x - y).abs() <= 1e-10 * x.abs().max(y.abs()).max(1.0)
}

/// H_s = sum a_i H_i, I_s = sum I_i and I_s^c = sum I_i^c, plug-in and corrected, to rounding: in a
/// closed lit scene (dense counts), an open one (escapes), and a mesh with sparse counts and unsampled
/// patches; with the one-pass estimators and with Chao–Shen (two passes).
#[test]
fn per_patch_terms_add_up_to_the_scene_measures() {
    for (spec, lines, estimator) in [
        ("@cornell", 200_000, EntropyEstimator::ChaoWangJost),
        ("@cornell-open", 200_000, EntropyEstimator::Grassberger),
        ("@cube:4", 100_000, EntropyEstimator::ChaoShen),
        ("@cube:30", 20_000, EntropyEstimator::ChaoWangJost),
    ] {
        let (scene, a) = run_with_patches(spec, lines, estimator);
        let p = a.patches.as_ref().expect("asked for");
        assert_eq!(p.len(), scene.patch_count());
        let total_area = scene.total_area();
        let a_i = |i: usize| scene.patches[i].area / total_area;
        let sum = |f: &dyn Fn(usize) -> f64| (0..p.len()).map(f).sum::<f64>();
        let checks = [
            (
                "H_s",
                sum(&|i| a_i(i) * p[i].get(PatchMeasure::RowEntropy).unwrap().value),
                a.estimate(Measure::Entropy).unwrap().value,
            ),
            (
                "H_s corrected",
                sum(&|i| a_i(i) * p[i].get(PatchMeasure::RowEntropyCorrected).unwrap().value),
                a.estimate(Measure::EntropyCorrected).unwrap().value,
            ),
            (
                "I_s",
                sum(&|i| p[i].get(PatchMeasure::MutualInformationTerm).unwrap().value),
                a.estimate(Measure::MutualInformation).unwrap().value,
            ),
            (
                "I_s corrected",
                sum(&|i| {
                    p[i].get(PatchMeasure::MutualInformationTermCorrected)
                        .unwrap()
                        .value
                }),
                a.estimate(Measure::MutualInformationCorrected)
                    .unwrap()
                    .value,
            ),
            (
                "I_s^c",
                sum(&|i| p[i].get(PatchMeasure::ContinuousTerm).unwrap().value),
                a.estimate(Measure::ContinuousMutualInformation)
                    .unwrap()
                    .value,
            ),
            (
                "I_s^c - I_s",
                sum(&|i| p[i].get(PatchMeasure::LostInformation).unwrap().value),
                a.estimate(Measure::ContinuousMutualInformation)
                    .unwrap()
                    .value
                    - a.estimate(Measure::MutualInformation).unwrap().value,
            ),
        ];
        for (name, parts, whole) in checks {
            assert!(
                close(parts, whole),
                "{spec}: {name}: sum of patches {parts} vs scene {whole}"
            );
        }
        // Every value with a standard error, no NaN from an unsampled patch.
        for (i, e) in p.iter().enumerate() {
            for x in [
                e.get(PatchMeasure::RowEntropy).unwrap(),
                e.get(PatchMeasure::MutualInformationTerm).unwrap(),
                e.get(PatchMeasure::ContinuousTerm).unwrap(),
            ] {
                assert!(
                    x.value.is_finite() && x.stderr.is_some_and(f64::is_finite),
                    "{spec} {i}: {e:?}"
                );
            }
            assert_eq!(
                e.get(PatchMeasure::Radiosity).is_some(),
                spec == "@cornell" || spec == "@cornell-open"
            );
        }
        if spec == "@cube:30" {
            assert!(
                p.iter().any(|e| !e.sampled()),
                "20 000 lines leave patches of @cube:30 unsampled"
            );
        }
    }
}

/// The radiosity columns solve eq. (2): B_i = E_i + R_i B_i^in for every patch.
#[test]
fn per_patch_radiosities_solve_the_radiosity_equation() {
    let (scene, a) = run_with_patches("@cornell", 300_000, EntropyEstimator::ChaoWangJost);
    for (i, e) in a.patches.as_ref().unwrap().iter().enumerate() {
        let m = &scene.materials[scene.patches[i].material as usize];
        let (b, b_in) = (
            e.get(PatchMeasure::Radiosity).unwrap(),
            e.get(PatchMeasure::IncomingRadiosity).unwrap(),
        );
        let residual = b.value - m.emission - m.reflectance * b_in.value;
        assert!(
            residual.abs() <= 1e-8 * m.emission.max(b.value),
            "patch {i}: {residual}"
        );
        assert!(b.stderr.is_some_and(|se| se > 0.0 || m.reflectance == 0.0));
    }
}

/// One computation: on the same lines (same seed and count), the `information` meshing strategy's
/// scores with B = 1, divided by A_T, are the per-patch table's lost information but for the table's
/// common correction `a_i delta` (the same `delta` for every patch), in a closed scene.
#[test]
fn refines_information_scores_are_the_tables_lost_information() {
    let (lines, seed) = (300_000, 7);
    for spec in ["@cube:4", "@cornell:2"] {
        let (scene, a) = run_with_patches(spec, lines, EntropyEstimator::PlugIn);
        assert_eq!(a.spec.seed, seed);
        let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
        let sample = oracle::sample_pairs(&scene, tracer.as_ref(), lines, seed).unwrap();
        let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
        let scores = information_loss(&areas, &sample, None);
        let total = scene.total_area();
        let p = a.patches.unwrap();
        let delta: Vec<f64> = (0..p.len())
            .map(|i| {
                let a_i = areas[i] / total;
                (p[i].get(PatchMeasure::LostInformation).unwrap().value - scores[i] / total) / a_i
            })
            .collect();
        for d in &delta {
            assert!((d - delta[0]).abs() < 1e-9, "{spec}: {delta:?}");
        }
        assert!(delta[0].abs() < 0.01, "{spec}: delta {}", delta[0]);
    }
}

/// The per-patch results are bit-identical whatever the thread count (every sum is exact or added in
/// batch order).
#[test]
fn per_patch_results_do_not_depend_on_the_threads() {
    let scene = scenes::load("@cube:30").unwrap();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    let cfg = RunSpec {
        per_patch: true,
        ..RunSpec::new(60_000, 3)
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| analyze(&scene, tracer.as_ref(), &cfg, &RunControl::default()))
            .unwrap()
            .patches
            .unwrap()
    };
    assert_eq!(run(1), run(2));
}

/// A unit cube standing in open space (outward normals: object `cube`) and, a unit above it, a
/// one-sided square facing up (object `lid`): every line that meets them leaves the scene, and the
/// cube's top sees the lid's back (segments absorbed there).
const CUBE_AND_LID: &str =
    "o cube\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
    f 5 7 3 1\nf 4 8 6 2\nf 2 6 5 1\nf 7 8 4 3\nf 3 4 2 1\nf 5 6 8 7\n\
    o lid\nv 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\nf 9 10 11 12\n";

/// A run of `lines` lines with per-patch results of `scene`, enclosed.
fn enclosed_run(scene: &scene_complexity::Scene, lines: u64, seed: u64) -> Analysis {
    let tracer = make_tracer(Backend::Rust, scene, Query::Single).unwrap();
    let cfg = RunSpec {
        per_patch: true,
        enclose: true,
        ..RunSpec::new(lines, seed)
    };
    analyze(scene, tracer.as_ref(), &cfg, &RunControl::default()).unwrap()
}

fn cube_and_lid() -> scene_complexity::Scene {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube_and_lid.obj");
    std::fs::write(&path, CUBE_AND_LID).unwrap();
    scenes::load(path.to_str().unwrap()).unwrap()
}

/// With `--enclose` the per-patch results are the enclosed scene's, the environment's row after the
/// scene's patches: the area fractions (the environment's, its counted area over the enclosed scene's)
/// sum to 1, and H_s = sum a_i H_i, I_s = sum I_i, I_s^c = sum I_i^c (eq. 27 with the environment
/// pairs' terms) and the lost information add up to the enclosed scene's readings to rounding, on an
/// open room (lit: the environment has no radiosity) and on objects in open space (with segments
/// absorbed at a back side). The objects, the environment's last, add up too.
#[test]
fn enclosed_per_patch_terms_add_up_to_the_enclosed_scene() {
    let room = scenes::load("@cornell-open").unwrap();
    let objects = cube_and_lid();
    for (name, scene, lines) in [
        ("@cornell-open", &room, 200_000),
        ("cube and lid", &objects, 100_000),
    ] {
        let a = enclosed_run(scene, lines, 11);
        let n = scene.patch_count();
        let p = a
            .patches
            .as_ref()
            .expect("per-patch results of an enclosed scene");
        assert_eq!(p.len(), n + 1, "{name}: the environment's row");
        let env = &p[n];
        let area = a.environment_area.expect("enclosed").value;
        let scale2 = scene.normalization.scale.powi(2);
        let own = scene.total_area() * scale2;
        assert!(close(env.area_fraction, area / (own + area)), "{name}");
        assert!(close(p.iter().map(|r| r.area_fraction).sum(), 1.0));
        let c = &a.tally.counters;
        assert_eq!(env.segments, c.escapes + 2 * c.misses, "{name}");
        assert_eq!((env.escapes, env.absorbed), (0, 0));
        assert!(env.get(PatchMeasure::Radiosity).is_none());
        assert_eq!(
            p[..n].iter().map(|r| r.escapes).sum::<u64>(),
            a.escapes,
            "{name}: the real rows' escapes are their pairs with the environment"
        );
        let whole = |m: Measure| a.estimate(m).unwrap().value;
        let parts = |q: PatchMeasure, weighted: bool| -> f64 {
            p.iter()
                .map(|r| r.get(q).unwrap().value * if weighted { r.area_fraction } else { 1.0 })
                .sum()
        };
        let checks = [
            (
                "H_s",
                parts(PatchMeasure::RowEntropy, true),
                whole(Measure::Entropy),
            ),
            (
                "H_s corrected",
                parts(PatchMeasure::RowEntropyCorrected, true),
                whole(Measure::EntropyCorrected),
            ),
            (
                "I_s",
                parts(PatchMeasure::MutualInformationTerm, false),
                whole(Measure::MutualInformation),
            ),
            (
                "I_s^c",
                parts(PatchMeasure::ContinuousTerm, false),
                whole(Measure::ContinuousMutualInformation),
            ),
            (
                "I_s^c - I_s",
                parts(PatchMeasure::LostInformation, false),
                whole(Measure::ContinuousMutualInformation) - whole(Measure::MutualInformation),
            ),
        ];
        for (what, parts, whole) in checks {
            assert!(
                close(parts, whole),
                "{name}: {what}: rows {parts}, scene {whole}"
            );
        }
        // Every row sampled, with a standard error.
        for (i, r) in p.iter().enumerate() {
            let e = r.get(PatchMeasure::ContinuousTerm).unwrap();
            assert!(
                r.sampled() && e.stderr.is_some_and(f64::is_finite),
                "{name} {i}: {r:?}"
            );
        }
        // The objects: the scene's, then the environment, adding up to the scene's readings.
        let o = &a.objects;
        assert_eq!(o.len(), scene.objects.len() + 1, "{name}");
        let last = o.last().unwrap();
        assert_eq!(
            (last.name.as_str(), last.patches, last.triangles),
            ("environment", 1, 0)
        );
        assert!(close(last.area, area) && close(last.area_fraction, env.area_fraction));
        assert_eq!(last.segments, Some(env.segments));
        assert!(close(o.iter().map(|x| x.area_fraction).sum(), 1.0));
        for (q, m) in [
            (PatchMeasure::RowEntropy, Measure::Entropy),
            (
                PatchMeasure::MutualInformationTerm,
                Measure::MutualInformation,
            ),
            (
                PatchMeasure::ContinuousTerm,
                Measure::ContinuousMutualInformation,
            ),
        ] {
            let sum: f64 = o.iter().map(|x| x.get(q).unwrap().value).sum();
            assert!(
                close(sum, whole(m)),
                "{name}: objects' {q:?} {sum} vs {}",
                whole(m)
            );
        }
    }
}

/// The enclosed scene's per-patch results, the environment's row among them, are bit-identical
/// whatever the thread count.
#[test]
fn enclosed_per_patch_results_do_not_depend_on_the_threads() {
    let scene = scenes::load("@cornell-open:2").unwrap();
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let a = pool.install(|| enclosed_run(&scene, 60_000, 3));
        (a.patches.unwrap(), a.objects)
    };
    let one = run(1);
    assert_eq!(one.0.len(), scene.patch_count() + 1);
    assert_eq!(one, run(2));
}

/// The mean of eq. (27)'s term `log2(A_T' cos_x cos_y / (pi d^2))` over the segments leaving a face of
/// the unit cube `[0, 1]^3` (outward normals) to the bounding sphere (centre `(1/2, 1/2, 1/2)`, radius
/// `R = sqrt(3) / 2`): x uniform on the face, the direction cosine-distributed, y where the line leaves
/// the sphere (cos_y = the half chord over R), `A_T' = a_total`. By quadrature on the face `z = 0`
/// (normal -z), whose value every face shares by symmetry: the cosine-weighted hemisphere as `cos_x =
/// s` with weight `2 s ds` and the azimuth uniform (midpoints); the face's corners lie on the sphere (d
/// -> 0 there), so each face coordinate is `u^2 (3 - 2 u)` of midpoints u (weight `6 u (1 - u)`, which
/// tames the logarithm at the corners), on 32 and 64 points, extrapolated (Richardson, the error going
/// as the square of the step: 0.290930 and 0.290648 give 0.290554 for the face's I_i^c).
fn cube_face_to_sphere_mean(a_total: f64) -> f64 {
    let mean = |nx: usize| {
        let r2: f64 = 0.75;
        let (ns, nphi) = (60, 16);
        let face: Vec<(f64, f64)> = (0..nx)
            .map(|k| {
                let u = (k as f64 + 0.5) / nx as f64;
                (u * u * (3.0 - 2.0 * u) - 0.5, 6.0 * u * (1.0 - u))
            })
            .collect();
        let mut sum = 0.0;
        for is in 0..ns {
            let s = (is as f64 + 0.5) / ns as f64;
            let sin = (1.0 - s * s).sqrt();
            for ip in 0..nphi {
                let phi = 2.0 * std::f64::consts::PI * (ip as f64 + 0.5) / nphi as f64;
                let (w0, w1) = (sin * phi.cos(), sin * phi.sin());
                for &(x, wx) in &face {
                    for &(y, wy) in &face {
                        let b = x * w0 + y * w1 + 0.5 * s;
                        let c = x * x + y * y + 0.25 - r2;
                        let half = (b * b - c).max(0.0).sqrt();
                        let t = -b + half;
                        let kernel = s * (half / r2.sqrt()) / (std::f64::consts::PI * t * t);
                        sum += 2.0 * s * wx * wy * (a_total * kernel).log2();
                    }
                }
            }
        }
        sum / (ns * nphi * nx * nx) as f64
    };
    let (coarse, fine) = (mean(32), mean(64));
    fine + (fine - coarse) / 3.0
}

/// Against quadrature: a unit cube in open space, enclosed, sees only the environment. Each face's
/// I_i^c is `a_i m`, m the mean term of its segments to the sphere ([`cube_face_to_sphere_mean`]); the
/// environment's ends are those escapes (a share `6 / (4 pi R^2)` of its segments, Crofton) and the
/// chords of the lines that miss the cube, whose term is `log2(A_T' / (4 pi R^2))`; so its I^c is
/// `a_env (6 m + (4 pi R^2 - 6) log2(A_T' / (4 pi R^2))) / (4 pi R^2)`, and the scene's is the sum.
/// Each reading within 4.5 of its standard errors (plus 1e-4 bits for the quadrature). (At 10^7 lines
/// the faces read 0.29057 +- 0.00004 on average, the quadrature 0.290554.)
#[test]
fn enclosed_cube_terms_agree_with_quadrature() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.obj");
    let cube = CUBE_AND_LID.split("o lid").next().unwrap();
    std::fs::write(&path, cube).unwrap();
    let scene = scenes::load(path.to_str().unwrap()).unwrap();
    assert_eq!(scene.patch_count(), 6);
    let a = enclosed_run(&scene, 2_000_000, 5);
    let sphere = 4.0 * std::f64::consts::PI * 0.75;
    let a_total = 6.0 + sphere;
    let m = cube_face_to_sphere_mean(a_total);
    let chord = (a_total / sphere).log2();
    let face = m / a_total;
    let env = (6.0 * m + (sphere - 6.0) * chord) / a_total;
    let p = a.patches.as_ref().unwrap();
    let check = |what: &str, e: scene_complexity::Estimate, expected: f64| {
        let se = e.stderr.unwrap();
        assert!(
            (e.value - expected).abs() < 4.5 * se + 1e-4,
            "{what}: {} +- {se} against {expected}",
            e.value
        );
    };
    for (i, r) in p[..6].iter().enumerate() {
        check(
            &format!("face {i}"),
            r.get(PatchMeasure::ContinuousTerm).unwrap(),
            face,
        );
    }
    check(
        "environment",
        p[6].get(PatchMeasure::ContinuousTerm).unwrap(),
        env,
    );
    check(
        "I_s^c",
        a.estimate(Measure::ContinuousMutualInformation).unwrap(),
        6.0 * face + env,
    );
}
