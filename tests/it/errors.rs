//! Honest error bars: the standard errors scale as they should, cover the spread of independent runs, and
//! the bias-corrected I_s is closer to the exact value than the plug-in.

use crate::support;
use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::scenes;

use scene_complexity::internals::analysis::{analyze, Analysis};
use scene_complexity::internals::measure::Estimate;
use scene_complexity::internals::run::{RunControl, RunSpec};
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::trace::Tracer;
use support::{all_tracers, cube_exact_measures};

fn fastest_tracer(scene: &Scene) -> Box<dyn Tracer> {
    all_tracers(scene).pop().unwrap()
}

fn run(scene: &Scene, tracer: &dyn Tracer, lines: u64, seed: u64) -> Analysis {
    analyze(
        scene,
        tracer,
        &RunSpec::new(lines, seed),
        &RunControl::default(),
    )
    .unwrap()
}

fn cmi(a: &Analysis) -> Estimate {
    a.estimate(Measure::ContinuousMutualInformation).unwrap()
}

#[test]
fn stderr_shrinks_like_one_over_sqrt_lines() {
    let scene = scenes::load("@cube:2").unwrap();
    let tracer = fastest_tracer(&scene);
    // Average over a few seeds: one stderr from 16 groups is itself uncertain by ~18%.
    let mean_se = |lines| {
        (1..=4)
            .map(|s| cmi(&run(&scene, tracer.as_ref(), lines, s)).stderr.unwrap())
            .sum::<f64>()
            / 4.0
    };
    let ratio = mean_se(10_000) / mean_se(1_000_000);
    assert!(
        (7.5..13.0).contains(&ratio),
        "stderr ratio over a 100x change in lines: {ratio} (expected 10)"
    );
}

#[test]
fn error_bars_cover_the_spread_of_independent_runs() {
    let scene = scenes::load("@cube:2").unwrap();
    let tracer = fastest_tracer(&scene);
    let runs: Vec<Estimate> = (100..140)
        .map(|seed| cmi(&run(&scene, tracer.as_ref(), 20_000, seed)))
        .collect();
    let n = runs.len() as f64;
    let mean = runs.iter().map(|e| e.value).sum::<f64>() / n;
    let sd = (runs.iter().map(|e| (e.value - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let mean_se = runs.iter().map(|e| e.stderr.unwrap()).sum::<f64>() / n;
    // The reported stderr estimates the run-to-run spread.
    assert!(
        (0.7..1.4).contains(&(sd / mean_se)),
        "spread {sd} vs mean stderr {mean_se}"
    );
    let within = |k: f64| {
        runs.iter()
            .filter(|e| (e.value - mean).abs() < k * e.stderr.unwrap())
            .count() as f64
            / n
    };
    // Student t with 15 degrees of freedom: ~67% within 1 stderr, ~94% within 2.
    assert!(
        (0.4..0.9).contains(&within(1.0)),
        "within 1 stderr: {}",
        within(1.0)
    );
    assert!(
        (0.8..=1.0).contains(&within(2.0)) && within(1.0) < 1.0,
        "within 2 stderr: {}",
        within(2.0)
    );
}

#[test]
fn corrected_mutual_information_beats_the_plug_in_on_a_small_cube() {
    let (_, exact) = cube_exact_measures(4);
    let scene = scenes::load("@cube:4").unwrap();
    let tracer = fastest_tracer(&scene);
    let a = run(&scene, tracer.as_ref(), 100_000, 7);
    let plug = a.estimate(Measure::MutualInformation).unwrap().value;
    let corrected = a
        .estimate(Measure::MutualInformationCorrected)
        .unwrap()
        .value;
    assert!(
        (corrected - exact).abs() < (plug - exact).abs(),
        "exact {exact}: corrected {corrected} vs plug-in {plug}"
    );
    // The plug-in is biased upwards (unseen patches count as impossible), the correction pulls it down.
    assert!(plug > exact && corrected < plug);
}
