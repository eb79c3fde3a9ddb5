//! Reports of an analysis: a table for people, JSON and CSV for programs.

use std::fmt::Write;

use scene_complexity::measure::Estimate;
use scene_complexity::run::{
    Analysis, ErrorMethod, RadiosityEstimates, RadiosityOutcome, StopReason,
};
use scene_complexity::scene::Scene;
use scene_complexity::trace::Query;
use serde_json::{json, Value};

/// JSON schema version of `analyze --format json`.
pub const SCHEMA_VERSION: u32 = 1;

/// Facts about the run that the analysis itself does not hold.
pub struct RunInfo<'a> {
    pub scene: &'a Scene,
    pub tracer: &'static str,
    pub query: Query,
    pub threads: usize,
    /// Lines per side of a bundle, 0 for independent lines.
    pub bundle: u32,
}

/// One row of the report: JSON key, table label, paper reference, plug-in and bias-corrected estimates.
pub(super) struct Row {
    pub key: &'static str,
    pub label: &'static str,
    pub reference: &'static str,
    pub estimate: Option<Estimate>,
    pub corrected: Option<Estimate>,
}

/// The visibility measures in report order.
pub(super) fn measures(a: &Analysis) -> Vec<Row> {
    let v = &a.visibility;
    let row = |key, label, reference, estimate, corrected| Row {
        key,
        label,
        reference,
        estimate,
        corrected,
    };
    vec![
        row(
            "positional_entropy",
            "positional entropy H_p",
            "eq. 19",
            v.positional_entropy,
            None,
        ),
        row(
            "entropy",
            "visibility entropy H_s",
            "eq. 17",
            v.entropy,
            v.entropy_corrected,
        ),
        row(
            "joint_entropy",
            "joint entropy H(X,Y)",
            "eq. 7",
            v.joint_entropy,
            None,
        ),
        row(
            "mutual_information",
            "mutual information I_s",
            "eq. 21",
            v.mutual_information,
            v.mutual_information_corrected,
        ),
        row(
            "continuous_mutual_information",
            "continuous mutual information I_s^c",
            "eq. 27",
            v.continuous_mutual_information,
            None,
        ),
        row(
            "accuracy",
            "discretisation accuracy I_s/I_s^c",
            "sec. 3.3",
            v.accuracy,
            v.accuracy_corrected,
        ),
        row(
            "relative_error",
            "discretisation relative error",
            "sec. 3.3",
            v.relative_error,
            None,
        ),
        row(
            "mse_per_line",
            "form-factor E(MSE) per line",
            "eq. 22",
            v.mse_per_line,
            None,
        ),
    ]
}

fn estimate_json(e: Option<Estimate>) -> Value {
    match e {
        Some(e) => json!({"value": finite(e.value), "stderr": e.stderr.and_then(finite)}),
        None => Value::Null,
    }
}

fn row_json(r: &Row) -> Value {
    let mut v = estimate_json(r.estimate);
    if let (Value::Object(map), Some(c)) = (&mut v, r.corrected) {
        map.insert("corrected".into(), estimate_json(Some(c)));
    }
    v
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// The JSON document of `analyze --format json`.
pub fn json(run: &RunInfo, a: &Analysis) -> String {
    let mut visibility = serde_json::Map::new();
    for r in measures(a) {
        visibility.insert(r.key.into(), row_json(&r));
    }
    let doc = json!({
        "schema_version": SCHEMA_VERSION,
        "scx_version": env!("CARGO_PKG_VERSION"),
        "scene": run.scene.name,
        "patches": run.scene.patch_count(),
        "triangles": run.scene.triangles.len(),
        "area": run.scene.total_area_scene_units(),
        "tracer": run.tracer,
        "query": run.query.to_string(),
        "bundle": run.bundle,
        "lines": a.lines,
        "seed": a.seed,
        "threads": run.threads,
        "groups": a.groups,
        "seconds": a.seconds,
        "stop_reason": a.stop_reason.name(),
        "interrupted": a.stop_reason == StopReason::Interrupted,
        "estimator": a.estimator.name(),
        "errors": a.errors.name(),
        "hits": a.hits,
        "pairs": a.pairs,
        "escapes": a.escapes,
        "unpaired": a.unpaired,
        "escape_fraction": a.escape_fraction(),
        "degenerate_pairs": a.degenerate_pairs,
        "coincident_crossings": a.tally.counters.coincident_crossings,
        "environment_area": estimate_json(a.environment_area),
        "distinct_pairs": a.distinct_pairs,
        "unsampled_patches": a.unsampled.map(|u| u.0),
        "unsampled_area_fraction": a.unsampled.map(|u| u.1),
        "visibility": Value::Object(visibility),
        "radiosity": radiosity_json(&a.radiosity),
        "radiosity_skipped": skipped_reason(&a.radiosity).map_or(Value::Null, Value::from),
        "warnings": a.warnings.iter().map(|w| w.message.as_str()).collect::<Vec<_>>(),
    });
    let mut s = serde_json::to_string_pretty(&doc).expect("a JSON value always serialises");
    s.push('\n');
    s
}

/// The radiosity measures in report order.
fn radiosity_measures(r: &RadiosityEstimates) -> [Row; 3] {
    let row = |key, label, reference, estimate, corrected| Row {
        key,
        label,
        reference,
        estimate: Some(estimate),
        corrected,
    };
    [
        row(
            "positional_entropy",
            "radiosity positional entropy H_p",
            "eq. 33",
            r.positional_entropy,
            None,
        ),
        row(
            "entropy",
            "radiosity entropy H_s",
            "eq. 34",
            r.entropy,
            Some(r.entropy_corrected),
        ),
        row(
            "mutual_information",
            "radiosity mutual information I_s",
            "eq. 35",
            r.mutual_information,
            Some(r.mutual_information_corrected),
        ),
    ]
}

/// The `radiosity` object of the JSON report (`null` when skipped).
fn radiosity_json(outcome: &RadiosityOutcome) -> Value {
    let RadiosityOutcome::Computed(r) = outcome else {
        return Value::Null;
    };
    let mut m = serde_json::Map::new();
    for row in radiosity_measures(r) {
        m.insert(row.key.into(), row_json(&row));
    }
    m.insert("solver_residual".into(), json!(finite(r.solver_residual)));
    m.insert("solver_tolerance".into(), json!(r.solver_tolerance));
    m.insert("solver_iterations".into(), json!(r.solver_sweeps));
    m.insert("excluded_patches".into(), json!(r.excluded_patches));
    m.insert(
        "excluded_area_fraction".into(),
        json!(finite(r.excluded_area_fraction)),
    );
    Value::Object(m)
}

/// Why the radiosity measures were left out (`None` when computed).
fn skipped_reason(outcome: &RadiosityOutcome) -> Option<&str> {
    match outcome {
        RadiosityOutcome::Computed(_) => None,
        RadiosityOutcome::NotRequested => Some("not requested (--measures leaves radiosity out)"),
        RadiosityOutcome::Skipped(reason) => Some(reason),
    }
}

/// The radiosity lines of the table.
fn radiosity_table(s: &mut String, outcome: &RadiosityOutcome) {
    match outcome {
        RadiosityOutcome::NotRequested | RadiosityOutcome::Skipped(_) => {
            let reason = skipped_reason(outcome).unwrap_or_default();
            let _ = writeln!(s, "\nradiosity measures left out: {reason}");
        }
        RadiosityOutcome::Computed(r) => {
            let _ = writeln!(s);
            for row in radiosity_measures(r) {
                table_row(s, &row);
            }
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
    }
}

/// `measure,value,stderr` rows with a header.
pub fn csv(a: &Analysis) -> String {
    let mut s = String::from("measure,value,stderr,corrected,corrected_stderr\n");
    let field = |e: Option<Estimate>| {
        (
            e.map(|e| e.value.to_string()).unwrap_or_default(),
            e.and_then(|e| e.stderr)
                .map(|x| x.to_string())
                .unwrap_or_default(),
        )
    };
    for r in measures(a) {
        if r.estimate.is_some() {
            let ((v, se), (c, cse)) = (field(r.estimate), field(r.corrected));
            let _ = writeln!(s, "{},{v},{se},{c},{cse}", r.key);
        }
    }
    if let RadiosityOutcome::Computed(r) = &a.radiosity {
        for row in radiosity_measures(r) {
            let ((v, se), (c, cse)) = (field(row.estimate), field(row.corrected));
            let _ = writeln!(s, "radiosity_{},{v},{se},{c},{cse}", row.key);
        }
    }
    s
}

/// A readable table.
pub fn table(run: &RunInfo, a: &Analysis) -> String {
    let mut s = String::new();
    let scene = run.scene;
    let _ = writeln!(
        s,
        "scene    {}  ({} patches, {} triangles, area {:.6} scene units^2)",
        scene.name,
        scene.patch_count(),
        scene.triangles.len(),
        scene.total_area_scene_units()
    );
    let _ = writeln!(
        s,
        "lines    {}{}  seed {}  tracer {} ({})  threads {}  {:.3} s  ({:.2} M lines/s)",
        a.lines,
        if run.bundle > 0 {
            format!(" in bundles of {0} x {0}", run.bundle)
        } else {
            String::new()
        },
        a.seed,
        run.tracer,
        run.query,
        run.threads,
        a.seconds,
        a.lines as f64 / a.seconds.max(1e-12) / 1e6
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
    if let Some(env) = a.environment_area {
        let r = scene.normalization.scale;
        let _ = writeln!(
            s,
            "enclosed by the environment patch (--enclose): area {:.6} +- {} scene units^2 of the bounding \
             sphere's {:.6}",
            env.value,
            stderr_text(env),
            4.0 * std::f64::consts::PI * r * r
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "{:<36} {:>12} {:>10}  {:>12} {:>10}",
        "measure", "plug-in", "stderr", "corrected", "stderr"
    );
    for r in measures(a) {
        table_row(&mut s, &r);
    }
    if a.pairs == 0 && a.lines > 0 && a.environment_area.is_none() {
        let _ = writeln!(
            s,
            "visibility measures undefined: no line segment joined two patches, so there are no form \
             factors to measure (the warning says what the lines met)"
        );
    }
    radiosity_table(&mut s, &a.radiosity);
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
    let _ = writeln!(
        s,
        "\nstandard errors: {errors} (statistical error only).\n\
         corrected: row entropies by the {} estimator; the plug-in H_s and I_s are biased when rows are \
         undersampled.",
        a.estimator.name()
    );
    if run.bundle > 0 && a.visibility.mutual_information_corrected.is_some() {
        // Measured: 8 x 8 bundles moved the corrected I_s of @cube:30 by 7.7 standard errors (README).
        let _ = writeln!(
            s,
            "bundles: the corrections infer unseen patch pairs as if the lines were independent; the lines \
             of a bundle repeat their neighbours' pairs, which can shift the corrected values (the plug-in \
             values, I_s^c and E(MSE) stay unbiased)."
        );
    }
    if a.stop_reason != StopReason::Lines {
        let _ = writeln!(s, "stopped by: {}", stop_text(a.stop_reason));
    }
    s
}

/// One measure's line of the table: plug-in and corrected values with their standard errors.
fn table_row(s: &mut String, r: &Row) {
    if let Some(e) = r.estimate {
        let corrected = r
            .corrected
            .map(|c| format!("{:>12.6} {:>10}", c.value, stderr_text(c)))
            .unwrap_or_else(|| format!("{:>23}", ""));
        let _ = writeln!(
            s,
            "{:<36} {:>12.6} {:>10}  {corrected}  {}",
            r.label,
            e.value,
            stderr_text(e),
            r.reference
        );
    }
}

fn stderr_text(e: Estimate) -> String {
    e.stderr
        .map(|x| format!("{x:.6}"))
        .unwrap_or_else(|| "n/a".into())
}

fn stop_text(r: StopReason) -> &'static str {
    match r {
        StopReason::Lines => "all lines cast",
        StopReason::Seconds => "the time budget (--seconds)",
        StopReason::Target => "the precision target (--target-stderr) was reached",
        StopReason::Interrupted => {
            "interrupted (Ctrl-C): the report covers the lines gathered so far"
        }
    }
}
