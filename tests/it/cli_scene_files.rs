//! Scenes from the wild through the `scx` binary (issue 15): the public test models of tinyobjloader
//! (when `../shared/real-scenes/` is beside the crate), undefined measures, unknown formats, glTF export.

use std::path::{Path, PathBuf};

use crate::support::{json_of, scx};

/// The public OBJ corpus, if it is there (it is not part of the project).
fn corpus() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()?
        .join("shared/real-scenes/tinyobjloader");
    dir.is_dir().then_some(dir)
}

/// The files of the corpus that are not valid scenes, and why: each must be refused with exit code 2 and
/// a message naming the file and a line.
const INVALID: &[(&str, &str)] = &[
    ("invalid-face-definition.obj", "a face with 1 vertex"),
    ("invalid-relative-texture-index.obj", "no vertices"),
    ("invalid-relative-vertex-index.obj", "no vertices"),
    ("issue-140-zero-face-idx.obj", "vertex index 0"),
    ("test-nan.obj", "NaN vertices"),
    ("line-prim.obj", "lines only, no faces"),
    ("points-prim.obj", "points only, no faces"),
    ("issue-356-leading-spaces-newmtl.obj", "no faces"),
];

/// Every valid file analyses (exit 0); every invalid one exits 2 naming the file and the line.
#[test]
fn the_tinyobjloader_models_analyse_or_are_refused_with_file_and_line() {
    let Some(dir) = corpus() else {
        eprintln!("skipped: ../shared/real-scenes/tinyobjloader is not there");
        return;
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    assert!(files.len() >= 40, "{} files", files.len());
    for path in &files {
        let name = path.file_name().unwrap().to_str().unwrap();
        let shown = path.display().to_string();
        let out = scx(&[
            "analyze", &shown, "--lines", "2e4", "--tracer", "rust", "--format", "json",
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{name}: {err}");
        if INVALID.iter().any(|(n, _)| *n == name) {
            assert_eq!(out.status.code(), Some(2), "{name}: {err}");
            let line = err.lines().find(|l| l.contains("error")).unwrap_or("");
            let names_line = line.contains(&format!("{shown}:")) || line.contains(": line ");
            assert!(line.contains(&shown) && names_line, "{name}: {err}");
        } else {
            assert_eq!(out.status.code(), Some(0), "{name}: {err}");
        }
    }
}

/// The two Cornell boxes among them (non-planar left walls, split now) give finite visibility measures,
/// and with `--enclose` every row of the enclosed channel sums to 1: no escape is left.
#[test]
fn the_public_cornell_boxes_give_finite_measures() {
    let Some(dir) = corpus() else {
        eprintln!("skipped: ../shared/real-scenes/tinyobjloader is not there");
        return;
    };
    for name in ["cornell_box.obj", "cornell_box_multimaterial.obj"] {
        let path = dir.join(name).display().to_string();
        let doc = json_of(&scx(&[
            "analyze", &path, "--lines", "1e5", "--tracer", "rust", "--format", "json",
        ]));
        for key in [
            "entropy",
            "mutual_information",
            "continuous_mutual_information",
        ] {
            let v = doc["visibility"][key]["value"].as_f64();
            assert!(v.is_some_and(f64::is_finite), "{name}: {key} {v:?}");
        }
        assert!(
            doc["escape_fraction"].as_f64().unwrap() > 0.0,
            "{name}: the box is open"
        );

        let scene = scene_complexity::load(&path).unwrap();
        let tracer = scene_complexity::make_tracer(
            scene_complexity::Backend::Rust,
            &scene,
            scene_complexity::Query::Single,
        )
        .unwrap();
        let cfg = scene_complexity::RunSpec {
            enclose: true,
            ..scene_complexity::RunSpec::new(100_000, 1)
        };
        let a =
            scene_complexity::analyze(&scene, tracer.as_ref(), &cfg, &Default::default()).unwrap();
        let (enclosed, _) = a.tally.enclosed(&scene);
        let mut rows = vec![0u64; scene.patch_count() + 1];
        enclosed.counts.as_ref().unwrap().for_each(|i, j, k| {
            rows[i as usize] += k;
            if i != j {
                rows[j as usize] += k;
            }
        });
        assert!(enclosed.escapes_by_patch.dense().iter().all(|&e| e == 0));
        // Every patch some line left has a row summing to 1: N_ij / N_i over j, with nothing escaping.
        let sampled = rows.iter().filter(|&&r| r > 0).count();
        assert!(sampled >= scene.patch_count(), "{name}: {sampled} rows");
        let mi = a.estimate(scene_complexity::Measure::MutualInformation);
        assert!(mi.unwrap().value.is_finite());
    }
}

/// A room exported with outward normals: exit 0, the visibility measures `null` in JSON and a sentence in
/// the table, a warning naming the object and the flag; `--flip-normals` gives measures.
#[test]
fn a_scene_without_pairs_reports_undefined_measures() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box.obj");
    std::fs::write(
        &path,
        "o box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    let path = path.display().to_string();
    let json = scx(&[
        "analyze", &path, "--lines", "2e4", "--tracer", "rust", "--format", "json",
    ]);
    let doc = json_of(&json);
    for key in [
        "entropy",
        "mutual_information",
        "continuous_mutual_information",
        "mse_per_line",
    ] {
        assert!(
            doc["visibility"][key].is_null(),
            "{key}: {}",
            doc["visibility"][key]
        );
    }
    assert!(doc["visibility"]["positional_entropy"]["value"].is_f64());
    let warnings = doc["warnings"].to_string();
    assert!(
        warnings.contains("no line segment joined two patches"),
        "{warnings}"
    );
    // As data: the stable code, the object by its name in the file, the counts behind the sentence.
    let all = doc["warnings"].as_array().unwrap();
    let no_pairs = all.iter().find(|w| w["code"] == "no-pairs").unwrap();
    assert_eq!(no_pairs["code"], "no-pairs", "{warnings}");
    assert_eq!(
        no_pairs["objects"],
        serde_json::json!(["box"]),
        "{warnings}"
    );
    assert_eq!(
        no_pairs["numbers"]["escapes"],
        doc["escapes"].as_f64().unwrap()
    );
    assert!(
        warnings.contains("`box`") && warnings.contains("--flip-normals"),
        "{warnings}"
    );

    let table = scx(&["analyze", &path, "--lines", "2e4", "--tracer", "rust"]);
    assert_eq!(table.status.code(), Some(0));
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(text.contains("visibility measures undefined"), "{text}");
    assert!(!text.contains("visibility entropy H_s"), "{text}");

    let flipped = json_of(&scx(&[
        "analyze",
        &path,
        "--lines",
        "2e4",
        "--tracer",
        "rust",
        "--format",
        "json",
        "--flip-normals",
    ]));
    assert!(flipped["visibility"]["entropy"]["value"].is_f64());
    assert_eq!(flipped["warnings"].as_array().unwrap().len(), 0);
}

/// A file in no format scx reads is refused naming it; a `.obj` that holds binary STL is read as STL;
/// `scx export -o x.gltf` writes glTF that analyses like the original.
#[test]
fn formats_come_from_the_content() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("notes.obj");
    std::fs::write(&junk, "hello, this is not a scene\n").unwrap();
    let junk = junk.display().to_string();
    let out = scx(&["analyze", &junk]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&junk) && err.contains("unknown scene format"),
        "{err}"
    );

    let gltf = dir.path().join("cornell.gltf").display().to_string();
    let out = scx(&["export", "@cornell", "-o", &gltf]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&gltf).unwrap();
    assert!(text.contains("\"asset\"") && text.contains("KHR_materials_emissive_strength"));
    let doc = json_of(&scx(&[
        "analyze", &gltf, "--lines", "1e5", "--tracer", "rust", "--format", "json",
    ]));
    let original = json_of(&scx(&[
        "analyze", "@cornell", "--lines", "1e5", "--tracer", "rust", "--format", "json", "--seed",
        "2",
    ]));
    let isc = |d: &serde_json::Value| {
        let e = &d["visibility"]["continuous_mutual_information"];
        (e["value"].as_f64().unwrap(), e["stderr"].as_f64().unwrap())
    };
    let (a, b) = (isc(&doc), isc(&original));
    assert!(
        (a.0 - b.0).abs() < 4.0 * (a.1 * a.1 + b.1 * b.1).sqrt(),
        "{a:?} {b:?}"
    );
    assert!((doc["area"].as_f64().unwrap() - original["area"].as_f64().unwrap()).abs() < 1.0);
}

/// I_s^c and its standard error from a JSON report.
fn continuous_isc(report: &serde_json::Value) -> (f64, f64) {
    let e = &report["visibility"]["continuous_mutual_information"];
    (e["value"].as_f64().unwrap(), e["stderr"].as_f64().unwrap())
}

/// `scx analyze SCENE --lines 1e5 --seed 3 --format json` (Rust tracer).
fn analyze_json(scene: &str) -> serde_json::Value {
    json_of(&scx(&[
        "analyze", scene, "--lines", "1e5", "--seed", "3", "--tracer", "rust", "--format", "json",
    ]))
}

/// A .glb's JSON chunk rewritten by `edit` (the binary chunk kept).
fn edit_glb(glb: &[u8], edit: impl Fn(&mut serde_json::Value)) -> Vec<u8> {
    let json_length = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_length]).unwrap();
    edit(&mut doc);
    let mut json = serde_json::to_vec(&doc).unwrap();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let bin = &glb[20 + json_length..];
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend(bin);
    out
}

/// glTF vertex attributes scx does not read are ignored, application-specific ones (`_s`, `_t` as
/// trimesh writes them, the specification's `_TEMPERATURE`) and names gltf-rs does not know alike
/// (before: exit 2, `attributes["<invalid semantic name>"]`): the file measures as the one without them,
/// bit for bit. A missing POSITION is still refused.
#[test]
fn gltf_application_specific_attributes_are_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_complexity::load("@cornell").unwrap();
    let plain = dir.path().join("plain.glb");
    std::fs::write(&plain, scene_complexity::gltf_bytes(&scene, true)).unwrap();
    let add_attributes = |doc: &mut serde_json::Value| {
        for mesh in doc["meshes"].as_array_mut().unwrap() {
            for primitive in mesh["primitives"].as_array_mut().unwrap() {
                let a = &mut primitive["attributes"];
                let position = a["POSITION"].clone();
                a["_s"] = position.clone();
                a["_t"] = position.clone();
                a["_TEMPERATURE"] = position.clone();
                a["VENDOR_THING"] = serde_json::json!(999);
            }
        }
    };
    let glb = dir.path().join("trimesh.glb");
    std::fs::write(
        &glb,
        edit_glb(&std::fs::read(&plain).unwrap(), add_attributes),
    )
    .unwrap();
    let mut doc: serde_json::Value =
        serde_json::from_slice(&scene_complexity::gltf_bytes(&scene, false)).unwrap();
    add_attributes(&mut doc);
    let gltf = dir.path().join("temperature.gltf");
    std::fs::write(&gltf, serde_json::to_vec(&doc).unwrap()).unwrap();

    let expected = analyze_json(&plain.display().to_string());
    for path in [&glb, &gltf] {
        let report = analyze_json(&path.display().to_string());
        assert_eq!(report["patches"], expected["patches"], "{path:?}");
        assert_eq!(
            continuous_isc(&report),
            continuous_isc(&expected),
            "{path:?}"
        );
    }
    doc["meshes"][0]["primitives"][0]["attributes"]
        .as_object_mut()
        .unwrap()
        .remove("POSITION");
    let missing = dir.path().join("missing.gltf");
    std::fs::write(&missing, serde_json::to_vec(&doc).unwrap()).unwrap();
    let out = scx(&["analyze", missing.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("missing.gltf") && err.contains("POSITION"),
        "{err}"
    );
}

/// A change to a glTF's JSON.
type GlbEdit = dyn Fn(&mut serde_json::Value);

/// A .glb whose buffer's byteLength is less than its views need, and one with a projective node
/// matrix, exit 2 naming the file and the buffer or node (both were read without a word); an OBJ with
/// Latin-1 names and comments is read (it exited 2, "not a text file").
#[test]
fn inconsistent_gltf_is_bad_input_and_latin_1_obj_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let scene = scene_complexity::load("@cornell").unwrap();
    let glb = scene_complexity::gltf_bytes(&scene, true);
    let cases: [(&str, &GlbEdit, &str); 2] = [
        (
            "short.glb",
            &|d| d["buffers"][0]["byteLength"] = 12.into(),
            "does not fit in buffer 0 of 12 bytes (its byteLength)",
        ),
        (
            "projective.glb",
            &|d| {
                d["nodes"][0]["matrix"] =
                    serde_json::json!([1, 0, 0, 0, 0, 1, 0, 2, 0, 0, 1, 0, 0, 0, 0, 1])
            },
            "its matrix is not affine (its last row is 0 2 0 1, not 0 0 0 1)",
        ),
    ];
    for (name, edit, expected) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, edit_glb(&glb, edit)).unwrap();
        let out = scx(&["analyze", path.to_str().unwrap(), "--lines", "1000"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains(&format!("{}: ", path.display())) && err.contains(expected),
            "{err}"
        );
    }
    let obj = dir.path().join("latin.obj");
    std::fs::write(
        &obj,
        b"# Soci\xe9t\xe9\no caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    let out = scx(&["analyze", obj.to_str().unwrap(), "--lines", "1000", "-q"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A glTF whose buffer file is missing names the file as the glTF writes it and as scx looked for it,
/// and says it was not found (exit 2; the message ended in "(os error 2)"); once the file is there, the
/// same glTF is read. `analyze` and `export` say the same.
#[test]
fn a_missing_gltf_buffer_is_named_and_not_found() {
    let dir = tempfile::tempdir().unwrap();
    let gltf = dir.path().join("tri.gltf");
    std::fs::write(
        &gltf,
        r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "buffers": [{"uri": "data/tri%20mesh.bin", "byteLength": 36}]}"#,
    )
    .unwrap();
    let resolved = dir.path().join("data/tri mesh.bin");
    let gltf_s = gltf.to_str().unwrap();
    let obj = dir.path().join("out.obj");
    for args in [
        vec!["analyze", gltf_s, "--lines", "1000", "--threads", "1"],
        vec!["export", gltf_s, "-o", obj.to_str().unwrap()],
    ] {
        let out = scx(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        let expected = format!(
            "{gltf_s}: buffer 0: the file `data/tri%20mesh.bin` (resolved as `{}`) was not found",
            resolved.display()
        );
        assert!(err.contains(&expected), "{args:?}: {err}");
        assert!(!err.contains("os error"), "{err}");
        assert!(out.stdout.is_empty() && !obj.exists(), "{args:?}");
    }
    let triangle: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    std::fs::create_dir(dir.path().join("data")).unwrap();
    std::fs::write(&resolved, triangle).unwrap();
    let doc = json_of(&scx(&[
        "analyze",
        gltf_s,
        "--lines",
        "1000",
        "--threads",
        "1",
        "--format",
        "json",
        "-q",
    ]));
    assert_eq!(doc["triangles"], 1);
}

/// `scx export -o` writes the format its extension names (before: OBJ text whatever the extension, and
/// an .mtl beside it): binary PLY (which reads back with the same patches and the same I_s^c bit for bit)
/// and binary STL (84 + 50 bytes per triangle), with no .mtl; a warning says what each cannot keep. Any
/// other extension is refused before work, exit 2, naming the ones scx writes.
#[test]
fn scene_export_writes_the_format_its_extension_names() {
    let dir = tempfile::tempdir().unwrap();
    let original = analyze_json("@cornell");
    let ply = dir.path().join("cornell.ply");
    let out = scx(&["export", "@cornell", "-o", ply.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("binary PLY holds no emission") && err.contains("`light`"),
        "{err}"
    );
    let bytes = std::fs::read(&ply).unwrap();
    assert!(bytes.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
    let report = analyze_json(ply.to_str().unwrap());
    assert_eq!(report["patches"], original["patches"]);
    assert_eq!(continuous_isc(&report), continuous_isc(&original));

    let stl = dir.path().join("cornell.stl");
    let out = scx(&["export", "@cornell", "-o", stl.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let triangles = scene_complexity::load("@cornell").unwrap().triangles.len();
    assert_eq!(
        std::fs::metadata(&stl).unwrap().len(),
        84 + 50 * triangles as u64
    );
    let report = analyze_json(stl.to_str().unwrap());
    assert_eq!(report["patches"].as_u64(), Some(triangles as u64));
    let (a, b) = (continuous_isc(&report), continuous_isc(&original));
    assert!((a.0 - b.0).abs() <= 4.0 * a.1.hypot(b.1), "{a:?} {b:?}");
    assert!(
        !dir.path().join("cornell.mtl").exists(),
        "no MTL beside PLY or STL"
    );

    // A scene of one object keeps its name through OBJ (it used to read back as tobj's
    // `unnamed_object`): `--flip-normals` can name it.
    let obj = dir.path().join("cube.obj");
    let out = scx(&["export", "@cube:2", "-o", obj.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let back = scene_complexity::load(obj.to_str().unwrap()).unwrap();
    assert_eq!(back.objects, ["@cube:2"]);

    for name in ["cornell.txt", "cornell", "cornell.mtl"] {
        let path = dir.path().join(name);
        let out = scx(&["export", "@cornell", "-o", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(
            err.contains(name) && err.contains(".obj (with its .mtl), .ply, .stl, .gltf, .glb"),
            "{name}: {err}"
        );
        assert!(!path.exists(), "{name}: refused before work");
    }
}

/// Every help text of a scene argument lists the formats scx reads and the built-ins; those of an
/// output scene list the formats it writes (before: `render` said "A scene file (OBJ)", `export` "OBJ +
/// MTL").
#[test]
fn scene_help_texts_list_the_formats() {
    for command in [
        "analyze",
        "export",
        "convergence",
        "refine",
        "crosscheck",
        "render",
    ] {
        let help = String::from_utf8_lossy(&scx(&[command, "--help"]).stdout).into_owned();
        assert!(
            help.contains("OBJ, glTF/GLB, PLY or STL") && help.contains("a built-in such as `@"),
            "{command}: {help}"
        );
    }
    for command in ["export", "refine"] {
        let help = String::from_utf8_lossy(&scx(&[command, "--help"]).stdout).into_owned();
        assert!(
            help.contains("`.ply` (binary PLY), `.stl` (binary STL), `.gltf` or `.glb`"),
            "{command}: {help}"
        );
    }
    let help = String::from_utf8_lossy(&scx(&["--help"]).stdout).into_owned();
    assert!(help.contains("OBJ + MTL, PLY, STL or glTF/GLB"), "{help}");
}

/// The count `export` prints is what the file reads back as: STL and glTF keep triangles only, so the
/// Cornell box's 29 patches (52 triangles) are said to go out as 52 triangles, a patch each when read
/// back (the message said "29 patches", the file read as 52); OBJ keeps the patches.
#[test]
fn export_says_how_many_patches_the_file_reads_back_as() {
    let dir = tempfile::tempdir().unwrap();
    for (name, says, reads_back) in [
        (
            "c.stl",
            "29 patches as 52 triangles (read back: a patch per triangle)",
            52,
        ),
        (
            "c.glb",
            "29 patches as 52 triangles (read back: a patch per triangle)",
            52,
        ),
        ("c.obj", "29 patches and", 29),
    ] {
        let path = dir.path().join(name);
        let out = scx(&["export", "@cornell", "-o", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success() && err.contains(says), "{name}: {err}");
        let report = json_of(&scx(&[
            "analyze",
            path.to_str().unwrap(),
            "--lines",
            "1e3",
            "--format",
            "json",
        ]));
        assert_eq!(report["patches"], reads_back, "{name}");
    }
}
