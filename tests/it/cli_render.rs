//! `scx render`: the PNG decodes to the size asked for plus the colour bar, the PLY parses with one
//! coloured face per patch whose corners are the patch's, and bad requests fail before any line is cast.

use crate::support::scx;
use scene_complexity::internals::scenes;

/// A careful ASCII PLY reader for the files `scx render` writes: the header's elements and properties,
/// then the vertices `(x, y, z, r, g, b)` and the faces `(indices, r, g, b, value)`.
struct Ply {
    vertices: Vec<([f64; 3], [u8; 3])>,
    faces: Vec<(Vec<usize>, [u8; 3], f64)>,
}

fn read_ply(text: &str) -> Ply {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("ply"));
    assert_eq!(lines.next(), Some("format ascii 1.0"));
    let (mut n_vertices, mut n_faces) = (None, None);
    let mut properties: Vec<String> = Vec::new();
    for line in lines.by_ref() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["end_header"] => break,
            ["comment", ..] => {}
            ["element", "vertex", n] => n_vertices = Some(n.parse::<usize>().unwrap()),
            ["element", "face", n] => n_faces = Some(n.parse::<usize>().unwrap()),
            ["property", ..] => properties.push(words[1..].join(" ")),
            other => panic!("unexpected header line {other:?}"),
        }
    }
    assert_eq!(
        properties,
        [
            "double x",
            "double y",
            "double z",
            "uchar red",
            "uchar green",
            "uchar blue",
            "list uchar int vertex_indices",
            "uchar red",
            "uchar green",
            "uchar blue",
            "double value"
        ]
    );
    let (n_vertices, n_faces) = (n_vertices.unwrap(), n_faces.unwrap());
    let mut vertices = Vec::new();
    for _ in 0..n_vertices {
        let w: Vec<&str> = lines.next().unwrap().split(' ').collect();
        assert_eq!(w.len(), 6);
        let x = [0, 1, 2].map(|k| w[k].parse::<f64>().unwrap());
        let c = [3, 4, 5].map(|k| w[k].parse::<u8>().unwrap());
        vertices.push((x, c));
    }
    let mut faces = Vec::new();
    for _ in 0..n_faces {
        let w: Vec<&str> = lines.next().unwrap().split(' ').collect();
        let k: usize = w[0].parse().unwrap();
        assert_eq!(w.len(), 1 + k + 4);
        let idx: Vec<usize> = w[1..=k].iter().map(|x| x.parse().unwrap()).collect();
        assert!(idx.iter().all(|&i| i < n_vertices));
        let c = [k + 1, k + 2, k + 3].map(|i| w[i].parse::<u8>().unwrap());
        faces.push((idx, c, w[k + 4].parse::<f64>().unwrap()));
    }
    assert_eq!(lines.next(), None, "nothing after the faces");
    Ply { vertices, faces }
}

#[test]
fn render_writes_a_png_and_a_ply_that_parse() {
    let dir = tempfile::tempdir().unwrap();
    let (png, ply) = (dir.path().join("map.png"), dir.path().join("mesh.ply"));
    let out = scx(&[
        "render",
        "@cornell:2",
        "--color",
        "radiosity",
        "--lines",
        "2e5",
        "--size",
        "320x240",
        "-o",
        png.to_str().unwrap(),
        "--patches-mesh",
        ply.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("wrote") && err.contains("map.png") && err.contains("mesh.ply"),
        "{err}"
    );

    let decoder = png::Decoder::new(std::fs::File::open(&png).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (320 + 210, 240 + 34));
    // Not a blank picture: many colours in the scene part.
    let colours: std::collections::BTreeSet<&[u8]> =
        buf.chunks(info.line_size / info.width as usize).collect();
    assert!(colours.len() > 50, "{} colours", colours.len());

    let scene = scenes::load("@cornell:2").unwrap();
    let mesh = read_ply(&std::fs::read_to_string(&ply).unwrap());
    assert_eq!(mesh.faces.len(), scene.patch_count(), "one face per patch");
    for (p, (idx, colour, value)) in mesh.faces.iter().enumerate() {
        let polygon = scene.polygon(&scene.patches[p]);
        assert_eq!(idx.len(), polygon.len());
        for (&i, &v) in idx.iter().zip(polygon) {
            let (x, c) = mesh.vertices[i];
            assert_eq!(
                x,
                scene.vertices[v as usize].to_array(),
                "patch {p}: corners in scene units"
            );
            assert_eq!(c, *colour, "patch {p}: vertex colours are the face's");
        }
        assert!(*value >= 0.0, "patch {p}: radiosity {value}");
    }
}

#[test]
fn bad_render_requests_fail_before_work() {
    for (args, says) in [
        (
            &["render", "@cube:2", "--color", "radiosity", "-o", "x.png"][..],
            "needs light",
        ),
        (
            &["render", "@cube:2", "--color", "segments", "-o", "x.jpg"],
            ".png",
        ),
        (
            &[
                "render",
                "@cube:2",
                "--color",
                "segments",
                "-o",
                "x.png",
                "--patches-mesh",
                "m.obj",
            ],
            ".ply",
        ),
        (
            &["render", "@cube:2", "--color", "entropy", "-o", "x.png"],
            "row-entropy",
        ),
        (
            &[
                "render",
                "@cube:2",
                "--color",
                "segments",
                "-o",
                "x.png",
                "--camera",
                "0,0,0,0,0,0,0,1,0,60",
            ],
            "same point",
        ),
        (
            &[
                "render",
                "@cube:2",
                "--color",
                "segments",
                "--per-area",
                "-o",
                "x.png",
            ],
            "--per-area",
        ),
        (
            &[
                "render", "@cube:2", "--color", "segments", "-o", "x.png", "--range", "2,1",
            ],
            "high end",
        ),
    ] {
        let out = scx(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("panicked"));
    }
    let out = scx(&[
        "render",
        "@cube:2",
        "--color",
        "segments",
        "-o",
        "/no/such/dir/x.png",
    ]);
    assert_eq!(out.status.code(), Some(3));
}
