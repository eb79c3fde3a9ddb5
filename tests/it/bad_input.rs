//! Bad input through the `scx` binary (issue 8): every case gets one clear message naming the file (and
//! the line where it is known) and the problem, exit code 2, no panic and no report on stdout. A missing
//! MTL library is the one warning-only case.

use crate::support;

use support::scx;

use std::path::Path;

/// Runs `scx analyze` on `path` (a few lines, the pure-Rust tracer) and checks the one-error contract.
fn assert_rejected(args: &[&str], expected: &[&str]) {
    let out = scx(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        out.stdout.is_empty(),
        "{args:?}: a partial report on stdout"
    );
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    let errors: Vec<&str> = err.lines().filter(|l| l.contains("error")).collect();
    assert_eq!(errors.len(), 1, "{args:?}: one message: {err}");
    for e in expected {
        assert!(errors[0].contains(e), "{args:?}: `{e}` not in: {err}");
    }
}

fn write(dir: &Path, name: &str, text: &[u8]) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.display().to_string()
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// Each malformed OBJ names the file and the line of the statement at fault.
#[test]
fn malformed_obj_files_name_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&str, String, &[&str])] = &[
        (
            "short_vertex.obj",
            "v 0 0\nf 1 1 1\n".into(),
            &[":1:", "has 2 coordinate(s)"],
        ),
        (
            "letters.obj",
            format!("{TRIANGLE}v 1 x 0\nf 1 2 3\n"),
            &[":4:", "`x` is not a number"],
        ),
        (
            "nan.obj",
            format!("{TRIANGLE}v nan 0 0\nf 1 2 4\n"),
            &[":4:", "non-finite coordinate (NaN"],
        ),
        (
            "inf.obj",
            format!("v 0 0 -inf\n{TRIANGLE}f 2 3 4\n"),
            &[":1:", "non-finite coordinate"],
        ),
        (
            "two_corners.obj",
            format!("{TRIANGLE}f 1 2 3\nf 1 2\n"),
            &[":5:", "at least 3 vertices, it has 2"],
        ),
        (
            "one_corner.obj",
            format!("{TRIANGLE}\nf 3\n"),
            &[":5:", "it has 1"],
        ),
        (
            "bad_corner.obj",
            format!("{TRIANGLE}f 1 2 three\n"),
            &[":4:", "not a vertex index"],
        ),
        (
            "past_end.obj",
            format!("{TRIANGLE}f 1 2 7\n"),
            &[":4:", "refers to vertex 7, but the file has 3"],
        ),
    ];
    for (name, text, expected) in cases {
        let path = write(dir.path(), name, text.as_bytes());
        let mut want = vec![path.as_str()];
        want.extend_from_slice(expected);
        assert_rejected(
            &["analyze", &path, "--lines", "1000", "--tracer", "rust"],
            &want,
        );
    }
    // A bent quad is split into planar triangles, or refused in strict mode.
    let bent = write(
        dir.path(),
        "non_planar.obj",
        b"v 0 0 0\nv 1 0 0\nv 1 1 0.5\nv 0 1 0\n# a bent quad\nf 1 2 3 4\n",
    );
    assert_rejected(
        &[
            "analyze",
            &bent,
            "--lines",
            "1000",
            "--tracer",
            "rust",
            "--strict-planarity",
        ],
        &[&bent, "line 6: face 1", "non-planar polygon"],
    );
    let binary = write(
        dir.path(),
        "binary.obj",
        &[0x7f, 0x45, 0x4c, 0x46, 0xff, 0x00, 0x01],
    );
    assert_rejected(&["analyze", &binary], &[&binary, "not a text file"]);
}

/// No faces at all, a missing file and a directory.
#[test]
fn empty_and_missing_scenes_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let empty = write(dir.path(), "empty.obj", b"");
    assert_rejected(
        &["analyze", &empty],
        &[&empty, "the scene is empty: no faces"],
    );
    let only_vertices = write(dir.path(), "vertices.obj", TRIANGLE.as_bytes());
    assert_rejected(&["analyze", &only_vertices], &[&only_vertices, "empty"]);
    let degenerate = write(
        dir.path(),
        "flat.obj",
        b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    );
    assert_rejected(
        &["analyze", &degenerate],
        &[&degenerate, "no faces of non-zero area"],
    );
    assert_rejected(
        &["analyze", "/no/such/scene.obj"],
        &["/no/such/scene.obj", "no such file"],
    );
    let d = dir.path().display().to_string();
    assert_rejected(&["analyze", &d], &[&d, "is a directory"]);
}

/// Materials outside the physical range name the file and the material; a missing MTL library is a
/// warning (every face gets the default material) and the run goes on.
#[test]
fn bad_materials_are_errors_and_a_missing_library_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let obj = |mtl: &str| {
        format!("mtllib {mtl}\n{TRIANGLE}v 0 0 1\nusemtl m\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n")
    };
    for (name, mtl, expected) in [
        (
            "bright",
            "newmtl m\nKd 1.2 1.2 1.2\nKe 1 1 1\n",
            "reflectance (Kd) red channel is 1.2",
        ),
        (
            "red_only",
            "newmtl m\nKd 1.5 0 0\nKe 1 1 1\n",
            "reflectance (Kd) red channel is 1.5",
        ),
        (
            "negative",
            "newmtl m\nKd 0.5 0.5 -0.1\nKe 1 1 1\n",
            "reflectance (Kd) blue channel is -0.1",
        ),
        (
            "dark_light",
            "newmtl m\nKd 0.5 0.5 0.5\nKe 2 -2 2\n",
            "emission (Ke) green channel is -2",
        ),
    ] {
        let library = write(dir.path(), &format!("{name}.mtl"), mtl.as_bytes());
        let path = write(
            dir.path(),
            &format!("{name}.obj"),
            obj(&format!("{name}.mtl")).as_bytes(),
        );
        // The library and the line of the material's `newmtl`, checked per channel.
        assert_rejected(
            &["analyze", &path, "--lines", "1000", "--tracer", "rust"],
            &[&format!("{library}:1:"), "material `m`", expected],
        );
    }
    let path = write(dir.path(), "lost.obj", obj("nowhere.mtl").as_bytes());
    let out = scx(&[
        "analyze", &path, "--lines", "1000", "--tracer", "rust", "--format", "json",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("warning")
            && err.contains(&path)
            && err.contains("material library not loaded"),
        "{err}"
    );
    // The path looked for is named.
    let looked = dir.path().join("nowhere.mtl");
    assert!(
        err.contains(&format!("no file `{}`", looked.display())),
        "{err}"
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["patches"], 4);
    assert_eq!(doc["warnings"][0]["code"], "material-library");
    // A path from another machine: the name as written, then its base name in the scene's folder.
    let path = write(dir.path(), "moved.obj", obj("scenes/lib.mtl").as_bytes());
    let out = scx(&["analyze", &path, "--lines", "1000", "--tracer", "rust"]);
    let err = String::from_utf8_lossy(&out.stderr);
    let (written, base) = (
        dir.path().join("scenes/lib.mtl"),
        dir.path().join("lib.mtl"),
    );
    assert!(
        err.contains(&format!(
            "no file `{}`, nor `{}` (its base name",
            written.display(),
            base.display()
        )),
        "{err}"
    );
}

/// Command-line values: no lines, unknown built-in scenes and parameters out of range.
#[test]
fn bad_arguments_and_built_in_names_are_errors() {
    assert_rejected(
        &["analyze", "@cube", "--lines", "0"],
        &["--lines", "whole number from 1"],
    );
    // A negative value reaches the parser (not "unexpected argument '-5'") and gets a sentence.
    for args in [
        &["analyze", "@cube", "--lines=-5"][..],
        &["analyze", "@cube", "--lines", "-5"],
    ] {
        assert_rejected(args, &["--lines", "cannot be negative"]);
    }
    assert_rejected(
        &["analyze", "@cube", "--seed", "-1"],
        &["--seed", "cannot be negative"],
    );
    assert_rejected(
        &["analyze", "@nosuch"],
        &["@nosuch", "unknown built-in scene"],
    );
    for (spec, what) in [
        ("@cube:0", "from 1 to 2000"),
        ("@cube:3x", "not `3x`"),
        ("@sphere:9", "from 0 to 7"),
        ("@cornell:-1", "whole number"),
        ("@cubes512:3", "takes no parameter"),
    ] {
        assert_rejected(&["analyze", spec], &[spec, what]);
    }
}

/// Fuzzing findings, kept as regression tests (fuzz/README.md).
///
/// 1. An MTL colour with fewer than three values (`Kd 02 4`) made tobj 4.0.5 panic (an unwrap in its
///    `parse_float3`): now an error naming the MTL file and line.
#[test]
fn fuzzing_findings_stay_fixed() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "short.mtl", b"newmtl m\nKd 02 4\n");
    let obj = format!("mtllib short.mtl\n{TRIANGLE}usemtl m\nf 1 2 3\n");
    let path = write(dir.path(), "short.obj", obj.as_bytes());
    let mtl = dir.path().join("short.mtl").display().to_string();
    assert_rejected(
        &["analyze", &path, "--lines", "1000", "--tracer", "rust"],
        &[&format!("{mtl}:2:"), "`Kd` needs three numbers"],
    );
}
