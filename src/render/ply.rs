//! The scene's patches as a coloured mesh: PLY, one face per patch, for MeshLab or Blender.
//!
//! Each face has its own copies of its vertices, so that the colours can be given both per face
//! (`red green blue` on the face: MeshLab) and per vertex (Blender's importer reads vertex colours
//! only) without blending across patches. Coordinates are in the scene's own units and frame; faces
//! are in patch order (the order of `scx export`), with the value shown as a `value` property and a
//! `valued` flag before it: 1 when the patch has a value, 0 when it has none (no line left it, say), its
//! `value` then written as 0. PLY has no missing value that every reader accepts (ASCII readers,
//! scx's among them, refuse `NaN`), so the flag says it and both formats hold the same numbers.
//!
//! Binary little-endian by default: a fine mesh's vertices in ASCII are written with up to 17 digits
//! each, three times the bytes of their doubles. ASCII on request, for reading or diffing by eye.

use std::io::{self, Write};

use crate::scene::Scene;

/// How a PLY file stores its numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PlyFormat {
    /// `binary_little_endian 1.0`: compact, and exact.
    #[default]
    Binary,
    /// `ascii 1.0`: readable text (numbers written exactly, as the shortest decimal that reads back).
    Ascii,
}

impl PlyFormat {
    /// The `format` line's name for it.
    fn header_name(self) -> &'static str {
        match self {
            PlyFormat::Binary => "binary_little_endian",
            PlyFormat::Ascii => "ascii",
        }
    }
}

/// Writes `scene`'s patches with `colours[p]` and `values[p]` for patch `p` in `format`; `comment`
/// goes into the header (what the values are).
pub fn write_ply(
    out: &mut dyn Write,
    scene: &Scene,
    colours: &[[u8; 3]],
    values: &[Option<f64>],
    comment: &str,
    format: PlyFormat,
) -> io::Result<()> {
    write_header(out, scene, comment, format)?;
    match format {
        PlyFormat::Ascii => write_ascii_body(out, scene, colours, values),
        PlyFormat::Binary => write_binary_body(out, scene, colours, values),
    }
}

fn write_header(
    out: &mut dyn Write,
    scene: &Scene,
    comment: &str,
    format: PlyFormat,
) -> io::Result<()> {
    let corners: usize = scene.patches.iter().map(|p| scene.polygon(p).len()).sum();
    writeln!(out, "ply")?;
    writeln!(out, "format {} 1.0", format.header_name())?;
    for line in comment.lines() {
        writeln!(out, "comment {line}")?;
    }
    writeln!(out, "element vertex {corners}")?;
    for p in ["x", "y", "z"] {
        writeln!(out, "property double {p}")?;
    }
    for c in ["red", "green", "blue"] {
        writeln!(out, "property uchar {c}")?;
    }
    writeln!(out, "element face {}", scene.patch_count())?;
    writeln!(out, "property list uchar int vertex_indices")?;
    for c in ["red", "green", "blue"] {
        writeln!(out, "property uchar {c}")?;
    }
    writeln!(out, "property uchar valued")?;
    writeln!(out, "property double value")?;
    writeln!(out, "end_header")
}

fn write_ascii_body(
    out: &mut dyn Write,
    scene: &Scene,
    colours: &[[u8; 3]],
    values: &[Option<f64>],
) -> io::Result<()> {
    for (p, patch) in scene.patches.iter().enumerate() {
        let [r, g, b] = colours[p];
        for &v in scene.polygon(patch) {
            let x = scene.vertices[v as usize];
            writeln!(out, "{} {} {} {r} {g} {b}", x.x, x.y, x.z)?;
        }
    }
    let mut next = 0usize;
    for (p, patch) in scene.patches.iter().enumerate() {
        let [r, g, b] = colours[p];
        write!(out, "{}", scene.polygon(patch).len())?;
        for _ in scene.polygon(patch) {
            write!(out, " {next}")?;
            next += 1;
        }
        let (valued, value) = flag_and_value(values[p]);
        writeln!(out, " {r} {g} {b} {valued} {value}")?;
    }
    Ok(())
}

fn write_binary_body(
    out: &mut dyn Write,
    scene: &Scene,
    colours: &[[u8; 3]],
    values: &[Option<f64>],
) -> io::Result<()> {
    for (p, patch) in scene.patches.iter().enumerate() {
        for &v in scene.polygon(patch) {
            let x = scene.vertices[v as usize];
            for c in [x.x, x.y, x.z] {
                out.write_all(&c.to_le_bytes())?;
            }
            out.write_all(&colours[p])?;
        }
    }
    let mut next = 0i32;
    for (p, patch) in scene.patches.iter().enumerate() {
        out.write_all(&[corner_count(scene.polygon(patch).len())?])?;
        for _ in scene.polygon(patch) {
            out.write_all(&next.to_le_bytes())?;
            next = next.checked_add(1).ok_or_else(too_many_corners)?;
        }
        out.write_all(&colours[p])?;
        let (valued, value) = flag_and_value(values[p]);
        out.write_all(&[valued])?;
        out.write_all(&value.to_le_bytes())?;
    }
    Ok(())
}

/// The `valued` flag and the `value` written for a patch's value: `(1, v)`, or `(0, 0.0)` without one
/// (a value that is not finite counts as none: ASCII readers refuse `NaN` and `inf`).
fn flag_and_value(value: Option<f64>) -> (u8, f64) {
    value.filter(|v| v.is_finite()).map_or((0, 0.0), |v| (1, v))
}

/// A face's corner count as the `uchar` the list is declared with.
fn corner_count(n: usize) -> io::Result<u8> {
    u8::try_from(n).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("a patch has {n} corners; a PLY face list holds at most 255"),
        )
    })
}

fn too_many_corners() -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        "more than 2^31 corners: PLY's int indices cannot number them",
    )
}
