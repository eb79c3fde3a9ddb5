//! Raw bindings to the C shim (`ffi/scx_embree.h`) and the Embree structs it shares with Rust, generated
//! by bindgen at build time from the installed Embree headers (never vendored: struct layouts depend on
//! how Embree was configured).

#![allow(
    non_camel_case_types,
    non_snake_case,
    non_upper_case_globals,
    dead_code,
    missing_docs,
    clippy::all,
    clippy::pedantic
)]

include!(concat!(env!("OUT_DIR"), "/embree_bindings.rs"));
