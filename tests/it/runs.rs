//! Runs beyond one machine and one sitting (issue 16): saved states, shards and `scx merge`, checkpoints
//! and `--resume`, interruption that keeps every finished batch. The invariant: however a run's batches
//! were split, interrupted or resumed, its report is that of the run cast at once, bit for bit (the
//! timings, command line, CPU and thread count aside).

use crate::support;

use support::scx;

use std::path::Path;
use std::process::{Command, Stdio};

/// Fields that describe the session rather than the run.
const SESSION: [&str; 5] = ["seconds", "command_line", "cpu", "threads", "shard"];

fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "no JSON ({e}); stderr: {}",
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// The differences between two reports, session fields aside.
fn differences(a: &serde_json::Value, b: &serde_json::Value, path: &str, out: &mut Vec<String>) {
    match (a, b) {
        (serde_json::Value::Object(x), serde_json::Value::Object(y)) => {
            for k in x.keys().chain(y.keys()) {
                if SESSION.contains(&k.as_str()) {
                    continue;
                }
                let (p, q) = (&x[k], &y[k]);
                differences(p, q, &format!("{path}/{k}"), out);
            }
        }
        _ if a != b => out.push(format!("{path}: {a} against {b}")),
        _ => {}
    }
}

fn assert_same(a: &serde_json::Value, b: &serde_json::Value, what: &str) {
    let mut d = Vec::new();
    differences(a, b, "", &mut d);
    assert!(d.is_empty(), "{what}: {}", d[..d.len().min(6)].join("\n"));
}

fn run_json(args: &[&str]) -> serde_json::Value {
    let out = scx(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    json(&out)
}

fn scene_file(name: &str) -> String {
    format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn tracers() -> Vec<&'static str> {
    if cfg!(feature = "embree") {
        vec!["embree", "rust"]
    } else {
        vec!["rust"]
    }
}

/// Shards in 1, 2 and 7 parts, merged, give the single run's report: a dense and a sparse built-in, an
/// OBJ scene with light (radiosity measures) and without them, both tracers.
#[test]
fn merged_shards_are_the_single_run() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = scene_file("cornell.obj");
    let cases: Vec<(&str, Vec<&str>)> = vec![
        ("@cube:10", vec![]),
        ("@cubes512", vec![]),
        (&cornell, vec![]),
        (&cornell, vec!["--measures", "discrete,continuous"]),
    ];
    for tracer in tracers() {
        for (scene, extra) in &cases {
            let mut base = vec![
                "analyze", scene, "--lines", "1.5e5", "--tracer", tracer, "--format", "json",
            ];
            base.extend(extra.iter());
            let single = run_json(&base);
            for shards in [1u32, 2, 7] {
                let mut parts = Vec::new();
                for k in 1..=shards {
                    let part = dir.path().join(format!("p{k}.scx"));
                    let shard = format!("{k}/{shards}");
                    let mut args = base.clone();
                    args.extend(["--shard", &shard, "--save", part.to_str().unwrap(), "-q"]);
                    let out = scx(&args);
                    assert!(
                        out.status.success(),
                        "{}",
                        String::from_utf8_lossy(&out.stderr)
                    );
                    parts.push(part);
                }
                let mut merge = vec!["merge", "--format", "json"];
                merge.extend(parts.iter().rev().map(|p| p.to_str().unwrap()));
                let merged = run_json(&merge);
                assert_same(
                    &single,
                    &merged,
                    &format!("{scene} {tracer} {extra:?} in {shards}"),
                );
                assert_eq!(merged["complete"], true);
            }
        }
    }
}

/// Spawns an analysis, interrupts it with `signal` after `after` seconds and waits for it.
fn interrupt(args: &[&str], signal: &str, after: f64) -> std::process::Output {
    let child = Command::new(env!("CARGO_BIN_EXE_scx"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_secs_f64(after));
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    child.wait_with_output().unwrap()
}

/// Ctrl-C keeps every finished batch and exits 130; SIGKILL loses only the work since the last
/// checkpoint; either way `--resume` finishes the run with the numbers of the run cast at once. A run
/// continued to more lines than first asked is the longer run.
#[test]
fn interrupted_killed_and_extended_runs_resume_to_the_same_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let full = run_json(&[
        "analyze", "@cube:30", "--lines", "1e7", "--format", "json", "--tracer", "rust",
    ]);

    let state = path("int.scx");
    let args = [
        "analyze",
        "@cube:30",
        "--lines",
        "1e7",
        "--format",
        "json",
        "--tracer",
        "rust",
        "--checkpoint",
        &state,
    ];
    let out = interrupt(&args, "-INT", 0.8);
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let partial = json(&out);
    assert_eq!(partial["interrupted"], true);
    assert_eq!(partial["complete"], false);
    // The report's lines are exactly the lines of the ranges it says it covers.
    let covered: u64 = partial["covered_lines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r[1].as_u64().unwrap() - r[0].as_u64().unwrap())
        .sum();
    assert_eq!(partial["lines"].as_u64().unwrap(), covered);
    assert!(covered > 0 && covered < 10_000_000);
    let resumed = run_json(&["analyze", "--resume", &state, "--format", "json", "-q"]);
    assert_same(&full, &resumed, "resumed after Ctrl-C");

    let killed = path("kill.scx");
    let args = [
        "analyze",
        "@cube:30",
        "--lines",
        "1e7",
        "--format",
        "json",
        "--tracer",
        "rust",
        "--checkpoint",
        &killed,
        "--checkpoint-every",
        "0.2",
    ];
    let out = interrupt(&args, "-KILL", 1.2);
    assert_eq!(out.status.code(), None, "killed by a signal");
    assert!(Path::new(&killed).exists(), "a checkpoint was written");
    let resumed = run_json(&["analyze", "--resume", &killed, "--format", "json", "-q"]);
    assert_same(&full, &resumed, "resumed after SIGKILL");

    let short = path("short.scx");
    run_json(&[
        "analyze", "@cube:30", "--lines", "2.5e6", "--tracer", "rust", "--format", "json",
        "--save", &short, "-q",
    ]);
    let extended = run_json(&[
        "analyze", "--resume", &short, "--lines", "1e7", "--format", "json",
    ]);
    assert_same(&full, &extended, "2.5e6 lines continued to 1e7");
}

/// Every bad state exits 2 with a message naming the file(s), and no report.
#[test]
fn bad_states_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let part = |scene: &str, seed: &str, shard: &str, name: &str| {
        let file = path(name);
        let out = scx(&[
            "analyze", scene, "--lines", "1e5", "--seed", seed, "--tracer", "rust", "--shard",
            shard, "--save", &file, "-q",
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        file
    };
    let (a, b) = (
        part("@cube:4", "1", "1/2", "a.scx"),
        part("@cube:4", "1", "2/2", "b.scx"),
    );
    let bytes = std::fs::read(&a).unwrap();
    let truncated = path("truncated.scx");
    std::fs::write(&truncated, &bytes[..bytes.len() - 100]).unwrap();
    let flipped = path("flipped.scx");
    let mut f = bytes.clone();
    f[bytes.len() - 50] ^= 1;
    std::fs::write(&flipped, &f).unwrap();
    let other_scene = part("@cube:5", "1", "2/2", "other_scene.scx");
    let other_seed = part("@cube:4", "2", "2/2", "other_seed.scx");
    let cases: [(&[&str], &[&str]); 6] = [
        (&[&truncated, &b], &["truncated.scx", "truncated"]),
        (&[&a, &flipped], &["flipped.scx", "checksum"]),
        (
            &[&a, &other_scene],
            &["other_scene.scx", "a.scx", "fingerprint"],
        ),
        (&[&a, &other_seed], &["other_seed.scx", "a.scx", "seed"]),
        (&[&a, &a], &["a.scx", "overlap"]),
        (&[&a], &["missing", "..100000"]),
    ];
    for (files, expected) in cases {
        let mut args = vec!["merge", "--format", "json"];
        args.extend(files.iter().copied());
        let out = scx(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{files:?}: {err}");
        assert!(out.stdout.is_empty(), "{files:?}: a report was printed");
        for e in expected {
            assert!(err.contains(e), "{files:?}: `{e}` not in: {err}");
        }
    }
    // With --partial the report covers the shard's lines and says so.
    let partial = run_json(&["merge", &a, "--partial", "--format", "json"]);
    assert_eq!(partial["complete"], false);
    assert_eq!(partial["covered_lines"][0][0], 0);
    assert!(partial["covered_lines"][0][1].as_u64().unwrap() < 100_000);
}
