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
        assert_eq!(report["sphere_lines"], 20_000, "{extra:?}");
    }
    assert!(dir.path().join("c.scx").is_file());
}

/// The machine's name as scx records it in temporaries and locks.
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_string())
        .unwrap_or_default()
}

/// The id of a process that has ended.
fn dead_pid() -> u32 {
    let mut child = Command::new("true").spawn().expect("true runs");
    let pid = child.id();
    child.wait().unwrap();
    pid
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_default()
}

/// Two outputs with one path, and an output that is an input, are refused before any work (exit 2,
/// both named), and no file is touched; the state that `--resume` continues is saved back by design.
#[test]
fn one_path_for_two_outputs_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.scx"), "old state").unwrap();
    std::fs::write(d.join("p.csv"), "old csv").unwrap();
    let out = scx_in(d, &["export", "@cube:2", "-o", "cube.obj"]);
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    let scene = read(&d.join("cube.obj"));
    let cases: &[(&[&str], &[&str])] = &[
        (
            &[
                "analyze", "@cube:2", "--lines", "1e4", "-o", "s.scx", "--save", "s.scx",
            ],
            &["-o s.scx", "--save s.scx"],
        ),
        (
            &[
                "analyze",
                "@cube:2",
                "--lines",
                "1e4",
                "--patches",
                "p.csv",
                "--form-factors",
                "./p.csv",
            ],
            &["--patches p.csv", "--form-factors ./p.csv"],
        ),
        (
            &["analyze", "cube.obj", "--lines", "1e4", "-o", "cube.obj"],
            &["-o cube.obj", "scene cube.obj"],
        ),
        (
            &[
                "analyze",
                "cube.obj",
                "--lines",
                "1e4",
                "--patches",
                "cube.obj",
            ],
            &["--patches cube.obj", "scene cube.obj"],
        ),
        (
            &["export", "@cube:3", "-o", "cube.mtl"],
            &["cube.mtl", "MTL"],
        ),
        (
            &["export", "cube.obj", "-o", "./cube.obj"],
            &["./cube.obj", "scene cube.obj"],
        ),
        (
            &["merge", "s.scx", "--save", "s.scx"],
            &["--save s.scx", "state s.scx"],
        ),
        (
            &["merge", "s.scx", "-o", "s.scx"],
            &["-o s.scx", "state s.scx"],
        ),
    ];
    for (args, names) in cases {
        let out = scx_in(d, args);
        let err = stderr(&out);
        assert_eq!(code(&out), Some(2), "{args:?}: {err}");
        for name in *names {
            assert!(err.contains(name), "{args:?} should name {name}: {err}");
        }
    }
    assert_eq!(read(&d.join("s.scx")), b"old state");
    assert_eq!(read(&d.join("p.csv")), b"old csv");
    assert_eq!(read(&d.join("cube.obj")), scene);

    // The state --resume continues is its own output.
    let out = scx_in(
        d,
        &["analyze", "@cube:2", "--lines", "1e4", "--save", "r.scx"],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    for args in [
        &["analyze", "--resume", "r.scx"][..],
        &["analyze", "--resume", "r.scx", "--save", "r.scx"],
        &["analyze", "--resume", "r.scx", "--checkpoint", "r.scx"],
    ] {
        let out = scx_in(d, args);
        assert_eq!(code(&out), Some(0), "{args:?}: {}", stderr(&out));
    }
    let out = scx_in(d, &["analyze", "--resume", "r.scx", "-o", "r.scx"]);
    assert_eq!(code(&out), Some(2), "{}", stderr(&out));
}

/// A file the scene names and scx reads (an OBJ's MTL library, a glTF buffer) is an input as much as
/// the scene file: no output may replace it, whichever command writes (the MTL library written beside
/// an exported OBJ included).
#[test]
fn files_a_scene_reads_are_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mtl = b"newmtl red\nKd 0.8 0.1 0.1\n";
    std::fs::write(d.join("out.mtl"), mtl).unwrap();
    std::fs::write(
        d.join("q.obj"),
        "mtllib out.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl red\nf 1 2 3\n",
    )
    .unwrap();
    // A glTF whose one triangle lies in a buffer file of its own.
    let corners: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let bin: Vec<u8> = corners.iter().flat_map(|c| c.to_le_bytes()).collect();
    std::fs::write(d.join("tri.bin"), &bin).unwrap();
    std::fs::write(
        d.join("tri.gltf"),
        r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
        "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
          "min":[0,0,0],"max":[1,1,0]}],
        "bufferViews":[{"buffer":0,"byteLength":36}],
        "buffers":[{"uri":"tri.bin","byteLength":36}]}"#,
    )
    .unwrap();
    let out = scx_in(d, &["export", "tri.gltf", "-o", "tri.obj"]);
    assert_eq!(code(&out), Some(0), "the glTF loads: {}", stderr(&out));
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["export", "q.obj", "-o", "out.obj"],
            "its MTL library out.mtl",
        ),
        (vec!["export", "q.obj", "-o", "out.mtl.ply"], ""),
        (
            vec![
                "refine",
                "q.obj",
                "-o",
                "out.obj",
                "--patches",
                "4",
                "--strategy",
                "uniform",
            ],
            "its MTL library out.mtl",
        ),
        (
            vec!["analyze", "q.obj", "--lines", "1e4", "-o", "out.mtl"],
            "-o out.mtl",
        ),
        (
            vec![
                "render",
                "q.obj",
                "-o",
                "x.png",
                "--patches-mesh",
                "out.mtl",
            ],
            "",
        ),
    ];
    for (args, names) in &cases {
        let out = scx_in(d, args);
        let err = stderr(&out);
        if names.is_empty() {
            // Refused for another reason (the extension) or written elsewhere: the library stays.
            assert_eq!(read(&d.join("out.mtl")), mtl, "{args:?}: {err}");
            continue;
        }
        assert_eq!(code(&out), Some(2), "{args:?}: {err}");
        for name in [*names, "which the scene q.obj reads"] {
            assert!(err.contains(name), "{args:?} should say {name}: {err}");
        }
        assert_eq!(
            read(&d.join("out.mtl")),
            mtl,
            "{args:?} replaced the library"
        );
    }
    let out = scx_in(
        d,
        &["analyze", "tri.gltf", "--lines", "1e4", "-o", "tri.bin"],
    );
    let err = stderr(&out);
    assert_eq!(code(&out), Some(2), "{err}");
    assert!(err.contains("which the scene tri.gltf reads"), "{err}");
    assert_eq!(read(&d.join("tri.bin")), bin);
}

/// Devices are written into as streams, states refused there; directories are refused before work;
/// a symbolic link to a file is written through (the link stays, its target holds the output).
#[test]
fn devices_directories_and_links_are_what_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = scx_in(
        d,
        &["analyze", "@cube:2", "--lines", "1e4", "-o", "/dev/null"],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let null = Path::new("/dev/null").metadata().unwrap();
        assert!(
            null.file_type().is_char_device(),
            "/dev/null is still a device"
        );
    }
    for flag in ["--save", "--checkpoint"] {
        let out = scx_in(
            d,
            &["analyze", "@cube:2", "--lines", "1e4", flag, "/dev/null"],
        );
        assert_eq!(code(&out), Some(2), "{}", stderr(&out));
        assert!(
            stderr(&out).contains("not a regular file"),
            "{}",
            stderr(&out)
        );
        assert!(out.stdout.is_empty(), "refused before work");
    }
    std::fs::create_dir(d.join("folder")).unwrap();
    for args in [
        &["analyze", "@cube:2", "--lines", "1e4", "-o", "folder"][..],
        &["analyze", "@cube:2", "--lines", "1e4", "--save", "folder"],
        &["export", "@cube:2", "-o", "folder"],
    ] {
        let out = scx_in(d, args);
        assert_ne!(code(&out), Some(0), "{args:?}");
        assert!(
            stderr(&out).contains("directory"),
            "{args:?}: {}",
            stderr(&out)
        );
        assert!(out.stdout.is_empty(), "{args:?}: refused before work");
    }
    assert!(d.join("folder").is_dir());

    std::fs::write(d.join("target.txt"), "old").unwrap();
    std::fs::write(d.join("target.scx"), "old").unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("target.txt", d.join("link.txt")).unwrap();
        std::os::unix::fs::symlink("target.scx", d.join("link.scx")).unwrap();
        let out = scx_in(
            d,
            &[
                "analyze", "@cube:2", "--lines", "1e4", "-o", "link.txt", "--save", "link.scx",
            ],
        );
        assert_eq!(code(&out), Some(0), "{}", stderr(&out));
        for (link, target) in [("link.txt", "target.txt"), ("link.scx", "target.scx")] {
            let meta = std::fs::symlink_metadata(d.join(link)).unwrap();
            assert!(meta.file_type().is_symlink(), "{link} is still a link");
            assert_ne!(read(&d.join(target)), b"old", "{target} holds the output");
        }
        assert!(String::from_utf8_lossy(&read(&d.join("target.txt"))).contains("@cube:2"));
        let out = scx_in(d, &["merge", "link.scx"]);
        assert_eq!(
            code(&out),
            Some(0),
            "the state behind the link: {}",
            stderr(&out)
        );
    }
}

/// A save that fails (here the file-size limit, `ulimit -f`, with the signal ignored so that writes
/// fail with EFBIG) comes after the report: the report is printed whole, the failure is exit 3 naming
/// the file, and no temporary is left.
#[cfg(unix)]
#[test]
fn a_failed_save_keeps_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("s.scx"), "old state").unwrap();
    let out = Command::new("sh")
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 4; exec \"$0\" analyze @cube:2 --lines 1e4 --save s.scx")
        .arg(env!("CARGO_BIN_EXE_scx"))
        .current_dir(d)
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(code(&out), Some(3), "{err}");
    assert!(err.contains("cannot write s.scx"), "{err}");
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(
        report.contains("@cube:2") && report.contains("mutual"),
        "{report}"
    );
    assert_eq!(read(&d.join("s.scx")), b"old state");
    let left: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "s.scx")
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}");

    // A report that cannot be written (a full device) does not cost the state either.
    let out = scx_in(
        d,
        &[
            "analyze",
            "@cube:2",
            "--lines",
            "1e4",
            "-o",
            "/dev/full",
            "--save",
            "t.scx",
        ],
    );
    assert_eq!(code(&out), Some(3), "{}", stderr(&out));
    assert!(stderr(&out).contains("/dev/full"));
    assert_eq!(code(&scx_in(d, &["merge", "t.scx"])), Some(0));
}

/// Temporaries of scx's naming whose process is gone on this host are removed at the next save; those
/// of a live process, of another host, or holding a whole state are kept.
#[cfg(target_os = "linux")]
#[test]
fn stale_temporaries_are_cleaned_at_the_next_save() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = scx_in(
        d,
        &[
            "analyze",
            "@cube:2",
            "--lines",
            "1e4",
            "--save",
            "whole.scx",
        ],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    let (host, dead, live) = (host(), dead_pid(), std::process::id());
    let stale = [
        format!(".s.scx.{dead}@{host}.scx-tmp"),
        format!(".s.scx.{dead}.tmp"),
    ];
    let kept = [
        format!(".s.scx.{live}@{host}.scx-tmp"),
        format!(".s.scx.{dead}@another-host.scx-tmp"),
        format!(".t.scx.{dead}@{host}.scx-tmp"),
        format!(".s.scx.{}@{host}.scx-tmp", dead_pid()),
    ];
    for name in stale.iter().chain(&kept[..3]) {
        std::fs::write(d.join(name), "cut short").unwrap();
    }
    std::fs::copy(d.join("whole.scx"), d.join(&kept[3])).unwrap();
    let out = scx_in(
        d,
        &["analyze", "@cube:2", "--lines", "1e4", "--save", "s.scx"],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    for name in &stale {
        assert!(!d.join(name).exists(), "{name} should be cleaned");
    }
    for name in &kept {
        assert!(d.join(name).exists(), "{name} should be kept");
    }
}

/// A lock beside a state: a second run on a live one is refused naming the host and process; a lock
/// whose process is gone is taken over; the lock goes when the run ends.
#[cfg(target_os = "linux")]
#[test]
fn a_live_state_is_locked() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (host, live) = (host(), std::process::id());
    std::fs::write(d.join("c.scx.lock"), format!("{host} {live}\n")).unwrap();
    for flag in ["--checkpoint", "--save"] {
        let out = scx_in(d, &["analyze", "@cube:2", "--lines", "1e4", flag, "c.scx"]);
        let err = stderr(&out);
        assert_eq!(code(&out), Some(3), "{err}");
        assert!(
            err.contains(&host) && err.contains(&live.to_string()),
            "{err}"
        );
        assert!(out.stdout.is_empty());
    }
    assert!(!d.join("c.scx").exists());
    std::fs::write(d.join("c.scx.lock"), format!("{host} {}\n", dead_pid())).unwrap();
    let out = scx_in(
        d,
        &[
            "analyze",
            "@cube:2",
            "--lines",
            "1e4",
            "--checkpoint",
            "c.scx",
        ],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    assert!(d.join("c.scx").is_file());
    assert!(!d.join("c.scx.lock").exists(), "the lock is released");
}

/// Every output is written to a temporary and renamed into place: an existing file is replaced whole
/// (its permissions kept), and no temporary stays beside it.
#[test]
fn outputs_are_renamed_into_place() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for name in ["r.json", "p.csv", "ff.mtx", "m.obj", "m.mtl", "c.csv"] {
        std::fs::write(d.join(name), "old").unwrap();
    }
    let runs: &[&[&str]] = &[
        &[
            "analyze",
            "@cube:2",
            "--lines",
            "1e4",
            "--format",
            "json",
            "-o",
            "r.json",
            "--patches",
            "p.csv",
            "--form-factors",
            "ff.mtx",
        ],
        &["export", "@cube:2", "-o", "m.obj"],
        &["export", "@cube:2", "-o", "m.glb"],
        &[
            "convergence",
            "@cube:2",
            "--lines",
            "1e3,2e3",
            "--csv",
            "c.csv",
        ],
    ];
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::Permissions::from_mode(0o640);
        std::fs::set_permissions(d.join("r.json"), mode).unwrap();
    }
    for args in runs {
        let out = scx_in(d, args);
        assert_eq!(code(&out), Some(0), "{args:?}: {}", stderr(&out));
    }
    for name in [
        "r.json", "p.csv", "ff.mtx", "m.obj", "m.mtl", "c.csv", "m.glb",
    ] {
        let bytes = read(&d.join(name));
        assert!(bytes.len() > 10 && bytes != b"old", "{name}");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(d.join("r.json"))
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(
            mode & 0o777,
            0o640,
            "the replaced file keeps its permissions"
        );
    }
    let left: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(left.is_empty(), "temporaries left: {left:?}");
}

/// A state edited with its checksum recomputed is refused (exit 2, "inconsistent contents" and what is
/// wrong), never counted, wrapped around, looped over nor a panic: a pair key stored twice, 2^64 - 1 or
/// 2^32 - 1 patches (before any allocation for them), a group holding more lines than its batches, a
/// pair count or a counter no line could give, done batches beyond the plan.
#[test]
fn forged_states_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (header, doc) = saved_state(d, "1e4");
    let header = header.as_slice();
    let forge = |name: &str, change: &dyn Fn(&mut ciborium::Value)| {
        let mut doc = doc.clone();
        change(&mut doc);
        write_state(&d.join(name), header, &doc);
    };
    let int = |n: u64| ciborium::Value::Integer(n.into());
    let counter = |doc: &mut ciborium::Value, name: &str, n: u64| {
        *field(field(first_group(doc), "counters"), name) = int(n);
    };
    let cases: [(&str, &Edit<'_>, &str); 7] = [
        (
            "repeated.scx",
            &|doc| {
                let tally = first_group(doc);
                let steps = field(field(tally, "counts"), "key_steps");
                steps.as_array_mut().unwrap()[1] = int(0);
            },
            "not a sorted list of distinct keys",
        ),
        (
            "huge.scx",
            &|doc| {
                let scene = field(field(doc, "identity"), "scene");
                *field(scene, "patches") = int(u64::MAX);
            },
            "patches",
        ),
        (
            "many.scx",
            &|doc| {
                let scene = field(field(doc, "identity"), "scene");
                *field(scene, "patches") = int(u64::from(u32::MAX));
            },
            "says its scene has 4294967295 patches, the scene has 24",
        ),
        (
            "lines.scx",
            &|doc| counter(doc, "lines", 1 << 63),
            "group 0: it holds 9223372036854775808 lines",
        ),
        (
            "count.scx",
            &|doc| {
                let tally = first_group(doc);
                let values = field(field(tally, "counts"), "values");
                values.as_array_mut().unwrap()[0] = int(u64::MAX);
            },
            "pair counts add up to",
        ),
        (
            "pairs.scx",
            &|doc| counter(doc, "pairs", u64::MAX),
            "more pairs than crossings",
        ),
        (
            "done.scx",
            &|doc| {
                *field(doc, "done") =
                    ciborium::Value::Array(vec![ciborium::Value::Array(vec![int(0), int(1 << 40)])])
            },
            "not a range within",
        ),
    ];
    for (name, change, problem) in cases {
        forge(name, change);
        let started = std::time::Instant::now();
        for args in [vec!["merge", name], vec!["analyze", "--resume", name]] {
            let out = scx_in(d, &args);
            let err = stderr(&out);
            assert_eq!(code(&out), Some(2), "{args:?}: {err}");
            assert!(
                err.contains(name) && err.contains("inconsistent") && err.contains(problem),
                "{args:?}: {err}"
            );
        }
        assert!(started.elapsed().as_secs() < 60, "{name} took too long");
    }
}

/// A run is continued only by the scx version that started it: another version's lines or estimates may
/// differ, and `--resume` would mix them without a word. A state stamped with another version is refused
/// by `--resume` (exit 2, both versions named, the state file unchanged) and still reported by `merge`;
/// a forged version's control characters are not printed.
#[test]
fn another_versions_state_is_reported_but_not_continued() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (header, doc) = saved_state(d, "3e5");
    let header = header.as_slice();
    let stamp = |name: &str, version: &str| {
        let mut doc = doc.clone();
        *field(field(&mut doc, "identity"), "scx_version") = ciborium::Value::Text(version.into());
        write_state(&d.join(name), header, &doc)
    };
    let old = stamp("old.scx", "0.0.9");
    let out = scx_in(d, &["analyze", "--resume", "old.scx", "--lines", "6e5"]);
    let err = stderr(&out);
    assert_eq!(code(&out), Some(2), "{err}");
    let here = env!("CARGO_PKG_VERSION");
    assert!(
        err.contains("old.scx")
            && err.contains("started by scx 0.0.9")
            && err.contains(&format!("this is scx {here}")),
        "{err}"
    );
    assert_eq!(
        read(&d.join("old.scx")),
        old,
        "the refused state was rewritten"
    );
    let out = scx_in(d, &["merge", "old.scx"]);
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("@cube:2"));
    // This version's own state goes on.
    let out = scx_in(d, &["analyze", "--resume", "s.scx", "--lines", "6e5"]);
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    stamp("odd.scx", "9\u{1b}[31m\nred");
    let out = scx_in(d, &["analyze", "--resume", "odd.scx"]);
    let err = stderr(&out);
    assert_eq!(code(&out), Some(2), "{err}");
    assert!(
        !err.contains('\u{1b}') && err.contains("scx 9?[31m?red"),
        "{err}"
    );
}

/// A FIFO or a directory named as a state to resume or merge is refused, not read without end.
#[test]
fn states_are_read_from_regular_files_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let made = std::process::Command::new("mkfifo")
        .arg(d.join("pipe.scx"))
        .status()
        .unwrap();
    assert!(made.success());
    std::fs::create_dir(d.join("dir.scx")).unwrap();
    for name in ["pipe.scx", "dir.scx"] {
        for args in [vec!["merge", name], vec!["analyze", "--resume", name]] {
            let out = scx_in(d, &args);
            let err = stderr(&out);
            // `--resume` also writes the state back: a directory is refused as that output first.
            let (expected, words) = match (args[0], name) {
                ("analyze", "dir.scx") => (3, "it is a directory"),
                _ => (2, "not a regular file"),
            };
            assert_eq!(code(&out), Some(expected), "{args:?}: {err}");
            assert!(err.contains(words), "{args:?}: {err}");
        }
    }
}

/// Runs `@cube:2` for `lines` lines in `d`, saved to `s.scx`: its state's first 24 bytes (magic, format
/// version, length, checksum) and its CBOR document.
fn saved_state(d: &std::path::Path, lines: &str) -> (Vec<u8>, ciborium::Value) {
    let out = scx_in(
        d,
        &["analyze", "@cube:2", "--lines", lines, "--save", "s.scx"],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    let bytes = read(&d.join("s.scx"));
    let (header, payload) = bytes.split_at(24);
    (header.to_vec(), ciborium::from_reader(payload).unwrap())
}

/// Writes a state of the CBOR document `doc` to `path` behind the magic and format version of `header`
/// (a state's first 24 bytes), with its length and checksum recomputed; returns the bytes written.
fn write_state(path: &std::path::Path, header: &[u8], doc: &ciborium::Value) -> Vec<u8> {
    let mut payload = Vec::new();
    ciborium::into_writer(doc, &mut payload).unwrap();
    let mut out = header[..12].to_vec();
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    std::fs::write(path, &out).unwrap();
    out
}

/// An edit of a state's CBOR document.
type Edit<'a> = dyn Fn(&mut ciborium::Value) + 'a;

/// The tally of the first group of a state's CBOR document.
fn first_group(doc: &mut ciborium::Value) -> &mut ciborium::Value {
    &mut field(doc, "groups").as_array_mut().unwrap()[0]
}

/// The value of `key` in the CBOR map `v`.
fn field<'a>(v: &'a mut ciborium::Value, key: &str) -> &'a mut ciborium::Value {
    let map = v.as_map_mut().unwrap();
    &mut map
        .iter_mut()
        .find(|(k, _)| k.as_text() == Some(key))
        .unwrap()
        .1
}

/// A folder that takes no new file (immutable, `chattr +i`: even root cannot create a file there) is
/// found before any line is traced, for a state, a checkpoint and a report, even when the state file
/// itself exists and is writable (the temporary and the rename need the folder). Skipped where
/// `chattr` does not work (not root, or a file system without the attribute).
#[test]
fn a_folder_that_takes_no_file_is_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let locked = d.join("locked");
    std::fs::create_dir(&locked).unwrap();
    std::fs::write(locked.join("s.scx"), b"old").unwrap();
    let chattr = |flag: &str| {
        Command::new("chattr")
            .arg(flag)
            .arg(&locked)
            .status()
            .is_ok_and(|s| s.success())
    };
    if !chattr("+i") {
        eprintln!("skipped: chattr +i does not work here");
        return;
    }
    let cases = [
        vec!["--save", "locked/s.scx"],
        vec!["--save", "locked/new.scx"],
        vec!["--checkpoint", "locked/c.scx"],
        vec!["-o", "locked/report.txt"],
    ];
    let mut failures = Vec::new();
    for extra in cases {
        let mut args = vec!["analyze", "@cube:2", "--lines", "1e8"];
        args.extend(&extra);
        let started = Instant::now();
        let out = scx_in(d, &args);
        let err = stderr(&out);
        if code(&out) != Some(3) || !err.contains("locked/") || started.elapsed().as_secs() > 20 {
            failures.push(format!(
                "{extra:?}: exit {:?} after {:?}: {err}",
                code(&out),
                started.elapsed()
            ));
        }
    }
    chattr("-i");
    assert_eq!(std::fs::read(locked.join("s.scx")).unwrap(), b"old");
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A FIFO named as the report is written into as a stream (a reader gets the whole report), never
/// replaced by a file.
#[test]
fn a_fifo_as_the_report_is_a_stream() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fifo = d.join("report.fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let out = scx_in(
        d,
        &[
            "analyze",
            "@cube:2",
            "--lines",
            "1e4",
            "--format",
            "json",
            "-o",
            "report.fifo",
        ],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    let text = reader.join().unwrap();
    assert!(
        text.contains("\"schema_version\"") && text.trim_end().ends_with('}'),
        "{text}"
    );
    let kind = std::fs::symlink_metadata(&fifo).unwrap().file_type();
    assert!(std::os::unix::fs::FileTypeExt::is_fifo(&kind));
}

/// Checks a refusal of the command line or the input: exit 2, every `expected` part in the message,
/// and none of the text of a parser that does not say what is wanted.
fn assert_usage(out: &Output, expected: &[&str]) {
    let err = stderr(out);
    assert_eq!(code(out), Some(2), "{err}");
    for e in expected {
        assert!(err.contains(e), "`{e}` not in: {err}");
    }
    assert!(
        !err.contains("invalid digit") && !err.contains("Some("),
        "{err}"
    );
}

/// Numeric flags say what they accept (issue 28: `--groups 1e9` said "invalid digit found in
/// string"): the flag, and its range.
#[test]
fn numeric_flags_name_their_range() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [(&[&str], &[&str]); 11] = [
        (
            &["analyze", "@cube:3", "--groups", "1e9"],
            &["--groups", "number of groups", "from 2 to 1024"],
        ),
        (
            &["analyze", "@cube:3", "--threads", "1e5"],
            &["--threads", "from 0 to 4096"],
        ),
        (
            &["analyze", "@cube:3", "--bundle", "x"],
            &["--bundle", "from 0 to 64"],
        ),
        (
            &["convergence", "@cube:2", "--repeats", "0"],
            &["--repeats", "from 1 to 1000"],
        ),
        (&["reproduce", "--table", "10"], &["--table", "from 1 to 9"]),
        (
            &["crosscheck", "@cube:2", "--show", "-1"],
            &["--show", "cannot be negative", "from 0"],
        ),
        (
            &["calibrate", "--scene", "@cube", "--seeds", "0"],
            &["--seeds", "runs per cell", "from 1"],
        ),
        (
            &["convergence", "@cube:2", "--lines", "-1,5"],
            &["--lines", "cannot be negative"],
        ),
        (
            &["reproduce", "--table", "-1,2"],
            &["--table", "cannot be negative"],
        ),
        (
            &[
                "render", "@cube:2", "--color", "segments", "-o", "c.png", "--camera", "--quiet",
            ],
            &["--camera", "`--quiet` is a flag, not a value"],
        ),
        (
            &["convergence", "@cube:2", "--lines", "1e3,-q"],
            &["--lines", "`-q` is a flag, not a value"],
        ),
    ];
    for (args, expected) in cases {
        assert_usage(&scx_in(d, args), expected);
    }
    // Lists that start with a negative number are values, not flags.
    let out = scx_in(
        d,
        &[
            "render",
            "@cube:2",
            "--color",
            "mutual-information",
            "--lines",
            "1e4",
            "-o",
            "c.png",
            "--camera",
            "-0.5,0.5,2.5,0.5,0.5,0.5,0,1,0,50",
            "--range",
            "-1,1",
        ],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
}

/// `refine --patches 0` speaks of patches, not of "a line count"; a target beyond the largest scene scx
/// builds (2^22 patches) is refused.
#[test]
fn refine_patches_says_what_it_needs() {
    let dir = tempfile::tempdir().unwrap();
    let out = scx_in(
        dir.path(),
        &[
            "refine",
            "@cube:2",
            "--strategy",
            "uniform",
            "--patches",
            "0",
            "-o",
            "r.obj",
        ],
    );
    assert_usage(&out, &["--patches", "number of patches", "from 1"]);
    assert!(!stderr(&out).contains("line count"), "{}", stderr(&out));
    assert!(!dir.path().join("r.obj").exists());
    // A target no memory could hold is refused before any round, with the largest one allowed.
    let out = scx_in(
        dir.path(),
        &[
            "refine",
            "@cube:2",
            "--strategy",
            "uniform",
            "--patches",
            "1e15",
            "-o",
            "r.obj",
        ],
    );
    assert_usage(&out, &["--patches", "from 1 to 4194304"]);
    assert!(!dir.path().join("r.obj").exists());
}

/// Durations take units (`30s`, `5m`, `1h30m`) as well as plain seconds; garbage says what a duration
/// is; a duration with units beyond the clock is no limit, as plain seconds are.
#[test]
fn durations_take_units() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for extra in [
        &["--seconds", "5m"][..],
        &["--seconds", "1h30m"],
        &["--seconds", "99999999999999999999h"],
        &["--checkpoint-every", "30s", "--checkpoint", "c.scx"],
    ] {
        let mut args = vec!["analyze", "@cube:2", "--lines", "2e4", "--format", "json"];
        args.extend_from_slice(extra);
        let out = scx_in(d, &args);
        assert_eq!(code(&out), Some(0), "{extra:?}: {}", stderr(&out));
        let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(report["sphere_lines"], 20_000, "{extra:?}");
    }
    for bad in ["abc", "0s", "-5", "5 parsecs"] {
        let out = scx_in(d, &["analyze", "@cube:2", "--seconds", bad]);
        assert_usage(&out, &["--seconds", "30s", "1h30m"]);
    }
}

/// A flag whose list is optional, put before the scene, takes the scene as its list: the error says
/// so and how to write it.
#[test]
fn a_list_flag_that_took_the_scene_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("scene.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    for flag in ["--two-sided", "--flip-normals"] {
        let out = scx_in(d, &["analyze", flag, "scene.obj"]);
        assert_usage(
            &out,
            &[
                &format!("{flag} took `scene.obj` as its list"),
                "put the scene first",
                "--",
            ],
        );
    }
    let out = scx_in(d, &["crosscheck", "--aimed", "@cube:2"]);
    assert_usage(&out, &["--aimed took `@cube:2` as its list"]);
    // The hint is for that case only: a missing scene with no list flag is clap's message alone.
    let out = scx_in(d, &["analyze", "--lines", "1e3"]);
    assert_eq!(code(&out), Some(2));
    assert!(!stderr(&out).contains("hint"), "{}", stderr(&out));
}

/// Makes the states of shard `k` of 2 of a run of `@cube:2` (with `more` settings) in `dir`.
fn shard_state(dir: &Path, k: u32, file: &str, more: &[&str]) {
    let shard = format!("{k}/2");
    let mut args = vec![
        "analyze", "@cube:2", "--lines", "1e4", "--shard", &shard, "--save", file, "-q",
    ];
    args.extend_from_slice(more);
    let out = scx_in(dir, &args);
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
}

/// `scx merge` refuses a state given twice, under one name or two (`./s2.scx`), naming it, before
/// reading any (issue 28: it said "s2.scx cannot join s1.scx").
#[test]
fn a_state_given_twice_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    shard_state(d, 1, "s1.scx", &[]);
    shard_state(d, 2, "s2.scx", &[]);
    let out = scx_in(d, &["merge", "s1.scx", "s2.scx", "s2.scx"]);
    assert_usage(&out, &["s2.scx is given twice", "name each state once"]);
    assert!(!stderr(&out).contains("cannot join"));
    let out = scx_in(d, &["merge", "s1.scx", "s2.scx", "./s2.scx"]);
    assert_usage(&out, &["given twice", "s2.scx and ./s2.scx"]);
    assert_eq!(code(&scx_in(d, &["merge", "s1.scx", "s2.scx"])), Some(0));
}

/// States of different runs are refused with both values in words: no Rust debug text, switches as
/// on/off, shards counted, scenes named.
#[test]
fn merge_differences_read_as_words() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Through the sphere, as --enclose draws: the settings differ in one thing each time.
    let sphere = ["--lines-through", "sphere"];
    shard_state(d, 1, "s1.scx", &sphere);
    shard_state(d, 2, "enclosed.scx", &["--enclose"]);
    let out = scx_in(
        d,
        &[
            "analyze",
            "@cube:2",
            "--lines",
            "1e4",
            "--save",
            "whole.scx",
            "-q",
            sphere[0],
            sphere[1],
        ],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    let out = scx_in(d, &["merge", "s1.scx", "whole.scx"]);
    assert_usage(
        &out,
        &["they differ in shard count (not sharded against 2 shards)"],
    );
    let out = scx_in(d, &["merge", "s1.scx", "enclosed.scx"]);
    assert_usage(&out, &["they differ in enclose (on against off)"]);
    assert!(!stderr(&out).contains("true"), "{}", stderr(&out));
}

/// Merging a state that a live run still holds (its `FILE.lock` names a running process) warns that
/// the merge may miss that run's latest batches, and merges.
#[cfg(target_os = "linux")]
#[test]
fn merging_a_live_state_warns() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    shard_state(d, 1, "s1.scx", &[]);
    shard_state(d, 2, "s2.scx", &[]);
    let live = std::process::id();
    std::fs::write(d.join("s2.scx.lock"), format!("{} {live}\n", host())).unwrap();
    let out = scx_in(d, &["merge", "s1.scx", "s2.scx"]);
    let err = stderr(&out);
    assert_eq!(code(&out), Some(0), "{err}");
    assert!(
        err.contains("warning: s2.scx is still being written by process")
            && err.contains(&live.to_string())
            && err.contains(&host())
            && err.contains("may miss its latest batches"),
        "{err}"
    );
    assert!(!err.contains("s1.scx is still"), "{err}");
    // A lock whose process is gone is no warning.
    std::fs::write(
        d.join("s2.scx.lock"),
        format!("{} {}\n", host(), dead_pid()),
    )
    .unwrap();
    let out = scx_in(d, &["merge", "s1.scx", "s2.scx"]);
    assert_eq!(code(&out), Some(0));
    assert!(
        !stderr(&out).contains("still being written"),
        "{}",
        stderr(&out)
    );
}

/// A report's format is the one `--format` gives, else the one the extension of `-o` names (`.json`,
/// `.csv`, in any case), else the table; `-o -` is standard output in the default format. A `--format`
/// the extension contradicts, and an extension naming a format the command does not write, are refused
/// before any work (exit 2, both named, nothing written), by every command that takes `-o`.
#[test]
fn the_extension_of_o_picks_the_format_and_contradictions_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let analyze = [
        "analyze",
        "@cube:2",
        "--lines",
        "1e4",
        "--threads",
        "1",
        "-q",
    ];
    let written = |extra: &[&str], file: &str| {
        let args: Vec<&str> = analyze.iter().chain(extra).copied().collect();
        let out = scx_in(d, &args);
        assert_eq!(code(&out), Some(0), "{args:?}: {}", stderr(&out));
        std::fs::read_to_string(d.join(file)).unwrap()
    };
    let json: serde_json::Value =
        serde_json::from_str(&written(&["-o", "r.json", "--save", "s.scx"], "r.json")).unwrap();
    assert_eq!(json["patches"], 24);
    assert!(written(&["-o", "r.CSV"], "r.CSV").starts_with("scene,lines,seed,"));
    assert!(written(&["-o", "r.txt"], "r.txt").starts_with("scene    @cube:2"));
    assert!(written(&["-o", "r", "--format", "json"], "r").starts_with('{'));
    let out = scx_in(d, &[&analyze[..], &["-o", "-"]].concat());
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("scene    @cube:2"));
    let out = scx_in(
        d,
        &["merge", "s.scx", "--threads", "1", "-q", "-o", "m.json"],
    );
    assert_eq!(code(&out), Some(0), "{}", stderr(&out));
    let merged: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("m.json")).unwrap()).unwrap();
    assert_eq!(merged["lines"], json["lines"]);
    let refused: [(&[&str], &str, &[&str]); 8] = [
        (
            &["--format", "table", "-o", "x.json"],
            "x.json",
            &["--format table and -o x.json disagree", ".json names JSON"],
        ),
        (
            &["--format", "json", "-o", "x.csv"],
            "x.csv",
            &["--format json and -o x.csv disagree", ".csv names CSV"],
        ),
        (
            &[
                "merge",
                "s.scx",
                "--threads",
                "1",
                "--format",
                "csv",
                "-o",
                "x.json",
            ],
            "x.json",
            &["--format csv and -o x.json disagree"],
        ),
        (
            &["convergence", "@cube:2", "--threads", "1", "-o", "x.csv"],
            "x.csv",
            &[
                "-o x.csv names a CSV file",
                "scx convergence",
                "table or json only",
                "--csv FILE",
            ],
        ),
        (
            &[
                "reproduce",
                "--table",
                "1",
                "--threads",
                "1",
                "-o",
                "x.json",
            ],
            "x.json",
            &[
                "-o x.json names a JSON file",
                "scx reproduce",
                "Markdown only",
            ],
        ),
        (
            &[
                "calibrate",
                "--scene",
                "@cube:1",
                "--threads",
                "1",
                "-o",
                "x.csv",
            ],
            "x.csv",
            &["-o x.csv names a CSV file", "scx calibrate", "--csv FILE"],
        ),
        (
            &["crosscheck", "@cube:1", "--threads", "1", "-o", "x.json"],
            "x.json",
            &["-o x.json names a JSON file", "scx crosscheck"],
        ),
        (
            &["scenes", "-o", "x.csv"],
            "x.csv",
            &["-o x.csv names a CSV file", "scx scenes"],
        ),
    ];
    for (args, file, expected) in refused {
        let args: Vec<&str> = if args[0].starts_with('-') {
            analyze.iter().chain(args).copied().collect()
        } else {
            args.to_vec()
        };
        let out = scx_in(d, &args);
        assert_usage(&out, expected);
        assert!(!d.join(file).exists(), "{args:?}: nothing written");
    }
}

/// Every option that writes files of one kind refuses another extension with one message, naming the
/// option, the file and the extension it takes (`convergence --csv x.txt` used to be taken).
#[test]
fn file_options_take_their_extension_only() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [(&[&str], &str, &str); 7] = [
        (&["analyze", "@cube:2"], "--patches", ".csv"),
        (&["analyze", "@cube:2"], "--objects", ".csv"),
        (&["analyze", "@cube:2"], "--form-factors", ".csv or .mtx"),
        (&["convergence", "@cube:2"], "--csv", ".csv"),
        (&["convergence", "@cube:2"], "--plot", ".svg or .png"),
        (&["calibrate", "--scene", "@cube:1"], "--csv", ".csv"),
        (&["calibrate", "--scene", "@cube:1"], "--readings", ".csv"),
    ];
    for (command, option, extensions) in cases {
        let mut args = command.to_vec();
        args.extend_from_slice(&["--lines", "1e3", "--threads", "1", option, "x.txt"]);
        let out = scx_in(d, &args);
        assert_usage(
            &out,
            &[&format!(
                "{option} x.txt: {option} writes {extensions} files only; name one ending in \
                 {extensions}"
            )],
        );
        assert!(!d.join("x.txt").exists(), "{args:?}: nothing written");
    }
}

/// A resume refused for its line count says so in the unit of `--lines`, the sphere's lines, though the
/// run draws its lines through the cube's box: the most it names is the most it takes, and the count it
/// names for full batches is the least that draws them.
#[test]
fn resume_refusals_count_lines_as_lines_does() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let first = scx_in(
        d,
        &[
            "analyze",
            "@cube:4",
            "--lines",
            "1e5",
            "--save",
            "s.scx",
            "-q",
            "--threads",
            "1",
        ],
    );
    assert_eq!(code(&first), Some(0), "{}", stderr(&first));
    let number_after = |text: &str, words: &str| -> u64 {
        let at = text
            .find(words)
            .unwrap_or_else(|| panic!("`{words}` not in: {text}"))
            + words.len();
        let digits: String = text[at..]
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        digits.parse().unwrap()
    };
    let refused = scx_in(d, &["analyze", "--resume", "s.scx", "--lines", "2e5", "-q"]);
    assert_eq!(code(&refused), Some(2));
    let err = stderr(&refused);
    assert!(
        err.contains("a run of 100000 lines") && err.contains("200000 lines would be"),
        "{err}"
    );
    assert!(err.contains("as --lines counts them"), "{err}");
    let most = number_after(&err, "here at most ");
    let full = number_after(&err, "Runs of ");
    for (lines, ok) in [(most, true), (most + 1, false)] {
        std::fs::copy(d.join("s.scx"), d.join("t.scx")).unwrap();
        let args = [
            "analyze",
            "--resume",
            "t.scx",
            "--lines",
            &lines.to_string(),
            "-q",
        ];
        let out = scx_in(d, &args);
        assert_eq!(code(&out) == Some(0), ok, "{lines}: {}", stderr(&out));
    }
    let drawn = |lines: u64| {
        let out = scx_in(
            d,
            &[
                "analyze",
                "@cube:4",
                "--lines",
                &lines.to_string(),
                "--format",
                "json",
                "-q",
            ],
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        doc["lines"].as_u64().unwrap()
    };
    // Full batches (4096 lines) from 131072 lines drawn on: `full` draws them, one line fewer does not.
    assert!(drawn(full) >= 131_072 && drawn(full - 1) < 131_072);
    let fewer = scx_in(d, &["analyze", "--resume", "s.scx", "--lines", "5e4", "-q"]);
    assert!(
        stderr(&fewer).contains("to fewer lines (50000)"),
        "{}",
        stderr(&fewer)
    );
}
