//! The scene's patches as a coloured mesh: ASCII PLY, one face per patch, for MeshLab or Blender.
//!
//! Each face has its own copies of its vertices, so that the colours can be given both per face
//! (`red green blue` on the face: MeshLab) and per vertex (Blender's importer reads vertex colours
//! only) without blending across patches. Coordinates are in the scene's own units and frame; faces
//! are in patch order (the order of `scx export`), with the value shown as a `value` property (NaN when
//! the patch has none).

use std::io::{self, Write};

use crate::scene::Scene;

/// Writes `scene`'s patches with `colours[p]` and `values[p]` for patch `p`; `comment` goes into the
/// header (what the values are).
pub fn write_ply(
    out: &mut dyn Write,
    scene: &Scene,
    colours: &[[u8; 3]],
    values: &[Option<f64>],
    comment: &str,
) -> io::Result<()> {
    let corners: usize = scene.patches.iter().map(|p| scene.polygon(p).len()).sum();
    writeln!(out, "ply")?;
    writeln!(out, "format ascii 1.0")?;
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
    writeln!(out, "property double value")?;
    writeln!(out, "end_header")?;
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
        let value = values[p].unwrap_or(f64::NAN);
        writeln!(out, " {r} {g} {b} {value}")?;
    }
    Ok(())
}
