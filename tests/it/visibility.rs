//! The visibility measures against independent truth: closed-form form factors of the unit cube, exact
//! positional entropy, closure and reciprocity, thread and scale invariance.

use crate::support;
use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::scenes;

use scene_complexity::internals::analysis::{analyze, Analysis};
use scene_complexity::internals::measure::channel::{for_each_form_factor, row_totals};
use scene_complexity::internals::run::Measures;
use scene_complexity::internals::run::{RunControl, RunSpec};
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::trace::Tracer;
use support::*;

const ALL: Measures = Measures::VISIBILITY;

fn run(scene: &Scene, tracer: &dyn Tracer, lines: u64, seed: u64) -> Analysis {
    let cfg = RunSpec {
        measures: ALL,
        ..RunSpec::new(lines, seed)
    };
    analyze(scene, tracer, &cfg, &RunControl::default()).expect("analysis runs")
}

/// Dense form-factor matrix of a run (small scenes only).
fn form_factors(scene: &Scene, a: &Analysis) -> Vec<Vec<f64>> {
    let n = scene.patch_count();
    let counts = a.tally.counts.as_ref().unwrap();
    let rows = row_totals(n, counts, &a.tally.escapes_by_patch.dense());
    let mut f = vec![vec![0.0; n]; n];
    for_each_form_factor(counts, &rows, |i, j, v| f[i][j] = v);
    f
}

/// The face of a `@cube:1` patch and whether two faces are opposite (same axis).
fn opposite(i: usize, j: usize) -> bool {
    i / 2 == j / 2 && i != j
}

#[test]
fn unit_cube_form_factors_and_mutual_information_match_closed_form() {
    let scene = scenes::load("@cube:1").unwrap();
    let f_par = ff_parallel_rectangles(1.0, 1.0, 1.0);
    let f_perp = ff_perpendicular_rectangles(1.0, 1.0, 1.0);
    // Closed-form I_s (eq. 21) with a_j = 1/6: sum_j F_1j log2(6 F_1j), the same for every row.
    let exact_is = f_par * (6.0 * f_par).log2() + 4.0 * f_perp * (6.0 * f_perp).log2();
    for tracer in all_tracers(&scene) {
        let a = run(&scene, tracer.as_ref(), 200_000, 11);
        let f = form_factors(&scene, &a);
        let rows = row_totals(
            6,
            a.tally.counts.as_ref().unwrap(),
            &a.tally.escapes_by_patch.dense(),
        );
        for i in 0..6 {
            assert_eq!(f[i][i], 0.0, "a planar patch cannot see itself");
            for j in (0..6).filter(|&j| j != i) {
                let exact = if opposite(i, j) { f_par } else { f_perp };
                let sigma = (exact * (1.0 - exact) / rows[i]).sqrt();
                assert!(
                    (f[i][j] - exact).abs() < 4.5 * sigma,
                    "{}: F[{i}][{j}] = {} vs closed form {exact} (sigma {sigma})",
                    tracer.name(),
                    f[i][j]
                );
            }
        }
        let is = a.estimate(Measure::MutualInformation).unwrap();
        let se = is.stderr.unwrap();
        assert!(se > 0.0 && se < 2e-3, "stderr {se}");
        assert!(
            (is.value - exact_is).abs() < 4.5 * se + 1e-4,
            "{}: I_s = {} +- {se}, closed form {exact_is}",
            tracer.name(),
            is.value
        );
        // And the continuous measure of the cube (paper Table 4: 1.6093), within its error.
        let cmi = a.estimate(Measure::ContinuousMutualInformation).unwrap();
        assert!(
            (cmi.value - 1.6093).abs() < 4.5 * cmi.stderr.unwrap() + 2e-3,
            "{cmi:?}"
        );
    }
}

#[test]
fn positional_entropy_is_exact() {
    for n in [1usize, 3, 7] {
        let scene = scenes::load(&format!("@cube:{n}")).unwrap();
        let tracer = &all_tracers(&scene)[0];
        let a = run(&scene, tracer.as_ref(), 5_000, 1);
        let hp = a.estimate(Measure::PositionalEntropy).unwrap();
        assert!((hp.value - ((6 * n * n) as f64).log2()).abs() < 1e-12);
        assert_eq!(hp.stderr, Some(0.0));
    }
}

#[test]
fn rows_sum_to_one_and_reciprocity_holds_in_a_closed_scene() {
    let scene = scenes::load("@cube:3").unwrap();
    for tracer in all_tracers(&scene) {
        let a = run(&scene, tracer.as_ref(), 100_000, 5);
        assert_eq!(a.escapes, 0, "a closed scene has no escapes");
        assert_eq!(a.unpaired, 0, "an empty enclosure has no unpaired segments");
        let f = form_factors(&scene, &a);
        let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
        for (i, row) in f.iter().enumerate() {
            let sum: f64 = row.iter().sum();
            assert!((sum - 1.0).abs() < 1e-12, "row {i} sums to {sum}");
        }
        // A_i F_ij = A_j F_ji: with F = N_ij / N_i this holds when every N_i / A_i agrees, which it does
        // up to the Poisson error of N_i.
        let rows = row_totals(scene.patch_count(), a.tally.counts.as_ref().unwrap(), &[]);
        let density: Vec<f64> = rows.iter().zip(&areas).map(|(n, a)| n / a).collect();
        let mean = density.iter().sum::<f64>() / density.len() as f64;
        for (i, d) in density.iter().enumerate() {
            assert!(
                (d - mean).abs() < 4.5 * mean / rows[i].sqrt(),
                "patch {i}: N_i/A_i = {d}, mean {mean}"
            );
        }
        for i in 0..f.len() {
            for j in 0..f.len() {
                let (x, y) = (areas[i] * f[i][j], areas[j] * f[j][i]);
                let n = a.tally.counts.as_ref().map(|_| f[i][j] * rows[i]).unwrap();
                if n > 100.0 {
                    assert!(
                        (x - y).abs() / x < 5.0 / n.sqrt(),
                        "A_{i} F_{i}{j} = {x} vs A_{j} F_{j}{i} = {y}"
                    );
                }
            }
        }
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let scene = scenes::load("@cube:4").unwrap();
    for tracer in all_tracers(&scene) {
        let go = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| run(&scene, tracer.as_ref(), 40_000, 3))
        };
        let (one, two) = (go(1), go(2));
        assert_eq!(count_entries(&one), count_entries(&two), "identical counts");
        assert_eq!(
            one.tally.counters.cmi_sum.value().to_bits(),
            two.tally.counters.cmi_sum.value().to_bits(),
            "identical f64 sums"
        );
        assert_eq!(
            one.estimate(Measure::MutualInformation)
                .unwrap()
                .value
                .to_bits(),
            two.estimate(Measure::MutualInformation)
                .unwrap()
                .value
                .to_bits()
        );
    }
}

#[test]
fn scaling_the_scene_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let results: Vec<(Analysis, f64)> = [1e-3, 1.0, 1e3]
        .iter()
        .map(|&s| {
            let path = dir.path().join(format!("room_{s}.obj"));
            std::fs::write(&path, room_with_box_obj(s)).unwrap();
            let scene = scenes::load(path.to_str().unwrap()).unwrap();
            let tracer = &all_tracers(&scene)[0];
            (
                run(&scene, tracer.as_ref(), 30_000, 9),
                scene.total_area_scene_units(),
            )
        })
        .collect();
    let (base, base_area) = &results[1];
    for (a, area) in &results {
        assert_eq!(a.pairs, base.pairs);
        assert_eq!(a.unpaired, base.unpaired);
        for (x, y) in [
            (
                a.estimate(Measure::MutualInformation),
                base.estimate(Measure::MutualInformation),
            ),
            (
                a.estimate(Measure::Entropy),
                base.estimate(Measure::Entropy),
            ),
            (
                a.estimate(Measure::ContinuousMutualInformation),
                base.estimate(Measure::ContinuousMutualInformation),
            ),
        ] {
            let (x, y) = (x.unwrap().value, y.unwrap().value);
            assert!((x - y).abs() <= 1e-9 * y.abs().max(1.0), "{x} vs {y}");
        }
        // Areas are reported in the scene's own units.
        let ratio = area / base_area;
        assert!(ratio > 0.5e-6 && ratio < 2e6);
    }
    assert!((results[0].1 / base_area - 1e-6).abs() < 1e-12);
    assert!((results[2].1 / base_area - 1e6).abs() < 1e-3);
}

/// The sphere is the independent channel (sec. 3.1.2): I_s^c = 0 for the true sphere, so on icospheres it
/// tends to 0 as the subdivision grows, and the discrete I_s stays below it (Proposition 2).
#[test]
fn sphere_mutual_information_tends_to_zero() {
    let mut previous_cmi = f64::INFINITY;
    let mut previous_is = f64::INFINITY;
    for level in 0..=3usize {
        let scene = scenes::load(&format!("@sphere:{level}")).unwrap();
        let tracer = all_tracers(&scene).pop().unwrap();
        let a = run(&scene, tracer.as_ref(), 400_000, 21);
        let cmi = a.estimate(Measure::ContinuousMutualInformation).unwrap();
        assert!(
            cmi.value > 0.0 && cmi.value < 0.45 * previous_cmi,
            "level {level}: I_s^c {cmi:?} after {previous_cmi}"
        );
        previous_cmi = cmi.value;
        if level <= 1 {
            // Rows are well sampled here (>= 2500 segments per patch), so the plug-in I_s is close to
            // its limit: below I_s^c, and falling with the subdivision.
            let is = a.estimate(Measure::MutualInformation).unwrap();
            assert!(
                is.value < cmi.value + 4.0 * cmi.stderr.unwrap(),
                "level {level}: {is:?} vs {cmi:?}"
            );
            assert!(is.value < previous_is, "level {level}: {is:?}");
            previous_is = is.value;
        }
    }
    assert!(previous_cmi < 0.02);
}

/// The closed-form form factors of `@cube:N` (used as truth for the bias corrections) are right: rows sum
/// to 1, reciprocity is exact, and N = 1 reproduces the unit-square values.
#[test]
fn closed_form_cube_form_factors_are_consistent() {
    let scene = scenes::load("@cube:4").unwrap();
    let rects: Vec<AxisRect> = (0..scene.patch_count())
        .map(|p| AxisRect::of_patch(&scene, p))
        .collect();
    let rows: Vec<Vec<f64>> = (0..scene.patch_count())
        .map(|i| cube_form_factor_row(&scene, &rects, i))
        .collect();
    for (i, row) in rows.iter().enumerate() {
        assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-10, "row {i}");
        for (j, f) in row.iter().enumerate() {
            assert!((f - rows[j][i]).abs() < 1e-12, "equal areas: F_ij = F_ji");
        }
    }
    let (_, is1) = cube_exact_measures(1);
    let (fp, fq) = (
        ff_parallel_rectangles(1.0, 1.0, 1.0),
        ff_perpendicular_rectangles(1.0, 1.0, 1.0),
    );
    assert!((is1 - (fp * (6.0 * fp).log2() + 4.0 * fq * (6.0 * fq).log2())).abs() < 1e-12);
}
