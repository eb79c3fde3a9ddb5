//! PLY scenes (ASCII, binary little- and big-endian), read with `ply-rs-bw`, and written.
//!
//! Reading: the `vertex` element gives `x`, `y`, `z`. Faces come from every other element with a list
//! `vertex_indices` (or `vertex_index`): each item of `face` (or of another such element) is one polygon
//! (planar: one patch; see [`super::SceneBuilder`]); each item of `tristrips` (Stanford's form, as in
//! igea.ply) is a triangle strip, `-1` starting a new strip, each triangle a patch. A face colour
//! (`red`, `green`, `blue`: 0-255 as integers, 0-1 as floats) is its reflectance, one material per
//! distinct colour; faces without one get scx's default material. The file is one object, named after
//! the file.
//!
//! Writing ([`to_bytes`]): binary little-endian, f64 vertices in the scene's units, one face per patch
//! with its material's reflectance as f64 `red`, `green`, `blue`, so that reading it back gives the same
//! patches and reflectances.

use std::path::Path;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{ElementDef, Property, PropertyAccess, PropertyType};

use super::{Material, Scene, SceneBuilder, SceneError, SceneOptions};

/// The names of the list property that holds a face's vertices.
const INDEX_LISTS: [&str; 2] = ["vertex_indices", "vertex_index"];

/// How an element's index lists make triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Each list is one polygon.
    Faces,
    /// Each list is triangle strips, `-1` restarting.
    Strips,
}

/// Loads PLY bytes read from `path`.
pub(crate) fn load_bytes(
    shown: &str,
    bytes: &[u8],
    path: &Path,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    read_bytes(shown, bytes, path)?.build_with(options)
}

/// The scene of PLY bytes read from `path`, ready to build: the bytes may go before it is built.
pub(crate) fn read_bytes(
    shown: &str,
    bytes: &[u8],
    path: &Path,
) -> Result<SceneBuilder, SceneError> {
    let file_error = |message: String| SceneError::in_file(shown, message);
    let bytes = with_text_comments(bytes).map_err(file_error)?;
    let mut cursor = std::io::Cursor::new(bytes.as_ref());
    let ply = Parser::<Item>::new()
        .read_ply(&mut cursor)
        .map_err(|e| file_error(format!("not a readable PLY file: {}", ply_problem(&e))))?;
    let vertices = ply.payload.get("vertex").map(Vec::as_slice).unwrap_or(&[]);
    let sources: Vec<(&str, Kind, &[Item])> = ply
        .header
        .elements
        .values()
        .filter_map(|def| {
            let kind = element_kind(def)?;
            let items = ply.payload.get(&def.name)?;
            Some((def.name.as_str(), kind, items.as_slice()))
        })
        .collect();
    if sources.iter().all(|(_, _, items)| items.is_empty()) {
        return Err(file_error(empty_message(&ply.header, vertices.len())));
    }

    let mut b = SceneBuilder::new(shown);
    b.object(&super::object_name(path));
    let mut ids = Vec::with_capacity(vertices.len());
    for (k, v) in vertices.iter().enumerate() {
        let coordinate = |axis: usize| {
            let given = v.xyz_given & (1 << axis) != 0;
            given.then_some(v.xyz[axis]).ok_or_else(|| {
                file_error(format!(
                    "vertex {k}: no number `{}` (x, y and z are needed)",
                    ["x", "y", "z"][axis]
                ))
            })
        };
        ids.push(b.vertex([coordinate(0)?, coordinate(1)?, coordinate(2)?]));
    }
    let mut materials = Materials::default();
    for (element, kind, items) in sources {
        for (k, item) in items.iter().enumerate() {
            let at = |message: String| file_error(format!("{element} {k}: {message}"));
            let mut inline = [0; INLINE_INDICES];
            let indices = item
                .indices
                .as_ref()
                .ok_or_else(|| at("no list `vertex_indices`".into()))?
                .values(&mut inline);
            let material = materials.of(&mut b, item);
            match kind {
                Kind::Faces => {
                    let corners = corners(indices, &ids, vertices).map_err(at)?;
                    if corners.len() < 3 {
                        return Err(at(format!(
                            "a face needs at least 3 vertices, it has {}",
                            corners.len()
                        )));
                    }
                    b.polygon(&corners, material, format!("{element} {k}"));
                }
                Kind::Strips => {
                    for (t, triangle) in strip_triangles(indices).into_iter().enumerate() {
                        let corners = corners(&triangle, &ids, vertices).map_err(at)?;
                        b.polygon(&corners, material, format!("{element} {k} triangle {t}"));
                    }
                }
            }
        }
    }
    Ok(b)
}

/// The bytes with the header's comments made text: tools write comments (`comment`, `obj_info`) in
/// their own encoding (Latin-1 and the like), which ply-rs-bw, reading the header as UTF-8, would refuse
/// with the whole file. scx does not use comments, so their other bytes become U+FFFD. Any other header
/// line must be text: `Err` names the first that is not.
fn with_text_comments(bytes: &[u8]) -> Result<std::borrow::Cow<'_, [u8]>, String> {
    let lines = || bytes.split_inclusive(|&b| b == b'\n');
    // Without `end_header` it is no PLY header at all: the parser says so.
    let Some(count) = lines().position(|l| l.trim_ascii() == b"end_header") else {
        return Ok(std::borrow::Cow::Borrowed(bytes));
    };
    let mut rewrite = false;
    for (k, line) in lines().take(count).enumerate() {
        let Err(e) = std::str::from_utf8(line) else {
            continue;
        };
        if !(line.starts_with(b"comment") || line.starts_with(b"obj_info")) {
            let at = e.valid_up_to();
            return Err(format!(
                "header line {}: byte 0x{:02X} at column {} is not text (UTF-8); of a PLY header \
                 only the comments may hold other bytes",
                k + 1,
                line[at],
                at + 1
            ));
        }
        rewrite = true;
    }
    if !rewrite {
        return Ok(std::borrow::Cow::Borrowed(bytes));
    }
    let end: usize = lines().take(count + 1).map(<[u8]>::len).sum();
    let mut out = String::from_utf8_lossy(&bytes[..end])
        .into_owned()
        .into_bytes();
    out.extend_from_slice(&bytes[end..]);
    Ok(std::borrow::Cow::Owned(out))
}

/// What ply-rs-bw's error says, in plain words: its messages hold the line read, Rust debug text of
/// the errors below (`Custom { kind: InvalidInput, ... }`, a parser's expected sets) and tabs and line
/// breaks. Kept: the line number, the line's text, and the cause where it is known.
fn ply_problem(e: &std::io::Error) -> String {
    let text = e.to_string();
    if e.kind() == std::io::ErrorKind::UnexpectedEof || text.contains("failed to fill whole buffer")
    {
        if text.contains("missing 'end_header'") {
            return "the header has no `end_header` line (cut short, or no PLY header)".into();
        }
        return format!(
            "{}the file ends before all the items its header announces are read (cut short?)",
            line_prefix(&text)
        );
    }
    let Some(written) = quoted(&text, "String: '") else {
        // A message of ply-rs-bw's own without debug text: its first sentence.
        return text.lines().next().unwrap_or("").to_string();
    };
    let written = written.trim();
    let cause = if let Some(value) = quoted(&text, "Value: '") {
        format!("`{value}` is not a number of its property's type (or out of its range)")
    } else if text.contains("but found nothing") {
        "fewer values than the element's properties".into()
    } else if text.contains("list elements, but found only") {
        "a list with fewer values than its count".into()
    } else if text.contains("Couldn't parse line") {
        "not a header statement (`format`, `element`, `property`, `comment`, `obj_info`, \
         `end_header`)"
            .into()
    } else if let Some(token) = written.split_whitespace().find(|t| !is_ply_number(t)) {
        format!("`{token}` is not a number")
    } else {
        text.lines().next().unwrap_or("").to_string()
    };
    format!("{}`{written}`: {cause}", line_prefix(&text))
}

/// `line N: ` from ply-rs-bw's `Line N:` (the file's line, from 1), or nothing.
fn line_prefix(text: &str) -> String {
    text.strip_prefix("Line ")
        .and_then(|rest| rest.split_once(':'))
        .filter(|(n, _)| n.parse::<u64>().is_ok())
        .map(|(n, _)| format!("line {n}: "))
        .unwrap_or_default()
}

/// The text between `start` and the next `'` in ply-rs-bw's message.
fn quoted<'a>(text: &'a str, start: &str) -> Option<&'a str> {
    let (_, rest) = text.split_once(start)?;
    Some(rest.split_once('\'').map_or(rest, |(q, _)| q))
}

/// Whether a value is a number as PLY writes them (ply-rs-bw reads no `nan` or `inf`).
fn is_ply_number(token: &str) -> bool {
    token
        .chars()
        .all(|c| c.is_ascii_digit() || "+-.eE".contains(c))
}

/// What scx reads of one item of any element: the coordinates of a vertex, the index list and colour of a
/// face or strip. Kept this small (rather than ply-rs-bw's map of every property by name) because a
/// large file has millions of items, all in memory until the last one is read.
struct Item {
    /// `x`, `y`, `z`: those given as numbers have their bit in `xyz_given` (an `Option` each would make
    /// every item 24 bytes larger).
    xyz: [f64; 3],
    xyz_given: u8,
    /// The first of [`INDEX_LISTS`] given (its rank there) and its values when it is a list of integers.
    indices_rank: u8,
    indices: Option<IndexList>,
    /// `red`, `green`, `blue` as reflectance (see [`face_colour`]), when any channel is given.
    colour: Option<Box<[Option<f64>; 3]>>,
}

impl PropertyAccess for Item {
    fn new() -> Self {
        Item {
            xyz: [0.0; 3],
            xyz_given: 0,
            indices_rank: u8::MAX,
            indices: None,
            colour: None,
        }
    }

    fn set_property(&mut self, name: &str, property: Property) {
        if let Some(axis) = ["x", "y", "z"].iter().position(|&a| a == name) {
            match number(&property) {
                Some(v) => {
                    self.xyz[axis] = v;
                    self.xyz_given |= 1 << axis;
                }
                None => self.xyz_given &= !(1 << axis),
            }
        } else if let Some(rank) = INDEX_LISTS.iter().position(|&l| l == name) {
            // The first name of the list given wins, whatever the order of the properties.
            let rank = rank as u8;
            if rank <= self.indices_rank {
                self.indices_rank = rank;
                self.indices = index_list(&property);
            }
        } else if let Some(channel) = ["red", "green", "blue"].iter().position(|&c| c == name) {
            let colour = self.colour.get_or_insert_with(|| Box::new([None; 3]));
            colour[channel] = channel_value(&property);
        }
    }
}

/// Whether an element holds faces, strips, or neither: `vertex` never does; `tristrips` (or
/// `tristrip`) with an index list is strips; any other element with one is faces.
fn element_kind(def: &ElementDef) -> Option<Kind> {
    if def.name == "vertex" {
        return None;
    }
    let has_list = INDEX_LISTS.iter().any(|name| {
        def.properties
            .get(*name)
            .is_some_and(|p| matches!(p.data_type, PropertyType::List(..)))
    });
    if !has_list {
        return None;
    }
    Some(if def.name.starts_with("tristrip") {
        Kind::Strips
    } else {
        Kind::Faces
    })
}

/// Why a PLY without faces is empty, naming the elements it does have.
fn empty_message(header: &ply_rs_bw::ply::Header, vertices: usize) -> String {
    let elements: Vec<String> = header
        .elements
        .values()
        .map(|e| format!("`{}` ({})", e.name, e.count))
        .collect();
    format!(
        "the scene is empty: no faces (an element such as `face` with a list `vertex_indices`, or \
         `tristrips`); {vertices} vertices; its elements: {}",
        if elements.is_empty() {
            "none".to_string()
        } else {
            elements.join(", ")
        }
    )
}

/// The triangles of a Stanford `tristrips` list: `-1` ends a strip; each triangle keeps the strip's
/// orientation (every second one is reversed, as strips alternate their winding); triangles with a
/// repeated corner are dropped, as strips use them to join.
fn strip_triangles(list: &[i64]) -> Vec<[i64; 3]> {
    let mut triangles = Vec::new();
    for strip in list.split(|&i| i == -1) {
        for (k, w) in strip.windows(3).enumerate() {
            let t = if k % 2 == 0 {
                [w[0], w[1], w[2]]
            } else {
                [w[1], w[0], w[2]]
            };
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                triangles.push(t);
            }
        }
    }
    triangles
}

/// A polygon's corners as the builder's vertex ids, each index checked against the vertex count and
/// its vertex for finite coordinates. Messages number vertices from 0, as the index lists do (and as
/// every PLY message numbers items).
fn corners(indices: &[i64], ids: &[u32], vertices: &[Item]) -> Result<Vec<u32>, String> {
    indices
        .iter()
        .map(|&i| {
            let k = usize::try_from(i).ok().filter(|&k| k < ids.len());
            let Some(k) = k else {
                return Err(format!(
                    "refers to vertex {i}, but the file has {} vertices (numbered from 0)",
                    ids.len()
                ));
            };
            let [x, y, z] = vertices[k].xyz;
            if ![x, y, z].iter().all(|c| c.is_finite()) {
                return Err(format!(
                    "its vertex {k} has a non-finite coordinate ({x}, {y}, {z}) (items numbered \
                     from 0, as the file's index lists number them)"
                ));
            }
            Ok(ids[k])
        })
        .collect()
}

/// The materials of faces: one per distinct colour, and scx's default for faces without one.
#[derive(Default)]
struct Materials {
    colours: std::collections::HashMap<[u64; 3], u32>,
    default: Option<u32>,
}

impl Materials {
    /// The material of a face (or strip), added to the builder the first time it is met.
    fn of(&mut self, b: &mut SceneBuilder, item: &Item) -> u32 {
        let Some(rgb) = face_colour(item) else {
            return *self
                .default
                .get_or_insert_with(|| b.material(Material::default()));
        };
        *self
            .colours
            .entry(rgb.map(f64::to_bits))
            .or_insert_with(|| {
                let name = format!("colour_{}_{}_{}", rgb[0], rgb[1], rgb[2]);
                b.material(Material::rgb(name, rgb, [0.0; 3]))
            })
    }
}

/// A scalar property as f64.
fn number(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(x) => x.into(),
        Property::UChar(x) => x.into(),
        Property::Short(x) => x.into(),
        Property::UShort(x) => x.into(),
        Property::Int(x) => x.into(),
        Property::UInt(x) => x.into(),
        Property::Float(x) => x.into(),
        Property::Double(x) => x,
        _ => return None,
    })
}

/// A list property of vertex indices.
fn index_list(p: &Property) -> Option<IndexList> {
    Some(match p {
        Property::ListChar(v) => IndexList::of(v.iter().map(|&x| x.into())),
        Property::ListUChar(v) => IndexList::of(v.iter().map(|&x| x.into())),
        Property::ListShort(v) => IndexList::of(v.iter().map(|&x| x.into())),
        Property::ListUShort(v) => IndexList::of(v.iter().map(|&x| x.into())),
        Property::ListInt(v) => IndexList::of(v.iter().map(|&x| x.into())),
        Property::ListUInt(v) => IndexList::of(v.iter().map(|&x| x.into())),
        _ => return None,
    })
}

/// Index lists of at most this many non-negative values are kept in their item.
const INLINE_INDICES: usize = 4;

/// A face's (or strip's) vertex indices as read. Triangles and quads, the faces of large meshes, are
/// kept in the item itself: a list of their own for each of millions of faces cost 32 bytes of a
/// small-object allocation per face, memory that the allocator keeps for small objects once they are
/// freed, where the BVH build that comes next needs it.
enum IndexList {
    /// `len` values, each within `0..2^32`.
    Inline {
        len: u8,
        values: [u32; INLINE_INDICES],
    },
    /// Any other list.
    Long(Box<[i64]>),
}

impl IndexList {
    fn of(values: impl ExactSizeIterator<Item = i64> + Clone) -> Self {
        let fits = |v: &i64| u32::try_from(*v).is_ok();
        if values.len() <= INLINE_INDICES && values.clone().all(|v| fits(&v)) {
            let mut inline = [0; INLINE_INDICES];
            for (slot, v) in inline.iter_mut().zip(values.clone()) {
                *slot = v as u32;
            }
            IndexList::Inline {
                len: values.len() as u8,
                values: inline,
            }
        } else {
            IndexList::Long(values.collect())
        }
    }

    /// The values, written into `inline` when they are kept inline.
    fn values<'a>(&'a self, inline: &'a mut [i64; INLINE_INDICES]) -> &'a [i64] {
        match self {
            IndexList::Inline { len, values } => {
                for (slot, &v) in inline.iter_mut().zip(values) {
                    *slot = v.into();
                }
                &inline[..usize::from(*len)]
            }
            IndexList::Long(values) => values,
        }
    }
}

/// A face's colour as reflectance in [0, 1]: integer channels are 0-255, float channels 0-1.
fn face_colour(f: &Item) -> Option<[f64; 3]> {
    let [r, g, b] = **f.colour.as_ref()?;
    Some([r?, g?, b?])
}

/// A colour channel as reflectance (see [`face_colour`]).
fn channel_value(p: &Property) -> Option<f64> {
    let v = number(p)?;
    Some(match p {
        Property::Float(_) | Property::Double(_) => v,
        _ => v / 255.0,
    })
}

/// A scene as binary little-endian PLY (see the module's documentation): every vertex as f64 `x`, `y`,
/// `z` in the scene's units, every patch as a face (its polygon) with its reflectance as f64 `red`,
/// `green`, `blue`. Written here rather than with ply-rs-bw's writer, which wants a map of properties
/// per vertex and face: a large scene would need several times its own size.
pub fn to_bytes(scene: &Scene) -> Vec<u8> {
    let wide = scene
        .patches
        .iter()
        .any(|p| scene.polygon(p).len() > usize::from(u8::MAX));
    let count_type = if wide { "uint" } else { "uchar" };
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by scx {}: {} patches\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list {count_type} uint vertex_indices\nproperty double red\n\
         property double green\nproperty double blue\nend_header\n",
        env!("CARGO_PKG_VERSION"),
        scene.patch_count(),
        scene.vertices.len(),
        scene.patch_count()
    )
    .into_bytes();
    for v in &scene.vertices {
        for c in v.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for p in &scene.patches {
        // A polygon has at most u32::MAX corners: its corners are u32 vertex indices of one scene.
        let n = scene.polygon(p).len() as u32;
        if wide {
            out.extend_from_slice(&n.to_le_bytes());
        } else {
            out.push(n as u8);
        }
        for v in scene.polygon(p) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for c in scene.materials[p.material as usize].reflectance_rgb {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A PLY header of three float vertices and one triangle, in `format`, with `extra` header lines.
    fn header(format: &str, extra: &str) -> Vec<u8> {
        format!(
            "ply\nformat {format} 1.0\n{extra}element vertex 3\nproperty float x\nproperty float y\n\
             property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        )
        .into_bytes()
    }

    fn error_of(bytes: &[u8]) -> String {
        read_bytes("t.ply", bytes, Path::new("t.ply"))
            .and_then(SceneBuilder::build)
            .unwrap_err()
            .to_string()
    }

    /// A NaN coordinate is named as the file numbers it: the face's item and the vertex's index, both
    /// from 0 (it said "face 0: vertex 3", the second counted from 1 among the welded vertices).
    #[test]
    fn a_non_finite_vertex_is_named_as_the_file_numbers_it() {
        let mut bytes = header("binary_little_endian", "");
        for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, f32::NAN, 1.0, 0.0] {
            bytes.extend(c.to_le_bytes());
        }
        bytes.push(3);
        for i in [0i32, 1, 2] {
            bytes.extend(i.to_le_bytes());
        }
        assert_eq!(
            error_of(&bytes),
            "t.ply: face 0: its vertex 2 has a non-finite coordinate (NaN, 1, 0) (items numbered \
             from 0, as the file's index lists number them)"
        );
    }

    /// ply-rs-bw's errors come out in words, with the line and its text: no tabs, line breaks or
    /// Rust debug text (`Custom { kind: InvalidInput, ... }`, `failed to fill whole buffer`).
    #[test]
    fn parser_errors_read_as_plain_words() {
        let ascii = |body: &str| [header("ascii", ""), body.as_bytes().to_vec()].concat();
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (
                ascii("0 0 0\n1 0 0\nnan 1 0\n3 0 1 2\n"),
                "line 12: `nan 1 0`: `nan` is not a number",
            ),
            (
                ascii("0 0 0\n1 0\n0 1 0\n3 0 1 2\n"),
                "line 11: `1 0`: fewer values than the element's properties",
            ),
            (
                ascii("0 0 0\n1 0 0\n0 1 0\n"),
                "line 13: the file ends before all the items its header announces are read",
            ),
            (
                b"ply\nformat ascii 1.0\nelement vertex 3\nproprty float x\nend_header\n".to_vec(),
                "line 4: `proprty float x`: not a header statement",
            ),
            (
                b"ply\nformat ascii 1.0\nelement vertex 3\n".to_vec(),
                "the header has no `end_header` line",
            ),
            (
                [header("binary_little_endian", ""), vec![0; 30]].concat(),
                "the file ends before all the items its header announces are read (cut short?)",
            ),
        ];
        for (bytes, expected) in cases {
            let e = error_of(&bytes);
            assert!(
                e.starts_with("t.ply: not a readable PLY file: ") && e.contains(expected),
                "{e}"
            );
            for raw in ["\n", "\t", "Error", "{", "fill whole buffer"] {
                assert!(!e.contains(raw), "{raw:?} in {e}");
            }
        }
    }

    /// Comments in Latin-1 (as tools write them) are read; a byte that is not text elsewhere in the
    /// header is an error naming the line (the whole file was refused: "stream did not contain valid
    /// UTF-8").
    #[test]
    fn comments_in_another_encoding_are_read() {
        let body = b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        let latin = [
            header("ascii", "comment caf\u{e9}\nobj_info \u{e9}\n").as_slice(),
            body,
        ]
        .concat();
        let latin: Vec<u8> = String::from_utf8(latin)
            .unwrap()
            .chars()
            .map(|c| c as u32 as u8)
            .collect();
        let scene = read_bytes("t.ply", &latin, Path::new("t.ply"))
            .and_then(SceneBuilder::build)
            .unwrap();
        assert_eq!(scene.patch_count(), 1);
        let mut bad = header("ascii", "").to_vec();
        bad.splice(21..21, [b'\xe9']);
        bad.extend_from_slice(body);
        assert_eq!(
            error_of(&bad),
            "t.ply: header line 3: byte 0xE9 at column 1 is not text (UTF-8); of a PLY header only \
             the comments may hold other bytes"
        );
    }
}
