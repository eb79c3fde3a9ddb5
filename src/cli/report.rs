//! Reports of an analysis: a table for people, JSON and CSV for programs.

use std::fmt::Write;

use scene_complexity::analysis::Analysis;
use scene_complexity::measure::Estimate;
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

/// The visibility measures in report order: (JSON key, table label, paper reference, estimate).
fn measures(a: &Analysis) -> Vec<(&'static str, &'static str, &'static str, Option<Estimate>)> {
    let v = &a.visibility;
    vec![
        (
            "positional_entropy",
            "positional entropy H_p",
            "eq. 19",
            v.positional_entropy,
        ),
        ("entropy", "visibility entropy H_s", "eq. 17", v.entropy),
        ("joint_entropy", "joint entropy H(X,Y)", "", v.joint_entropy),
        (
            "mutual_information",
            "mutual information I_s",
            "eq. 21",
            v.mutual_information,
        ),
        (
            "continuous_mutual_information",
            "continuous mutual information I_s^c",
            "eq. 27",
            v.continuous_mutual_information,
        ),
        (
            "accuracy",
            "discretisation accuracy I_s/I_s^c",
            "sec. 3.3",
            v.accuracy,
        ),
        (
            "relative_error",
            "discretisation relative error",
            "sec. 3.3",
            v.relative_error,
        ),
        (
            "mse_per_line",
            "form-factor E(MSE) per line",
            "eq. 22",
            v.mse_per_line,
        ),
    ]
}

/// Warnings a user must see about a run's numbers.
pub fn warnings(scene: &Scene, a: &Analysis) -> Vec<String> {
    let mut w = Vec::new();
    let segments = a.pairs + a.escapes;
    if a.escapes > 0 && segments > 0 {
        w.push(format!(
            "{}: the scene is open: {:.3}% of the segments leaving a front side escape the scene, so form-factor \
             rows sum to less than 1",
            scene.name,
            100.0 * a.escapes as f64 / segments as f64
        ));
    }
    if let Some((n, frac)) = a.unsampled {
        if n > 0 {
            w.push(format!(
                "{}: {n} patch(es) ({:.4}% of the area) were never left by a line: their rows are empty; cast more lines",
                scene.name,
                100.0 * frac
            ));
        }
    }
    if a.degenerate_pairs > 0 {
        w.push(format!(
            "{}: {} pair(s) joined coincident points (touching surfaces) and were left out of I_s^c",
            scene.name, a.degenerate_pairs
        ));
    }
    w
}

fn estimate_json(e: Option<Estimate>) -> Value {
    match e {
        Some(e) => json!({"value": finite(e.value), "stderr": e.stderr.and_then(finite)}),
        None => Value::Null,
    }
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// The JSON document of `analyze --format json`.
pub fn json(run: &RunInfo, a: &Analysis) -> String {
    let mut visibility = serde_json::Map::new();
    for (key, _, _, e) in measures(a) {
        visibility.insert(key.into(), estimate_json(e));
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
        "hits": a.hits,
        "pairs": a.pairs,
        "escapes": a.escapes,
        "unpaired": a.unpaired,
        "degenerate_pairs": a.degenerate_pairs,
        "distinct_pairs": a.distinct_pairs,
        "unsampled_patches": a.unsampled.map(|u| u.0),
        "unsampled_area_fraction": a.unsampled.map(|u| u.1),
        "visibility": Value::Object(visibility),
        "warnings": warnings(run.scene, a),
    });
    let mut s = serde_json::to_string_pretty(&doc).expect("a JSON value always serialises");
    s.push('\n');
    s
}

/// `measure,value,stderr` rows with a header.
pub fn csv(_run: &RunInfo, a: &Analysis) -> String {
    let mut s = String::from("measure,value,stderr\n");
    for (key, _, _, e) in measures(a) {
        if let Some(e) = e {
            let se = e.stderr.map(|x| x.to_string()).unwrap_or_default();
            let _ = writeln!(s, "{key},{},{se}", e.value);
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
    let _ = writeln!(
        s,
        "segments {} pairs, {} escapes, {} unpaired; {} hits{}",
        a.pairs,
        a.escapes,
        a.unpaired,
        a.hits,
        a.distinct_pairs
            .map(|d| format!("; {d} distinct patch pairs"))
            .unwrap_or_default()
    );
    let _ = writeln!(s);
    let _ = writeln!(s, "{:<38} {:>12} {:>12}", "measure", "value", "stderr");
    for (_, label, reference, e) in measures(a) {
        if let Some(e) = e {
            let se = e
                .stderr
                .map(|x| format!("{x:.6}"))
                .unwrap_or_else(|| "n/a".into());
            let _ = writeln!(s, "{label:<38} {:>12.6} {se:>12}  {reference}", e.value);
        }
    }
    let _ = writeln!(
        s,
        "\nstandard errors: spread of {} independent groups of lines / sqrt({}); statistical only (the plug-in \
         H_s and I_s are biased at few lines)",
        a.groups, a.groups
    );
    s
}
