//! `scx`: the command-line front end of the scene complexity analyser.

// The JSON report is one `serde_json::json!` document of some forty fields, deeper than the macro's
// default recursion allows.
#![recursion_limit = "256"]

mod cli;

// jemalloc keeps the memory of long runs on large meshes compact, where glibc's malloc kept up to half a
// gigabyte of freed round buffers resident on a 100,000-patch run (docs/performance.md, "Memory").
#[global_allocator]
static ALLOCATOR: tikv_jemallocator::Jemalloc = tikv_jemallocator::Jemalloc;

fn main() -> std::process::ExitCode {
    cli::main()
}
