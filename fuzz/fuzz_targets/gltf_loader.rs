//! Fuzzes the glTF loader (JSON `.gltf` and binary `.glb`): whatever the bytes, scx must load them or
//! refuse them with an error, never panic, never loop, and never read a file (buffers named by a path
//! are looked for in a folder that does not exist, and absolute ones are refused by the policy).
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use scene_complexity::internals::scene::format::{load_as, Format};
use scene_complexity::internals::scene::SceneOptions;

fuzz_target!(|data: &[u8]| {
    let loaded = load_as(
        Format::Gltf,
        "fuzz.gltf",
        data,
        common::NO_FOLDER.as_ref(),
        &SceneOptions::default(),
        &common::policy(),
    );
    if let Ok(scene) = loaded {
        common::trace_a_little(&scene);
    }
});
