//! Runs beyond one machine and one sitting (issue 16): saved states, shards and `scx merge`, checkpoints
//! and `--resume`, interruption that keeps every finished batch. The invariant: however a run's batches
//! were split, interrupted or resumed, its report is that of the run cast at once, bit for bit (the
//! timings, command line, CPU and thread count aside).

use crate::support;

use support::scx;

use std::path::Path;
use std::process::{Command, Stdio};

/// Fields that describe the session rather than the run.
const SESSION: [&str; 6] = support::SESSION_FIELDS;

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
    interrupt_when(args, signal, after, || true)
}

/// [`interrupt`], but waiting (up to two minutes more) after `after` seconds until `ready` says so: on a
/// loaded machine a fixed delay may come before the run has done what the test needs (a checkpoint).
fn interrupt_when(
    args: &[&str],
    signal: &str,
    after: f64,
    ready: impl Fn() -> bool,
) -> std::process::Output {
    let child = Command::new(env!("CARGO_BIN_EXE_scx"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_secs_f64(after));
    let waited = std::time::Instant::now();
    while !ready() && waited.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
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
    let out = interrupt_when(&args, "-KILL", 1.2, || Path::new(&killed).exists());
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
    let copy = path("copy.scx");
    std::fs::copy(&a, &copy).unwrap();
    let cases: [(&[&str], &[&str]); 7] = [
        (&[&truncated, &b], &["truncated.scx", "truncated"]),
        (&[&a, &flipped], &["flipped.scx", "checksum"]),
        (
            &[&a, &other_scene],
            &["other_scene.scx", "a.scx", "fingerprint"],
        ),
        (&[&a, &other_seed], &["other_seed.scx", "a.scx", "seed"]),
        (&[&a, &a], &["a.scx", "given twice"]),
        (&[&a, &copy], &["copy.scx", "a.scx", "overlap"]),
        (&[&a], &["missing", "..63663"]),
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

/// A scene file read with options (two-sided, flipped normals) is read the same way by a resume and a
/// merge, which take the options from the state: both give the single run's report, orientation
/// counts and warnings included.
#[test]
fn resumed_and_merged_runs_read_the_scene_file_as_first_read() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("box.obj");
    let out = scx(&["export", "@cube", "-o", obj.to_str().unwrap(), "-q"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for reading in [
        ["--two-sided", "--planarity=1e-3"],
        ["--flip-normals", "--planarity=1e-3"],
    ] {
        let mut base = vec![
            "analyze",
            obj.to_str().unwrap(),
            "--tracer",
            "rust",
            "--format",
            "json",
        ];
        base.extend(reading);
        let mut full = base.clone();
        full.extend(["--lines", "6e5"]);
        let single = run_json(&full);
        assert!(single["pairs"].as_u64().is_some());

        let state = dir.path().join("half.scx");
        let mut half = base.clone();
        half.extend(["--lines", "3e5", "--save", state.to_str().unwrap(), "-q"]);
        assert!(scx(&half).status.success());
        let resumed = run_json(&[
            "analyze",
            "--resume",
            state.to_str().unwrap(),
            "--lines",
            "6e5",
            "--format",
            "json",
        ]);
        assert_same(&single, &resumed, &format!("resumed {reading:?}"));

        let mut parts = Vec::new();
        for k in 1..=2 {
            let part = dir.path().join(format!("r{k}.scx"));
            let shard = format!("{k}/2");
            let mut args = full.clone();
            args.extend(["--shard", &shard, "--save", part.to_str().unwrap(), "-q"]);
            assert!(scx(&args).status.success());
            parts.push(part);
        }
        let mut merge = vec!["merge", "--format", "json"];
        merge.extend(parts.iter().map(|p| p.to_str().unwrap()));
        assert_same(&single, &run_json(&merge), &format!("merged {reading:?}"));
    }
    let flipped = run_json(&[
        "analyze",
        obj.to_str().unwrap(),
        "--flip-normals",
        "--lines",
        "1e4",
        "--format",
        "json",
    ]);
    assert_eq!(flipped["pairs"], 0, "a room turned inside out has no pairs");
}

/// The per-patch files asked of a run: the per-patch and per-object tables and the form factors in both
/// formats, as command-line arguments writing into `dir` with names beginning with `stem`.
fn patch_file_args(dir: &Path, stem: &str) -> Vec<String> {
    let file = |ext: &str| {
        dir.join(format!("{stem}{ext}"))
            .to_str()
            .unwrap()
            .to_string()
    };
    vec![
        "--patches".into(),
        file("-patches.csv"),
        "--form-factors".into(),
        file("-ff.csv"),
        "--form-factors".into(),
        file("-ff.mtx"),
        "--objects".into(),
        file("-objects.csv"),
    ]
}

/// The bytes of the per-patch files of `patch_file_args(dir, stem)`.
fn patch_files(dir: &Path, stem: &str) -> Vec<(String, Vec<u8>)> {
    ["-patches.csv", "-ff.csv", "-ff.mtx", "-objects.csv"]
        .iter()
        .map(|ext| {
            let name = format!("{stem}{ext}");
            let bytes = std::fs::read(dir.join(&name))
                .unwrap_or_else(|e| panic!("{name} was not written: {e}"));
            (name, bytes)
        })
        .collect()
}

/// Asserts that two runs' per-patch files are the same bytes.
fn assert_same_files(a: &[(String, Vec<u8>)], b: &[(String, Vec<u8>)], what: &str) {
    for ((name_a, x), (name_b, y)) in a.iter().zip(b) {
        assert!(!x.is_empty(), "{what}: {name_a} is empty");
        assert!(x == y, "{what}: {name_b} differs from {name_a}");
    }
}

/// `a` followed by `b`.
fn joined<'a>(a: &[&'a str], b: &[&'a str]) -> Vec<&'a str> {
    a.iter().chain(b).copied().collect()
}

/// Runs scx with `args` and the per-patch file arguments, and checks it succeeded.
fn run_with_files(args: &[&str], files: &[String]) -> serde_json::Value {
    let mut all: Vec<&str> = args.to_vec();
    all.extend(files.iter().map(String::as_str));
    run_json(&all)
}

/// `--patches`, `--form-factors` and `--objects` after `--resume` from a half-way state, and from `scx
/// merge` of 3 shards, write the very bytes of the run cast at once: the per-patch sums of eq. (27)
/// travel in the states, as exact integers. On a closed cube, on the lit Cornell box (radiosity
/// columns) and on the open Cornell box enclosed (`--enclose`: the environment's row, whose sums of the
/// escapes travel too), whose files are also the same bytes with 1 thread as with 2.
#[test]
fn per_patch_files_of_resumed_and_merged_runs_are_the_single_runs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let state = |name: &str| d.join(name).to_str().unwrap().to_string();
    let cornell = scene_file("cornell.obj");
    for (scene, enclose) in [
        ("@cube:4", false),
        (cornell.as_str(), false),
        ("@cornell-open", true),
    ] {
        let mut base = vec!["analyze", scene, "--tracer", "rust", "--format", "json"];
        if enclose {
            base.push("--enclose");
        }
        let single = run_with_files(
            &joined(&base, &["--lines", "6e5"]),
            &patch_file_args(d, "single"),
        );
        let single_files = patch_files(d, "single");
        if enclose {
            let text = String::from_utf8_lossy(&single_files[0].1).to_string();
            let last = text.lines().last().unwrap();
            assert!(last.starts_with("28,environment,environment,"), "{last}");
            let one_thread = run_with_files(
                &joined(&base, &["--lines", "6e5", "--threads", "1"]),
                &patch_file_args(d, "one"),
            );
            assert_eq!(one_thread["threads"], 1);
            assert_same_files(&single_files, &patch_files(d, "one"), "1 thread");
        }
        // The columns that need the per-patch sums are filled, and the radiosities of the lit box.
        let text = String::from_utf8_lossy(&single_files[0].1).to_string();
        let mut lines = text.lines().map(|l| l.split(',').collect::<Vec<_>>());
        let (header, row) = (lines.next().unwrap(), lines.next().unwrap());
        let cell = |name: &str| row[header.iter().position(|h| *h == name).unwrap()];
        assert!(
            !cell("continuous_mutual_information_term").is_empty(),
            "{scene}"
        );
        assert!(
            !cell("lost_information_corrected_stderr").is_empty(),
            "{scene}"
        );
        assert_eq!(cell("radiosity").is_empty(), scene == "@cube:4", "{scene}");

        // (a) Half the lines saved (the half-way run asked for the per-patch table too, so its state
        // keeps the sums), then resumed to all of them.
        let half = state("half.scx");
        run_with_files(
            &joined(&base, &["--lines", "3e5", "--save", &half, "-q"]),
            &patch_file_args(d, "half"),
        );
        let resumed = run_with_files(
            &[
                "analyze", "--resume", &half, "--lines", "6e5", "--format", "json", "-q",
            ],
            &patch_file_args(d, "resumed"),
        );
        assert_same(&single, &resumed, &format!("{scene} resumed"));
        assert_same_files(
            &single_files,
            &patch_files(d, "resumed"),
            &format!("{scene} resumed"),
        );

        // (b) 3 shards, merged in another order.
        let mut parts = Vec::new();
        for k in 1..=3 {
            let part = state(&format!("part{k}.scx"));
            let shard = format!("{k}/3");
            run_with_files(
                &joined(
                    &base,
                    &["--lines", "6e5", "--shard", &shard, "--save", &part, "-q"],
                ),
                &patch_file_args(d, &format!("shard{k}")),
            );
            parts.push(part);
        }
        let merge: Vec<&str> = ["merge", "--format", "json", "-q"]
            .into_iter()
            .chain(parts.iter().rev().map(String::as_str))
            .collect();
        let merged = run_with_files(&merge, &patch_file_args(d, "merged"));
        assert_same(&single, &merged, &format!("{scene} merged"));
        assert_same_files(
            &single_files,
            &patch_files(d, "merged"),
            &format!("{scene} merged"),
        );
    }
}

/// The columns of the per-patch table that need the per-patch sums of eq. (27).
const CONTINUOUS_COLUMNS: [&str; 3] = [
    "continuous_mutual_information_term",
    "lost_information",
    "lost_information_corrected",
];

/// A state saved without the per-patch sums (its run was not asked for `--patches`) cannot give the
/// I_s^c columns: `--resume` and `scx merge` with `--patches` say so in a warning naming the file, leave
/// those columns (and their errors) empty and write every other cell as the run cast at once. A state
/// of a run that counted no pairs cannot give per-patch files at all: exit 2 naming it, before any work.
#[test]
fn states_without_per_patch_sums_say_so() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let file = |name: &str| d.join(name).to_str().unwrap().to_string();
    let base = ["analyze", "@cube:4", "--tracer", "rust", "--format", "json"];
    run_with_files(
        &joined(&base, &["--lines", "6e5"]),
        &patch_file_args(d, "single"),
    );
    let single = patch_files(d, "single");

    // Each table without its I_s^c cells, which must be empty in the second.
    let check = |files: &[(String, Vec<u8>)], what: &str| {
        let table = |bytes: &[u8]| -> Vec<Vec<String>> {
            String::from_utf8_lossy(bytes)
                .lines()
                .map(|l| l.split(',').map(String::from).collect())
                .collect()
        };
        let (ours, theirs) = (table(&single[0].1), table(&files[0].1));
        let header = &ours[0];
        let continuous: Vec<usize> = (0..header.len())
            .filter(|&k| {
                CONTINUOUS_COLUMNS
                    .iter()
                    .any(|c| header[k] == *c || header[k] == format!("{c}_stderr"))
            })
            .collect();
        assert_eq!(continuous.len(), 6, "{header:?}");
        assert_eq!(ours.len(), theirs.len());
        for (a, b) in ours.iter().zip(&theirs).skip(1) {
            for (k, (x, y)) in a.iter().zip(b).enumerate() {
                if continuous.contains(&k) {
                    assert!(!x.is_empty() && y.is_empty(), "{what}: {} `{y}`", header[k]);
                } else {
                    assert_eq!(x, y, "{what}: {}", header[k]);
                }
            }
        }
        // The form factors need only the pair counts, which every state keeps.
        assert_same_files(&single[1..3], &files[1..3], what);
    };

    let half = file("bare-half.scx");
    run_json(&joined(&base, &["--lines", "3e5", "--save", &half, "-q"]));
    let mut args = vec![
        "analyze", "--resume", &half, "--lines", "6e5", "--format", "json",
    ];
    let files = patch_file_args(d, "resumed");
    args.extend(files.iter().map(String::as_str));
    let out = scx(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("bare-half.scx") && err.contains("per-patch sums") && err.contains("empty"),
        "{err}"
    );
    check(&patch_files(d, "resumed"), "resumed");

    // Shard 2 saved without the sums, the others with them: the merge names shard 2 only.
    let mut parts = Vec::new();
    for k in 1..=3 {
        let part = file(&format!("mixed{k}.scx"));
        let shard = format!("{k}/3");
        let args = joined(
            &base,
            &["--lines", "6e5", "--shard", &shard, "--save", &part, "-q"],
        );
        if k == 2 {
            run_json(&args);
        } else {
            run_with_files(&args, &patch_file_args(d, &format!("shard{k}")));
        }
        parts.push(part);
    }
    let mut args = vec!["merge", "--format", "json"];
    args.extend(parts.iter().map(String::as_str));
    let files = patch_file_args(d, "merged");
    args.extend(files.iter().map(String::as_str));
    let out = scx(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("mixed2.scx") && err.contains("per-patch sums"),
        "{err}"
    );
    assert!(
        !err.contains("mixed1.scx") && !err.contains("mixed3.scx"),
        "{err}"
    );
    check(&patch_files(d, "merged"), "merged");

    // No pair counts at all: refused before any work, the file named, nothing written.
    let bare = file("continuous.scx");
    run_json(&joined(
        &base,
        &[
            "--lines",
            "3e5",
            "--measures",
            "continuous",
            "--save",
            &bare,
            "-q",
        ],
    ));
    let table = file("none.csv");
    for args in [
        vec![
            "analyze",
            "--resume",
            &bare,
            "--lines",
            "6e5",
            "--patches",
            &table,
        ],
        vec!["merge", &bare, "--patches", &table],
    ] {
        let out = scx(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("continuous.scx") && err.contains("no patch pairs"),
            "{err}"
        );
        assert!(out.stdout.is_empty() && !Path::new(&table).exists());
    }
}

/// Shards saved beside their scene, named relative to that folder, merge from another folder (the
/// scene is found beside the states; it said only "cube.obj: no such file"); when it is not there
/// either, the message says what the name is and how to give the scene.
#[test]
fn merge_finds_the_scene_beside_its_states() {
    let dir = tempfile::tempdir().unwrap();
    let shards = dir.path().join("shards");
    std::fs::create_dir(&shards).unwrap();
    let in_dir = |dir: &Path, args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_scx"))
            .current_dir(dir)
            .args(args)
            .output()
            .unwrap()
    };
    assert!(
        in_dir(&shards, &["export", "@cube:3", "-o", "cube.obj", "-q"])
            .status
            .success()
    );
    for k in ["1/2", "2/2"] {
        let save = format!("s{}.scx", &k[..1]);
        let args = [
            "analyze", "cube.obj", "--lines", "2e4", "--shard", k, "--save", &save, "-q",
        ];
        assert!(in_dir(&shards, &args).status.success());
    }
    let whole = json(&in_dir(
        &shards,
        &["analyze", "cube.obj", "--lines", "2e4", "--format", "json"],
    ));
    let merge = [
        "merge",
        "shards/s1.scx",
        "shards/s2.scx",
        "--format",
        "json",
    ];
    let merged = json(&in_dir(dir.path(), &merge));
    for key in [
        "entropy",
        "mutual_information",
        "continuous_mutual_information",
    ] {
        assert_eq!(merged["visibility"][key], whole["visibility"][key], "{key}");
    }
    std::fs::rename(shards.join("cube.obj"), shards.join("moved.obj")).unwrap();
    let lost = in_dir(dir.path(), &merge);
    let err = String::from_utf8_lossy(&lost.stderr);
    assert_eq!(lost.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cube.obj: no such file") && err.contains("--scene"),
        "{err}"
    );
}
