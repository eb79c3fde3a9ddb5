//! STL scenes: binary, read with `stl_io`, and ASCII, read here.
//!
//! An STL file is one object (named after the file), or with several ASCII solids an object per solid,
//! of triangles with one material, scx's default (reflectance 0.5, no emission): STL has no materials. Each triangle is a patch, facing the side its
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
    // A file of a binary STL's exact size is read as ASCII only when it looks so in full (a binary
    // header may start with `solid` too); any other file that starts `solid` is ASCII, read by scx's
    // reader whatever its first 4 KiB hold (stl_io's would take it, with messages of its own).
    let ascii = if is_binary_stl(bytes) {
        looks_like_ascii_stl(bytes)
    } else {
        starts_with_solid(bytes)
    };
    if ascii {
        match read_ascii(shown, bytes, path) {
            // A binary STL's header is free text and may start `solid` and name facets.
            Err(_) if is_binary_stl(bytes) => read_binary(shown, bytes, path),
            read => read,
        }
    } else {
        read_binary(shown, bytes, path)
    }
}

/// Whether bytes start like an ASCII STL: `solid` (in any case, after a byte-order mark and blank
/// space), with `facet` or `endsolid` among the first 4 KiB.
pub(crate) fn looks_like_ascii_stl(bytes: &[u8]) -> bool {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]).to_ascii_lowercase();
    let text = head.trim_start_matches('\u{feff}').trim_start();
    text.starts_with("solid") && (text.contains("facet") || text.contains("endsolid"))
}

/// Whether bytes start `solid` (in any case, after a byte-order mark and blank space).
fn starts_with_solid(bytes: &[u8]) -> bool {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(64)]).to_ascii_lowercase();
    head.trim_start_matches('\u{feff}')
        .trim_start()
        .starts_with("solid")
}

/// A binary STL, read with `stl_io`: only bytes of the size its header gives, so that stl_io's reader,
/// whose messages are its own (`failed to fill whole buffer`), has nothing to refuse.
fn read_binary(shown: &str, bytes: &[u8], path: &Path) -> Result<SceneBuilder, SceneError> {
    let file_error = |message: String| SceneError::in_file(shown, message);
    if !is_binary_stl(bytes) {
        return Err(file_error(binary_size_problem(bytes)));
    }
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

/// Why bytes read as a binary STL are none: shorter than its header, or not of the size it gives.
fn binary_size_problem(bytes: &[u8]) -> String {
    let Some(count) = bytes.get(80..84) else {
        return format!(
            "not a binary STL: {} bytes, shorter than its 84-byte header and triangle count",
            bytes.len()
        );
    };
    let count = u64::from(u32::from_le_bytes([count[0], count[1], count[2], count[3]]));
    wrong_size_text(count, 84 + 50 * count, bytes.len() as u64)
}

/// The message for a binary STL of `size` bytes whose header's `count` triangles need `expected`.
pub(crate) fn wrong_size_text(count: u64, expected: u64, size: u64) -> String {
    format!(
        "a binary STL of the wrong size: its header says {count} triangles ({expected} bytes), the \
         file has {size} bytes: {}",
        size_why(size, expected, count)
    )
}

/// Why a binary STL's size may be wrong, from the size it has, the one its header gives and the
/// header's triangle count.
fn size_why(size: u64, expected: u64, count: u64) -> String {
    if size < expected {
        format!(
            "it holds {} bytes fewer than its header's {count} triangles need (cut short?)",
            expected - size
        )
    } else {
        format!(
            "it holds {} bytes more than its header's {count} triangles need (a wrong count, or data \
             after the triangles)",
            size - expected
        )
    }
}

/// An ASCII STL: `solid NAME`, facets (`facet normal x y z`, `outer loop`, three or more `vertex x y
/// z`, `endloop`, `endfacet`), `endsolid [NAME]`, keywords in any case, any blank space, and any
/// number of solids one after another (CAD tools write an assembly so). A file of one solid is one
/// object named after the file; of several, an object per solid, named after it. Read by hand:
/// `stl_io` reads the first solid only, and takes indented, tabbed or upper-case files for binary.
fn read_ascii(shown: &str, bytes: &[u8], path: &Path) -> Result<SceneBuilder, SceneError> {
    let text = String::from_utf8_lossy(bytes);
    let text = text.trim_start_matches('\u{feff}');
    let solids = text
        .lines()
        .filter(|l| first_word(l).eq_ignore_ascii_case("solid"))
        .count();
    let mut b = SceneBuilder::new(shown);
    let material = b.material(Material::default());
    let (mut in_solid, mut in_facet, mut in_loop) = (false, false, false);
    let mut corners: Vec<u32> = Vec::new();
    let (mut facets, mut solid_count) = (0usize, 0usize);
    for (k, line) in text.lines().enumerate() {
        let at = |message: String| SceneError::in_file(shown, format!("line {}: {message}", k + 1));
        let mut words = line.split_whitespace();
        let Some(word) = words.next() else { continue };
        let expected = |what: &str| at(format!("`{word}` where {what} was expected"));
        match word.to_ascii_lowercase().as_str() {
            "solid" if !in_solid => {
                in_solid = true;
                solid_count += 1;
                let name = line.trim().get(5..).unwrap_or("").trim();
                if solids > 1 {
                    let name = if name.is_empty() {
                        format!("solid {solid_count}")
                    } else {
                        name.to_string()
                    };
                    b.object(&name);
                } else {
                    b.object(&super::object_name(path));
                }
            }
            "endsolid" if in_solid && !in_facet => in_solid = false,
            "facet" if in_solid && !in_facet => {
                in_facet = true;
                corners.clear();
            }
            "outer" if in_facet && !in_loop => {
                if !words.next().is_some_and(|w| w.eq_ignore_ascii_case("loop")) {
                    return Err(at("`outer` without `loop`".into()));
                }
                in_loop = true;
            }
            "vertex" if in_loop => {
                let mut c = [0.0f32; 3];
                for v in &mut c {
                    let w = words
                        .next()
                        .ok_or_else(|| at("a vertex with fewer than 3 coordinates".into()))?;
                    *v = w
                        .parse::<f32>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            at(format!("vertex coordinate `{w}` is not a finite number"))
                        })?;
                }
                corners.push(b.vertex(c.map(f64::from)));
            }
            "endloop" if in_loop => in_loop = false,
            "endfacet" if in_facet && !in_loop => {
                in_facet = false;
                facets += 1;
                if corners.len() < 3 {
                    return Err(at(format!("facet {facets} has {} corners", corners.len())));
                }
                b.polygon(&corners, material, format!("triangle {facets}"));
            }
            _ if !in_solid => return Err(expected("`solid`")),
            _ if !in_facet => return Err(expected("`facet` or `endsolid`")),
            _ if !in_loop => return Err(expected("`outer loop` or `endfacet`")),
            _ => return Err(expected("`vertex` or `endloop`")),
        }
    }
    if in_solid {
        return Err(SceneError::in_file(
            shown,
            "the file ends inside a solid (no `endsolid`): it is cut short".into(),
        ));
    }
    Ok(b)
}

/// The first word of a line.
fn first_word(line: &str) -> &str {
    line.split_whitespace().next().unwrap_or("")
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

#[cfg(test)]
mod tests {
    use super::*;

    /// An ASCII STL whose first line is longer than the 4 KiB the detection looks at went to stl_io's
    /// reader, whose messages are its own ("triangle 1: expected finite f32, got NaN which is Nan"):
    /// scx's reader reads it now, naming the line.
    #[test]
    fn a_long_first_line_is_read_by_scx_s_own_reader() {
        let facet = "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
                     endloop\nendfacet\n";
        let name = "x".repeat(5000);
        let fine = format!("solid {name}\n{facet}endsolid\n");
        assert!(!looks_like_ascii_stl(fine.as_bytes()));
        let scene = read_bytes("t.stl", fine.as_bytes(), Path::new("t.stl"))
            .and_then(SceneBuilder::build)
            .unwrap();
        assert_eq!(scene.patch_count(), 1);
        let nan = fine.replacen("vertex 0 0 0", "vertex nan 0 0", 1);
        let e = read_bytes("t.stl", nan.as_bytes(), Path::new("t.stl"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.stl: line 4: vertex coordinate `nan` is not a finite number"
        );
    }

    /// Bytes read as binary STL that are not of the size its header gives are refused in scx's words
    /// (stl_io said "failed to fill whole buffer").
    #[test]
    fn a_binary_stl_of_the_wrong_size_is_refused_in_words() {
        let mut bytes = vec![0u8; 80];
        bytes.extend(2u32.to_le_bytes());
        bytes.extend([0u8; 50]);
        let e = read_bytes("t.stl", &bytes, Path::new("t.stl"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("t.stl: a binary STL of the wrong size: its header says 2 triangles")
                && e.contains("it holds 50 bytes fewer than its header's 2 triangles need"),
            "{e}"
        );
        let e = read_bytes("t.stl", &[0u8; 20], Path::new("t.stl"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("20 bytes, shorter than its 84-byte header"),
            "{e}"
        );
    }
}
