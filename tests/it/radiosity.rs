//! The radiosity measures (paper sec. 4) against independent truth: the Table 8 identity, a unit cube
//! with one emitting face solved from closed-form form factors, rows of the transition matrix, and the
//! refinement strategies.

use crate::support;
use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::scenes;

use scene_complexity::internals::analysis::{analyze, RadiosityOutcome};
use scene_complexity::internals::measure::radiosity::{
    for_each_transition, solve, transformed_areas, FormFactors, PatchMaterials, SolveOptions,
};
use scene_complexity::internals::measure::shares::information_loss;
use scene_complexity::internals::run::{RunControl, RunSpec};
use scene_complexity::internals::scene::{self, Material, Scene};
use scene_complexity::internals::trace::{make_tracer, Backend, Query, Tracer};
use scene_complexity::refine::{oracle, refine, RefineConfig, Strategy};
use support::*;

fn config(lines: u64, seed: u64) -> RunSpec {
    RunSpec::new(lines, seed)
}

fn rust_tracer(scene: &Scene) -> Box<dyn Tracer> {
    make_tracer(Backend::Rust, scene, Query::Single).unwrap()
}

/// Gives patch k the material `mats[k % mats.len()]`.
fn set_materials(scene: &mut Scene, mats: &[(f64, f64)]) {
    scene.materials = mats
        .iter()
        .enumerate()
        .map(|(k, &(emission, reflectance))| Material::grey(format!("m{k}"), reflectance, emission))
        .collect();
    for (k, p) in scene.patches.iter_mut().enumerate() {
        p.material = (k % mats.len()) as u32;
    }
}

/// Paper sec. 4.2 and Table 8: with R_i + E_i = 1 everywhere, B = 1 solves the system, so 𝒜_i = A_i and
/// 𝓕 = F: the radiosity measures are the visibility measures, group by group (so the stderrs agree too).
#[test]
fn table_8_constant_radiosity_gives_the_visibility_measures() {
    for spec in ["@cube:3", "@cornell"] {
        let mut scene = scenes::load(spec).unwrap();
        set_materials(
            &mut scene,
            &[(0.3, 0.7), (0.0, 1.0), (0.55, 0.45), (1.0, 0.0)],
        );
        for tracer in all_tracers(&scene) {
            let a = analyze(
                &scene,
                tracer.as_ref(),
                &config(200_000, 4),
                &RunControl::default(),
            )
            .unwrap();
            let r = a.radiosity.clone();
            let RadiosityOutcome::Computed(r) = r else {
                panic!("{spec}: radiosity skipped: {r:?}")
            };
            let v = |m| a.estimate(m).unwrap();
            for (name, rad, vis) in [
                (
                    "H_p",
                    Measure::RadiosityPositionalEntropy,
                    Measure::PositionalEntropy,
                ),
                ("H_s", Measure::RadiosityEntropy, Measure::Entropy),
                (
                    "I_s",
                    Measure::RadiosityMutualInformation,
                    Measure::MutualInformation,
                ),
                (
                    "corrected H_s",
                    Measure::RadiosityEntropyCorrected,
                    Measure::EntropyCorrected,
                ),
                (
                    "corrected I_s",
                    Measure::RadiosityMutualInformationCorrected,
                    Measure::MutualInformationCorrected,
                ),
            ] {
                let (rad, vis) = (v(rad), v(vis));
                assert!(
                    (rad.value - vis.value).abs() < 1e-8,
                    "{spec} {}: radiosity {name} {} vs visibility {}",
                    tracer.name(),
                    rad.value,
                    vis.value
                );
                let (rs, vs) = (rad.stderr.unwrap(), vis.stderr.unwrap());
                assert!((rs - vs).abs() < 1e-7, "{spec} {name}: stderr {rs} vs {vs}");
            }
            assert_eq!(r.excluded_patches, 0);
        }
    }
}

/// The unit cube, face 0 (x = 0) emitting E = 1, every face R = 1/2. By symmetry three radiosities:
/// the emitter e, the opposite face o and the four sides s, with the closed-form form factors of unit
/// squares (parallel F_p, perpendicular F_q):
///   B_e = 1 + R (F_p B_o + 4 F_q B_s),  B_o = R (F_p B_e + 4 F_q B_s),
///   B_s = R (F_q B_e + F_q B_o + F_p B_s + 2 F_q B_s).
fn unit_cube_exact() -> ([f64; 6], [[f64; 6]; 6]) {
    let (fp, fq) = (
        ff_parallel_rectangles(1.0, 1.0, 1.0),
        ff_perpendicular_rectangles(1.0, 1.0, 1.0),
    );
    let r = 0.5;
    // Unknowns (e, o, s): (I - M) x = (1, 0, 0), solved by Cramer's rule.
    let m = [
        [1.0, -r * fp, -4.0 * r * fq],
        [-r * fp, 1.0, -4.0 * r * fq],
        [-r * fq, -r * fq, 1.0 - r * (fp + 2.0 * fq)],
    ];
    let det = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let d = det(m);
    let solve_col = |c: usize| {
        let mut a = m;
        for (row, rhs) in a.iter_mut().zip([1.0, 0.0, 0.0]) {
            row[c] = rhs;
        }
        det(a) / d
    };
    let (be, bo, bs) = (solve_col(0), solve_col(1), solve_col(2));
    // @cube:1 patches: x = 0, x = 1, y = 0, y = 1, z = 0, z = 1; i / 2 == j / 2 means opposite faces.
    let b = [be, bo, bs, bs, bs, bs];
    let mut f = [[0.0; 6]; 6];
    for (i, row) in f.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            if i != j {
                *x = if i / 2 == j / 2 { fp } else { fq };
            }
        }
    }
    (b, f)
}

/// Eqs. (30)-(35) written out as in the paper, with the incoming radiosity as (B_i - E_i) / R_i.
fn paper_measures(b: &[f64; 6], f: &[[f64; 6]; 6], e: &[f64; 6], r: f64) -> (f64, f64, f64) {
    let a = [1.0; 6];
    let calligraphic_a: Vec<f64> = (0..6).map(|i| a[i] * (b[i] - e[i]) / r * b[i]).collect();
    let total: f64 = calligraphic_a.iter().sum();
    let p: Vec<f64> = calligraphic_a.iter().map(|x| x / total).collect();
    let (mut hp, mut hs, mut is) = (0.0, 0.0, 0.0);
    for i in 0..6 {
        hp -= p[i] * p[i].log2();
        for j in 0..6 {
            let t = r * f[i][j] * b[j] / (b[i] - e[i]);
            if t > 0.0 {
                hs -= p[i] * t * t.log2();
                is += p[i] * t * (t / p[j]).log2();
            }
        }
    }
    (hp, hs, is)
}

#[test]
fn unit_cube_with_one_emitting_face_matches_the_hand_solution() {
    let (b, f) = unit_cube_exact();
    let e = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let mats = PatchMaterials {
        emission: e.to_vec(),
        reflectance: vec![0.5; 6],
    };
    // The solver on the exact form factors reproduces the hand solution.
    let entries: Vec<(usize, usize, f64)> = (0..6)
        .flat_map(|i| (0..6).map(move |j| (i, j)))
        .map(|(i, j)| (i, j, f[i][j]))
        .collect();
    let exact_ff = FormFactors::from_entries(6, &entries);
    let s = solve(&exact_ff, &mats, &SolveOptions::default()).unwrap();
    for (i, (x, exact)) in s.radiosity.iter().zip(b).enumerate() {
        assert!((x - exact).abs() < 1e-9, "B_{i}: {x} vs {exact}");
    }
    // And a Monte Carlo run lands on the closed-form radiosity measures within its standard errors.
    let (hp, hs, is) = paper_measures(&b, &f, &e, 0.5);
    let mut scene = scenes::load("@cube:1").unwrap();
    set_materials(
        &mut scene,
        &[
            (1.0, 0.5),
            (0.0, 0.5),
            (0.0, 0.5),
            (0.0, 0.5),
            (0.0, 0.5),
            (0.0, 0.5),
        ],
    );
    for tracer in all_tracers(&scene) {
        let analysis = analyze(
            &scene,
            tracer.as_ref(),
            &config(400_000, 9),
            &RunControl::default(),
        )
        .unwrap();
        let r = analysis.radiosity.clone();
        let RadiosityOutcome::Computed(_) = r else {
            panic!("skipped: {r:?}")
        };
        for (name, m, exact) in [
            ("H_p", Measure::RadiosityPositionalEntropy, hp),
            ("H_s", Measure::RadiosityEntropy, hs),
            ("I_s", Measure::RadiosityMutualInformation, is),
        ] {
            let est = analysis.estimate(m).unwrap();
            let se = est.stderr.unwrap();
            assert!(
                (est.value - exact).abs() < 4.5 * se + 2e-4,
                "{} {name}: {} +- {se}, closed form {exact}",
                tracer.name(),
                est.value
            );
        }
    }
}

#[test]
fn transition_rows_sum_to_one_in_the_cornell_box() {
    for spec in ["@cornell", "@cornell-open"] {
        let scene = scenes::load(spec).unwrap();
        let tracer = rust_tracer(&scene);
        let a = analyze(
            &scene,
            tracer.as_ref(),
            &config(30_000, 2),
            &RunControl::default(),
        )
        .unwrap();
        let ff = FormFactors::from_counts(
            scene.patch_count(),
            a.tally.counts.as_ref().unwrap(),
            &a.tally.escapes_by_patch.dense(),
        );
        let mats = PatchMaterials::of_scene(&scene).unwrap();
        let s = solve(&ff, &mats, &SolveOptions::default()).unwrap();
        let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
        let t = transformed_areas(&areas, &s);
        let mut sums = vec![0.0; scene.patch_count()];
        for_each_transition(&ff, &s, &t, |i, _, p| sums[i] += p);
        let mut rows = 0;
        for (i, sum) in sums.iter().enumerate() {
            if t[i] > 0.0 {
                rows += 1;
                assert!((sum - 1.0).abs() < 1e-12, "{spec} row {i}: {sum}");
            }
        }
        assert_eq!(rows, scene.patch_count(), "{spec}: every patch is lit");
    }
}

/// The information oracle's scores add up to the discretisation loss: with B = 1 (no light),
/// sum_i score_i / A_T = I_s^c - I_s (sec. 3.3). On the unit cube both sides are known: I_s from the
/// closed-form form factors and I_s^c = 1.6093 (paper Table 4, also checked in tests/visibility.rs).
#[test]
fn information_scores_add_up_to_the_discretisation_loss() {
    let scene = scenes::load("@cube:1").unwrap();
    let (fp, fq) = (
        ff_parallel_rectangles(1.0, 1.0, 1.0),
        ff_perpendicular_rectangles(1.0, 1.0, 1.0),
    );
    let exact_is = fp * (6.0 * fp).log2() + 4.0 * fq * (6.0 * fq).log2();
    let tracer = rust_tracer(&scene);
    let sample = oracle::sample_pairs(&scene, tracer.as_ref(), 400_000, 3).unwrap();
    let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
    let scores = information_loss(&areas, &sample, None);
    let loss = scores.iter().sum::<f64>() / scene.total_area();
    assert!(
        (loss - (1.6093 - exact_is)).abs() < 0.01,
        "loss {loss} vs {}",
        1.6093 - exact_is
    );
    // By symmetry every face loses the same.
    for s in &scores {
        assert!((s - scores[0]).abs() < 0.03 * scores[0].abs(), "{scores:?}");
    }
}

fn refine_with(spec: &str, strategy: Strategy, target: usize) -> (Scene, Scene) {
    let scene = scenes::load(spec).unwrap();
    let cfg = RefineConfig {
        strategy,
        target_patches: target,
        lines_per_round: 20_000,
        seed: 5,
        growth: 1.5,
        solve: SolveOptions::default(),
    };
    let out = refine(
        &scene,
        &|s| make_tracer(Backend::Rust, s, Query::Single),
        &cfg,
        &RunControl::default(),
        &mut |_| {},
    )
    .unwrap();
    (scene, out.scene)
}

/// Total area per (emission, reflectance) pair, in the scene's units.
fn area_by_material(s: &Scene) -> Vec<((u64, u64), f64)> {
    let mut v: Vec<((u64, u64), f64)> = Vec::new();
    let scale2 = s.normalization.scale.powi(2);
    for p in &s.patches {
        let m = &s.materials[p.material as usize];
        let key = (m.emission.to_bits(), m.reflectance.to_bits());
        match v.iter_mut().find(|(k, _)| *k == key) {
            Some((_, a)) => *a += p.area * scale2,
            None => v.push((key, p.area * scale2)),
        }
    }
    v.sort_by_key(|x| x.0);
    v
}

#[test]
fn every_strategy_reaches_the_target_and_keeps_areas_and_materials() {
    for strategy in [
        Strategy::Uniform,
        Strategy::Power,
        Strategy::Smoothness,
        Strategy::Information,
    ] {
        let (before, after) = refine_with("@cornell", strategy, 60);
        let n = after.patch_count();
        assert!((60..=62).contains(&n), "{strategy}: {n} patches");
        let (a, b) = (area_by_material(&before), area_by_material(&after));
        assert_eq!(a.len(), b.len());
        for ((ka, xa), (kb, xb)) in a.iter().zip(&b) {
            assert_eq!(ka, kb, "{strategy}: materials changed");
            assert!(
                (xa - xb).abs() < 1e-9 * xa,
                "{strategy}: area {xa} became {xb}"
            );
        }
        assert!(
            after.warnings.is_empty(),
            "{strategy}: {:?}",
            after.warnings
        );
    }
}

/// Power splits the light first: its A_i B_i dwarfs every wall's.
#[test]
fn power_refines_the_light_first() {
    let (before, after) = refine_with("@cornell", Strategy::Power, 32);
    let light_patches = |s: &Scene| {
        s.patches
            .iter()
            .filter(|p| s.materials[p.material as usize].emission > 0.0)
            .count()
    };
    assert_eq!(light_patches(&before), 1);
    assert_eq!(light_patches(&after), 4);
}

#[test]
fn refined_mesh_round_trips_through_obj_with_its_materials() {
    let (_, refined) = refine_with("@cornell", Strategy::Information, 45);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mesh.obj");
    scene::obj::write(&refined, &path).unwrap();
    let back = scenes::load(path.to_str().unwrap()).unwrap();
    assert_eq!(back.patch_count(), refined.patch_count());
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    for (p, q) in refined.patches.iter().zip(&back.patches) {
        let (m, n) = (
            &refined.materials[p.material as usize],
            &back.materials[q.material as usize],
        );
        assert_eq!((m.emission, m.reflectance), (n.emission, n.reflectance));
        assert!((p.area - q.area).abs() < 1e-12);
    }
}

#[test]
fn uniform_refinement_keeps_patch_sizes_even() {
    let (_, after) = refine_with("@cube", Strategy::Uniform, 96);
    // 6 faces split twice each: 96 equal squares.
    assert_eq!(after.patch_count(), 96);
    let a0 = after.patches[0].area;
    assert!(after.patches.iter().all(|p| (p.area - a0).abs() < 1e-12));
}
