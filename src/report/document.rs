//! The JSON document of `scx analyze --format json` (and `scx merge`): every field of a run's report,
//! each reading with its unit, standard error, interval and verdict.

use serde_json::{json, Value};

use super::rows::{finite, positive_zero, rows, Row};
use crate::analysis::{
    Analysis, HalfRun, ObjectResult, RadiosityOutcome, Reliability, TargetOutcome, Verdict,
};
use crate::measure::catalogue::{Family, PatchMeasure, Unit};
use crate::measure::Estimate;
use crate::run::{Shard, StopReason, Tracing};
use crate::sample::bounds::sphere_lines_of_drawn;
use crate::sample::lines::LineSource;
use crate::scene::Scene;

/// JSON schema version of the report (2: units, reliability, sampling, target, command line, CPU; 3:
/// segments to back sides counted in their rows (`absorbed`), and I_s^c of an open scene on the footing
/// of the discrete measures, the lost segments counted; 4: warnings as data with stable codes, per-object
/// results).
pub const SCHEMA_VERSION: u32 = 4;

/// Facts about a run that its [`Analysis`] does not hold: the scene, how it was traced, and (for a
/// report of a process, such as the command line's) the process.
pub struct Context<'a> {
    /// The scene analysed.
    pub scene: &'a Scene,
    /// The tracer and query that cast the lines.
    pub tracing: Tracing,
    /// How long building the tracer's acceleration structure took, in seconds.
    pub build_seconds: f64,
    /// The shard, when the run was one.
    pub shard: Option<Shard>,
    /// The process that ran it: `None` leaves its fields (`command_line`, `cpu`, `threads`) out of the
    /// document, as for a report made inside another program.
    pub process: Option<Process>,
}

/// The fields of a report that belong to the process, not the run: they differ between two
/// processes that compute the same numbers.
pub struct Process {
    /// The command line as given.
    pub command_line: Vec<String>,
    /// The CPU's model name.
    pub cpu: String,
    /// The worker threads.
    pub threads: usize,
}

impl Process {
    /// This process, run with `threads` worker threads.
    pub fn current(threads: usize) -> Process {
        Process {
            command_line: std::env::args().collect(),
            cpu: cpu(),
            threads,
        }
    }
}

/// Lines per side of a bundle, 0 for independent lines.
pub fn bundle(a: &Analysis) -> u32 {
    match a.spec.source {
        LineSource::Independent => 0,
        LineSource::Bundles { grid } => grid,
    }
}

/// A reading's verdict as JSON (`null` for none: an exact reading or none at all), as `analyze`'s report
/// writes it.
pub fn reliability_json(r: Option<&Reliability>) -> Value {
    match r {
        None => Value::Null,
        Some(r) => json!({
            "verdict": r.verdict.name(),
            "estimated_bias": r.estimated_bias.and_then(finite),
            "lines_needed": r.lines_needed,
            "flags": r.flags,
        }),
    }
}

fn estimate_json(e: Estimate, unit: Unit, r: Option<&Reliability>, quantile: f64) -> Value {
    let interval = e
        .interval(quantile)
        .filter(|(lo, hi)| lo.is_finite() && hi.is_finite());
    json!({
        "value": finite(e.value),
        "stderr": e.stderr.and_then(finite),
        "interval_95": interval.map(|(lo, hi)| [positive_zero(lo), positive_zero(hi)]),
        "unit": unit.name(),
        "reliability": reliability_json(r),
    })
}

fn row_json(r: &Row, quantile: f64) -> Value {
    let Some(e) = r.estimate else {
        return Value::Null;
    };
    let mut v = estimate_json(e, r.unit, r.reliability, quantile);
    if let (Value::Object(map), Some(c)) = (&mut v, r.corrected) {
        map.insert(
            "corrected".into(),
            estimate_json(c, r.unit, r.corrected_reliability, quantile),
        );
    }
    v
}

/// The CPU's model name (Linux), else its architecture.
fn cpu() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, name)| name.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string())
}

fn sampling_json(a: &Analysis) -> Value {
    match &a.sampling {
        None => Value::Null,
        Some(s) => json!({
            "rows": s.sampling.rows,
            "sampled_rows": s.sampling.sampled_rows,
            "segments_per_row": finite(s.sampling.segments_per_row),
            "coverage": finite(s.sampling.coverage),
            "singleton_share": finite(s.sampling.singleton_share),
            "thin_rows": s.sampling.thin_rows,
            "lines_for_coverage_0_99": s.lines_for_coverage,
            "lines_for_coverage_0_99_from_half": match s.from_half {
                HalfRun::Lines(n) => Some(n),
                HalfRun::NotComputed | HalfRun::BeyondReach => None,
            },
            "lines_advice": s.advice.code(),
        }),
    }
}

fn target_json(t: &Option<TargetOutcome>) -> Value {
    match t {
        None => Value::Null,
        Some(t) => json!({
            "measure": t.measure.key(),
            "stderr_goal": t.stderr_goal,
            "stderr": t.stderr.and_then(finite),
            "verdict": t.verdict.map(Verdict::name),
            "met": t.met(),
        }),
    }
}

/// The JSON document of `scx analyze --format json` (docs/results.md describes its fields).
pub fn json(run: &Context, a: &Analysis) -> Value {
    let mut visibility = serde_json::Map::new();
    for r in rows(a, Family::Visibility) {
        visibility.insert(r.key.into(), row_json(&r, a.interval_quantile()));
    }
    let mut doc = json!({
        "schema_version": SCHEMA_VERSION,
        "scx_version": env!("CARGO_PKG_VERSION"),
        "command_line": run.process.as_ref().map(|p| p.command_line.clone()),
        "cpu": run.process.as_ref().map(|p| p.cpu.clone()),
        "unit": "bit",
        "scene": run.scene.name,
        "patches": run.scene.patch_count(),
        "triangles": run.scene.triangles.len(),
        "area": run.scene.total_area_scene_units(),
        "tracer": run.tracing.backend.name(),
        "query": run.tracing.query.to_string(),
        "bundle": bundle(a),
        "sampler": a.spec.sampler.name(),
        "lines_through": a.spec.bound.name(),
        "lines": a.lines,
        "sphere_lines": sphere_lines_of_drawn(run.scene, a.spec.bound, a.lines),
        "seed": a.spec.seed,
        "threads": run.process.as_ref().map(|p| p.threads),
        "groups": a.groups,
        "intervals": json!({
            "level": 0.95,
            "quantile": finite(a.interval_quantile()),
            "degrees_of_freedom": a.groups.saturating_sub(1),
        }),
        "seconds": a.seconds,
        "build_seconds": run.build_seconds,
        "stop_reason": a.stop_reason.name(),
        "interrupted": a.stop_reason == StopReason::Interrupted,
        "complete": a.is_complete(),
        "covered_lines": a.covered_lines().iter().map(|r| [r.start, r.end]).collect::<Vec<_>>(),
        "shard": run.shard.map(|s| json!({"index": s.index, "count": s.count})),
        "target": target_json(&a.target),
        "estimator": a.spec.estimator.name(),
        "errors": a.errors.name(),
        "hits": a.hits,
        "pairs": a.pairs,
        "escapes": a.escapes,
        "unpaired": a.unpaired,
        "escape_fraction": a.escape_fraction(),
        "absorbed": a.absorbed,
        "absorbed_fraction": a.absorbed_fraction(),
        "degenerate_pairs": a.degenerate_pairs,
        "coincident_crossings": a.tally.counters.coincident_crossings,
        "environment_area": a.environment_area.map(|e| json!({
            "value": finite(e.value), "stderr": e.stderr.and_then(finite), "unit": "scene units^2"
        })),
        "distinct_pairs": a.distinct_pairs,
        "unsampled_patches": a.unsampled.map(|u| u.0),
        "unsampled_area_fraction": a.unsampled.map(|u| u.1),
        "sampling": sampling_json(a),
        "visibility": Value::Object(visibility),
        "radiosity": radiosity_json(a),
        "radiosity_skipped": skipped_reason(&a.radiosity).map_or(Value::Null, Value::from),
        "objects": objects_json(a),
        "warnings": warnings_json(run.scene, a),
    });
    if run.process.is_none() {
        leave_out_process(&mut doc);
    }
    doc
}

/// Takes the process's fields out of a document, keeping the order of the others.
fn leave_out_process(doc: &mut Value) {
    if let Value::Object(map) = doc {
        for key in ["command_line", "cpu", "threads"] {
            map.shift_remove(key);
        }
    }
}

/// Each object's results: what it is, how its sides were met, its segments (when the pairs were
/// counted) and, with per-patch results, its value of each per-patch quantity with its standard error.
fn objects_json(a: &Analysis) -> Value {
    let object = |o: &ObjectResult| {
        let mut doc = json!({
            "name": o.name,
            "patches": o.patches,
            "triangles": o.triangles,
            "area": finite(o.area),
            "area_fraction": finite(o.area_fraction),
            "segments": o.segments,
            "escapes": o.escapes,
            "escape_fraction": o.escape_fraction(),
            "absorbed": o.absorbed,
            "front_sides_to_open_space": o.sides.front_open,
            "back_sides_seen_from_fronts": o.sides.back_seen,
            "back_sides_from_open_space": o.sides.back_from_open,
            "back_sides_to_open_space": o.sides.back_to_open,
        });
        let map = doc.as_object_mut().expect("an object");
        for q in PatchMeasure::ALL {
            let value = o.get(q).map_or(
                Value::Null,
                |e| json!({"value": finite(e.value), "stderr": e.stderr.and_then(finite)}),
            );
            map.insert(q.info().column.to_string(), value);
        }
        doc
    };
    Value::Array(a.objects.iter().map(object).collect())
}

/// The warnings as data: how the scene was read, then the run's; each with its stable code, the
/// objects it is about, the numbers it reports and its sentence.
fn warnings_json(scene: &Scene, a: &Analysis) -> Value {
    let entry =
        |from: &str, code: &str, message: &str, objects: &[String], numbers: &[(&str, f64)]| {
            let numbers: serde_json::Map<String, Value> = numbers
                .iter()
                .map(|&(k, v)| (k.to_string(), finite(v).map_or(Value::Null, Value::from)))
                .collect();
            json!({
                "code": code,
                "from": from,
                "objects": objects,
                "numbers": numbers,
                "message": message,
            })
        };
    let read = scene
        .warnings
        .iter()
        .map(|w| entry("scene", w.kind.code(), &w.message, &w.objects, &w.numbers));
    let run = a
        .warnings
        .iter()
        .map(|w| entry("run", w.kind.code(), &w.message, &w.objects, &w.numbers));
    Value::Array(read.chain(run).collect())
}

/// Why the radiosity measures were left out (`None` when computed).
pub fn skipped_reason(outcome: &RadiosityOutcome) -> Option<&str> {
    match outcome {
        RadiosityOutcome::Computed(_) => None,
        RadiosityOutcome::NotRequested => Some("not requested (--measures leaves radiosity out)"),
        RadiosityOutcome::Skipped(reason) => Some(reason),
    }
}

/// The `radiosity` object of the JSON report (`null` when skipped).
fn radiosity_json(a: &Analysis) -> Value {
    let RadiosityOutcome::Computed(r) = &a.radiosity else {
        return Value::Null;
    };
    let mut m = serde_json::Map::new();
    for row in rows(a, Family::Radiosity) {
        m.insert(row.key.into(), row_json(&row, a.interval_quantile()));
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
