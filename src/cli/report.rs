//! Reports of an analysis: a table for people, JSON and CSV for programs. Every reading carries its
//! unit, its standard error and its reliability verdict; a reading that breaks a bound of the theory is
//! marked, never printed bare.

use std::fmt::Write;

use clap::ValueEnum;

use scene_complexity::report::{
    bundle, positive_zero, rows, skipped_reason, Context, Process, Row,
};
use scene_complexity::VerdictRule;
use scene_complexity::{quantity_text, Scene};
use scene_complexity::{
    sphere_lines, sphere_lines_of_drawn, EntropyEstimator, ErrorMethod, LineBound, Sampler, Shard,
    StopReason, Tracing,
};
use scene_complexity::{
    Analysis, LinesAdvice, RadiosityOutcome, Reliability, SamplingReport, TargetOutcome, Verdict,
    COVERAGE_OK, COVERAGE_UNUSABLE, MIN_PAIRS,
};
use scene_complexity::{Estimate, Family, Measure, RunWarningKind};

use super::file_kind::{Kind, ReportFormat};
use super::table::{fixed, Align, Table};

/// Output formats of a report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// A readable table.
    Table,
    /// One JSON document.
    Json,
    /// CSV rows with a header.
    Csv,
}

impl ReportFormat for Format {
    fn kind(self) -> Kind {
        match self {
            Format::Table => Kind::Text,
            Format::Json => Kind::Json,
            Format::Csv => Kind::Csv,
        }
    }
}

/// The report of an analysis in `format`.
pub fn render(format: Format, run: &RunInfo, a: &Analysis) -> String {
    match format {
        Format::Table => table(run, a),
        Format::Json => json(run, a),
        Format::Csv => csv(run, a),
    }
}

/// Facts about the run that the analysis itself does not hold: the scene, how it ran.
pub struct RunInfo<'a> {
    pub scene: &'a Scene,
    pub tracing: Tracing,
    pub threads: usize,
    /// How long building the tracer's acceleration structure took, in seconds.
    pub build_seconds: f64,
    /// The shard, when the run was one.
    pub shard: Option<Shard>,
}

/// The JSON document of `analyze --format json`, with this process's fields.
pub fn json(run: &RunInfo, a: &Analysis) -> String {
    let context = Context {
        scene: run.scene,
        tracing: run.tracing,
        build_seconds: run.build_seconds,
        shard: run.shard,
        process: Some(Process::current(run.threads)),
    };
    let doc = scene_complexity::report::json(&context, a);
    let mut s = serde_json::to_string_pretty(&doc).expect("a JSON value always serialises");
    s.push('\n');
    s
}

/// One CSV row per reading, with the run's scene, lines, seed and tracer (and, last, the lines through
/// the bounding sphere they are worth and where they were drawn, as JSON's `sphere_lines` and
/// `lines_through`), so that files combine; a reading that breaks a bound of the theory says which in
/// its `flags` (or `corrected_flags`) cell, and an `undersampled` one its estimated bias and the lines
/// it would need, as the JSON report does.
pub fn csv(run: &RunInfo, a: &Analysis) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = [
        "scene",
        "lines",
        "seed",
        "tracer",
        "patches",
        "escape_fraction",
        "seconds",
        "family",
        "measure",
        "unit",
        "value",
        "stderr",
        "reliability",
        "corrected",
        "corrected_stderr",
        "corrected_reliability",
        "flags",
        "corrected_flags",
        "estimated_bias",
        "lines_needed",
        "corrected_estimated_bias",
        "corrected_lines_needed",
        "sphere_lines",
        "lines_through",
    ];
    w.write_record(header).expect("writing to memory");
    let num = |x: Option<f64>| x.map(|v| positive_zero(v).to_string()).unwrap_or_default();
    let verdict = |r: Option<&Reliability>| r.map_or("", |r| r.verdict.name()).to_string();
    // The bounds of the theory a reading breaks, as the table's `!` notes say them: one cell, the
    // sentences joined by "; " (the CSV writer quotes a cell that holds a comma).
    let flags = |r: Option<&Reliability>| r.map(|r| r.flags.join("; ")).unwrap_or_default();
    // What an `undersampled` reading's verdict rests on (JSON's `estimated_bias` and `lines_needed`):
    // empty where there is no estimate.
    let bias =
        |r: Option<&Reliability>| num(r.and_then(|r| r.estimated_bias).filter(|b| b.is_finite()));
    let needed = |r: Option<&Reliability>| {
        r.and_then(|r| r.lines_needed)
            .map(|n| n.to_string())
            .unwrap_or_default()
    };
    let mut families = vec![Family::Visibility];
    if let RadiosityOutcome::Computed(_) = &a.radiosity {
        families.push(Family::Radiosity);
    }
    let all = families
        .into_iter()
        .flat_map(|f| rows(a, f).into_iter().map(move |r| (f.name(), r)));
    for (family, r) in all {
        let Some(e) = r.estimate else { continue };
        w.write_record([
            run.scene.name.clone(),
            a.lines.to_string(),
            a.spec.seed.to_string(),
            run.tracing.backend.name().to_string(),
            run.scene.patch_count().to_string(),
            num(a.escape_fraction()),
            a.seconds.to_string(),
            family.to_string(),
            r.key.to_string(),
            r.unit.name().to_string(),
            num(Some(e.value)),
            num(e.stderr),
            verdict(r.reliability),
            num(r.corrected.map(|c| c.value)),
            num(r.corrected.and_then(|c| c.stderr)),
            verdict(r.corrected_reliability),
            flags(r.reliability),
            flags(r.corrected_reliability),
            bias(r.reliability),
            needed(r.reliability),
            bias(r.corrected_reliability),
            needed(r.corrected_reliability),
            sphere_lines_of_drawn(run.scene, a.spec.bound, a.lines).to_string(),
            a.spec.bound.name().to_string(),
        ])
        .expect("writing to memory");
    }
    String::from_utf8(w.into_inner().expect("writing to memory")).expect("CSV of UTF-8 text")
}

/// Whether a reading breaks a bound of the theory (its verdict names the bounds).
pub fn flagged(r: Option<&Reliability>) -> bool {
    r.is_some_and(|r| !r.flags.is_empty())
}

/// The mark after a reading that breaks a bound of the theory, ` !`, or as many blanks, so that marked
/// and unmarked values keep their digits aligned.
pub fn flag_mark(r: Option<&Reliability>) -> &'static str {
    if flagged(r) {
        " !"
    } else {
        "  "
    }
}

/// The note under a table that says which bound a marked reading breaks: `! ` and the verdict's
/// sentence, after `whose` (`1e4 lines, seed 1: `) when one table holds the readings of several runs.
pub fn flag_note(whose: &str, sentence: &str) -> String {
    format!("! {whose}{sentence}")
}

/// The text of a value with a mark when it breaks a bound of the theory (unmarked values keep the same
/// width, so that the digits stay aligned).
fn marked(e: Estimate, r: Option<&Reliability>) -> String {
    format!("{}{}", fixed(e.value), flag_mark(r))
}

fn stderr_text(e: Estimate) -> String {
    e.stderr.map_or_else(|| "n/a".into(), fixed)
}

fn verdict_text(e: Estimate, r: Option<&Reliability>) -> String {
    match r {
        Some(r) => r.verdict.name().into(),
        None if e.stderr == Some(0.0) => "exact".into(),
        None => String::new(),
    }
}

/// Adds the table rows of `rows`, collecting the flags of marked readings into `notes`.
fn add_rows(t: &mut Table, rows: &[Row], notes: &mut Vec<String>) {
    for r in rows {
        let Some(e) = r.estimate else { continue };
        let (c, cse, cverdict) = match r.corrected {
            Some(c) => (
                marked(c, r.corrected_reliability),
                stderr_text(c),
                verdict_text(c, r.corrected_reliability),
            ),
            None => Default::default(),
        };
        t.row(vec![
            r.label.into(),
            r.unit.name().into(),
            marked(e, r.reliability),
            stderr_text(e),
            verdict_text(e, r.reliability),
            c,
            cse,
            cverdict,
            r.reference.into(),
        ]);
        for rel in [r.reliability, r.corrected_reliability]
            .into_iter()
            .flatten()
        {
            for f in &rel.flags {
                let note = flag_note("", f);
                if !notes.contains(&note) {
                    notes.push(note);
                }
            }
        }
    }
}

/// A readable table.
pub fn table(run: &RunInfo, a: &Analysis) -> String {
    let mut s = String::new();
    let scene = run.scene;
    let _ = writeln!(
        s,
        "scene    {}  ({} patches, {} triangles, area {} scene units^2)",
        scene.name,
        scene.patch_count(),
        scene.triangles.len(),
        quantity_text(scene.total_area_scene_units())
    );
    let _ = writeln!(
        s,
        "lines    {}{}  seed {}  tracer {} ({})  threads {}  {:.3} s  ({:.2} M {}lines/s)",
        a.lines,
        match (bundle(a), a.spec.sampler) {
            (0, Sampler::Sobol) => " (sobol: randomised quasi-Monte Carlo)".to_string(),
            (0, Sampler::Independent) => String::new(),
            (grid, _) => format!(" in bundles of {grid} x {grid}"),
        } + &through_the_box(scene, a),
        a.spec.seed,
        run.tracing.backend.name(),
        run.tracing.query,
        run.threads,
        a.seconds,
        // Through a container, the rate of the sphere's lines they are worth: comparable across bounds.
        sphere_lines(scene, a.spec.bound, a.lines) / a.seconds.max(1e-12) / 1e6,
        match a.spec.bound {
            LineBound::Sphere => "",
            LineBound::Box | LineBound::Polytope => "sphere ",
        }
    );
    let back_seen: u64 = a.orientation.iter().map(|o| o.back_seen).sum();
    let _ = writeln!(
        s,
        "segments {} pairs, {} escapes, {} unpaired{}; {} hits{}",
        a.pairs,
        a.escapes,
        a.unpaired,
        if back_seen > 0 {
            format!(" ({back_seen} from a front side to a back side)")
        } else {
            String::new()
        },
        a.hits,
        a.distinct_pairs
            .map(|d| format!("; {d} distinct patch pairs"))
            .unwrap_or_default()
    );
    if let Some(smp) = &a.sampling {
        let _ = writeln!(
            s,
            "sampling {:.0} segments per row over {} rows; coverage {:.4}; {:.1}% of the outcomes seen once{}",
            smp.sampling.segments_per_row,
            smp.sampling.rows,
            smp.sampling.coverage,
            100.0 * smp.sampling.singleton_share,
            if a.environment_area.is_some() {
                " (the scene's own rows; the environment's row apart)"
            } else {
                ""
            }
        );
    }
    if let Some(line) = covers_line(run, a) {
        let _ = writeln!(s, "{line}");
    }
    if let Some(env) = a.environment_area {
        let r = scene.normalization.scale;
        let _ = writeln!(
            s,
            "enclosed by the environment patch (--enclose): area {} +- {} scene units^2 of the bounding \
             sphere's {}",
            quantity_text(env.value),
            env.stderr.map_or_else(|| "n/a".into(), quantity_text),
            quantity_text(4.0 * std::f64::consts::PI * r * r)
        );
    }
    let _ = writeln!(s);
    let mut t = Table::new(
        &[
            "measure",
            "unit",
            "plug-in",
            "stderr",
            "reliability",
            "corrected",
            "stderr",
            "reliability",
            "",
        ],
        &[
            Align::Left,
            Align::Left,
            Align::Right,
            Align::Right,
            Align::Left,
            Align::Right,
            Align::Right,
            Align::Left,
            Align::Left,
        ],
    );
    let mut notes = Vec::new();
    add_rows(&mut t, &rows(a, Family::Visibility), &mut notes);
    if let RadiosityOutcome::Computed(_) = &a.radiosity {
        t.separator();
        add_rows(&mut t, &rows(a, Family::Radiosity), &mut notes);
    }
    s += &t.render();
    for n in &notes {
        let _ = writeln!(s, "{n}");
    }
    if a.pairs == 0 && a.lines > 0 && a.environment_area.is_none() {
        let met = if a.hits == 0 {
            "no line met the scene: cast more lines"
        } else if a.warnings.iter().any(|w| w.kind == RunWarningKind::NoPairs) {
            "the warning says what the lines met"
        } else {
            "cast more lines"
        };
        let _ = writeln!(
            s,
            "visibility measures undefined: no line segment joined two patches, so there are no form \
             factors to measure ({met})"
        );
    }
    radiosity_lines(&mut s, &a.radiosity);
    let errors = match a.errors {
        ErrorMethod::Groups => format!(
            "spread of {} independent groups of lines / sqrt({})",
            a.groups, a.groups
        ),
        ErrorMethod::Jackknife => format!(
            "delete-a-group jackknife over {} groups of lines (I_s^c: spread of the groups / sqrt({}))",
            a.groups, a.groups
        ),
    };
    if a.groups < 2 {
        let _ = writeln!(
            s,
            "\nstandard errors: none: the lines fill fewer than two groups, and a standard error is the spread of two \
             or more (the warning says how many lines it takes)."
        );
    } else {
        let _ = writeln!(
            s,
            "\nstandard errors: {errors} (statistical error only).\n\
             95% intervals: value ± {:.3} stderr (Student's t, {} degrees of freedom).",
            a.interval_quantile(),
            a.groups - 1,
        );
    }
    if a.estimate(Measure::MutualInformationCorrected).is_some() {
        let _ = writeln!(
            s,
            "corrected: row entropies by the {} estimator, E(MSE) from each row's unbiased sum of \
             F_ij^2; the plug-in readings are biased when rows are undersampled.",
            a.spec.estimator.name()
        );
    }
    reliability_summary(&mut s, a);
    if bundle(a) > 0 && a.estimate(Measure::MutualInformationCorrected).is_some() {
        // Measured: 8 x 8 bundles moved the corrected I_s of @cube:30 by 7.7 standard errors (docs/performance.md, "Bundles").
        let _ = writeln!(
            s,
            "bundles: the corrections infer unseen patch pairs as if the lines were independent; the lines \
             of a bundle repeat their neighbours' pairs, which can shift the corrected values (I_s^c and the \
             form factors stay unbiased)."
        );
    }
    if a.spec.sampler == Sampler::Sobol && a.estimate(Measure::MutualInformationCorrected).is_some()
    {
        let _ = writeln!(
            s,
            "sobol: the estimator's corrections assume independent lines; the corrected readings are its \
             values less the delete-a-group jackknife's estimate of their bias, with the jackknife's \
             standard errors, or flagged where there is no jackknife (docs/sampling.md)."
        );
    } else if a.spec.sampler == Sampler::Sobol {
        let _ = writeln!(
            s,
            "sobol: randomised quasi-Monte Carlo lines, one scrambled Sobol' sequence per group: the groups \
             are independent, the lines within one are not (--sampler auto draws them for a run that \
             counts no patch pairs; --sampler independent for the paper's independent lines)."
        );
    }
    if a.spec.bound != LineBound::Sphere {
        let name = a.spec.bound.name();
        let worth = sphere_lines(scene, a.spec.bound, a.lines) / a.lines.max(1) as f64;
        let _ = writeln!(
            s,
            "lines through the {name}: each is worth {worth:.4} lines through the bounding sphere, the \
             unit of --lines, so {:.1}% as many are drawn{}{}",
            100.0 / worth,
            if a.estimate(Measure::MsePerLine).is_some() {
                " (E(MSE) is per line through the sphere, as in the paper)"
            } else {
                ""
            },
            if worth < 1.0 {
                format!(
                    "; on this scene the {name} is the larger container, so the sphere wastes fewer \
                     lines (--lines-through sphere)."
                )
            } else {
                ".".to_string()
            }
        );
    }
    if let Some(t) = &a.target {
        let _ = writeln!(s, "{}", target_text(t, a, scene));
    }
    if a.stop_reason != StopReason::Lines {
        let _ = writeln!(s, "stopped by: {}", stop_text(a.stop_reason));
    }
    s
}

/// The radiosity solver's line, or why the radiosity measures were left out.
fn radiosity_lines(s: &mut String, outcome: &RadiosityOutcome) {
    match outcome {
        RadiosityOutcome::Computed(r) => {
            let _ = writeln!(
                s,
                "radiosity: B = E + R F B solved by Gauss-Seidel to relative residual {:.1e} (tolerance {:.0e}) \
                 in {} sweeps; {} patch(es) ({:.4}% of the area) receive or send no light and leave the channel",
                r.solver_residual,
                r.solver_tolerance,
                r.solver_sweeps,
                r.excluded_patches,
                100.0 * r.excluded_area_fraction
            );
        }
        _ => {
            let reason = skipped_reason(outcome).unwrap_or_default();
            let _ = writeln!(s, "\nradiosity measures left out: {reason}");
        }
    }
}

/// One line on what the verdicts mean, when some reading is not ok.
fn reliability_summary(s: &mut String, a: &Analysis) {
    // The ratios inherit their I_s's verdict: they add nothing here.
    let worst = Measure::of_family(Family::Visibility)
        .filter(|m| !matches!(m.info().verdict, VerdictRule::RatioOf { .. }))
        .filter_map(|m| a.verdict(m))
        .max();
    if worst.is_some_and(|v| v != Verdict::Ok) {
        let needed = corrected_needs(a);
        let why = unusable_reasons(a);
        let jackknife = e_mse_by_jackknife(a);
        let _ = writeln!(
            s,
            "reliability: an `undersampled` reading is biased beyond what its interval allows, an `unusable` one \
             cannot be trusted{why}{needed}{jackknife} (docs/results.md, \"Reading the reliability verdict\")."
        );
    }
}

/// Why this run's `unusable` readings are so, for the reliability line: rows' coverage below 0.5 (the
/// discrete readings), too few visible pairs (the means such as I_s^c); empty when none is.
fn unusable_reasons(a: &Analysis) -> String {
    let unusable = |m: Measure| a.verdict(m) == Some(Verdict::Unusable);
    let mut reasons = Vec::new();
    let coverage_low = a
        .sampling
        .as_ref()
        .is_some_and(|smp| smp.sampling.coverage < COVERAGE_UNUSABLE);
    if coverage_low && unusable(Measure::Entropy) {
        reasons.push(format!("rows' coverage below {COVERAGE_UNUSABLE}"));
    }
    if a.groups < 2 {
        reasons.push("no standard error: fewer than two groups of lines".to_string());
    } else if unusable(Measure::ContinuousMutualInformation) {
        reasons.push(format!("I_s^c from fewer than {MIN_PAIRS} visible pairs"));
    }
    if reasons.is_empty() {
        String::new()
    } else {
        format!(" ({})", reasons.join("; "))
    }
}

/// When the corrected E(MSE) is `unusable` only for want of the jackknife's error: below a coverage of
/// 0.5 it is still unbiased while every row holds two segments, but batch means overstate its error
/// there, and `--errors jackknife` can make it `ok` (empty otherwise, and where the jackknife does not
/// apply: `--enclose`, Chao-Shen, fewer than two groups).
fn e_mse_by_jackknife(a: &Analysis) -> String {
    let unusable = a.verdict(Measure::MsePerLineCorrected) == Some(Verdict::Unusable);
    let thin_free = a.sampling.as_ref().is_some_and(|smp| {
        smp.sampling.coverage < COVERAGE_UNUSABLE && smp.sampling.thin_rows == 0
    });
    let jackknife_applies = a.spec.errors == ErrorMethod::Groups
        && !a.spec.enclose
        && a.spec.estimator != EntropyEstimator::ChaoShen
        && a.groups >= 2;
    if unusable && thin_free && jackknife_applies {
        "; the corrected E(MSE) is unbiased at this coverage (every row holds two segments), and \
         `--errors jackknife` gives it the error bar that can make it ok"
            .into()
    } else {
        String::new()
    }
}

/// What the corrected readings need to be ok, for the reliability line (empty when they are ok).
fn corrected_needs(a: &Analysis) -> String {
    let corrected = a.reliability.get(Measure::MutualInformationCorrected);
    let Some(r) = corrected.filter(|r| r.verdict != Verdict::Ok) else {
        return String::new();
    };
    let coverage_short = a
        .sampling
        .as_ref()
        .is_some_and(|smp| smp.sampling.coverage < COVERAGE_OK);
    let unreachable = a
        .sampling
        .as_ref()
        .is_some_and(|smp| smp.lines_for_coverage.is_none());
    match r.lines_needed {
        _ if coverage_short && unreachable => {
            "; a coverage of 0.99 is beyond reach of the extrapolation".into()
        }
        Some(n) => format!(
            "; the corrected readings need a coverage of 0.99 and a remaining bias (the jackknife's \
             estimate) within their standard error, at least about {n:.1e} lines ({})",
            extrapolation_note(a.sampling.as_ref().filter(|_| coverage_short), n)
        ),
        None => String::new(),
    }
}

/// What the advice of `n` lines is worth, from the coverage's extrapolation when the coverage is short.
fn extrapolation_note(sampling: Option<&SamplingReport>, n: u64) -> String {
    let Some(s) = sampling.filter(|s| s.advice == LinesAdvice::LowerBound) else {
        return "an extrapolation, good to about twice the lines cast".into();
    };
    // The advice may be the bias's rather than the coverage's: then name the coverage's.
    let what = if s.lines_for_coverage == Some(n) {
        "it"
    } else {
        "the coverage's"
    };
    match s.advice_growth() {
        Some(g) => format!(
            "an extrapolation that has not settled: {what} grew {g:.1}x from half the lines, so more \
             may be needed"
        ),
        None => "an extrapolation that has not settled: from half the lines a coverage of 0.99 was \
                 beyond the extrapolation's reach, so more may be needed"
            .into(),
    }
}

/// Whether a run ended at its budget (`--seconds`, a precision target, the floor of f32 tracing): its
/// lines are then the whole run, not a part of it, whatever the cap (`--lines`) would have allowed.
fn stopped_by_budget(reason: StopReason) -> bool {
    matches!(
        reason,
        StopReason::Seconds | StopReason::Target | StopReason::Floor
    )
}

/// The line that says which lines a report covers, when they are not simply the run's: a part of the
/// run (a shard, a partial merge, an interruption), or the batches a budget's stop left, when they are
/// not the first ones.
fn covers_line(run: &RunInfo, a: &Analysis) -> Option<String> {
    if a.is_complete() {
        return None;
    }
    let covered = a.covered_lines();
    let ranges: Vec<String> = covered
        .iter()
        .map(|r| format!("{}..{}", r.start, r.end))
        .collect();
    let ranges = if ranges.is_empty() {
        "none".to_string()
    } else {
        ranges.join(", ")
    };
    if stopped_by_budget(a.stop_reason) {
        // The first batches are simply the run's lines, which the `lines` line already counts.
        return (covered.len() > 1 || covered.first().is_some_and(|r| r.start > 0)).then(|| {
            format!(
                "covers   lines {ranges}: the batches finished when the run stopped (every figure is \
                 of these lines)"
            )
        });
    }
    // The ranges number the lines drawn; the run's size is also given as --lines gave it.
    let worth = match a.spec.bound {
        LineBound::Sphere => String::new(),
        bound => format!(
            " ({} through the sphere)",
            sphere_lines_of_drawn(run.scene, bound, a.plan.lines)
        ),
    };
    Some(format!(
        "covers   lines {ranges} of the run's {}{worth}{} (a partial run: every figure is of these lines \
         only)",
        a.plan.lines,
        run.shard
            .map(|s| format!(", shard {} of {}", s.index, s.count))
            .unwrap_or_default()
    ))
}

/// What became of a precision target, and when it was not met, when the run ended.
fn target_text(t: &TargetOutcome, a: &Analysis, scene: &Scene) -> String {
    let se = t.stderr.map_or_else(
        || "no standard error".into(),
        |e| format!("standard error {e:.3e}"),
    );
    let verdict = t.verdict.map_or("no verdict", Verdict::name);
    if t.met() {
        return format!(
            "precision target met: {} {se} <= {:.3e}, and the reading is {verdict}",
            t.measure.key(),
            t.stderr_goal
        );
    }
    format!(
        "precision target NOT met: {} {se} (goal {:.3e}) and reading {verdict} {}; a target counts \
         only when the standard error is small enough and the reading is ok",
        t.measure.key(),
        t.stderr_goal,
        unmet_when(a, scene)
    )
}

/// When a run whose precision target was not met ended, and what that leaves to do (its cap in lines
/// through the sphere, as `--lines` gave it).
fn unmet_when(a: &Analysis, scene: &Scene) -> String {
    match a.stop_reason {
        StopReason::Lines if a.is_complete() => format!(
            "when the run reached its cap (--lines) at {} lines (a larger --lines may meet it)",
            sphere_lines_of_drawn(scene, a.spec.bound, a.lines)
        ),
        StopReason::Lines => "on the lines this report covers".into(),
        StopReason::Seconds => "when the time budget (--seconds) ran out".into(),
        StopReason::Floor => "at the floor of f32 tracing (more lines would not make it ok)".into(),
        StopReason::Interrupted => "when the run was interrupted".into(),
        StopReason::Target => "when the run stopped".into(),
    }
}

fn stop_text(r: StopReason) -> &'static str {
    match r {
        StopReason::Lines => "all lines cast",
        StopReason::Seconds => "the time budget (--seconds)",
        StopReason::Target => "the precision target (--target-stderr) was met",
        StopReason::Floor => {
            "the precision target's reading reached the floor of f32 tracing (I_s^c's flag says \
             why): more lines would not make it ok"
        }
        StopReason::Interrupted => {
            "interrupted (Ctrl-C): the report covers the lines gathered so far"
        }
    }
}

/// For lines through the bounding box or polytope, what they are worth in lines through the sphere
/// (the unit of `--lines` and of the paper's runs).
fn through_the_box(scene: &Scene, a: &Analysis) -> String {
    match a.spec.bound {
        LineBound::Sphere => String::new(),
        bound => format!(
            " through the bounding {} (as many as {} through the sphere)",
            bound.name(),
            sphere_lines_of_drawn(scene, bound, a.lines)
        ),
    }
}
