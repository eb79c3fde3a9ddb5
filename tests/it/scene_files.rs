//! Scenes as users bring them (issue 15), through the library: non-planar and concave polygons, the OBJ
//! `w`, objects flipped or two-sided, the orientation diagnosis, glTF with node transforms, PLY and STL
//! in ASCII and binary, materials in RGB, and I_s^c the same whatever the format and the triangulation.

use scene_complexity::internals::measure::Measure;
use std::path::{Path, PathBuf};

use scene_complexity::internals::analysis::RunWarningKind;
use scene_complexity::internals::scene::{ObjectSet, Planarity, SceneOptions};
use scene_complexity::internals::scenes::load_with;
use scene_complexity::{
    analyze, load, make_tracer, Analysis, Backend, Measures, Query, RunControl, RunSpec, Scene,
};

use crate::support::room_with_box_obj;

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn load_file(path: &Path, options: &SceneOptions) -> Scene {
    load_with(path.to_str().unwrap(), options).unwrap_or_else(|e| panic!("{e}"))
}

fn run(scene: &Scene, lines: u64, seed: u64, measures: Measures) -> Analysis {
    let tracer = make_tracer(Backend::Rust, scene, Query::Single).unwrap();
    let cfg = RunSpec {
        measures,
        ..RunSpec::new(lines, seed)
    };
    analyze(scene, tracer.as_ref(), &cfg, &RunControl::default()).unwrap()
}

/// The sentences of a scene's warnings, one a line.
fn messages(warnings: &[scene_complexity::SceneWarning]) -> String {
    warnings
        .iter()
        .map(|w| w.message.as_str())
        .collect::<Vec<_>>()
        .join("\n")
}

fn kinds(a: &Analysis) -> Vec<RunWarningKind> {
    a.warnings.iter().map(|w| w.kind).collect()
}

/// A unit square with corner 3 lifted by h: two triangles along the shorter diagonal (1-3), whose areas
/// are 1/2 and sqrt(1 + 2 h^2) / 2; one warning naming the line; one patch under a looser tolerance; an
/// error in strict mode.
#[test]
fn a_slightly_non_planar_quad_becomes_two_planar_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let h: f64 = 2e-3;
    let obj = format!("o bent\nv 0 0 0\nv 1 0 0\nv 1 1 {h}\nv 0 1 0\nf 1 2 3 4\n");
    let path = write(dir.path(), "bent.obj", obj.as_bytes());
    let scene = load_file(&path, &SceneOptions::default());
    assert_eq!(scene.patch_count(), 2);
    let exact = 0.5 + 0.5 * (1.0 + 2.0 * h * h).sqrt();
    assert!((scene.total_area_scene_units() - exact).abs() < 1e-12);
    for p in &scene.patches {
        assert_eq!(scene.polygon(p).len(), 3);
        assert_eq!(scene.objects[p.object as usize], "bent");
    }
    let warning = messages(&scene.warnings);
    assert!(
        warning.contains("split 1 non-planar polygon") && warning.contains("line 6: face 1"),
        "{warning}"
    );

    let loose = SceneOptions {
        planarity: Planarity {
            tolerance: 1e-2,
            strict: false,
        },
        ..SceneOptions::default()
    };
    assert_eq!(load_file(&path, &loose).patch_count(), 1);
    // Two-sided: its back side is split too (4 patches), but it is still one polygon split in two.
    let both = SceneOptions {
        two_sided: ObjectSet::All,
        ..SceneOptions::default()
    };
    let two_sided = load_file(&path, &both);
    assert_eq!(two_sided.patch_count(), 4);
    let warning = messages(&two_sided.warnings);
    assert!(
        warning.contains(
            "split 1 non-planar polygon(s) into 2 planar triangles (and their back \
                          sides, two-sided: 2 more)"
        ),
        "{warning}"
    );
    let strict = SceneOptions {
        planarity: Planarity {
            tolerance: 1e-4,
            strict: true,
        },
        ..SceneOptions::default()
    };
    let e = load_with(path.to_str().unwrap(), &strict)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 6: face 1") && e.contains("non-planar polygon"),
        "{e}"
    );
}

/// An L-shaped floor (concave hexagon) is one patch of area 3, its triangles inside the L.
#[test]
fn a_concave_polygon_is_one_patch_with_the_right_area() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n";
    let scene = load_file(
        &write(dir.path(), "l.obj", obj.as_bytes()),
        &SceneOptions::default(),
    );
    assert_eq!(scene.patch_count(), 1);
    assert!((scene.total_area_scene_units() - 3.0).abs() < 1e-12);
}

/// `v x y z w`: the weight is ignored, so the cube is the plain cube (area 6 of a unit cube).
#[test]
fn the_vertex_weight_is_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let mut obj = String::new();
    for (k, c) in [
        [0, 0, 0],
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 1, 1],
    ]
    .iter()
    .enumerate()
    {
        obj.push_str(&format!(
            "v {} {} {} {}\n",
            c[0],
            c[1],
            c[2],
            0.1 * (k + 1) as f64
        ));
    }
    obj.push_str("f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
    let scene = load_file(
        &write(dir.path(), "w.obj", obj.as_bytes()),
        &SceneOptions::default(),
    );
    assert_eq!(scene.patch_count(), 6);
    assert!((scene.total_area_scene_units() - 6.0).abs() < 1e-12);
    assert!(scene
        .warnings
        .iter()
        .any(|w| w.message.contains("weight `w`")));
}

/// Boxes as OBJ objects: `(lo, hi, inward, name)`.
fn boxes_obj(boxes: &[([f64; 3], [f64; 3], bool, &str)]) -> String {
    let mut s = String::new();
    let mut base = 0;
    for (lo, hi, inward, name) in boxes {
        s.push_str(&format!("o {name}\n"));
        for i in 0..8 {
            let c = |a: usize| if i >> a & 1 == 0 { lo[a] } else { hi[a] };
            s.push_str(&format!("v {} {} {}\n", c(0), c(1), c(2)));
        }
        for q in crate::support::CUBE_QUADS {
            let mut f: Vec<usize> = q.iter().map(|&k| base + k + 1).collect();
            if *inward {
                f.reverse();
            }
            let idx: Vec<String> = f.iter().map(|i| i.to_string()).collect();
            s.push_str(&format!("f {}\n", idx.join(" ")));
        }
        base += 8;
    }
    s
}

/// A crate with inward normals in a room: its back sides are seen from the room's front sides, its front
/// sides only from inside it: InsideOut naming it; flipped, the scene is closed and consistent (every
/// segment a pair). A room exported with outward normals has no pair at all: the visibility measures are
/// undefined (None, not zeros), NoPairs; flipped, it is the unit cube, whose H_s is that of the closed
/// form.
#[test]
fn inside_out_objects_are_diagnosed_and_flipped() {
    let dir = tempfile::tempdir().unwrap();
    let obj = boxes_obj(&[
        ([0.0; 3], [4.0; 3], true, "room"),
        ([1.0; 3], [2.0; 3], true, "crate"),
    ]);
    let path = write(dir.path(), "crate.obj", obj.as_bytes());
    let scene = load_file(&path, &SceneOptions::default());
    let a = run(&scene, 100_000, 1, Measures::VISIBILITY);
    assert_eq!(kinds(&a), vec![RunWarningKind::InsideOut]);
    assert!(a.warnings[0].message.contains("--flip-normals crate"));
    let crate_sides = a.orientation[1];
    assert!(crate_sides.back_seen > 0 && crate_sides.back_seen == a.unpaired);

    let flipped = SceneOptions {
        flip_normals: ObjectSet::Named(vec!["crate".into()]),
        ..SceneOptions::default()
    };
    let a = run(
        &load_file(&path, &flipped),
        100_000,
        1,
        Measures::VISIBILITY,
    );
    assert!(a.warnings.is_empty(), "{:?}", a.warnings);
    // Unpaired now means inside the crate (a solid): never a front side seeing a back side.
    assert_eq!(a.escapes, 0);
    assert!(a.unpaired > 0 && a.orientation.iter().all(|o| o.back_seen == 0));
    let unknown = SceneOptions {
        flip_normals: ObjectSet::Named(vec!["crates".into()]),
        ..SceneOptions::default()
    };
    let e = load_with(path.to_str().unwrap(), &unknown)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no object named `crates`") && e.contains("`room`, `crate`"));

    let room = write(
        dir.path(),
        "room.obj",
        boxes_obj(&[([0.0; 3], [1.0; 3], false, "room")]).as_bytes(),
    );
    let a = run(
        &load_file(&room, &SceneOptions::default()),
        50_000,
        1,
        Measures::VISIBILITY,
    );
    assert_eq!(a.pairs, 0);
    assert!(kinds(&a).contains(&RunWarningKind::NoPairs));
    assert!(a.estimate(Measure::PositionalEntropy).is_some());
    assert!(
        a.estimate(Measure::Entropy).is_none()
            && a.estimate(Measure::MutualInformation).is_none()
            && a.estimate(Measure::MsePerLine).is_none()
    );
    assert!(
        a.estimate(Measure::ContinuousMutualInformation).is_none()
            && a.estimate(Measure::Accuracy).is_none()
    );
    // Undefined readings have no verdict either (nor lines to advise for them).
    let judged: Vec<Measure> = a.reliability.iter().map(|(m, _)| m).collect();
    assert!(
        judged.iter().all(|&m| m == Measure::PositionalEntropy),
        "{judged:?}"
    );
    let all = SceneOptions {
        flip_normals: ObjectSet::All,
        ..SceneOptions::default()
    };
    let a = run(&load_file(&room, &all), 200_000, 1, Measures::VISIBILITY);
    assert!(a.warnings.is_empty());
    // The unit cube, one patch per face: every row is F to the opposite face (closed form) and a quarter
    // of the rest to each neighbour.
    let f_opposite = crate::support::ff_parallel_rectangles(1.0, 1.0, 1.0);
    let f_side = (1.0 - f_opposite) / 4.0;
    let h_exact = -(f_opposite * f_opposite.log2() + 4.0 * f_side * f_side.log2());
    let h = v_entropy(&a);
    assert!(
        (h.0 - h_exact).abs() < 5.0 * h.1 + 1e-4,
        "{h:?} against {h_exact}"
    );
}

fn v_entropy(a: &Analysis) -> (f64, f64) {
    let e = a.estimate(Measure::Entropy).unwrap();
    (e.value, e.stderr.unwrap())
}

/// A one-sided sign in a room is seen from behind: OneSided naming it. Two-sided, it is two patches back
/// to back with the sign's area each, both seen, and no segment reaches a back side from a front.
#[test]
fn one_sided_surfaces_are_diagnosed_and_made_two_sided() {
    let dir = tempfile::tempdir().unwrap();
    let mut obj = boxes_obj(&[([0.0; 3], [4.0; 3], true, "room")]);
    obj.push_str("o sign\nv 1 1 2\nv 3 1 2\nv 3 3 2\nv 1 3 2\nf 9 10 11 12\n");
    let path = write(dir.path(), "sign.obj", obj.as_bytes());
    let a = run(
        &load_file(&path, &SceneOptions::default()),
        100_000,
        1,
        Measures::VISIBILITY,
    );
    assert_eq!(kinds(&a), vec![RunWarningKind::OneSided]);
    assert!(a.warnings[0].message.contains("--two-sided sign"));

    let options = SceneOptions {
        two_sided: ObjectSet::Named(vec!["sign".into()]),
        ..SceneOptions::default()
    };
    let scene = load_file(&path, &options);
    assert_eq!(scene.patch_count(), 8);
    let sign: Vec<_> = scene.patches.iter().filter(|p| p.object == 1).collect();
    assert_eq!(sign.len(), 2);
    let scale2 = scene.normalization.scale.powi(2);
    for p in &sign {
        assert!((p.area * scale2 - 4.0).abs() < 1e-9);
    }
    assert!((sign[0].normal + sign[1].normal).length() < 1e-12);
    let a = run(&scene, 100_000, 1, Measures::VISIBILITY);
    assert!(a.warnings.is_empty(), "{:?}", a.warnings);
    assert_eq!(a.orientation[1].back_seen, 0);
    // Crossed front-in, back, front-out: one empty segment between the two sides per crossing.
    let rows = crate::support::count_entries(&a);
    let touching = |p: u32| rows.iter().filter(|e| e.0 == p || e.1 == p).count();
    assert!(touching(6) > 0 && touching(7) > 0);
}

/// Advice that keeps the scene's meaning: a light seen from behind (a lamp under the ceiling, whose back
/// the ceiling sees) is said to be one, never advised two-sided (it would emit from its back); a closed
/// solid whose inside is seen (a box holding another box) is said to be one, never advised two-sided
/// either; only the open surface seen from behind (the sign) gets the `--two-sided` advice.
#[test]
fn lights_and_closed_solids_are_not_advised_two_sided() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "lamp.mtl",
        b"newmtl wall\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n",
    );
    let mut obj = String::from("mtllib lamp.mtl\nusemtl wall\n");
    obj.push_str(&boxes_obj(&[
        ([0.0; 3], [4.0; 3], true, "room"),
        ([0.5, 0.5, 0.5], [1.8, 1.8, 1.8], false, "crate"),
        ([0.9, 0.9, 0.9], [1.4, 1.4, 1.4], false, "inner"),
    ]));
    // A lamp 0.1 below the ceiling, facing down; a one-sided sign facing +y, seen from behind.
    obj.push_str(
        "o lamp\nusemtl lamp\nv 1 1 3.9\nv 1 3 3.9\nv 3 3 3.9\nv 3 1 3.9\nf 25 26 27 28\n",
    );
    obj.push_str(
        "o sign\nusemtl wall\nv 2.5 2 0.5\nv 3.5 2 0.5\nv 3.5 2 1.5\nv 2.5 2 1.5\nf 29 30 31 32\n",
    );
    let path = write(dir.path(), "lamp.obj", obj.as_bytes());
    let a = run(
        &load_file(&path, &SceneOptions::default()),
        200_000,
        1,
        Measures::VISIBILITY,
    );
    let by_kind = |kind: RunWarningKind| a.warnings.iter().find(|w| w.kind == kind);
    let light = by_kind(RunWarningKind::LightSeenFromBehind).expect("the lamp is named");
    assert_eq!(light.objects, ["lamp"]);
    assert!(
        !light.message.contains("--two-sided lamp"),
        "{}",
        light.message
    );
    let solid = by_kind(RunWarningKind::SeenInsideSolid).expect("the crate is named");
    assert_eq!(solid.objects, ["crate"]);
    let sign = by_kind(RunWarningKind::OneSided).expect("the sign is named");
    assert_eq!(sign.objects, ["sign"]);
    assert!(
        sign.message.contains("--two-sided sign"),
        "{}",
        sign.message
    );
    assert_eq!(a.warnings.len(), 3, "{:?}", kinds(&a));
}

/// A light marked as some files do, by an ambient `Ka` above 1 and no `Ke`, does not emit in scx, and
/// the scene's warning says so, naming the material and its `Ka`.
#[test]
fn a_light_marked_by_ka_is_named() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "ka.mtl",
        b"newmtl wall\nKd 0.5 0.5 0.5\nnewmtl lamp\nKa 20 20 20\nKd 0.78 0.78 0.78\n",
    );
    let mut obj = String::from("mtllib ka.mtl\nusemtl lamp\n");
    obj.push_str(&boxes_obj(&[([0.0; 3], [1.0; 3], true, "room")]));
    let scene = load_file(
        &write(dir.path(), "ka.obj", obj.as_bytes()),
        &SceneOptions::default(),
    );
    assert!(scene.materials.iter().all(|m| m.emission == 0.0));
    let w = scene
        .warnings
        .iter()
        .find(|w| w.kind.code() == "light-in-other-convention")
        .unwrap_or_else(|| panic!("{}", messages(&scene.warnings)));
    assert!(w.message.contains("`lamp` (Ka 20 20 20)"), "{}", w.message);
}

/// glTF JSON with a buffer in a data URI: a unit quad's mesh placed by a node chain (parent translation,
/// child scale 2 and a mirror in z), two materials (one double-sided and emitting with a strength).
#[test]
fn gltf_nodes_place_meshes_and_materials_carry_over() {
    use base64::Engine as _;
    let positions: [f32; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut buffer: Vec<u8> = positions.iter().flat_map(|x| x.to_le_bytes()).collect();
    buffer.extend(indices.iter().flat_map(|x| x.to_le_bytes()));
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buffer)
    );
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "parent", "translation": [10.0, 0.0, 0.0], "children": [1]},
            {"name": "panel", "mesh": 0, "scale": [2.0, 2.0, -1.0]},
            {"name": "lamp", "mesh": 1, "translation": [0.0, 0.0, 5.0]}
        ],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]},
            {"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 1}]}
        ],
        "materials": [
            {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.2, 1.0]}},
            {"name": "light", "doubleSided": true, "emissiveFactor": [1.0, 0.5, 0.25],
             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 12}
        ],
        "buffers": [{"byteLength": 60, "uri": uri}],
        "extensionsUsed": ["KHR_materials_emissive_strength"]
    });
    let dir = tempfile::tempdir().unwrap();
    // The extension says nothing: the content does.
    let path = write(dir.path(), "scene.data", doc.to_string().as_bytes());
    let scene = load_file(&path, &SceneOptions::default());
    assert_eq!(scene.objects, ["panel", "lamp"]);
    // Panel: x in [10, 12], y in [0, 2], one side: area 4; lamp: area 1, two sides.
    assert!((scene.total_area_scene_units() - (4.0 + 2.0 * 1.0)).abs() < 1e-9);
    let mut lamp_normals = Vec::new();
    for p in &scene.patches {
        let m = &scene.materials[p.material as usize];
        let corner = scene.vertices[scene.polygon(p)[0] as usize];
        if scene.objects[p.object as usize] == "panel" {
            assert!(
                (10.0..=12.0).contains(&corner.x) && corner.z == 0.0,
                "{corner}"
            );
            assert_eq!(m.reflectance_rgb, [0.8f32, 0.1, 0.2].map(f64::from));
            // Mirrored by the node's scale z = -1: the specification's front side is then the one its
            // corners run clockwise about, -z.
            assert!(p.normal.z < -0.99, "{}", p.normal);
        } else {
            assert_eq!(corner.z, 5.0);
            assert_eq!(m.emission_rgb, [4.0, 2.0, 1.0]);
            assert_eq!(m.emission, 7.0 / 3.0);
            lamp_normals.push(p.normal.z.round());
        }
    }
    lamp_normals.sort_by(f64::total_cmp);
    assert_eq!(lamp_normals, [-1.0, -1.0, 1.0, 1.0]);
}

/// A unit cube (outward faces) as binary and ASCII STL and PLY: 12 triangles (STL) or 6 quads (PLY),
/// area 6, every normal pointing away from the centre; PLY face colours become materials.
#[test]
fn stl_and_ply_in_ascii_and_binary() {
    let corners: Vec<[f32; 3]> = (0..8)
        .map(|i| [(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32])
        .collect();
    let quads = crate::support::CUBE_QUADS;
    let triangles: Vec<[usize; 3]> = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    let dir = tempfile::tempdir().unwrap();

    let mut binary_stl = b"solid but binary: some exporters write this".to_vec();
    binary_stl.resize(80, b' ');
    binary_stl.extend((triangles.len() as u32).to_le_bytes());
    let mut ascii_stl = String::from("solid cube\n");
    for t in &triangles {
        binary_stl.extend([0f32; 3].iter().flat_map(|x| x.to_le_bytes()));
        ascii_stl.push_str(" facet normal 0 0 0\n  outer loop\n");
        for &v in t {
            binary_stl.extend(corners[v].iter().flat_map(|x| x.to_le_bytes()));
            let c = corners[v];
            ascii_stl.push_str(&format!("   vertex {} {} {}\n", c[0], c[1], c[2]));
        }
        binary_stl.extend([0u8; 2]);
        ascii_stl.push_str("  endloop\n endfacet\n");
    }
    ascii_stl.push_str("endsolid cube\n");

    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex 8\nproperty float x\nproperty float y\n\
             property float z\nelement face 6\nproperty list uchar int vertex_indices\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
        )
    };
    let colour = |k: usize| if k < 3 { [255u8, 0, 0] } else { [0, 0, 255] };
    let mut ascii_ply = header("ascii");
    let mut binary_ply = header("binary_little_endian").into_bytes();
    for c in &corners {
        ascii_ply.push_str(&format!("{} {} {}\n", c[0], c[1], c[2]));
        binary_ply.extend(c.iter().flat_map(|x| x.to_le_bytes()));
    }
    for (k, q) in quads.iter().enumerate() {
        let [r, g, b] = colour(k);
        ascii_ply.push_str(&format!(
            "4 {} {} {} {} {r} {g} {b}\n",
            q[0], q[1], q[2], q[3]
        ));
        binary_ply.push(4);
        binary_ply.extend(q.iter().flat_map(|&i| (i as i32).to_le_bytes()));
        binary_ply.extend([r, g, b]);
    }

    for (name, bytes, patches) in [
        ("binary.stl", binary_stl, 12),
        ("ascii.stl", ascii_stl.into_bytes(), 12),
        ("ascii.ply", ascii_ply.into_bytes(), 6),
        ("binary.ply", binary_ply, 6),
    ] {
        let path = write(dir.path(), name, &bytes);
        let scene = load_file(&path, &SceneOptions::default());
        assert_eq!(scene.patch_count(), patches, "{name}");
        assert!(
            (scene.total_area_scene_units() - 6.0).abs() < 1e-9,
            "{name}"
        );
        assert_eq!(
            scene.objects,
            vec![name.split('.').next().unwrap().to_string()]
        );
        for p in &scene.patches {
            let centroid = scene.vertices[scene.polygon(p)[0] as usize];
            let outward = (centroid - scene.normalization.center).dot(p.normal);
            assert!(outward > 0.0, "{name}: a face looks into the cube");
        }
        if name.ends_with("ply") {
            let reds = scene
                .patches
                .iter()
                .filter(|p| scene.materials[p.material as usize].reflectance_rgb == [1.0, 0.0, 0.0])
                .count();
            assert_eq!(reds, 3, "{name}");
        }
    }
}

/// The unit cube's 12 triangles (counter-clockwise seen from outside), as an ASCII STL facet each:
/// `facet` with the given indent and separator.
fn cube_stl_facets(indent: &str, sep: &str) -> Vec<String> {
    let corner = |i: usize| [(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32];
    crate::support::CUBE_QUADS
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .map(|t| {
            let mut f =
                format!("{indent}facet{sep}normal{sep}0{sep}0{sep}0\n{indent}{indent}outer loop\n");
            for v in t {
                let c = corner(v);
                f.push_str(&format!(
                    "{indent}{indent}{indent}vertex{sep}{}{sep}{}{sep}{}\n",
                    c[0], c[1], c[2]
                ));
            }
            f + &format!("{indent}{indent}endloop\n{indent}endfacet\n")
        })
        .collect()
}

/// ASCII STL as tools write it: several solids in one file (each an object, none dropped), a
/// byte-order mark, blank lines, tabs, indentation, upper case; a file cut short, a facet of two
/// corners and a coordinate that is not a number are refused by line.
#[test]
fn ascii_stl_in_the_forms_tools_write() {
    let facets = cube_stl_facets(" ", " ");
    let dir = tempfile::tempdir().unwrap();
    let two_solids = format!(
        "solid lower\n{}endsolid lower\nsolid upper half\n{}endsolid upper half\n",
        facets[..6].concat(),
        facets[6..].concat()
    );
    let spaced = format!(
        "\u{feff}\n\n  solid\n{}\nendsolid\n",
        cube_stl_facets("\t", " \t ").concat()
    );
    let upper = format!("solid cube\n{}endsolid cube\n", facets.concat()).to_uppercase();
    for (name, text, objects) in [
        ("two.stl", two_solids, vec!["lower", "upper half"]),
        ("spaced.stl", spaced, vec!["spaced"]),
        ("upper.stl", upper, vec!["upper"]),
    ] {
        let path = write(dir.path(), name, text.as_bytes());
        let scene = load_file(&path, &SceneOptions::default());
        assert_eq!(scene.patch_count(), 12, "{name}");
        assert!(
            (scene.total_area_scene_units() - 6.0).abs() < 1e-9,
            "{name}"
        );
        assert_eq!(scene.objects, objects, "{name}");
    }
    let one = &facets[0];
    for (text, says) in [
        (format!("solid t\n{one}"), "cut short"),
        (
            format!(
                "solid t\n{}endsolid\n",
                one.replacen("vertex 0 0 0", "vertex 0 nan 0", 1)
            ),
            "line 4: vertex coordinate `nan` is not a finite number",
        ),
        (
            format!(
                "solid t\n{}endsolid\n",
                one.replacen("   vertex 0 0 0\n", "", 1)
            ),
            "line 7: facet 1 has 2 corners",
        ),
        (
            format!("solid t\n{one}junk\nendsolid\n"),
            "line 9: `junk` where `facet` or `endsolid`",
        ),
    ] {
        let path = write(dir.path(), "bad.stl", text.as_bytes());
        let err = load_with(path.to_str().unwrap(), &SceneOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("bad.stl") && err.contains(says),
            "{err}\n{text}"
        );
    }
}

/// I_s^c depends on the geometry only (paper sec. 3.2): the room with a box as quads, as triangles, as
/// exported glTF and as PLY gives the same I_s^c within the combined standard errors (independent seeds).
#[test]
fn continuous_mutual_information_is_the_same_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let quads = room_with_box_obj(1.0);
    let quads_path = write(dir.path(), "quads.obj", quads.as_bytes());
    let mut triangles = String::new();
    for line in quads.lines() {
        match line.strip_prefix("f ") {
            Some(rest) => {
                let v: Vec<&str> = rest.split_whitespace().collect();
                triangles.push_str(&format!(
                    "f {} {} {}\nf {} {} {}\n",
                    v[0], v[1], v[2], v[0], v[2], v[3]
                ));
            }
            None => {
                triangles.push_str(line);
                triangles.push('\n');
            }
        }
    }
    let triangles_path = write(dir.path(), "triangles.obj", triangles.as_bytes());
    let scene = load(quads_path.to_str().unwrap()).unwrap();
    let gltf_path = dir.path().join("room.glb");
    scene_complexity::internals::scene::gltf::write(&scene, &gltf_path).unwrap();
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        scene.vertices.len(),
        scene.patch_count()
    );
    for v in &scene.vertices {
        ply.push_str(&format!("{:?} {:?} {:?}\n", v.x, v.y, v.z));
    }
    for p in &scene.patches {
        let idx: Vec<String> = scene.polygon(p).iter().map(|i| i.to_string()).collect();
        ply.push_str(&format!("{} {}\n", idx.len(), idx.join(" ")));
    }
    let ply_path = write(dir.path(), "room.ply", ply.as_bytes());

    let continuous = Measures {
        discrete: false,
        continuous: true,
        radiosity: false,
    };
    let mut results = Vec::new();
    for (seed, (path, patches)) in [
        (quads_path, 12),
        (triangles_path, 24),
        (gltf_path, 24),
        (ply_path, 12),
    ]
    .into_iter()
    .enumerate()
    {
        let scene = load(path.to_str().unwrap()).unwrap();
        assert_eq!(scene.patch_count(), patches, "{}", path.display());
        let a = run(&scene, 300_000, seed as u64 + 1, continuous);
        let e = a.estimate(Measure::ContinuousMutualInformation).unwrap();
        results.push((path, e.value, e.stderr.unwrap()));
    }
    for a in &results {
        for b in &results {
            let combined = (a.2 * a.2 + b.2 * b.2).sqrt();
            assert!(
                (a.1 - b.1).abs() < 4.0 * combined,
                "{}: {} ± {}, {}: {} ± {}",
                a.0.display(),
                a.1,
                a.2,
                b.0.display(),
                b.1,
                b.2
            );
        }
    }
}

/// Materials keep RGB: the Cornell box's red wall exports as its RGB triple, which reads back with the
/// same single value (exactly the built-in's), so the exported box measures the same.
#[test]
fn materials_keep_their_colours_through_export() {
    use scene_complexity::internals::scene::grey_value;
    use scene_complexity::internals::scenes::cornell::{
        GREEN, GREEN_RGB, RED, RED_RGB, WHITE, WHITE_RGB,
    };
    for (rgb, mean) in [(RED_RGB, RED), (WHITE_RGB, WHITE), (GREEN_RGB, GREEN)] {
        assert_eq!(grey_value(rgb), mean);
    }
    let scene = load("@cornell").unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cornell.obj");
    scene_complexity::internals::scene::obj::write(&scene, &path).unwrap();
    let mtl = std::fs::read_to_string(dir.path().join("cornell.mtl")).unwrap();
    let [r, g, b] = RED_RGB;
    assert!(mtl.contains(&format!("Kd {r} {g} {b}")), "{mtl}");
    let back = load(path.to_str().unwrap()).unwrap();
    let red = back
        .materials
        .iter()
        .find(|m| m.name.ends_with("red"))
        .unwrap();
    assert_eq!((red.reflectance_rgb, red.reflectance), (RED_RGB, RED));
    for path in [
        dir.path().join("cornell.gltf"),
        dir.path().join("cornell.glb"),
    ] {
        scene_complexity::internals::scene::gltf::write(&scene, &path).unwrap();
        let back = load(path.to_str().unwrap()).unwrap();
        let red = back.materials.iter().find(|m| m.name == "red").unwrap();
        for (a, b) in red.reflectance_rgb.iter().zip(RED_RGB) {
            assert!((a - b).abs() < 1e-7, "{path:?}");
        }
        let light = back.materials.iter().find(|m| m.name == "light").unwrap();
        assert!((light.emission - scene.materials[3].emission).abs() < 1e-5);
        assert_eq!(back.patch_count(), scene.triangles.len(), "{path:?}");
    }
}

/// A line's ends, by hand: through a one-sided square from behind it is a single crossing arriving at the
/// back: the escape is at the line's end (toward the sphere's exit), and the line's start met a back side.
/// From the front, the escape is at the start. A second square behind the first, facing the same way,
/// is reached from the first one's front at its back: a `BackSeen` segment.
#[test]
fn the_ends_of_a_line_and_back_sides_seen() {
    use scene_complexity::internals::sample::pairs::{segments, segments_and_ends, Segment};
    use scene_complexity::internals::trace::{Line, LineHits};
    let dir = tempfile::tempdir().unwrap();
    let obj = "o a\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n\
               o b\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nf 5 6 7 8\n";
    let scene = load_file(
        &write(dir.path(), "two.obj", obj.as_bytes()),
        &SceneOptions::default(),
    );
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    let trace = |origin: [f32; 3], dir: [f32; 3]| {
        let line = Line {
            origin,
            dir,
            t_max: 4.0,
        };
        let (mut raw, mut hits) = (Vec::new(), LineHits::default());
        tracer.all_hits(&[line], &mut raw, &mut hits).unwrap();
        let row = hits.of_line(0).to_vec();
        let mut seen = Vec::new();
        let ends = segments_and_ends(&scene, &line, &row, |s| seen.push(s));
        (seen, ends)
    };
    // Both squares face +z (tracing space: z from -1 to 1 after centring); upwards through both: arrive
    // at a's back, leave its front, arrive at b's back (BackSeen b, from a's front), leave b's front into
    // open space.
    let (seen, ends) = trace([0.1, 0.2, -2.0], [0.0, 0.0, 1.0]);
    assert_eq!(
        seen,
        [
            Segment::BackSeen { patch: 1, front: 0 },
            Segment::Escape {
                patch: 1,
                at_start: false
            }
        ]
    );
    assert_eq!((ends.back_first, ends.back_last), (Some(0), None));
    // Downwards: arrive at b's front from open space (an escape at the start), leave its back, arrive at
    // a's front: a segment from a back side to a front side (BackSeen b, to a's front), and leave a's
    // back.
    let (seen, ends) = trace([0.1, 0.2, 2.0], [0.0, 0.0, -1.0]);
    assert_eq!(
        seen,
        [
            Segment::Escape {
                patch: 1,
                at_start: true
            },
            Segment::BackSeen { patch: 1, front: 0 }
        ]
    );
    assert_eq!((ends.back_first, ends.back_last), (None, Some(0)));
    let mut count = 0;
    segments(
        &scene,
        &Line {
            origin: [5.0, 5.0, 5.0],
            dir: [1.0, 0.0, 0.0],
            t_max: 1.0,
        },
        &[],
        |_| count += 1,
    );
    assert_eq!(count, 0);
}

/// Every wall of the unit cube two-sided: one sheet of walls seen from both sides. Inside, the lines
/// pair the inner sides exactly as in the one-sided cube (same seed, same pairs); outside, each line
/// enters and leaves through an outer side (two escapes per line through the cube) and crosses each
/// wall's zero thickness (an empty segment); no pair joins the two sides of a wall (d = 0).
#[test]
fn two_sided_walls_one_after_another_pair_as_thin_panels() {
    let one_sided = load("@cube").unwrap();
    let two_sided = load_with(
        "@cube",
        &SceneOptions {
            two_sided: ObjectSet::All,
            ..SceneOptions::default()
        },
    )
    .unwrap();
    assert_eq!(two_sided.patch_count(), 12);
    let a = run(&one_sided, 100_000, 3, Measures::VISIBILITY);
    let b = run(&two_sided, 100_000, 3, Measures::VISIBILITY);
    assert_eq!(b.pairs, a.pairs);
    // Lines grazing an edge of the cube from outside meet only outer sides: a few more escapes.
    assert!(
        (2 * a.pairs..2 * a.pairs + 10).contains(&b.escapes),
        "{}",
        b.escapes
    );
    assert!(
        (2 * a.pairs..2 * a.pairs + 10).contains(&b.unpaired),
        "{}",
        b.unpaired
    );
    assert_eq!(b.degenerate_pairs, 0);
    let e = b.estimate(Measure::ContinuousMutualInformation).unwrap();
    assert!(e.value.is_finite());
}

/// The corners of a unit cube (corner bits x=1, y=2, z=4) and its faces as quads, counter-clockwise
/// seen from inside (a room, as `@cube:1`).
fn inward_cube() -> (Vec<[f32; 3]>, Vec<[usize; 4]>) {
    let corners = (0..8)
        .map(|i| [(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32])
        .collect();
    let outward = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    (corners, outward.map(|[a, b, c, d]| [d, c, b, a]).to_vec())
}

/// The cube's faces as Stanford triangle strips: a quad `a b c d` is the strip `b c a d` (triangles
/// `b c a` and, turned, `a c d`); two faces per strip, joined by repeating the last and next corners (four
/// degenerate triangles), the strips separated by `-1`.
fn cube_strips(quads: &[[usize; 4]]) -> Vec<i32> {
    let mut list: Vec<i32> = Vec::new();
    for (k, q) in quads.iter().enumerate() {
        let strip = [q[1], q[2], q[0], q[3]].map(|v| v as i32);
        if k % 2 == 0 {
            if !list.is_empty() {
                list.push(-1);
            }
        } else {
            let last = *list.last().unwrap();
            list.extend([last, strip[0]]);
        }
        list.extend(strip);
    }
    list
}

/// Stanford `tristrips` (igea.ply's form: `-1` restarts a strip, repeated corners join strips) read as
/// triangles keeping the strip's orientation (before: "the scene is empty: no faces"): the cube's 6 faces
/// as strips give its 12 triangles, area 6, every normal into the room, and the very triangles of an OBJ
/// with the same faces, so the same I_s^c bit for bit; `@cube:1` gives the same I_s^c too (its triangles
/// are the same). A face element of another name with a `vertex_index` list reads as faces.
#[test]
fn ply_triangle_strips_read_as_the_same_triangles() {
    let (corners, quads) = inward_cube();
    let strips = cube_strips(&quads);
    let dir = tempfile::tempdir().unwrap();
    let header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\ncomment Stanford style\nelement vertex 8\nproperty float x\n\
             property float y\nproperty float z\nelement tristrips 1\n\
             property list int int vertex_indices\nend_header\n"
        )
    };
    let mut ascii = header("ascii");
    let mut binary = header("binary_big_endian").into_bytes();
    for c in &corners {
        ascii.push_str(&format!("{} {} {}\n", c[0], c[1], c[2]));
        binary.extend(c.iter().flat_map(|x| x.to_be_bytes()));
    }
    let listed: Vec<String> = strips.iter().map(i32::to_string).collect();
    ascii.push_str(&format!("{} {}\n", strips.len(), listed.join(" ")));
    binary.extend((strips.len() as i32).to_be_bytes());
    binary.extend(strips.iter().flat_map(|x| x.to_be_bytes()));

    let mut obj = String::new();
    for c in &corners {
        obj.push_str(&format!("v {} {} {}\n", c[0], c[1], c[2]));
    }
    for q in &quads {
        obj.push_str(&format!("f {} {} {}\n", q[1] + 1, q[2] + 1, q[0] + 1));
        obj.push_str(&format!("f {} {} {}\n", q[0] + 1, q[2] + 1, q[3] + 1));
    }
    let obj = load_file(
        &write(dir.path(), "cube.obj", obj.as_bytes()),
        &SceneOptions::default(),
    );
    let continuous = Measures {
        discrete: false,
        continuous: true,
        radiosity: false,
    };
    let isc = |scene: &Scene| {
        let a = run(scene, 100_000, 7, continuous);
        let e = a.estimate(Measure::ContinuousMutualInformation).unwrap();
        (e.value, e.stderr.unwrap())
    };
    let expected = isc(&obj);
    for (name, bytes) in [("ascii.ply", ascii.into_bytes()), ("binary.ply", binary)] {
        let scene = load_file(&write(dir.path(), name, &bytes), &SceneOptions::default());
        assert_eq!(
            (scene.patch_count(), scene.triangles.len()),
            (12, 12),
            "{name}"
        );
        assert!(
            (scene.total_area_scene_units() - 6.0).abs() < 1e-12,
            "{name}"
        );
        for p in &scene.patches {
            let corner = scene.vertices[scene.polygon(p)[0] as usize];
            let inward = (scene.normalization.center - corner).dot(p.normal);
            assert!(inward > 0.0, "{name}: a triangle faces out of the room");
        }
        assert_eq!(scene.triangles, obj.triangles, "{name}");
        assert_eq!(scene.positions, obj.positions, "{name}");
        assert_eq!(isc(&scene), expected, "{name}");
        assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
    }
    let cube = isc(&load("@cube:1").unwrap());
    assert!(
        (cube.0 - expected.0).abs() <= 4.0 * cube.1.hypot(expected.1),
        "{cube:?} {expected:?}"
    );

    let mut polygons = String::from(
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n\
         property float z\nelement polygon 6\nproperty list uchar uint vertex_index\nend_header\n",
    );
    for c in &corners {
        polygons.push_str(&format!("{} {} {}\n", c[0], c[1], c[2]));
    }
    for q in &quads {
        polygons.push_str(&format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3]));
    }
    let scene = load_file(
        &write(dir.path(), "polygons.ply", polygons.as_bytes()),
        &SceneOptions::default(),
    );
    assert_eq!((scene.patch_count(), scene.triangles.len()), (6, 12));
    assert_eq!(isc(&scene), isc(&load("@cube:1").unwrap()));
}

/// A PLY with no element of faces says which elements it has, strips among the forms it looks for.
#[test]
fn a_ply_without_faces_names_its_elements() {
    let dir = tempfile::tempdir().unwrap();
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
               property float z\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n\
               end_header\n0 0 0\n1 0 0\n0 1 0\n0 1\n";
    let path = write(dir.path(), "edges.ply", ply.as_bytes());
    let e = load_with(path.to_str().unwrap(), &SceneOptions::default())
        .unwrap_err()
        .to_string();
    for words in [
        "edges.ply",
        "the scene is empty",
        "`tristrips`",
        "3 vertices",
        "`vertex` (3), `edge` (1)",
    ] {
        assert!(e.contains(words), "{words}: {e}");
    }
}

/// `write_scene` picks the format by the extension; each file reads back as the scene it was: OBJ and
/// PLY with the same triangles, positions and patches, so I_s^c bit for bit; STL and glTF (triangles
/// only, f32) with a patch per triangle and every corner the f32 of the original's, I_s^c within its
/// error; an STL read back and written again gives the same scene. Any other extension is refused.
#[test]
fn scenes_written_in_every_format_read_back_the_same() {
    use scene_complexity::{write_scene, WriteFormat};
    let dir = tempfile::tempdir().unwrap();
    let continuous = Measures {
        discrete: false,
        continuous: true,
        radiosity: false,
    };
    let isc = |scene: &Scene| {
        let a = run(scene, 50_000, 11, continuous);
        let e = a.estimate(Measure::ContinuousMutualInformation).unwrap();
        (e.value, e.stderr.unwrap())
    };
    let room = load_file(
        &write(dir.path(), "room.obj", room_with_box_obj(3.0).as_bytes()),
        &SceneOptions::default(),
    );
    for (label, scene) in [("cornell", load("@cornell").unwrap()), ("room", room)] {
        let original = isc(&scene);
        for ext in ["obj", "ply", "stl", "gltf", "glb"] {
            let path = dir.path().join(format!("{label}_out.{ext}"));
            write_scene(&scene, &path).unwrap();
            let format = WriteFormat::of_path(&path).unwrap();
            let back = load_file(&path, &SceneOptions::default());
            let what = format!("{label} as {ext}");
            assert!(
                (back.total_area_scene_units() - scene.total_area_scene_units()).abs()
                    < 1e-6 * scene.total_area_scene_units(),
                "{what}"
            );
            if matches!(format, WriteFormat::Obj | WriteFormat::Ply) {
                assert_eq!(back.patch_count(), scene.patch_count(), "{what}");
                assert_eq!(back.triangles, scene.triangles, "{what}");
                assert_eq!(back.positions, scene.positions, "{what}");
                assert_eq!(back.vertices, scene.vertices, "{what}");
                assert_eq!(back.triangle_patch, scene.triangle_patch, "{what}");
                assert_eq!(isc(&back), original, "{what}");
                continue;
            }
            assert_eq!(back.triangles.len(), scene.triangles.len(), "{what}");
            assert_eq!(back.patch_count(), scene.triangles.len(), "{what}");
            let corners = |s: &Scene| {
                let mut v: Vec<[u32; 3]> = s
                    .triangles
                    .iter()
                    .flatten()
                    .map(|&k| {
                        let p = s.vertices[k as usize];
                        [p.x as f32, p.y as f32, p.z as f32].map(f32::to_bits)
                    })
                    .collect();
                v.sort_unstable();
                v
            };
            assert_eq!(corners(&back), corners(&scene), "{what}");
            let again = isc(&back);
            assert!(
                (again.0 - original.0).abs() <= 4.0 * again.1.hypot(original.1),
                "{what}: {again:?} {original:?}"
            );
            if format == WriteFormat::Stl {
                let twice = dir.path().join(format!("{label}_twice.stl"));
                write_scene(&back, &twice).unwrap();
                let twice = load_file(&twice, &SceneOptions::default());
                assert_eq!(twice.triangles, back.triangles, "{what}");
                assert_eq!(twice.positions, back.positions, "{what}");
                assert_eq!(isc(&twice), again, "{what}");
            }
        }
    }
    let e = write_scene(&load("@cube:1").unwrap(), &dir.path().join("cube.txt")).unwrap_err();
    assert!(
        e.to_string()
            .contains(".obj (with its .mtl), .ply, .stl, .gltf, .glb"),
        "{e}"
    );
    assert!(!dir.path().join("cube.txt").exists());
}

/// A byte-order mark before the OBJ's first statement (or the MTL's) is no part of it: the library
/// that statement names is read and its light kept, where the mark glued to `mtllib` used to drop the
/// statement unseen.
#[test]
fn a_byte_order_mark_is_not_part_of_the_first_statement() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "lit.mtl",
        "\u{feff}newmtl lamp\nKd 0.5 0.5 0.5\nKe 2 2 2\n".as_bytes(),
    );
    let obj = write(
        dir.path(),
        "lit.obj",
        "\u{feff}mtllib lit.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl lamp\nf 1 2 3 4\n"
            .as_bytes(),
    );
    let scene = load_file(&obj, &SceneOptions::default());
    assert!(scene.warnings.is_empty(), "{}", messages(&scene.warnings));
    let lamp = &scene.materials[scene.patches[0].material as usize];
    assert_eq!(
        (lamp.name.as_str(), lamp.emission, lamp.reflectance),
        ("lamp", 2.0, 0.5)
    );
}

/// A file holding a byte-order mark and a comment is an OBJ without faces, not a file of unknown format.
#[test]
fn a_byte_order_mark_alone_is_an_empty_obj() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(dir.path(), "bom.obj", "\u{feff}# a comment\r\n".as_bytes());
    let e = load_with(obj.to_str().unwrap(), &SceneOptions::default())
        .expect_err("no faces")
        .to_string();
    assert!(e.contains("no faces"), "{e}");
}

/// A face that goes round its corners twice (`f 1 3 2 1 3 2`) is read once round, with a warning:
/// read as listed it laid two copies of itself on one patch, whose area then counted twice.
#[test]
fn a_face_listing_its_corners_twice_counts_once() {
    let dir = tempfile::tempdir().unwrap();
    let tetrahedron = |first: &str| {
        format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf {first}\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    };
    let once = load_file(
        &write(dir.path(), "once.obj", tetrahedron("1 3 2").as_bytes()),
        &SceneOptions::default(),
    );
    for corners in ["1 3 2 1 3 2", "1 3 2 1 3 2 1 3 2"] {
        let path = write(dir.path(), "twice.obj", tetrahedron(corners).as_bytes());
        let scene = load_file(&path, &SceneOptions::default());
        assert_eq!(scene.patch_count(), 4, "{corners}");
        assert_eq!(scene.triangles.len(), 4, "{corners}");
        let area = scene.total_area_scene_units();
        assert!(
            (area - once.total_area_scene_units()).abs() < 1e-12,
            "{area}"
        );
        assert!((area - (1.5 + 0.75f64.sqrt())).abs() < 1e-12, "{area}");
        assert!(
            messages(&scene.warnings).contains("list their corners more than once round"),
            "{}",
            messages(&scene.warnings)
        );
    }
    assert!(once.warnings.is_empty(), "{}", messages(&once.warnings));
}

/// A glTF of one triangle named `tri` whose positions are `positions`, edited by `edit`; its buffer in a
/// data URI.
fn triangle_gltf(positions: [f32; 9], edit: impl FnOnce(&mut serde_json::Value)) -> String {
    use base64::Engine as _;
    let buffer: Vec<u8> = positions.iter().flat_map(|x| x.to_le_bytes()).collect();
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buffer)
    );
    let mut doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 1]}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": uri}],
    });
    edit(&mut doc);
    doc.to_string()
}

const TRIANGLE: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// The error of loading `text` as `name` in `dir`.
fn load_error(dir: &Path, name: &str, text: &[u8]) -> String {
    let path = write(dir, name, text);
    match load_with(path.to_str().unwrap(), &SceneOptions::default()) {
        Ok(_) => panic!("{name} was read"),
        Err(e) => format!("{e}").replace(&format!("{}/", dir.display()), ""),
    }
}

/// A glTF vertex with one NaN coordinate shows its own values, not `(NaN, NaN, NaN)` (the node's
/// transform spread the NaN to every coordinate), and names its vertex as glTF numbers it.
#[test]
fn a_gltf_vertex_with_a_nan_shows_its_own_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let mut positions = TRIANGLE;
    positions[6] = f32::NAN;
    positions[7] = 0.5;
    positions[8] = 1.0;
    let e = load_error(
        dir.path(),
        "nan.gltf",
        triangle_gltf(positions, |_| {}).as_bytes(),
    );
    assert_eq!(
        e,
        "nan.gltf: mesh `tri` primitive 0: triangle 0: its vertex 2 (of POSITION accessor 0) has a \
         non-finite coordinate (NaN, 0.5, 1) (numbered from 0, as glTF numbers them)"
    );
}

/// A glTF of points or lines only says so, naming the mesh and the mode (it said "the scene is empty:
/// no faces"); mixed with triangles, the warning names them too.
#[test]
fn gltf_points_and_lines_are_named_with_their_mode() {
    let dir = tempfile::tempdir().unwrap();
    for (mode, name) in [(0, "POINTS"), (1, "LINES"), (3, "LINE_STRIP")] {
        let doc = triangle_gltf(TRIANGLE, |d| {
            d["meshes"][0]["primitives"][0]["mode"] = mode.into()
        });
        let e = load_error(dir.path(), "lines.gltf", doc.as_bytes());
        assert_eq!(
            e,
            format!(
                "lines.gltf: the scene has no triangles: its meshes hold only primitives of points \
                 or lines (mesh `tri` primitive 0: mode {mode} {name}), which scx does not read: they \
                 have no area; scx reads triangles (modes 4 TRIANGLES, 5 TRIANGLE_STRIP, 6 \
                 TRIANGLE_FAN)"
            )
        );
    }
    let mixed = triangle_gltf(TRIANGLE, |d| {
        let triangles = d["meshes"][0]["primitives"][0].clone();
        let mut lines = triangles.clone();
        lines["mode"] = 1.into();
        d["meshes"][0]["primitives"] = serde_json::json!([triangles, lines]);
    });
    let path = write(dir.path(), "mixed.gltf", mixed.as_bytes());
    let scene = load_file(&path, &SceneOptions::default());
    assert_eq!(scene.patch_count(), 1);
    assert!(
        messages(&scene.warnings).ends_with(
            "mixed.gltf: ignored 1 primitive(s) of points or lines (mesh `tri` primitive 1: mode 1 \
             LINES): they have no area"
        ),
        "{}",
        messages(&scene.warnings)
    );
}

/// A buffer view must fit in its buffer as `byteLength` gives it, even when the data URI holds more
/// (it was read silently); a node matrix must be affine (a projective one was applied as if it were).
#[test]
fn gltf_byte_lengths_and_projective_matrices_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let short = triangle_gltf(TRIANGLE, |d| d["buffers"][0]["byteLength"] = 10.into());
    assert_eq!(
        load_error(dir.path(), "short.gltf", short.as_bytes()),
        "short.gltf: mesh `tri` primitive 0: its POSITION accessor 0: its buffer view 0 (bytes 0 to \
         36) does not fit in buffer 0 of 10 bytes (its byteLength)"
    );
    let projective = triangle_gltf(TRIANGLE, |d| {
        d["nodes"][0]["name"] = "camera rig".into();
        d["nodes"][0]["matrix"] =
            serde_json::json!([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 0, 0, 1]);
    });
    assert_eq!(
        load_error(dir.path(), "projective.gltf", projective.as_bytes()),
        "projective.gltf: node 0 (`camera rig`): its matrix is not affine (its last row is 0 0 0.5 \
         1, not 0 0 0 1): a projective matrix cannot place a mesh"
    );
    // An affine matrix (a translation) places the mesh.
    let moved = triangle_gltf(TRIANGLE, |d| {
        d["nodes"][0]["matrix"] =
            serde_json::json!([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1]);
    });
    let scene = load_file(
        &write(dir.path(), "moved.gltf", moved.as_bytes()),
        &SceneOptions::default(),
    );
    assert_eq!(scene.vertices[0].x, 5.0);
}

/// A zero-area STL triangle is one zero-area face, warned about once (it was warned about twice: as a
/// zero-area triangle and as a zero-area face); a quad keeping a triangle after dropping another still
/// gets the triangle warning.
#[test]
fn a_zero_area_stl_triangle_is_warned_about_once() {
    let dir = tempfile::tempdir().unwrap();
    let facet = |v: [[f32; 3]; 3]| {
        let corners: String = v
            .iter()
            .map(|c| format!("vertex {} {} {}\n", c[0], c[1], c[2]))
            .collect();
        format!("facet normal 0 0 0\nouter loop\n{corners}endloop\nendfacet\n")
    };
    let stl = format!(
        "solid t\n{}{}endsolid t\n",
        facet([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
        facet([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    );
    let scene = load_file(
        &write(dir.path(), "flat.stl", stl.as_bytes()),
        &SceneOptions::default(),
    );
    let codes: Vec<&str> = scene.warnings.iter().map(|w| w.kind.code()).collect();
    assert_eq!(codes, ["zero-area-faces"]);
    assert_eq!(
        messages(&scene.warnings),
        format!(
            "{}: dropped 1 zero-area face(s), first: triangle 2",
            dir.path().join("flat.stl").display()
        )
    );
    assert_eq!(scene.warnings[0].numbers, [("faces", 1.0)]);
}

/// OBJ and MTL names and comments in Latin-1, as tools write them, are read (the file was refused
/// whole: "not a text file (invalid UTF-8 at byte 2)"): objects keep their names (two names that differ
/// in an accented letter stay two objects), a material named in Latin-1 in both files is found, and a
/// library named in Latin-1 is found under its UTF-8 name. A byte that is not text in a number is still
/// an error naming the line, and a library name still may not leave the scene's folder.
#[test]
fn latin_1_names_and_comments_are_read() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "caf\u{e9}.mtl",
        b"# r\xf6t\nnewmtl r\xf6t\nKd 0.8 0.1 0.1\n",
    );
    let obj =
        b"# \xa9 1999 Soci\xe9t\xe9\nmtllib caf\xe9.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                o caf\xe9\nusemtl r\xf6t\nf 1 2 3\no caf\xe8\nf 1 3 4\n";
    let scene = load_file(
        &write(dir.path(), "latin.obj", obj),
        &SceneOptions::default(),
    );
    assert_eq!(scene.objects, ["caf\u{e9}", "caf\u{e8}"]);
    assert!(scene.warnings.is_empty(), "{}", messages(&scene.warnings));
    let red = &scene.materials[scene.patches[0].material as usize];
    assert_eq!(
        (red.name.as_str(), red.reflectance_rgb),
        ("r\u{f6}t", [0.8, 0.1, 0.1])
    );

    let e = load_error(dir.path(), "bad.obj", b"o caf\xe9\nv 0 0 0\nv 1 \xe9 0\n");
    assert_eq!(
        e,
        "bad.obj:3: byte 0xE9 at column 5 is not text (UTF-8) in a `v` statement; only names (`o`, \
         `g`, `usemtl`, `mtllib`, `maplib`, `usemap`) and comments may hold other bytes"
    );
    let scenes = dir.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    let outside = b"mtllib ../caf\xe9.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl r\xf6t\nf 1 2 3\n";
    let scene = load_file(
        &write(&scenes, "out.obj", outside),
        &SceneOptions::default(),
    );
    let warning = messages(&scene.warnings);
    assert!(
        warning.contains("`../caf\u{e9}.mtl` climbs out with `..`, outside the scene's folder"),
        "{warning}"
    );
    assert_eq!(
        scene.materials[scene.patches[0].material as usize].name,
        "default"
    );
}
