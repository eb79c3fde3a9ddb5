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
    let mut cursor = std::io::Cursor::new(bytes);
    let ply = Parser::<Item>::new()
        .read_ply(&mut cursor)
        .map_err(|e| file_error(format!("not a readable PLY file: {e}")))?;
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
                    let corners = corners(indices, &ids).map_err(at)?;
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
                        let corners = corners(&triangle, &ids).map_err(at)?;
                        b.polygon(&corners, material, format!("{element} {k} triangle {t}"));
                    }
                }
            }
        }
    }
    Ok(b)
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

/// A polygon's corners as the builder's vertex ids, each index checked against the vertex count.
fn corners(indices: &[i64], ids: &[u32]) -> Result<Vec<u32>, String> {
    indices
        .iter()
        .map(|&i| {
            usize::try_from(i)
                .ok()
                .and_then(|i| ids.get(i).copied())
                .ok_or_else(|| {
                    format!(
                        "refers to vertex {i}, but the file has {} vertices (0-based)",
                        ids.len()
                    )
                })
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
