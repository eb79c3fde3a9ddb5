//! Fuzzes the OBJ + MTL loader and the built-in scene names, then traces the scene a little: whatever the
//! input, scx must load it or refuse it with an error, never panic, and a loaded scene must trace to
//! finite measures.
//!
//! Input: OBJ text, optionally followed by `\n#MTL\n` and the text of the MTL library that any `mtllib`
//! resolves to. An input starting with `@` is a built-in scene name instead.
#![no_main]

use libfuzzer_sys::fuzz_target;
use scene_complexity::internals::measure::Measure;
use scene_complexity::internals::run::{RunSpec, RunControl};
use scene_complexity::internals::analysis::analyze;
use scene_complexity::internals::scene::{obj, Scene};
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::{make_tracer, Backend, Query};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let scene = if let Some(spec) = text.strip_prefix('@') {
        // Built-ins: only names and small parameters (a large one is a valid, slow scene).
        if spec.len() > 16 || spec.bytes().filter(u8::is_ascii_digit).count() > 1 {
            return;
        }
        scenes::build(text)
    } else {
        let (obj_text, mtl_text) = text.split_once("\n#MTL\n").unwrap_or((text, ""));
        let mtl = mtl_text.to_string();
        obj::load_text("fuzz.obj", obj_text, &move |_| Ok(("fuzz.mtl".into(), mtl.clone())))
    };
    if let Ok(scene) = scene {
        trace_a_little(&scene);
    }
});

fn trace_a_little(scene: &Scene) {
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
        a.estimate(Measure::PositionalEntropy),
        a.estimate(Measure::Entropy),
        a.estimate(Measure::MutualInformation),
        a.estimate(Measure::ContinuousMutualInformation),
    ]
    .into_iter()
    .flatten()
    {
        assert!(!e.value.is_nan(), "NaN measure on {}", scene.name);
    }
}
