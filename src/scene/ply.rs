//! PLY scenes (ASCII, binary little- and big-endian), read with `ply-rs-bw`.
//!
//! The `vertex` element gives `x`, `y`, `z`; the `face` element a list `vertex_indices` (or
//! `vertex_index`), each face one polygon (planar: one patch; see [`super::SceneBuilder`]). A face colour
//! (`red`, `green`, `blue`: 0-255 as integers, 0-1 as floats) is its reflectance, one material per
//! distinct colour; faces without one get scx's default material. The file is one object, named after
//! the file.

use std::path::Path;

use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Property};

use super::{Material, Scene, SceneBuilder, SceneError, SceneOptions};

/// Loads PLY bytes read from `path`.
pub(crate) fn load_bytes(
    shown: &str,
    bytes: &[u8],
    path: &Path,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    let file_error = |message: String| SceneError::in_file(shown, message);
    let mut cursor = std::io::Cursor::new(bytes);
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut cursor)
        .map_err(|e| file_error(format!("not a readable PLY file: {e}")))?;
    let vertices = ply.payload.get("vertex").map(Vec::as_slice).unwrap_or(&[]);
    let faces = ply.payload.get("face").map(Vec::as_slice).unwrap_or(&[]);
    if faces.is_empty() {
        return Err(file_error(format!(
            "the scene is empty: no faces (a `face` element with `vertex_indices`); {} vertices",
            vertices.len()
        )));
    }

    let mut b = SceneBuilder::new(shown);
    b.object(&super::object_name(path));
    let mut ids = Vec::with_capacity(vertices.len());
    for (k, v) in vertices.iter().enumerate() {
        let coordinate = |name: &str| {
            v.get(name).and_then(number).ok_or_else(|| {
                file_error(format!(
                    "vertex {k}: no number `{name}` (x, y and z are needed)"
                ))
            })
        };
        ids.push(b.vertex([coordinate("x")?, coordinate("y")?, coordinate("z")?]));
    }
    let mut colours: Vec<([u64; 3], u32)> = Vec::new();
    let mut default_material = None;
    for (k, f) in faces.iter().enumerate() {
        let indices = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(index_list)
            .ok_or_else(|| file_error(format!("face {k}: no list `vertex_indices`")))?;
        let corners = indices
            .iter()
            .map(|&i| {
                usize::try_from(i)
                    .ok()
                    .and_then(|i| ids.get(i).copied())
                    .ok_or_else(|| {
                        file_error(format!(
                            "face {k} refers to vertex {i}, but the file has {} vertices (0-based)",
                            ids.len()
                        ))
                    })
            })
            .collect::<Result<Vec<u32>, _>>()?;
        if corners.len() < 3 {
            return Err(file_error(format!(
                "face {k}: a face needs at least 3 vertices, it has {}",
                corners.len()
            )));
        }
        let material = match face_colour(f) {
            Some(rgb) => {
                let key = rgb.map(f64::to_bits);
                match colours.iter().find(|(c, _)| *c == key) {
                    Some(&(_, m)) => m,
                    None => {
                        let name = format!("colour_{}_{}_{}", rgb[0], rgb[1], rgb[2]);
                        let m = b.material(Material::rgb(name, rgb, [0.0; 3]));
                        colours.push((key, m));
                        m
                    }
                }
            }
            None => *default_material.get_or_insert_with(|| b.material(Material::default())),
        };
        b.polygon(&corners, material, format!("face {k}"));
    }
    b.build_with(options)
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
fn index_list(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x.into()).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x.into()).collect(),
        _ => return None,
    })
}

/// A face's colour as reflectance in [0, 1]: integer channels are 0-255, float channels 0-1.
fn face_colour(f: &DefaultElement) -> Option<[f64; 3]> {
    let channel = |name: &str| {
        let p = f.get(name)?;
        let v = number(p)?;
        Some(match p {
            Property::Float(_) | Property::Double(_) => v,
            _ => v / 255.0,
        })
    };
    Some([channel("red")?, channel("green")?, channel("blue")?])
}
