//! What every fuzz target does with a scene that loaded: trace it a little and check its measures.
#![allow(dead_code)]

use scene_complexity::internals::scene::{ReadPolicy, Scene};
use scene_complexity::internals::trace::{make_tracer, Backend, Query};
use scene_complexity::{analyze, Measure, RunControl, RunSpec};

/// The reading policy of the fuzz targets: references inside a folder that does not exist (so no input
/// reads a file), and a small size limit (so that no input may ask for much memory and slow the run).
pub fn policy() -> ReadPolicy {
    ReadPolicy {
        max_bytes: 1 << 20,
        ..ReadPolicy::default()
    }
}

/// The folder the targets' scenes name their files in: one that does not exist.
pub const NO_FOLDER: &str = "/nonexistent-scx-fuzz-folder";

/// Traces a loaded scene with 256 lines (pure-Rust tracer, with and without `--enclose`): the measures
/// must come out, and none may be NaN.
pub fn trace_a_little(scene: &Scene) {
    if scene.triangles.len() > 5000 {
        return;
    }
    let tracer = make_tracer(Backend::Rust, scene, Query::Single).expect("the Rust tracer builds");
    let cfg = RunSpec {
        groups: 2,
        enclose: scene.triangles.len() % 2 == 0,
        ..RunSpec::new(256, 1)
    };
    let a = match analyze(scene, tracer.as_ref(), &cfg, &RunControl::default()) {
        Ok(a) => a,
        // Materials outside the physical range are refused with a message, as they should be.
        Err(e) if e.is_bad_input() => return,
        Err(e) => panic!("tracing a loaded scene failed: {e}"),
    };
    for e in [
        Measure::PositionalEntropy,
        Measure::Entropy,
        Measure::MutualInformation,
        Measure::ContinuousMutualInformation,
    ]
    .into_iter()
    .filter_map(|m| a.estimate(m))
    {
        assert!(!e.value.is_nan(), "NaN measure on {}", scene.name);
    }
}
