//! scx's integration tests: one test binary (the library and Embree are linked once), one module per
//! concern. Modules that run the `scx` binary need the `cli` feature; the Embree backend's need `embree`.

#[path = "../common/meshed_room.rs"]
mod meshed_room;
mod support;

// The library against independent truth.
mod bounds;
mod bundles;
mod calibration;
mod crosscheck;
#[cfg(feature = "embree")]
mod embree_backend;
mod errors;
mod findings;
mod lines_and_tracers;
mod patches;
mod radiosity;
mod render;
mod report;
mod rust_bvh;
mod sampler;
mod scene_files;
mod stability;
mod visibility;

// The `scx` binary.
#[cfg(feature = "cli")]
mod bad_input;
#[cfg(feature = "cli")]
mod cli;
#[cfg(feature = "cli")]
mod cli_honest;
#[cfg(feature = "cli")]
mod cli_patches;
#[cfg(feature = "cli")]
mod cli_radiosity;
#[cfg(feature = "cli")]
mod cli_render;
#[cfg(feature = "cli")]
mod cli_reproduce;
#[cfg(feature = "cli")]
mod cli_scene_files;
#[cfg(feature = "cli")]
mod hostile;
#[cfg(feature = "cli")]
mod outputs;
#[cfg(feature = "cli")]
mod runs;

// The source's structure.
mod layers;

// The README's and the guide's links (docs/).
mod docs;

// The system-package setup script (`.ci/setup`), a bash script.
#[cfg(unix)]
mod setup;
