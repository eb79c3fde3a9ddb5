//! Fuzzes the MTL reader: the input is the text of the material library of a fixed OBJ (two faces,
//! each with a material of the library, and one with a material it may not define). Whatever the text,
//! scx must load the scene or refuse it with an error naming the library, never panic.
#![no_main]

#[path = "common.rs"]
mod common;

use libfuzzer_sys::fuzz_target;
use scene_complexity::internals::scene::obj;

const OBJ: &str = "mtllib fuzz.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                   usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\nusemtl c\nf 1 4 2\n";

fuzz_target!(|data: &[u8]| {
    let Ok(mtl) = std::str::from_utf8(data) else {
        return;
    };
    let mtl = mtl.to_string();
    let loaded = obj::load_text("fuzz.obj", OBJ, &move |_| {
        Ok(("fuzz.mtl".into(), mtl.clone()))
    });
    if let Ok(scene) = loaded {
        common::trace_a_little(&scene);
    }
});
