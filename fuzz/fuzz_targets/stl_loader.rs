//! Fuzzes the STL loader (ASCII and binary; also the detection of the format from the bytes, which
//! tells binary STL by its size): whatever the bytes, scx must load them or refuse them with an error,
//! never panic.
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use scene_complexity::internals::scene::format::{detect, load_as, Format};
use scene_complexity::internals::scene::SceneOptions;

fuzz_target!(|data: &[u8]| {
    let _ = detect(data);
    let loaded = load_as(
        Format::StlBinary,
        "fuzz.stl",
        data,
        common::NO_FOLDER.as_ref(),
        &SceneOptions::default(),
        &common::policy(),
    );
    if let Ok(scene) = loaded {
        common::trace_a_little(&scene);
    }
});
