//! STL scenes (ASCII and binary), read with `stl_io`.
//!
//! An STL file is one object (named after the file) of triangles with one material, scx's default
//! (reflectance 0.5, no emission): STL has no materials. Each triangle is a patch, facing the side its
//! corners run counter-clockwise about (the STL rule; the stored facet normals are often zero or stale).
//!
//! Writing ([`to_bytes`]): binary STL with `stl_io`, every triangle with its patch's normal, f32
//! coordinates in the scene's units.

use std::path::Path;

use super::{Material, Scene, SceneBuilder, SceneError, SceneOptions};

/// Loads STL bytes (ASCII or binary) read from `path`.
pub(crate) fn load_bytes(
    shown: &str,
    bytes: &[u8],
    path: &Path,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    read_bytes(shown, bytes, path)?.build_with(options)
}

/// The scene of STL bytes read from `path`, ready to build: the bytes may go before it is built.
pub(crate) fn read_bytes(
    shown: &str,
    bytes: &[u8],
    path: &Path,
) -> Result<SceneBuilder, SceneError> {
    let file_error = |message: String| SceneError::in_file(shown, message);
    // A binary STL's 80-byte header is free text, and some exporters start it with `solid`, which
    // stl_io would take for the ASCII form: hide the word from it (the header carries no geometry).
    let binary_solid = is_binary_stl(bytes) && bytes.starts_with(b"solid");
    let mut owned;
    let bytes = if binary_solid {
        owned = bytes.to_vec();
        owned[..5].copy_from_slice(b"SOLID");
        owned.as_slice()
    } else {
        bytes
    };
    let mut cursor = std::io::Cursor::new(bytes);
    let triangles = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| file_error(format!("not a readable STL file: {e}")))?;
    let mut b = SceneBuilder::new(shown);
    b.object(&super::object_name(path));
    let material = b.material(Material::default());
    for (k, t) in triangles.enumerate() {
        let t = t.map_err(|e| file_error(format!("triangle {}: {e}", k + 1)))?;
        let corners = t.vertices.map(|v| b.vertex(v.0.map(f64::from)));
        b.polygon(&corners, material, format!("triangle {}", k + 1));
    }
    Ok(b)
}

/// Whether bytes are a binary STL by their size: an 80-byte header, a triangle count, and 50 bytes per
/// triangle, exactly.
pub(crate) fn is_binary_stl(bytes: &[u8]) -> bool {
    if bytes.len() < 84 {
        return false;
    }
    let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    bytes.len() as u64 == 84 + 50 * count
}

/// A scene as binary STL: each of its triangles (front side counter-clockwise) with its patch's normal,
/// coordinates in the scene's units rounded to f32 (what STL holds). STL keeps neither patches,
/// materials nor objects: reading it back gives a patch per triangle.
pub fn to_bytes(scene: &Scene) -> Vec<u8> {
    let corner = |v: u32| {
        let p = scene.vertices[v as usize];
        stl_io::Vertex::new([p.x as f32, p.y as f32, p.z as f32])
    };
    let triangles = scene
        .triangles
        .iter()
        .zip(&scene.triangle_patch)
        .map(|(t, &patch)| {
            let n = scene.patches[patch as usize].normal;
            stl_io::Triangle {
                normal: stl_io::Normal::new([n.x as f32, n.y as f32, n.z as f32]),
                vertices: t.map(corner),
            }
        });
    let mut out = Vec::with_capacity(84 + 50 * scene.triangles.len());
    stl_io::write_stl(&mut out, triangles).expect("writing to memory cannot fail");
    out
}
