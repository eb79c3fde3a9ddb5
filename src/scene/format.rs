//! Which format a scene file is in, from its content (the extension only breaks a tie), and loading it.

use std::path::Path;

use super::stl::is_binary_stl;
use super::{gltf, obj, ply, stl, Scene, SceneError, SceneOptions};

/// The scene file formats scx reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (+ MTL), text.
    Obj,
    /// glTF 2.0 as JSON (`.gltf`), with its buffers in files beside it or in data URIs.
    Gltf,
    /// glTF 2.0 binary (`.glb`).
    Glb,
    /// PLY (Stanford polygon file), ASCII or binary.
    Ply,
    /// STL, ASCII.
    StlAscii,
    /// STL, binary.
    StlBinary,
}

impl Format {
    /// A name for messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "OBJ",
            Format::Gltf => "glTF (JSON)",
            Format::Glb => "glTF (binary .glb)",
            Format::Ply => "PLY",
            Format::StlAscii => "STL (ASCII)",
            Format::StlBinary => "STL (binary)",
        }
    }
}

/// The format of a file's bytes: magic numbers first (`glTF` for .glb, `ply` for PLY), then the text
/// forms (glTF JSON has an `"asset"`, ASCII STL starts `solid` and has a `facet`, OBJ has statements such
/// as `v` and `f`), then binary STL, whose size is exactly 84 + 50 bytes per triangle. `None` when nothing
/// fits.
pub fn detect(bytes: &[u8]) -> Option<Format> {
    if bytes.starts_with(b"glTF") {
        return Some(Format::Glb);
    }
    if bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n") {
        return Some(Format::Ply);
    }
    let head = &bytes[..bytes.len().min(4096)];
    let text = std::str::from_utf8(head)
        .or_else(|e| std::str::from_utf8(&head[..e.valid_up_to()]))
        .unwrap_or("");
    let trimmed = text.trim_start_matches('\u{feff}').trim_start();
    if trimmed.starts_with('{') && text.contains("\"asset\"") {
        return Some(Format::Gltf);
    }
    if trimmed.starts_with("solid") && text.contains("facet") {
        return Some(Format::StlAscii);
    }
    if is_binary_stl(bytes) {
        return Some(Format::StlBinary);
    }
    if looks_like_obj(text) {
        return Some(Format::Obj);
    }
    None
}

/// Text with OBJ statements (`v`, `f`, `o`, `usemtl`, ...) among its first ones; other statements
/// (extensions such as `vw`, comments) may be mixed in. Text without any statement is an OBJ with no
/// faces, which the OBJ reader then names as such.
fn looks_like_obj(text: &str) -> bool {
    const KEYWORDS: &[&str] = &[
        "v", "vt", "vn", "vp", "f", "l", "p", "o", "g", "s", "usemtl", "mtllib",
    ];
    if text.contains('\0') {
        return false;
    }
    let mut statements = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .peekable();
    if statements.peek().is_none() {
        return true;
    }
    statements
        .take(50)
        .any(|l| KEYWORDS.contains(&l.split_whitespace().next().unwrap_or("")))
}

/// Loads a scene file in any format scx reads, found from its content ([`detect`]).
pub fn load_file(path: &Path, options: &SceneOptions) -> Result<Scene, SceneError> {
    let shown = path.display().to_string();
    let file_error = |message: String| SceneError::in_file(&shown, message);
    if !path.exists() {
        return Err(file_error("no such file".into()));
    }
    if path.is_dir() {
        return Err(file_error("is a directory, not a scene file".into()));
    }
    let bytes =
        std::fs::read(path).map_err(|e| file_error(format!("cannot read the file: {e}")))?;
    let format = detect(&bytes).ok_or_else(|| file_error(unknown_format(path, &bytes)))?;
    match format {
        Format::Obj => {
            let text = String::from_utf8(bytes).map_err(|e| {
                file_error(format!(
                    "not a text file (invalid UTF-8 at byte {})",
                    e.utf8_error().valid_up_to()
                ))
            })?;
            obj::load_obj_text(&shown, &text, path, options)
        }
        Format::Gltf | Format::Glb => gltf::load_bytes(&shown, &bytes, path, options),
        Format::Ply => ply::load_bytes(&shown, &bytes, path, options),
        Format::StlAscii | Format::StlBinary => stl::load_bytes(&shown, &bytes, path, options),
    }
}

/// Why a file is in no format scx reads, naming what it looks like.
fn unknown_format(path: &Path, bytes: &[u8]) -> String {
    let ext = path
        .extension()
        .map(|e| format!(" (extension `.{}`)", e.to_string_lossy()))
        .unwrap_or_default();
    let start: String = bytes
        .iter()
        .take(8)
        .map(|&b| {
            if b.is_ascii_graphic() || b == b' ' {
                (b as char).to_string()
            } else {
                format!("\\x{b:02x}")
            }
        })
        .collect();
    if bytes.is_empty() {
        return "the file is empty".into();
    }
    let stl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("stl"));
    if stl && bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        return format!(
            "a binary STL of the wrong size: its header says {count} triangles ({} bytes), the file has \
             {} bytes (cut short?)",
            84 + 50 * count,
            bytes.len()
        );
    }
    if std::str::from_utf8(&bytes[..bytes.len().min(4096)]).is_err() && !is_binary_stl(bytes) {
        return format!(
            "not a text file and in no binary format scx reads{ext}: it starts `{start}`; scx reads \
             OBJ, glTF (.gltf, .glb), PLY and STL"
        );
    }
    format!(
        "unknown scene format{ext}: it starts `{start}`; scx reads OBJ, glTF (.gltf, .glb), PLY and STL"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_by_their_content() {
        assert_eq!(detect(b"glTF\x02\0\0\0"), Some(Format::Glb));
        assert_eq!(detect(b"ply\nformat ascii 1.0\n"), Some(Format::Ply));
        assert_eq!(
            detect(b"{\"asset\": {\"version\": \"2.0\"}}"),
            Some(Format::Gltf)
        );
        assert_eq!(
            detect(b"solid x\n facet normal 0 0 1\n"),
            Some(Format::StlAscii)
        );
        let mut binary = vec![0u8; 84 + 50];
        binary[80] = 1;
        assert_eq!(detect(&binary), Some(Format::StlBinary));
        // A binary STL whose header starts `solid` (some exporters do) is still binary.
        binary[..5].copy_from_slice(b"solid");
        assert_eq!(detect(&binary), Some(Format::StlBinary));
        assert_eq!(detect(b"# cube\nv 0 0 0\nf 1 2 3\n"), Some(Format::Obj));
        assert_eq!(detect(b""), Some(Format::Obj));
        assert_eq!(detect(b"hello world\n"), None);
        assert_eq!(detect(&[0x7f, 0x45, 0x4c, 0x46, 0xff, 0x00]), None);
    }
}
