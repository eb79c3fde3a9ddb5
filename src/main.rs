//! `scx`: the command-line front end of the scene complexity analyser.

mod cli;

// jemalloc keeps the memory of long runs on large meshes compact, where glibc's malloc kept up to half a
// gigabyte of freed round buffers resident on a 100,000-patch run (docs/performance.md, "Memory").
#[global_allocator]
static ALLOCATOR: tikv_jemallocator::Jemalloc = tikv_jemallocator::Jemalloc;

fn main() -> std::process::ExitCode {
    cli::main()
}
