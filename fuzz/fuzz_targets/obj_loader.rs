//! Fuzzes the OBJ + MTL loader and the built-in scene names, then traces the scene a little: whatever the
//! input, scx must load it or refuse it with an error, never panic, and a loaded scene must trace to
//! finite measures.
//!
//! Input: OBJ text, optionally followed by `\n#MTL\n` and the text of the MTL library that any `mtllib`
//! resolves to. An input starting with `@` is a built-in scene name instead.
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use scene_complexity::internals::scene::obj;
use scene_complexity::internals::scenes;

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
        obj::load_text("fuzz.obj", obj_text, &move |_| {
            Ok(("fuzz.mtl".into(), mtl.clone()))
        })
    };
    if let Ok(scene) = scene {
        common::trace_a_little(&scene);
    }
});
