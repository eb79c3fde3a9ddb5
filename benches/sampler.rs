//! Do randomised quasi-Monte Carlo lines pay? For each scene, runs the whole analysis (`scx analyze`'s
//! defaults: every measure, 16 groups for independent lines and 8 for Sobol' ones, Embree single lines,
//! 2 threads) with independent lines and with
//! the Sobol' sampler, each through the bounding sphere and through the bounding box, and the Sobol'
//! sampler through the bounding polytope (`--lines-through`), over the same seeds (seed outermost, so
//! that a drift of the machine's speed falls on every series alike), and prints per measure and series:
//!
//! * the spread (sample standard deviation) of the estimates over the seeds at equal lines (lines
//!   through the sphere, as `--lines` counts them: through the box fewer are drawn, worth as many), with
//!   its own relative uncertainty 1/sqrt(2(n-1)): the direct measure of the error;
//! * the rms reported standard error, and spread / rms se (near 1 when the error bars are honest);
//! * the mean, and with an exact value (the calibration scenes: `@cube:N`, the regular solids) its
//!   distance to it in standard errors of the mean, (mean - exact) / (spread / sqrt(n)): a bias shows
//!   here, however small the spread;
//! * the spread ratio independent / this series, at equal lines and (`same cpu`, scaling the spreads as
//!   1/sqrt(CPU time)) at equal CPU time, and the CPU-time ratio this / independent (CPU time of all
//!   threads: robust when the machine is shared, but the runs of both samplers are interleaved, not
//!   alone on it).
//!
//! For `@cube:N` it also gives the form factors' error: the relative Frobenius norm
//! `|F - F_exact| / |F_exact|` against the closed forms, per run, its mean over the seeds.
//!
//! `cargo bench --bench sampler [-- SCENE... [LINES]]`, default `@cube:30 @cubes512` and 10^6 lines;
//! `SCX_SAMPLER_SEEDS=N` seeds (default 30); `SCX_SAMPLER_MEASURES=continuous` runs I_s^c alone
//! (`scx analyze --measures continuous`: no pair is counted, the runs `--sampler auto` draws with Sobol'
//! lines); `SCX_SAMPLER_GROUPS=G` gives every series G standard-error groups (`scx analyze --groups`).

mod common;

use std::time::Instant;

use scene_complexity::calibrate::rectangles::{form_factor_row, AxisRect};
use scene_complexity::calibrate::{truth, Basis, CalibrationScene};
use scene_complexity::internals::analysis::{analyze, Analysis};
use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::run::{LinesThrough, Measures, RunControl, RunSpec};
use scene_complexity::internals::sample::bounds::LineBound;
use scene_complexity::internals::sample::lines::Sampler;
use scene_complexity::internals::scene::Scene;
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::{make_tracer, Backend, Query};
use scene_complexity::report::FormFactors;

/// The readings followed: name and measure. With the Sobol' sampler the readings on corrected rows
/// are the delete-a-group jackknife's debiased ones (see `Spread::debiased`).
const FOLLOWED: [(&str, Measure); 7] = [
    ("I_s^c", Measure::ContinuousMutualInformation),
    ("H_s", Measure::Entropy),
    ("H_s corr.", Measure::EntropyCorrected),
    ("I_s", Measure::MutualInformation),
    ("I_s corr.", Measure::MutualInformationCorrected),
    ("E(MSE)", Measure::MsePerLine),
    ("I_s/I_s^c c", Measure::AccuracyCorrected),
];

/// The series compared: a label, the sampler and where the lines are drawn (`--lines-through`).
const SAMPLERS: [(&str, Sampler, LineBound); 5] = [
    ("independent", Sampler::Independent, LineBound::Sphere),
    ("sobol", Sampler::Sobol, LineBound::Sphere),
    ("indep. box", Sampler::Independent, LineBound::Box),
    ("sobol box", Sampler::Sobol, LineBound::Box),
    ("sobol poly.", Sampler::Sobol, LineBound::Polytope),
];

fn main() -> anyhow::Result<()> {
    let (specs, lines) = common::scenes_and_lines(1e6)?;
    let seeds: u64 = std::env::var("SCX_SAMPLER_SEEDS").map_or(Ok(30), |s| s.parse())?;
    let measures = match std::env::var("SCX_SAMPLER_MEASURES").as_deref() {
        Ok("continuous") => Measures {
            discrete: false,
            continuous: true,
            radiosity: false,
        },
        Ok(other) => anyhow::bail!("SCX_SAMPLER_MEASURES: `{other}` is not `continuous`"),
        Err(_) => Measures::ALL,
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build()?;
    let groups: Option<usize> = match std::env::var("SCX_SAMPLER_GROUPS") {
        Ok(g) => Some(g.parse()?),
        Err(_) => None,
    };
    let group_text = groups.map_or("16 groups (8 for sobol)".to_string(), |g| {
        format!("{g} groups")
    });
    println!("{lines} lines per run (through the sphere, or worth as many through the box), 2 threads, Embree single lines, {group_text}, {seeds} seeds per sampler");
    for spec in &specs {
        pool.install(|| compare(spec, lines, seeds, measures, groups))?;
    }
    Ok(())
}

/// What the runs of one sampler gave.
#[derive(Default)]
struct Runs {
    /// values[measure][seed], and the standard errors.
    values: Vec<Vec<f64>>,
    stderrs: Vec<Vec<f64>>,
    cpu: f64,
    wall: f64,
    /// The relative Frobenius error of F per run (with exact form factors).
    f_errors: Vec<f64>,
}

fn compare(
    spec: &str,
    lines: u64,
    seeds: u64,
    measures: Measures,
    groups: Option<usize>,
) -> anyhow::Result<()> {
    let scene = scenes::load(spec)?;
    let tracer = make_tracer(Backend::Embree, &scene, Query::Single)
        .or_else(|_| make_tracer(Backend::Rust, &scene, Query::Single))?;
    let exact = exact_values(spec);
    let exact_f = match CalibrationScene::parse(spec) {
        Ok(CalibrationScene::Cube(_)) => exact_form_factors(&scene),
        _ => None,
    };
    let mut runs: Vec<Runs> = SAMPLERS
        .iter()
        .map(|_| Runs {
            values: vec![Vec::new(); FOLLOWED.len()],
            stderrs: vec![Vec::new(); FOLLOWED.len()],
            ..Runs::default()
        })
        .collect();
    for seed in 1..=seeds {
        for (s, &(_, sampler, bound)) in SAMPLERS.iter().enumerate() {
            // `lines` through the sphere, as `scx analyze --lines` counts them: through the box, as many
            // as are worth that many.
            let cfg = RunSpec {
                sampler,
                measures,
                ..RunSpec::new(lines, seed)
            }
            .grouped(groups)
            .through(&scene, LinesThrough::Bound(bound));
            let (w0, c0) = (Instant::now(), common::cpu_seconds());
            let a = analyze(&scene, tracer.as_ref(), &cfg, &RunControl::default())?;
            let r = &mut runs[s];
            r.wall += w0.elapsed().as_secs_f64();
            r.cpu += common::cpu_seconds() - c0;
            for (m, &(_, measure)) in FOLLOWED.iter().enumerate() {
                let e = a.estimate(measure);
                r.values[m].push(e.map_or(f64::NAN, |e| e.value));
                r.stderrs[m].push(e.and_then(|e| e.stderr).unwrap_or(f64::NAN));
            }
            if let Some(exact) = &exact_f {
                r.f_errors.push(frobenius_error(&a, &scene, exact));
            }
        }
    }
    print_table(spec, &runs, &exact, seeds);
    Ok(())
}

/// The exact values (closed scene basis) of a calibration scene, by followed measure.
fn exact_values(spec: &str) -> Vec<Option<f64>> {
    let truth = CalibrationScene::parse(spec)
        .ok()
        .and_then(|s| truth(&s).ok());
    FOLLOWED
        .iter()
        .map(|&(_, m)| {
            let t = truth.as_ref()?;
            t.value(m, Basis::Closed)
                .or_else(|| t.value(m, Basis::PerArea))
        })
        .collect()
}

/// The exact form factors of `@cube:N` (up to 2000 patches; every patch an axis-aligned rectangle of
/// the box, which no other patch hides): rows of F.
fn exact_form_factors(scene: &Scene) -> Option<Vec<Vec<f64>>> {
    let n = scene.patch_count();
    if n > 2000 {
        return None;
    }
    let rects: Option<Vec<AxisRect>> = (0..n).map(|p| AxisRect::of_patch(scene, p)).collect();
    let rects = rects?;
    Some((0..n).map(|i| form_factor_row(&rects, i)).collect())
}

/// `|F - F_exact|_F / |F_exact|_F` for a run's form factors.
fn frobenius_error(a: &Analysis, scene: &Scene, exact: &[Vec<f64>]) -> f64 {
    let Some(ff) = FormFactors::of(a, scene.patch_count()) else {
        return f64::NAN;
    };
    let mut estimated = vec![vec![0.0; exact.len()]; exact.len()];
    for (k, &(i, j, _)) in ff.entries.iter().enumerate() {
        estimated[i as usize][j as usize] = ff.value(k).0;
    }
    let (mut diff, mut norm) = (0.0, 0.0);
    for (row, exact_row) in estimated.iter().zip(exact) {
        for (x, y) in row.iter().zip(exact_row) {
            diff += (x - y) * (x - y);
            norm += y * y;
        }
    }
    (diff / norm).sqrt()
}

fn print_table(spec: &str, runs: &[Runs], exact: &[Option<f64>], seeds: u64) {
    let n = seeds as f64;
    println!(
        "{:<12} {:<11} {:<11} {:>7} {:>15} {:>10} {:>6} {:>13} {:>8} {:>7} {:>8}",
        "scene",
        "measure",
        "sampler",
        "cpu s",
        "spread (+-)",
        "rms se",
        "sp/se",
        "mean",
        "z(mean)",
        "ind/this",
        "same cpu"
    );
    for (m, (name, ..)) in FOLLOWED.iter().enumerate() {
        // A measure the runs did not compute (`SCX_SAMPLER_MEASURES`) has no row.
        if runs.iter().all(|r| r.values[m].iter().all(|v| v.is_nan())) {
            continue;
        }
        let base = sample_sd(&runs[0].values[m]);
        for (s, (label, ..)) in SAMPLERS.iter().enumerate() {
            let r = &runs[s];
            let v = &r.values[m];
            let sd = sample_sd(v);
            let rms = (r.stderrs[m].iter().map(|s| s * s).sum::<f64>() / n).sqrt();
            let mean = v.iter().sum::<f64>() / n;
            let z = exact[m].map_or(f64::NAN, |x| (mean - x) / (sd / n.sqrt()));
            println!(
                "{spec:<12} {name:<11} {:<11} {:>7.3} {:>10.3e} {:>3.0}% {rms:>10.3e} {:>6.2} {mean:>13.7} {z:>+8.1} {:>7.2} {:>8.2}",
                label,
                r.cpu / n,
                sd,
                100.0 / (2.0 * (n - 1.0)).sqrt(),
                sd / rms,
                base / sd,
                base / sd * (runs[0].cpu / r.cpu).sqrt(),
            );
        }
    }
    for (s, (label, ..)) in SAMPLERS.iter().enumerate() {
        let r = &runs[s];
        let f = if r.f_errors.is_empty() {
            String::new()
        } else {
            let mean = r.f_errors.iter().sum::<f64>() / r.f_errors.len() as f64;
            format!(", F error (relative Frobenius) {:.4}%", 100.0 * mean)
        };
        println!(
            "{spec:<12} {:<11} cpu {:.3} s/run ({:.2}x independent), wall {:.3} s/run ({:.2}x){f}",
            label,
            r.cpu / n,
            r.cpu / runs[0].cpu,
            r.wall / n,
            r.wall / runs[0].wall,
        );
    }
}

fn sample_sd(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}
