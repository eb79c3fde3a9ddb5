//! A scene file is untrusted input (issue 28): whatever a file holds, `scx` may not read outside the
//! scene's folder, allocate without bound, loop, or hang on a special file. Every case here is a small
//! fixture written into a fresh folder; each run must end in seconds, under a 1 GiB address-space
//! limit, with exit code 0 or 2, one clear message naming the file and the problem, and never a
//! panic's text.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use base64::Engine as _;
use serde_json::{json, Value};

/// The longest any hostile case may run (generous for a loaded machine: each takes well under a second).
const TIME_LIMIT: Duration = Duration::from_secs(30);
/// The address space each run gets (`ulimit -v`, KiB): 1 GiB.
const MEMORY_LIMIT_KIB: u64 = 1 << 20;

/// Runs `scx` with `args` (and standard input from `stdin`, or none) under the time and memory limits,
/// and checks what every run must show: exit code 0 or 2, no panic text.
fn run(args: &[&str], stdin: Option<&Path>) -> Output {
    let mut shell = format!("ulimit -v {MEMORY_LIMIT_KIB}; exec \"$0\"");
    for k in 1..=args.len() {
        shell.push_str(&format!(" \"${k}\""));
    }
    let mut command = Command::new("sh");
    command
        .arg("-c")
        .arg(shell)
        .arg(env!("CARGO_BIN_EXE_scx"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    command.stdin(match stdin {
        Some(path) => Stdio::from(std::fs::File::open(path).expect("stdin file")),
        None => Stdio::null(),
    });
    let start = Instant::now();
    let mut child = command.spawn().expect("scx runs");
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            panic!("{args:?}: still running after {TIME_LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("output");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        matches!(out.status.code(), Some(0 | 2)),
        "{args:?}: exit {:?}: {err}",
        out.status
    );
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{args:?}: {err}"
    );
    out
}

/// `scx analyze` of a scene with few lines and the pure-Rust tracer, under [`run`].
fn analyze(scene: &str, more: &[&str]) -> Output {
    let mut args = vec!["analyze", scene, "--lines", "1000", "--tracer", "rust"];
    args.extend_from_slice(more);
    run(&args, None)
}

/// Checks a refusal: exit code 2, nothing on stdout, one error line holding every `expected` part.
fn assert_refused(out: &Output, expected: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(out.stdout.is_empty(), "a report on stdout: {err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.contains("error")).collect();
    assert_eq!(errors.len(), 1, "one message: {err}");
    for e in expected {
        assert!(errors[0].contains(e), "`{e}` not in: {err}");
    }
}

/// Checks a success, and that its warnings hold every `expected` part.
fn assert_read(out: &Output, expected: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    for e in expected {
        assert!(err.contains(e), "`{e}` not in: {err}");
    }
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> String {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path.display().to_string()
}

/// A FIFO (named pipe) at `path`, made by `mkfifo`.
fn fifo(path: &Path) {
    let made = Command::new("mkfifo").arg(path).status().expect("mkfifo");
    assert!(made.success());
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// The little-endian bytes of f32 positions.
fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A data URI holding `bytes`.
fn data_uri(bytes: &[u8]) -> String {
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// A glTF of one triangle whose one buffer is at `uri`.
fn triangle_gltf(uri: &str) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
        "buffers": [{"uri": uri, "byteLength": 36}],
    })
}

/// The 36 bytes of the triangle's three positions.
fn triangle_bytes() -> Vec<u8> {
    f32_bytes(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0])
}

/// A glTF of a 4 x 4 grid of vertices (9 quads, 18 triangles, 54 u32 indices) with the index accessor
/// changed by `edit`; everything in one data URI.
fn indexed_gltf(edit: impl FnOnce(&mut Value)) -> Value {
    let mut positions = Vec::new();
    for k in 0..16 {
        positions.extend([(k % 4) as f32, (k / 4) as f32, 0.0]);
    }
    let mut indices: Vec<u32> = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            let a = i * 4 + j;
            indices.extend([a, a + 1, a + 5, a, a + 5, a + 4]);
        }
    }
    let mut buffer = f32_bytes(&positions);
    let index_start = buffer.len();
    buffer.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 16, "type": "VEC3",
             "min": [0, 0, 0], "max": [3, 3, 0]},
            {"bufferView": 1, "componentType": 5125, "count": 54, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": index_start},
            {"buffer": 0, "byteOffset": index_start, "byteLength": buffer.len() - index_start},
        ],
        "buffers": [{"uri": data_uri(&buffer), "byteLength": buffer.len()}],
    });
    edit(&mut doc);
    doc
}

fn write_json(dir: &Path, name: &str, doc: &Value) -> String {
    write(dir, name, serde_json::to_string(doc).unwrap().as_bytes())
}

/// A folder with a scene in it and, beside the folder, a secret the scene must not reach.
struct Setup {
    _root: tempfile::TempDir,
    scenes: PathBuf,
    secret: PathBuf,
}

fn setup(secret_name: &str, secret: &[u8]) -> Setup {
    let root = tempfile::tempdir().unwrap();
    let scenes = root.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    let secret_path = root.path().join(secret_name);
    std::fs::write(&secret_path, secret).unwrap();
    Setup {
        _root: root,
        scenes,
        secret: secret_path,
    }
}

/// glTF buffer URIs are read only inside the scene's folder: an absolute path (plain or
/// percent-encoded), `..`, a `file:` URI and a link out of the folder are refused (before: read, and
/// `scx export` wrote the file's bytes out as vertices); a URL is never fetched; `--read-anywhere`
/// lets the absolute path through.
#[test]
fn hostile_gltf_buffers_outside_the_folder_are_not_read() {
    let s = setup("secret.bin", &triangle_bytes());
    let secret = s.secret.display().to_string();
    #[cfg(unix)]
    std::os::unix::fs::symlink(&s.secret, s.scenes.join("link.bin")).unwrap();
    let encoded = secret.replace('/', "%2F");
    for (name, uri, expected) in [
        ("absolute", secret.as_str(), "is an absolute path"),
        ("dotdot", "../secret.bin", "climbs out with `..`"),
        ("encoded", encoded.as_str(), "is an absolute path"),
        ("link", "link.bin", "through a link"),
        ("file", &format!("file://{secret}"), "`file:` URI"),
        (
            "remote",
            "https://example.com/secret.bin",
            "never from a network",
        ),
    ] {
        if name == "link" && !cfg!(unix) {
            continue;
        }
        let path = write_json(&s.scenes, &format!("{name}.gltf"), &triangle_gltf(uri));
        assert_refused(&analyze(&path, &[]), &[&path, "buffer 0", expected]);
        let out_obj = s.scenes.join(format!("{name}-out.obj"));
        let out = run(
            &["export", &path, "-o", &out_obj.display().to_string()],
            None,
        );
        assert_refused(&out, &[&path, expected]);
        assert!(!out_obj.exists(), "{name}: an export was written");
    }
    let path = s.scenes.join("absolute.gltf").display().to_string();
    assert_read(&analyze(&path, &["--read-anywhere"]), &[]);
    // Inside the folder (a subfolder, `..` that stays inside) is fine.
    std::fs::create_dir(s.scenes.join("sub")).unwrap();
    write(&s.scenes, "sub/inside.bin", &triangle_bytes());
    let path = write_json(
        &s.scenes,
        "inside.gltf",
        &triangle_gltf("sub/../sub/inside.bin"),
    );
    assert_read(&analyze(&path, &[]), &[]);
}

/// The Kd of the materials `scx export` writes for a scene.
fn exported_colours(scene: &str, dir: &Path, more: &[&str]) -> (Output, String) {
    let out_obj = dir.join("exported.obj");
    let mut args = vec!["export", scene, "-o"];
    let out_path = out_obj.display().to_string();
    args.push(&out_path);
    args.extend_from_slice(more);
    let out = run(&args, None);
    let mtl = std::fs::read_to_string(out_obj.with_extension("mtl")).unwrap_or_default();
    (out, mtl)
}

/// An OBJ's `mtllib` is read only inside its folder: the name as written, then its base name there (as
/// other OBJ readers do); one outside is not opened, and the warning says why (before: `/etc/passwd` was
/// opened).
#[test]
fn hostile_mtllib_outside_the_folder_is_not_read() {
    let s = setup("secret.mtl", b"newmtl m\nKd 0.125 0.25 0.375\n");
    let secret = s.secret.display().to_string();
    for (name, library) in [("absolute", secret.as_str()), ("dotdot", "../secret.mtl")] {
        let obj = format!("mtllib {library}\n{TRIANGLE}usemtl m\nf 1 2 3\n");
        let path = write(&s.scenes, &format!("{name}.obj"), obj.as_bytes());
        let (out, mtl) = exported_colours(&path, &s.scenes, &[]);
        assert_read(
            &out,
            &["material library not loaded", "outside the scene's folder"],
        );
        assert!(!mtl.contains("0.125"), "{name}: the secret was read: {mtl}");
        let (out, mtl) = exported_colours(&path, &s.scenes, &["--read-anywhere"]);
        assert_read(&out, &[]);
        assert!(mtl.contains("Kd 0.125 0.25 0.375"), "{name}: {mtl}");
    }
    // A library of the same base name in the folder is read instead.
    write(&s.scenes, "secret.mtl", b"newmtl m\nKd 0.5 0.75 0.875\n");
    let path = s.scenes.join("absolute.obj").display().to_string();
    let (out, mtl) = exported_colours(&path, &s.scenes, &[]);
    assert_read(&out, &[]);
    assert!(mtl.contains("Kd 0.5 0.75 0.875"), "{mtl}");
}

/// Only regular files are read: a device or a FIFO as the scene, as a glTF buffer or as an MTL library
/// is refused at once (before: `/dev/zero` grew to the memory limit, a FIFO hung forever).
#[cfg(unix)]
#[test]
fn hostile_special_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let not_regular = "not a regular file";
    assert_refused(
        &analyze("/dev/zero", &[]),
        &["/dev/zero", "a device", not_regular],
    );
    fifo(&d.join("scene.obj"));
    let scene_fifo = d.join("scene.obj").display().to_string();
    assert_refused(&analyze(&scene_fifo, &[]), &["a FIFO", not_regular]);

    fifo(&d.join("pipe.bin"));
    let path = write_json(d, "pipe.gltf", &triangle_gltf("pipe.bin"));
    assert_refused(&analyze(&path, &[]), &["buffer 0", "a FIFO", not_regular]);
    let path = write_json(d, "zero.gltf", &triangle_gltf("/dev/zero"));
    assert_refused(
        &analyze(&path, &["--read-anywhere"]),
        &["buffer 0", "a device"],
    );

    fifo(&d.join("pipe.mtl"));
    let obj = format!("mtllib pipe.mtl\n{TRIANGLE}f 1 2 3\n");
    let path = write(d, "pipe.obj", obj.as_bytes());
    assert_read(
        &analyze(&path, &[]),
        &["material library not loaded", "a FIFO"],
    );
    let obj = format!("mtllib /dev/zero\n{TRIANGLE}f 1 2 3\n");
    let path = write(d, "zero.obj", obj.as_bytes());
    assert_read(&analyze(&path, &["--read-anywhere"]), &["a device"]);
}

/// Standard input is read like a file: bytes in no format scx reads are refused after a look at their
/// start (before: `/dev/zero` and `/dev/urandom` grew to the memory limit, and garbage exited 3 where
/// a garbage file exits 2); a scene of any format can come that way.
#[cfg(target_os = "linux")]
#[test]
fn hostile_standard_input_is_read_like_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["analyze", "-", "--lines", "1000", "--tracer", "rust"];
    let out = run(&args, Some(Path::new("/dev/zero")));
    assert_refused(
        &out,
        &["<stdin>", "scx reads OBJ, glTF (.gltf, .glb), PLY and STL"],
    );
    let out = run(&args, Some(Path::new("/dev/urandom")));
    assert_refused(&out, &["<stdin>"]);
    let garbage: Vec<u8> = (0..1000u32)
        .map(|k| (k * 7919 % 251) as u8 | 0x80)
        .collect();
    let garbage_file = write(dir.path(), "garbage.obj", &garbage);
    let from_file = analyze(&garbage_file, &[]);
    let from_stdin = run(&args, Some(Path::new(&garbage_file)));
    assert_refused(&from_file, &["not a text file"]);
    assert_refused(&from_stdin, &["<stdin>", "not a text file"]);
    let stl = write(dir.path(), "tri.stl", &binary_stl(1, 1));
    assert_read(&run(&args, Some(Path::new(&stl))), &[]);
}

/// A binary STL whose header says `said` triangles and which holds `has` (a triangle in z = 0).
fn binary_stl(said: u32, has: u32) -> Vec<u8> {
    let mut bytes = vec![b'x'; 80];
    bytes.extend(said.to_le_bytes());
    for _ in 0..has {
        bytes.extend(f32_bytes(&[0.0, 0.0, 1.0]));
        bytes.extend(triangle_bytes());
        bytes.extend([0, 0]);
    }
    bytes
}

/// Files larger than `--max-file-size` are refused with their size and the limit; a library read many
/// times is read once (before: 20 `mtllib` lines of one library read it 20 times, 3 GB).
#[test]
fn hostile_sizes_are_bounded_and_libraries_read_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut library = String::new();
    for k in 0..20_000 {
        library.push_str(&format!("newmtl m{k}\nKd 0.5 0.5 0.5\nKe 0 0 0\nNs 10\n"));
    }
    write(d, "big.mtl", library.as_bytes());
    let obj = format!(
        "{}{TRIANGLE}usemtl m7\nf 1 2 3\n",
        "mtllib big.mtl\n".repeat(20)
    );
    let path = write(d, "repeat.obj", obj.as_bytes());
    let (out, mtl) = exported_colours(&path, d, &[]);
    assert_read(&out, &[]);
    assert_eq!(
        mtl.matches("newmtl").count(),
        20_000 + 1,
        "each material once (and the default)"
    );
    assert_read(
        &analyze(&path, &["--max-file-size", "100KB"]),
        &[
            "material library not loaded",
            "more than the",
            "--max-file-size",
        ],
    );
    assert_refused(
        &analyze(&path, &["--max-file-size", "100"]),
        &[
            &path,
            "more than the 100 bytes scx reads",
            "--max-file-size",
        ],
    );
    let path = write_json(d, "tri.gltf", &triangle_gltf("tri.bin"));
    let mut padded = triangle_bytes();
    padded.resize(2000, 0);
    write(d, "tri.bin", &padded);
    assert_refused(
        &analyze(&path, &["--max-file-size", "900"]),
        &["buffer 0", "more than the 900 bytes"],
    );
    assert_read(&analyze(&path, &["--max-file-size", "4KiB"]), &[]);
}

/// glTF nodes must form trees: a node its own child, a cycle, a shared child and an exponential graph
/// (each node's two children the same node) are refused at once (before: 2.3 GB in 8 s, then abort).
#[test]
fn hostile_gltf_node_graphs_are_trees() {
    let dir = tempfile::tempdir().unwrap();
    let with_nodes = |nodes: Value, roots: Value| {
        let mut doc = triangle_gltf(&data_uri(&triangle_bytes()));
        doc["nodes"] = nodes;
        doc["scenes"][0]["nodes"] = roots;
        doc
    };
    let exponential: Vec<Value> = (0..40)
        .map(|k| json!({"mesh": 0, "children": [k + 1, k + 1]}))
        .chain(std::iter::once(json!({"mesh": 0})))
        .collect();
    for (name, nodes, roots, expected) in [
        (
            "self",
            json!([{"mesh": 0, "children": [0]}]),
            json!([0]),
            "its own ancestor",
        ),
        (
            "cycle",
            json!([{"children": [1]}, {"mesh": 0, "children": [2]}, {"children": [1]}]),
            json!([0]),
            "nodes 1 -> 2 -> 1",
        ),
        (
            "shared",
            json!([{"children": [2]}, {"children": [2]}, {"mesh": 0}]),
            json!([0, 1]),
            "a child of node 0 and of node 1",
        ),
        (
            "exponential",
            Value::Array(exponential),
            json!([0]),
            "listed twice among the children",
        ),
        (
            "root twice",
            json!([{"mesh": 0}]),
            json!([0, 0]),
            "twice among its root nodes",
        ),
        (
            "root and child",
            json!([{"children": [1]}, {"mesh": 0}]),
            json!([0, 1]),
            "a root node of its scene and a child of node 0",
        ),
    ] {
        let path = write_json(
            dir.path(),
            &format!("{name}.gltf"),
            &with_nodes(nodes, roots),
        );
        assert_refused(&analyze(&path, &[]), &[&path, expected]);
    }
    // A proper tree still reads, each node once.
    let tree = with_nodes(
        json!([{"children": [1, 2]}, {"mesh": 0}, {"mesh": 0, "translation": [2, 0, 0]}]),
        json!([0]),
    );
    let path = write_json(dir.path(), "tree.gltf", &tree);
    assert_read(&analyze(&path, &[]), &[]);
}

/// Accessors that do not fit their buffers, strides below their elements, index types scx does not
/// read and index counts that are no multiple of 3 are each refused with what is wrong (before:
/// ignored and read as unindexed, a dropped triangle, a panic's text, or "no POSITION attribute").
#[test]
fn hostile_gltf_accessors_must_fit_their_buffers() {
    let dir = tempfile::tempdir().unwrap();
    let fine = write_json(dir.path(), "fine.gltf", &indexed_gltf(|_| {}));
    let out = analyze(&fine, &["--format", "json"]);
    assert_read(&out, &[]);
    let cases: Vec<(&str, Value, &str)> = vec![
        (
            "count",
            indexed_gltf(|d| d["accessors"][1]["count"] = json!(1u64 << 31)),
            "do not fit in its buffer view 1",
        ),
        (
            "offset",
            indexed_gltf(|d| d["accessors"][1]["byteOffset"] = json!(1u64 << 63)),
            "do not fit in its buffer view 1",
        ),
        (
            "not triples",
            indexed_gltf(|d| d["accessors"][1]["count"] = json!(53)),
            "53 indices: a list of triangles needs a multiple of 3",
        ),
        (
            "float indices",
            indexed_gltf(|d| d["accessors"][1]["componentType"] = json!(5126)),
            "holds FLOAT: indices are",
        ),
        (
            "stride",
            indexed_gltf(|d| d["bufferViews"][0]["byteStride"] = json!(4)),
            "byte stride of 4, less than its 12-byte elements",
        ),
        (
            "view past buffer",
            indexed_gltf(|d| d["bufferViews"][0]["byteLength"] = json!(100_000)),
            "its POSITION accessor 0: its buffer view 0 (bytes 0 to 100000) does not fit",
        ),
        (
            "short positions",
            indexed_gltf(|d| d["accessors"][0]["componentType"] = json!(5123)),
            "holds UNSIGNED_SHORT VEC3: scx reads positions as FLOAT VEC3",
        ),
        (
            "sparse backwards",
            indexed_gltf(|d| {
                d["accessors"][1]["sparse"] = json!({"count": 2,
                    "indices": {"bufferView": 1, "componentType": 5125, "byteOffset": 8},
                    "values": {"bufferView": 1}});
            }),
            "sparse index",
        ),
        (
            // Found by fuzzing: gltf-json's validation indexed the accessors with it unchecked.
            "no such accessor",
            indexed_gltf(|d| d["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(5)),
            "its POSITION accessor 5 does not exist",
        ),
        (
            "version 1",
            indexed_gltf(|d| d["asset"]["version"] = json!("1.0")),
            "glTF version `1.0`: scx reads glTF 2.0",
        ),
    ];
    for (name, doc, expected) in cases {
        let path = write_json(dir.path(), &format!("{name}.gltf"), &doc);
        assert_refused(&analyze(&path, &[]), &[&path, expected]);
    }
}

/// A mesh placed by very many nodes counts once per node against the read limit (a small file could
/// otherwise ask for any amount of memory).
#[test]
fn hostile_gltf_instancing_is_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = indexed_gltf(|_| {});
    let nodes: Vec<Value> = (0..2000)
        .map(|k| json!({"mesh": 0, "translation": [k, 0, 0]}))
        .collect();
    doc["nodes"] = Value::Array(nodes);
    doc["scenes"][0]["nodes"] = json!((0..2000).collect::<Vec<_>>());
    let path = write_json(dir.path(), "many.gltf", &doc);
    assert_read(&analyze(&path, &[]), &[]);
    assert_refused(
        &analyze(&path, &["--max-file-size", "200KB"]),
        &[
            "the meshes its nodes place hold more than",
            "--max-file-size",
        ],
    );
}

/// A face of 100,000 corners (a circle whose coordinates are rounded to 6 digits, so that some corners
/// turn the wrong way by a hair) reads in well under a second (before: 43 s and more: quadratic ear
/// clipping, then a bounding volume hierarchy over 100,000 slivers); a concave one too intricate for
/// ear clipping's bound is refused with a message.
#[test]
fn hostile_huge_polygons_take_bounded_time() {
    let dir = tempfile::tempdir().unwrap();
    let n = 100_000;
    let mut obj = String::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        obj.push_str(&format!("v {:.6} {:.6} 0\n", a.cos(), a.sin()));
    }
    let corners: Vec<String> = (1..=n).map(|k| k.to_string()).collect();
    obj.push_str(&format!("f {}\n", corners.join(" ")));
    let path = write(dir.path(), "circle.obj", obj.as_bytes());
    let out = analyze(&path, &["--format", "json"]);
    assert_read(&out, &[]);
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let area = report["area"].as_f64().unwrap_or(f64::NAN);
    assert!((area - std::f64::consts::PI).abs() < 1e-3, "area {area}");

    let teeth = 30_000;
    let mut comb = String::new();
    for k in 0..teeth {
        comb.push_str(&format!("v {k} 0 0\nv {k}.5 1000 0\n"));
    }
    comb.push_str(&format!("v {teeth} -1 0\nv 0 -1 0\n"));
    let corners: Vec<String> = (1..=2 * teeth + 2).map(|k| k.to_string()).collect();
    comb.push_str(&format!("f {}\n", corners.join(" ")));
    let path = write(dir.path(), "comb.obj", comb.as_bytes());
    assert_refused(
        &analyze(&path, &[]),
        &["line ", "too intricate to cut into triangles"],
    );
}

/// Built-in scene parameters are checked against a patch limit before anything is built (before:
/// `@cube:2000` aborted on allocation).
#[test]
fn hostile_built_in_parameters_are_bounded() {
    for (spec, max) in [
        ("@cube:2000", "836"),
        ("@icosahedron:1000", "457"),
        ("@octahedron:1000", "724"),
    ] {
        assert_refused(
            &analyze(spec, &[]),
            &[spec, "a built-in scene may have", max],
        );
    }
}

/// Messages name the real problem: an STL longer than its header says is not "cut short", a radius
/// beyond f64 is not "no extent", nor a radius that underflows when squared.
#[test]
fn hostile_messages_name_the_real_problem() {
    let dir = tempfile::tempdir().unwrap();
    let long = write(dir.path(), "long.stl", &binary_stl(1, 2));
    assert_refused(
        &analyze(&long, &[]),
        &[
            &long,
            "says 1 triangles (134 bytes), the file has 184 bytes",
            "it holds 50 bytes more than its header's 1 triangles need",
            "data after the triangles",
        ],
    );
    let short = write(dir.path(), "short.stl", &binary_stl(3, 2));
    assert_refused(
        &analyze(&short, &[]),
        &["it holds 50 bytes fewer than its header's 3 triangles need (cut short?)"],
    );
    // Found by fuzzing: a .glb header whose length is less than the header (the gltf crate's
    // unchecked subtraction).
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(0u32.to_le_bytes());
    glb.extend([0; 24]);
    let glb = write(dir.path(), "short.glb", &glb);
    assert_refused(
        &analyze(&glb, &[]),
        &[&glb, "less than the header's own 12"],
    );
    let huge = write(
        dir.path(),
        "huge.obj",
        b"v 0 0 0\nv 1e308 0 0\nv -1e308 1e308 0\nf 1 2 3\n",
    );
    assert_refused(
        &analyze(&huge, &[]),
        &[
            &huge,
            "too large to measure",
            "radius 1e-50 to 1e50",
            "rescale it",
        ],
    );
    // A box 1e-200 across is no point: it is too small (its radius underflowed to 0 when squared).
    let tiny = write(
        dir.path(),
        "tiny.obj",
        b"v 0 0 0\nv 1e-200 0 0\nv 0 1e-200 0\nf 1 2 3\n",
    );
    assert_refused(
        &analyze(&tiny, &[]),
        &[&tiny, "too small to measure", "rescale it"],
    );
    // Just inside the limits, areas (and the environment's, enclosed) are finite and positive.
    for scale in ["1e49", "1e-49"] {
        let obj = format!("v 0 0 0\nv {scale} 0 0\nv 0 {scale} 0\nf 1 2 3\n");
        let path = write(dir.path(), "edge.obj", obj.as_bytes());
        let out = analyze(&path, &["--enclose", "--format", "json"]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        for area in [&doc["area"], &doc["environment_area"]["value"]] {
            let a = area.as_f64().unwrap_or_else(|| panic!("{scale}: {area}"));
            assert!(a.is_finite() && a > 0.0, "{scale}: {a}");
        }
    }
    let point = write(
        dir.path(),
        "point.obj",
        b"v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n",
    );
    let out = analyze(&point, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains("too small"), "{err}");
}
