//! The `scx` binary's radiosity report, `scx refine`, and its errors (exit code 2 naming file and material).

use crate::support;

use support::{json_of, scx};

use std::path::Path;

#[test]
fn cornell_json_has_the_radiosity_object() {
    let out = scx(&[
        "analyze", "@cornell", "--lines", "2e4", "--tracer", "rust", "--format", "json",
    ]);
    let doc = json_of(&out);
    let r = &doc["radiosity"];
    for key in ["positional_entropy", "entropy", "mutual_information"] {
        assert!(r[key]["value"].as_f64().unwrap().is_finite(), "{key}: {r}");
        assert!(r[key]["stderr"].as_f64().unwrap() > 0.0, "{key}: {r}");
    }
    assert!(r["solver_residual"].as_f64().unwrap() <= 1e-10);
    assert!(r["solver_iterations"].as_u64().unwrap() > 0);
    assert_eq!(r["excluded_patches"], 0);
    assert!(doc["radiosity_skipped"].is_null());
    // H_p - H_s = I_s holds for the transformed scene as for any closed one, up to sampling.
    let v = |k: &str| r[k]["value"].as_f64().unwrap();
    assert!(v("positional_entropy") > v("mutual_information"));
}

#[test]
fn scenes_without_light_say_why_radiosity_is_left_out() {
    let doc = json_of(&scx(&[
        "analyze", "@cube:2", "--lines", "1e4", "--tracer", "rust", "--format", "json",
    ]));
    assert!(doc["radiosity"].is_null());
    assert!(doc["radiosity_skipped"]
        .as_str()
        .unwrap()
        .contains("nothing emits"));
    let doc = json_of(&scx(&[
        "analyze",
        "@cornell",
        "--lines",
        "1e4",
        "--tracer",
        "rust",
        "--format",
        "json",
        "--measures",
        "continuous",
    ]));
    assert!(doc["radiosity"].is_null());
    assert!(doc["radiosity_skipped"]
        .as_str()
        .unwrap()
        .contains("not requested"));
    let table = scx(&["analyze", "@cube", "--lines", "1e4", "--tracer", "rust"]);
    assert!(String::from_utf8_lossy(&table.stdout)
        .contains("radiosity measures left out: nothing emits"));
    // Asked for alone, the radiosity measures of a scene without light leave nothing to compute: refused
    // before any line is cast (it printed an empty report and exited 0), as `render --color radiosity`.
    let alone = scx(&[
        "analyze",
        "@cube:2",
        "--lines",
        "1e4",
        "--measures",
        "radiosity",
    ]);
    assert_eq!(alone.status.code(), Some(2));
    assert!(alone.stdout.is_empty());
    assert!(String::from_utf8_lossy(&alone.stderr).contains("nothing in this scene emits"));
    // With light they are computed.
    let lit = json_of(&scx(&[
        "analyze",
        "@cornell",
        "--lines",
        "1e4",
        "--measures",
        "radiosity",
        "--format",
        "json",
    ]));
    assert!(lit["radiosity"].is_object());
}

#[test]
fn table_and_csv_show_the_radiosity_measures() {
    let table = scx(&["analyze", "@cornell", "--lines", "1e4", "--tracer", "rust"]);
    let text = String::from_utf8_lossy(&table.stdout);
    for label in [
        "radiosity positional entropy H_p",
        "radiosity entropy H_s",
        "radiosity mutual information I_s",
        "Gauss-Seidel",
    ] {
        assert!(text.contains(label), "{label} missing:\n{text}");
    }
    let csv = scx(&[
        "analyze", "@cornell", "--lines", "1e4", "--tracer", "rust", "--format", "csv",
    ]);
    let text = String::from_utf8_lossy(&csv.stdout);
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| l.contains(",radiosity,mutual_information,bit,"))
        .collect();
    assert_eq!(rows.len(), 1, "{text}");
    // The room's lines are drawn through its box, worth the 10000 asked through the sphere.
    assert!(rows[0].starts_with("@cornell,6366,1,rust,"), "{text}");
    assert!(rows[0].ends_with(",10000,box"), "{text}");
}

/// A closed room (unit cube, quads facing in) with one emitting wall, as OBJ + MTL.
fn write_room(dir: &Path, mtl: &str) -> String {
    let obj = dir.join("room.obj");
    let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n";
    // Corner k has bits (x = 1, y = 2, z = 4); each face listed counter-clockwise seen from inside.
    let faces = "usemtl lamp\nf 1 3 7 5\nusemtl wall\nf 2 6 8 4\nf 1 5 6 2\nf 3 4 8 7\nf 1 2 4 3\nf 5 7 8 6\n";
    std::fs::write(&obj, format!("mtllib room.mtl\n{v}{faces}")).unwrap();
    std::fs::write(dir.join("room.mtl"), mtl).unwrap();
    obj.display().to_string()
}

#[test]
fn bad_materials_are_exit_code_2_naming_file_and_material() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\nnewmtl wall\nKd 1.2 1.5 1.2\n",
            "`wall`",
            "room.mtl:4: material `wall`: reflectance (Kd) red channel is 1.2",
        ),
        (
            "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 -1\nnewmtl wall\nKd 0.5 0.5 0.5\n",
            "`lamp`",
            "room.mtl:1: material `lamp`: emission (Ke) blue channel is -1",
        ),
        (
            "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\nnewmtl wall\nKd 0.5 1.5 0.5\n",
            "`wall`",
            "green channel is 1.5; each channel must be in [0, 1]",
        ),
        (
            "newmtl lamp\nKd 1 1 1\nKe 1 1 1\nnewmtl wall\nKd 1 1 1\n",
            "`lamp`",
            "no finite solution",
        ),
    ];
    for (mtl, material, problem) in cases {
        let obj = write_room(dir.path(), mtl);
        let out = scx(&["analyze", &obj, "--lines", "1e4", "--tracer", "rust"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{mtl}: {err}");
        // The library with the material (room.mtl) or, for the solve, the scene (room.obj).
        let stem = obj.trim_end_matches(".obj");
        for needle in [stem, material, problem] {
            assert!(err.contains(needle), "`{needle}` missing from: {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
    }
    // A valid room: the lamp's Ke is read, and the radiosity measures appear.
    let obj = write_room(
        dir.path(),
        "newmtl lamp\nKd 0.5 0.5 0.5\nKe 1 1 1\nnewmtl wall\nKd 0.6 0.6 0.6\n",
    );
    let doc = json_of(&scx(&[
        "analyze", &obj, "--lines", "1e4", "--tracer", "rust", "--format", "json",
    ]));
    assert!(doc["radiosity"]["mutual_information"]["value"].is_f64());
}

#[test]
fn refine_writes_a_mesh_that_analyze_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("mesh.obj");
    let mesh_s = mesh.display().to_string();
    let out = scx(&[
        "refine",
        "@cornell",
        "--strategy",
        "power",
        "--patches",
        "50",
        "--lines",
        "2e4",
        "--tracer",
        "rust",
        "-o",
        &mesh_s,
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("wrote"), "{err}");
    assert!(mesh.with_extension("mtl").exists());
    let doc = json_of(&scx(&[
        "analyze", &mesh_s, "--lines", "2e4", "--tracer", "rust", "--format", "json",
    ]));
    let n = doc["patches"].as_u64().unwrap();
    assert!((50..=52).contains(&n), "{n}");
    assert_eq!(doc["escapes"], 0, "the refined box is still closed");
    assert!(doc["radiosity"]["mutual_information"]["value"].is_f64());
}

#[test]
fn refine_errors_are_clear() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("m.obj").display().to_string();
    let out = scx(&[
        "refine",
        "@cube",
        "--strategy",
        "power",
        "--patches",
        "20",
        "-o",
        &mesh,
        "--tracer",
        "rust",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("nothing in this scene emits"), "{err}");
    let out = scx(&[
        "refine",
        "@cornell",
        "--strategy",
        "uniform",
        "--patches",
        "40",
        "-o",
        &mesh,
        "--growth",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("growth"));
}

/// Refine only splits patches: a target below the scene's count is refused (exit 2, naming the count)
/// and writes nothing; the count itself writes the scene as it is, and says so.
#[test]
fn refine_below_the_scenes_patch_count_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("m.obj");
    let mesh_s = mesh.display().to_string();
    let refine = |patches: &str| {
        scx(&[
            "refine",
            "@cornell",
            "--strategy",
            "uniform",
            "--patches",
            patches,
            "-o",
            &mesh_s,
            "--threads",
            "1",
        ])
    };
    let out = refine("10");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--patches 10: @cornell already has 29 patches")
            && err.contains("only splits patches"),
        "{err}"
    );
    assert!(!mesh.exists(), "nothing written");
    let out = refine("29");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("@cornell already has 29 patches (--patches 29): no patch is split"),
        "{err}"
    );
    let doc = json_of(&scx(&[
        "analyze",
        &mesh_s,
        "--lines",
        "1e3",
        "--threads",
        "1",
        "--format",
        "json",
        "-q",
    ]));
    assert_eq!(doc["patches"], 29);
}
