//! STL scenes (ASCII and binary), read with `stl_io`.
//!
//! An STL file is one object (named after the file) of triangles with one material, scx's default
//! (reflectance 0.5, no emission): STL has no materials. Each triangle is a patch, facing the side its
//! corners run counter-clockwise about (the STL rule; the stored facet normals are often zero or stale).

use std::path::Path;

use super::{Material, Scene, SceneBuilder, SceneError, SceneOptions};

/// Loads STL bytes (ASCII or binary) read from `path`.
pub(crate) fn load_bytes(
    shown: &str,
    bytes: &[u8],
    path: &Path,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    let file_error = |message: String| SceneError::File {
        path: shown.to_string(),
        message,
    };
    // A binary STL's 80-byte header is free text, and some exporters start it with `solid`, which
    // stl_io would take for the ASCII form: hide the word from it (the header carries no geometry).
    let binary_solid = super::format::detect(bytes) == Some(super::format::Format::StlBinary)
        && bytes.starts_with(b"solid");
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
    b.object(&object_name(path));
    let material = b.material(Material::default());
    for (k, t) in triangles.enumerate() {
        let t = t.map_err(|e| file_error(format!("triangle {}: {e}", k + 1)))?;
        let corners = t.vertices.map(|v| b.vertex(v.0.map(f64::from)));
        b.polygon(&corners, material, format!("triangle {}", k + 1));
    }
    b.build_with(options)
}

/// The object name of a single-object file: its name without the extension.
pub(crate) fn object_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "object".into())
}
