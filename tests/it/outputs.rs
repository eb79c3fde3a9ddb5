//! What scx writes, and what it must never do to files (issue 28, outputs): no panic on durations
//! beyond the clock and no hang after a worker's panic; the report kept when a save fails; one path for
//! two outputs refused; devices, FIFOs, directories and symbolic links treated as what they are; every
//! file written whole or not at all; a lock on a live checkpoint.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Far beyond what any run below takes: only a hang reaches it.
const HANG: Duration = Duration::from_secs(120);

/// Runs `scx` with `args` in `dir`, killing it (and failing) if it hangs; checks that no panic's text
/// or backtrace reaches standard error.
fn scx_in(dir: &Path, args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_scx"))
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("scx runs");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > HANG {
            let _ = child.kill();
            panic!("{args:?}: hangs");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("output");
    let err = stderr(&out);
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE") && !err.contains("backtrace"),
        "{args:?}: {err}"
    );
    out
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn code(out: &Output) -> Option<i32> {
    out.status.code()
}

/// Durations longer than the clock can count are no limit (the run ends with its lines), not a panic
/// in a worker followed by a hang.
#[test]
fn durations_beyond_the_clock_are_no_limit() {
    let dir = tempfile::tempdir().unwrap();
    for extra in [
        &["--seconds", "1e30"][..],
        &["--seconds", "1.8e19"],
        &["--checkpoint-every", "1e30", "--checkpoint", "c.scx"],
    ] {
        let mut args = vec!["analyze", "@cube:2", "--lines", "2e4", "--format", "json"];
        args.extend_from_slice(extra);
        let out = scx_in(dir.path(), &args);
        assert_eq!(code(&out), Some(0), "{extra:?}: {}", stderr(&out));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(report["lines"], 20_000, "{extra:?}");
    }
    assert!(dir.path().join("c.scx").is_file());
}
