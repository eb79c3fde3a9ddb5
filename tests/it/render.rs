//! Pictures of a scene (`scene_complexity::render`): the default camera stands inside an enclosure
//! (every sample sees the front of a wall) and outside an object (background around it, no back side
//! seen); a camera behind a wall sees its back side.

use scene_complexity::internals::geom::{Point, Vector};
use scene_complexity::internals::scene::{obj, Scene};
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::{make_tracer, Backend, Query};
use scene_complexity::render::{default_camera, trace_view, Camera, Sample};

fn samples(scene: &Scene, camera: Option<Camera>) -> Vec<Sample> {
    let tracer = make_tracer(Backend::Rust, scene, Query::Single).unwrap();
    let camera = camera.unwrap_or_else(|| default_camera(scene, tracer.as_ref()).unwrap());
    camera.validate().unwrap();
    trace_view(scene, tracer.as_ref(), &camera, 64, 48)
        .unwrap()
        .samples
}

fn count(s: &[Sample], f: impl Fn(&Sample) -> bool) -> usize {
    s.iter().filter(|x| f(x)).count()
}

#[test]
fn the_default_view_of_a_room_is_from_inside() {
    for spec in ["@cube:4", "@cornell", "@fig2:a", "@labyrinth"] {
        let scene = scenes::load(spec).unwrap();
        let s = samples(&scene, None);
        let front = count(&s, |x| matches!(x, Sample::Front { .. }));
        assert_eq!(
            front,
            s.len(),
            "{spec}: every sample sees the front of a surface"
        );
        let seen: std::collections::BTreeSet<u32> = s.iter().filter_map(Sample::patch).collect();
        assert!(seen.len() > 3, "{spec}: the view shows several patches");
    }
}

/// A box with outward faces (an object in open space).
fn a_box() -> Scene {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
                f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
    obj::load_text("box.obj", text, &|_| Err(obj::MtlError::other("no MTL"))).unwrap()
}

#[test]
fn the_default_view_of_an_object_is_from_outside() {
    let scene = a_box();
    let s = samples(&scene, None);
    assert!(count(&s, |x| *x == Sample::Background) > s.len() / 4);
    assert!(count(&s, |x| matches!(x, Sample::Front { .. })) > s.len() / 10);
    assert_eq!(count(&s, |x| matches!(x, Sample::Back { .. })), 0);
    // Three faces show from the front, above and to the right.
    let seen: std::collections::BTreeSet<u32> = s.iter().filter_map(Sample::patch).collect();
    assert_eq!(seen.len(), 3, "{seen:?}");
}

#[test]
fn a_camera_outside_a_room_sees_the_back_of_a_wall() {
    let scene = scenes::load("@cube:2").unwrap();
    let camera = Camera {
        eye: Point::new(0.5, 0.5, -2.0),
        target: Point::new(0.5, 0.5, 0.5),
        up: Vector::Y,
        fov_degrees: 20.0,
    };
    let s = samples(&scene, Some(camera));
    assert_eq!(count(&s, |x| matches!(x, Sample::Back { .. })), s.len());
    // And from inside, looking at the same wall from the far side, its front.
    let inside = Camera {
        eye: Point::new(0.5, 0.5, 0.9),
        target: Point::new(0.5, 0.5, 0.0),
        ..camera
    };
    let s = samples(&scene, Some(inside));
    assert_eq!(count(&s, |x| matches!(x, Sample::Front { .. })), s.len());
}

/// The share of the samples that see a front side.
fn front_share(s: &[Sample]) -> f64 {
    count(s, |x| matches!(x, Sample::Front { .. })) as f64 / s.len() as f64
}

/// An axis-aligned rectangle at `at` on `axis`, spanning `u` and `v` on the next two axes (cyclic),
/// its front facing `+axis` when `facing > 0`, as an OBJ face after the vertices so far.
fn rectangle(obj: &mut String, axis: usize, at: f64, u: (f64, f64), v: (f64, f64), facing: f64) {
    let mut corners = [(u.0, v.0), (u.1, v.0), (u.1, v.1), (u.0, v.1)];
    if facing < 0.0 {
        corners.reverse();
    }
    for (a, b) in corners {
        let mut p = [0.0; 3];
        p[axis] = at;
        p[(axis + 1) % 3] = a;
        p[(axis + 2) % 3] = b;
        obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    obj.push_str("f -4 -3 -2 -1\n");
}

/// A room of 2 x 2 x 2 (x and z from -1 to 1, y from 0 to 2), walls facing in, open at +z like
/// McGuire's Cornell boxes, with a tall block near the back wall (faces out).
fn open_room() -> Scene {
    let mut obj = String::new();
    rectangle(&mut obj, 1, 0.0, (-1.0, 1.0), (-1.0, 1.0), 1.0); // floor: y, spans z then x
    rectangle(&mut obj, 1, 2.0, (-1.0, 1.0), (-1.0, 1.0), -1.0);
    rectangle(&mut obj, 2, -1.0, (-1.0, 1.0), (0.0, 2.0), 1.0); // back wall: z, spans x then y
    rectangle(&mut obj, 0, -1.0, (0.0, 2.0), (-1.0, 1.0), 1.0); // side walls: x, spans y then z
    rectangle(&mut obj, 0, 1.0, (0.0, 2.0), (-1.0, 1.0), -1.0);
    let (x, y, z) = ((-0.7, -0.1), (0.0, 1.2), (-0.8, -0.2));
    rectangle(&mut obj, 0, x.0, y, z, -1.0);
    rectangle(&mut obj, 0, x.1, y, z, 1.0);
    rectangle(&mut obj, 2, z.0, x, y, -1.0);
    rectangle(&mut obj, 2, z.1, x, y, 1.0);
    rectangle(&mut obj, 1, y.1, z, x, 1.0);
    obj::load_text("open-room.obj", &obj, &|_| {
        Err(obj::MtlError::other("no MTL"))
    })
    .unwrap()
}

/// The eye is inside the scene's bounds, or outside them on one side only (`open`, the axis and end
/// of the opening), level with the bounds on the other two axes.
fn eye_inside_or_at(scene: &Scene, eye: Point, open: Option<(usize, f64)>) -> bool {
    let (lo, hi) = scene.vertices.iter().fold(
        (Point::splat(f64::INFINITY), Point::splat(f64::NEG_INFINITY)),
        |(lo, hi), v| (lo.min(*v), hi.max(*v)),
    );
    (0..3).all(|k| {
        let within = (lo[k]..=hi[k]).contains(&eye[k]);
        match open {
            Some((axis, sign)) if axis == k => {
                within || (eye[k] - 0.5 * (lo[k] + hi[k])) * sign > 0.0
            }
            _ => within,
        }
    })
}

#[test]
fn the_default_view_of_a_room_open_on_one_side_looks_in_through_the_opening() {
    let scene = open_room();
    let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
    let camera = default_camera(&scene, tracer.as_ref()).unwrap();
    let s = samples(&scene, Some(camera));
    let front = front_share(&s);
    eprintln!("open room: eye {:?}, front share {front:.3}", camera.eye);
    assert!(
        eye_inside_or_at(&scene, camera.eye, Some((2, 1.0))),
        "{camera:?}"
    );
    assert!(front > 0.8, "front share {front}");
    assert_eq!(count(&s, |x| matches!(x, Sample::Back { .. })), 0);
    // The floor, the ceiling, the back wall, both side walls and the block's front (patches 0 to 4
    // and 8, in the order above) all show.
    let seen: std::collections::BTreeSet<u32> = s.iter().filter_map(Sample::patch).collect();
    assert!(
        [0, 1, 2, 3, 4, 8].iter().all(|p| seen.contains(p)),
        "{seen:?}"
    );
}

/// McGuire's Cornell boxes (public, Morgan McGuire's Computer Graphics Archive), when a copy is under
/// `../shared/real-scenes` or the folder `SCX_REAL_SCENES` names: both are open at +z.
fn mcguire_boxes() -> Vec<std::path::PathBuf> {
    let root = std::env::var_os("SCX_REAL_SCENES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| {
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/real-scenes")
        });
    let mut found = Vec::new();
    let mut folders = vec![root];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).into_iter().flatten().flatten() {
            let path = entry.path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            if path.is_dir() {
                folders.push(path);
            } else if name == "CornellBox-Original.obj" || name == "CornellBox-Glossy.obj" {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

#[test]
fn the_default_view_of_mcguires_cornell_boxes_shows_their_inside() {
    let files = mcguire_boxes();
    if files.is_empty() {
        eprintln!(
            "skipped: no CornellBox-Original.obj or CornellBox-Glossy.obj in the real scenes"
        );
        return;
    }
    for file in files {
        let scene = scenes::load(file.to_str().unwrap()).unwrap();
        let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
        let camera = default_camera(&scene, tracer.as_ref()).unwrap();
        let s = samples(&scene, Some(camera));
        let front = front_share(&s);
        let back = count(&s, |x| matches!(x, Sample::Back { .. }));
        eprintln!(
            "{}: eye {:?}, front share {front:.3}",
            file.display(),
            camera.eye
        );
        assert!(front > 0.8, "{}: front share {front}", file.display());
        assert!(
            back * 50 < s.len(),
            "{}: {back} back-side samples",
            file.display()
        );
        assert!(
            eye_inside_or_at(&scene, camera.eye, Some((2, 1.0))),
            "{}: {camera:?}",
            file.display()
        );
    }
}

/// The noise summary of a picture's values: on `@cube:30` at few lines I_s^c's per-patch terms are
/// noise and some patches unsampled; the median relative error falls as 1/sqrt(lines), so the lines it
/// asks for hold from one line count to the next; `@cube:3` at 10^6 lines is not noisy.
#[test]
fn the_noise_summary_follows_the_square_root_law() {
    use scene_complexity::internals::measure::PatchMeasure;
    use scene_complexity::render::{noise_summary, Quantity};
    use scene_complexity::{analyze, RunControl, RunSpec};
    let summary = |spec: &str, lines: u64| {
        let scene = scenes::load(spec).unwrap();
        let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
        let cfg = RunSpec {
            per_patch: true,
            ..RunSpec::new(lines, 3)
        };
        let a = analyze(&scene, tracer.as_ref(), &cfg, &RunControl::default()).unwrap();
        let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
        let q = Quantity::Patch(PatchMeasure::ContinuousTerm);
        noise_summary(a.patches.as_ref().unwrap(), &areas, q, lines)
    };
    let few = summary("@cube:30", 20_000);
    let more = summary("@cube:30", 80_000);
    assert!(few.is_noisy() && more.is_noisy());
    assert_eq!(few.patches, 5400);
    assert!(few.unsampled_patches > 10, "{few:?}");
    assert!(
        more.unsampled_patches < few.unsampled_patches / 4,
        "{more:?}"
    );
    let (r1, r2) = (
        few.median_relative_error.unwrap(),
        more.median_relative_error.unwrap(),
    );
    assert!(r1 > 0.4 && r1 < 0.8, "{few:?}");
    assert!((0.4..0.62).contains(&(r2 / r1)), "{r1} -> {r2}");
    let (n1, n2) = (few.lines_needed().unwrap(), more.lines_needed().unwrap());
    assert!((n1 / n2 - 1.0).abs() < 0.3, "{n1} against {n2}");
    let coarse = summary("@cube:3", 1_000_000);
    assert!(!coarse.is_noisy(), "{coarse:?}");
    assert!(coarse.median_relative_error.unwrap() < 0.05, "{coarse:?}");
    assert_eq!(coarse.unsampled_patches, 0);
}

/// A flat scene (one triangle, in each axis plane) has a default view that shows its front: the
/// bounding box has no depth, so a view framed on it alone would look from the triangle's own plane.
#[test]
fn the_default_view_of_a_flat_scene_shows_its_front() {
    for (corners, plane) in [
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "z = 0"),
        ("v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\n", "y = 0"),
        ("v 0 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n", "x = 0"),
    ] {
        let scene = obj::load_text("triangle.obj", corners, &|_| {
            Err(obj::MtlError::other("no MTL"))
        })
        .unwrap();
        let s = samples(&scene, None);
        let front = count(&s, |x| matches!(x, Sample::Front { .. }));
        let back = count(&s, |x| matches!(x, Sample::Back { .. }));
        assert!(front * 10 > s.len(), "{plane}: {front} front samples");
        assert_eq!(back, 0, "{plane}: the back of the triangle shows");
    }
}

/// The texts of a colour bar's labels, from the low end, on a bar of 400 pixels with labels 16 apart.
fn bar_texts(lo: f64, hi: f64, log: bool, clipped: (bool, bool), marks: &[f64]) -> Vec<String> {
    use scene_complexity::render::{bar_labels, ColourScale};
    let scale = ColourScale { lo, hi, log };
    bar_labels(&scale, clipped, marks, 400.0, 16.0)
        .into_iter()
        .map(|l| l.text)
        .collect()
}

/// Both ends of a colour bar are labelled, rounded to what the scale can tell apart, with round ticks
/// between them that keep clear of the ends; an end that is 0 up to rounding reads 0.
#[test]
fn a_colour_bar_labels_both_ends_and_round_ticks_between() {
    // @cornell's radiosity, log scale: the bottom end is no round value and still labelled.
    assert_eq!(
        bar_texts(0.03468, 0.49437, true, (false, true), &[]),
        ["0.0347", "0.05", "0.1", "0.2", "≥ 0.494"]
    );
    // Floating-point dust at an end reads 0; the round tick at 0 gives way to the end.
    assert_eq!(
        bar_texts(-6.41e-16, 0.49437, false, (true, true), &[]),
        ["≤ 0", "0.1", "0.2", "0.3", "0.4", "≥ 0.494"]
    );
    // Neither end round, nothing clipped: both ends labelled bare, ticks every 0.005 between.
    assert_eq!(
        bar_texts(0.01368, 0.0389, false, (false, false), &[]),
        ["0.0137", "0.015", "0.02", "0.025", "0.03", "0.035", "0.0389"]
    );
    // A value to mark (0, where the theory bounds the values) is labelled, the tick there gives way.
    assert_eq!(
        bar_texts(-7.62e-5, 0.0010934, false, (true, true), &[0.0]),
        [
            "≤ -7.6e-5",
            "0",
            "2e-4",
            "4e-4",
            "6e-4",
            "8e-4",
            "0.001",
            "≥ 0.00109"
        ]
    );
}

/// On any scale and bar length, the first label is the low end and the last the high end, no two labels
/// are closer than the room a label needs, and the round ticks between are evenly spaced.
#[test]
fn every_colour_bar_has_both_ends_labelled_and_labels_apart() {
    use scene_complexity::render::{bar_labels, ColourScale};
    let scales = [
        (0.0, 1.0, false),
        (-1.0, 1.0, false),
        (4.674, 6.141, false),
        (1e-5, 5.2e-5, false),
        (-3.63, 0.409, false),
        (0.0118, 0.4888, true),
        (0.035, 0.05, true),
        (1e-9, 1e9, true),
        (3.0, 3.3, true),
    ];
    for (lo, hi, log) in scales {
        for length in [20.0, 82.0, 200.0, 441.0, 900.0] {
            let scale = ColourScale { lo, hi, log };
            let labels = bar_labels(&scale, (true, false), &[0.0], length, 16.0);
            let (first, last) = (&labels[0], &labels[labels.len() - 1]);
            assert!(
                first.position == 0.0 && first.text.starts_with('≤'),
                "{labels:?}"
            );
            assert!(last.position == 1.0 && last.value == hi, "{labels:?}");
            for pair in labels.windows(2) {
                let apart = (pair[1].position - pair[0].position) * length;
                assert!(apart >= 16.0 || labels.len() == 2, "{length}: {labels:?}");
            }
            // On a linear scale the round ticks between the ends (and the mark at 0) are evenly
            // spaced: none left out between two others.
            let inner: Vec<f64> = labels[1..labels.len() - 1]
                .iter()
                .filter(|l| l.value != 0.0)
                .map(|l| l.value)
                .collect();
            if !log && inner.len() >= 3 {
                let step = inner[1] - inner[0];
                for pair in inner.windows(2) {
                    let d = pair[1] - pair[0];
                    assert!((d - step).abs() < 1e-9 * step, "{length}: {labels:?}");
                }
            }
        }
    }
}

/// A width model for titles, independent of any font file: every character 0.6 of the size wide.
fn model_width(text: &str, size: f64) -> f64 {
    text.chars().count() as f64 * 0.6 * size
}

/// The words of `text`, without the `…` of an elision.
fn words(text: &str) -> Vec<String> {
    text.split_whitespace().map(str::to_string).collect()
}

/// At 640x480 (a file 850 wide, 830 for the title) the longest quantity's title with a real file's
/// path fits in the 34-pixel strip: one line in a smaller font, or two, every word there in order.
#[test]
fn a_long_title_fits_a_640_pixel_picture_whole() {
    use scene_complexity::render::{fit_title, TitleParts};
    let parts = TitleParts {
        scene: "/work/shared/real-scenes/objects/teapot.obj",
        quantity: "information lost, I_i^c - I_i (corrected) [bit per unit area fraction]",
        lines: "10 000 000 lines",
    };
    let width = 850.0 - 20.0;
    let layout = fit_title(&parts, width, &model_width);
    assert!(layout.lines.len() <= 2, "{layout:?}");
    assert_eq!(layout.height(), 34.0);
    assert!(layout.size >= 12.0, "{layout:?}");
    for line in &layout.lines {
        assert!(model_width(line, layout.size) <= width, "{line}");
    }
    let mut shown: Vec<String> = layout.lines.iter().flat_map(|l| words(l)).collect();
    let mut said: Vec<String> = [parts.scene, parts.quantity, parts.lines]
        .iter()
        .flat_map(|p| words(p))
        .collect();
    shown.sort();
    said.sort();
    assert_eq!(shown, said, "every word of the title, none cut");
}

/// A path too long for its line keeps its start and its file's name around `…`; the line count stays.
#[test]
fn a_long_path_in_a_title_is_elided_in_the_middle() {
    use scene_complexity::render::{fit_title, TitleParts};
    let folder = "/home/someone/projects/lighting/scenes/archive/2019/".repeat(3);
    let scene = format!("{folder}living_room_final.obj");
    let parts = TitleParts {
        scene: &scene,
        quantity: "row entropy H_i [bit]",
        lines: "1 000 000 lines",
    };
    let width = 830.0;
    let layout = fit_title(&parts, width, &model_width);
    assert_eq!(layout.lines.len(), 2, "{layout:?}");
    let first = &layout.lines[0];
    assert!(model_width(first, layout.size) <= width, "{first}");
    let (start, end) = first.split_once('…').expect("an ellipsis");
    assert!(scene.starts_with(start) && start.len() > 10, "{first}");
    assert!(
        end.ends_with("living_room_final.obj   1 000 000 lines"),
        "{first}"
    );
    assert_eq!(layout.lines[1], parts.quantity);
}

/// A picture too narrow for the quantity on one line (64 pixels: a file 274 wide) wraps the title on a
/// taller strip; no line is wider than the room.
#[test]
fn a_title_wraps_in_a_narrow_picture() {
    use scene_complexity::render::{fit_title, TitleParts};
    let parts = TitleParts {
        scene: "@fig2:a",
        quantity: "information lost, I_i^c - I_i (corrected) [bit per unit area fraction]",
        lines: "1 000 000 lines",
    };
    let width = 274.0 - 20.0;
    let layout = fit_title(&parts, width, &model_width);
    assert!(layout.lines.len() >= 3, "{layout:?}");
    assert!(layout.height() > 34.0);
    assert!(layout.top(layout.lines.len() - 1) + layout.size <= layout.height());
    for line in &layout.lines {
        assert!(model_width(line, layout.size) <= width, "{line}");
    }
    assert_eq!(layout.lines[0], "@fig2:a");
    assert_eq!(
        layout.lines[1..].join(" ").replace("   ", " "),
        format!("{} {}", parts.quantity, parts.lines)
    );
}

/// The share of `samples` that see the front of a patch for which `pick` holds.
fn share_showing(samples: &[Sample], pick: impl Fn(u32) -> bool) -> f64 {
    let n = samples
        .iter()
        .filter(|s| matches!(s, Sample::Front { patch, .. } if pick(*patch)))
        .count();
    n as f64 / samples.len() as f64
}

/// Whether every corner of patch `p` lies within `eps` of `value` on `axis` (scene units).
fn patch_on_plane(scene: &Scene, p: u32, axis: usize, value: f64, eps: f64) -> bool {
    let patch = &scene.patches[p as usize];
    scene
        .polygon(patch)
        .iter()
        .all(|&v| (scene.vertices[v as usize][axis] - value).abs() <= eps)
}

/// The default view of a closed room stands inside it (the renderer draws the near wall's back, so a
/// camera outside would see nothing else) and shows what a picture of a room is for: the floor (the
/// patches in the plane of the lowest y), the far wall (in the plane of the bounds the camera faces)
/// and, in the Cornell box, the light (the emitting patches), each on a visible part of the picture.
#[test]
fn the_default_view_of_a_room_shows_its_floor_light_and_far_wall() {
    for spec in ["@cornell", "@cornell:4", "@cube:4"] {
        let scene = scenes::load(spec).unwrap();
        let tracer = make_tracer(Backend::Rust, &scene, Query::Single).unwrap();
        let camera = default_camera(&scene, tracer.as_ref()).unwrap();
        eprintln!("{spec}: {camera:?}");
        assert!(
            eye_inside_or_at(&scene, camera.eye, None),
            "{spec}: {camera:?}"
        );
        let s = trace_view(&scene, tracer.as_ref(), &camera, 160, 120)
            .unwrap()
            .samples;
        let (lo, hi) = scene.vertices.iter().fold(
            (Point::splat(f64::INFINITY), Point::splat(f64::NEG_INFINITY)),
            |(lo, hi), v| (lo.min(*v), hi.max(*v)),
        );
        let eps = 1e-6 * (hi - lo).max_element();
        // The far wall: across the axis the camera looks along most, on the side it looks to.
        let view = camera.target - camera.eye;
        let axis = if view.x.abs() > view.z.abs() { 0 } else { 2 };
        let far = if view[axis] > 0.0 { hi[axis] } else { lo[axis] };
        let floor = share_showing(&s, |p| patch_on_plane(&scene, p, 1, lo.y, eps));
        let wall = share_showing(&s, |p| patch_on_plane(&scene, p, axis, far, eps));
        assert!(
            floor > 0.02,
            "{spec}: the floor on {floor:.3} of the picture"
        );
        assert!(
            wall > 0.05,
            "{spec}: the far wall on {wall:.3} of the picture"
        );
        let emits = |p: u32| {
            let patch = &scene.patches[p as usize];
            scene.materials[patch.material as usize].emission > 0.0
        };
        if scene
            .patches
            .iter()
            .enumerate()
            .any(|(p, _)| emits(p as u32))
        {
            let light = share_showing(&s, emits);
            assert!(
                light > 0.01,
                "{spec}: the light on {light:.3} of the picture"
            );
        }
    }
}
