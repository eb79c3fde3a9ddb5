//! Writing scenes: the format chosen by the file's extension (`.obj`, `.ply`, `.stl`, `.gltf`,
//! `.glb`), the bytes of each file it needs, and what the format cannot keep.
//!
//! The encoders live beside their readers (obj.rs, ply.rs, stl.rs, gltf.rs), so that each format's
//! reading and writing agree; this module only picks among them. A caller that writes files its own way
//! (atomically, checked first) takes [`files`]; [`write()`] writes them plainly.

use std::path::{Path, PathBuf};

use super::{gltf, obj, ply, stl, Scene, SceneError};

/// The formats a scene is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WriteFormat {
    /// Wavefront OBJ text, with its MTL library beside it: patches, materials and objects kept.
    Obj,
    /// Binary little-endian PLY: patches and reflectances kept (one object, no emission).
    Ply,
    /// Binary STL: triangles only.
    Stl,
    /// glTF 2.0 JSON with its buffer in a data URI: objects and materials, a patch per triangle.
    Gltf,
    /// glTF 2.0 binary (`.glb`): as [`WriteFormat::Gltf`].
    Glb,
}

/// The extensions scenes are written with, in a form for messages.
pub const WRITE_EXTENSIONS: &str = ".obj (with its .mtl), .ply, .stl, .gltf, .glb";

/// A path whose extension names no format scenes are written in.
#[derive(Debug, thiserror::Error)]
#[error(
    "scx writes scenes as {WRITE_EXTENSIONS}, chosen by the extension; {}",
    extension_text(.path)
)]
pub struct UnknownExtension {
    /// The path asked for.
    pub path: PathBuf,
}

fn extension_text(path: &Path) -> String {
    match path.extension() {
        Some(e) if e.eq_ignore_ascii_case("mtl") => {
            "`.mtl` names an OBJ's MTL library, which is written beside the `.obj`".into()
        }
        Some(e) => format!("`.{}` is none of them", e.to_string_lossy()),
        None => "this name has no extension".into(),
    }
}

impl WriteFormat {
    /// The format a path's extension asks for (any letter case).
    pub fn of_path(path: &Path) -> Result<Self, UnknownExtension> {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        Ok(match extension.as_deref() {
            Some("obj") => WriteFormat::Obj,
            Some("ply") => WriteFormat::Ply,
            Some("stl") => WriteFormat::Stl,
            Some("gltf") => WriteFormat::Gltf,
            Some("glb") => WriteFormat::Glb,
            _ => {
                return Err(UnknownExtension {
                    path: path.to_path_buf(),
                })
            }
        })
    }

    /// A name for messages.
    pub fn name(self) -> &'static str {
        match self {
            WriteFormat::Obj => "OBJ",
            WriteFormat::Ply => "binary PLY",
            WriteFormat::Stl => "binary STL",
            WriteFormat::Gltf => "glTF",
            WriteFormat::Glb => "binary glTF",
        }
    }

    /// How many patches a file in this format holds of `scene`, for messages: its patches in OBJ and PLY;
    /// in STL and glTF, which keep triangles only, the triangles too when there are more of them, since
    /// the file reads back as a patch per triangle.
    pub fn patches_written(self, scene: &Scene) -> String {
        let (patches, triangles) = (scene.patch_count(), scene.triangles.len());
        match self {
            WriteFormat::Stl | WriteFormat::Gltf | WriteFormat::Glb if triangles > patches => {
                format!(
                    "{patches} patches as {triangles} triangles (read back: a patch per triangle)"
                )
            }
            _ => format!("{patches} patches"),
        }
    }

    /// The file written beside `path` in this format, if any: an OBJ's MTL library.
    pub fn companion(self, path: &Path) -> Option<PathBuf> {
        (self == WriteFormat::Obj).then(|| path.with_extension("mtl"))
    }

    /// What a scene loses when written in this format, one sentence each (empty when nothing is lost
    /// but patches that several triangles make, which the count of patches read back shows).
    pub fn losses(self, scene: &Scene) -> Vec<String> {
        let emitting: Vec<String> = scene
            .materials
            .iter()
            .filter(|m| m.emission_rgb.iter().any(|&e| e != 0.0))
            .map(|m| m.name.clone())
            .collect();
        let mut losses = Vec::new();
        let no_emission = matches!(self, WriteFormat::Ply | WriteFormat::Stl);
        if no_emission && !emitting.is_empty() {
            losses.push(format!(
                "{} holds no emission: the light(s) {} are written without it",
                self.name(),
                super::build::list_names(&emitting)
            ));
        }
        if self == WriteFormat::Stl && scene.materials.len() > 1 {
            losses
                .push("STL holds no materials: every triangle reads back with the default".into());
        }
        let one_object = matches!(self, WriteFormat::Ply | WriteFormat::Stl);
        if one_object && scene.objects.len() > 1 {
            losses.push(format!(
                "{} holds one object: the scene's {} objects become one",
                self.name(),
                scene.objects.len()
            ));
        }
        losses
    }
}

/// The files a scene is written as at `path` in `format`, each with its bytes, in the order to write
/// them (an OBJ's MTL library first, so that the OBJ never names a library not yet there).
pub fn files(scene: &Scene, format: WriteFormat, path: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let single = |bytes: Vec<u8>| vec![(path.to_path_buf(), bytes)];
    match format {
        WriteFormat::Obj => {
            let mtl = path.with_extension("mtl");
            let mtl_name = mtl
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene.mtl".into());
            let (obj, library) = obj::to_text(scene, &mtl_name);
            vec![
                (mtl, library.into_bytes()),
                (path.to_path_buf(), obj.into_bytes()),
            ]
        }
        WriteFormat::Ply => single(ply::to_bytes(scene)),
        WriteFormat::Stl => single(stl::to_bytes(scene)),
        WriteFormat::Gltf => single(gltf::to_bytes(scene, false)),
        WriteFormat::Glb => single(gltf::to_bytes(scene, true)),
    }
}

/// Writes a scene at `path` in the format its extension names ([`WriteFormat::of_path`]), with any
/// file beside it the format needs.
pub fn write(scene: &Scene, path: &Path) -> Result<(), SceneError> {
    let format = WriteFormat::of_path(path).map_err(|e| SceneError::File {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    for (file, bytes) in files(scene, format, path) {
        std::fs::write(&file, bytes).map_err(|e| SceneError::File {
            path: file.display().to_string(),
            message: format!("cannot write: {e}"),
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_extension_picks_the_format() {
        for (name, format) in [
            ("a.obj", WriteFormat::Obj),
            ("a.PLY", WriteFormat::Ply),
            ("dir.x/a.stl", WriteFormat::Stl),
            ("a.gltf", WriteFormat::Gltf),
            ("a.Glb", WriteFormat::Glb),
        ] {
            assert_eq!(WriteFormat::of_path(Path::new(name)).unwrap(), format);
        }
        for name in ["a.mtl", "a.txt", "a", "a.obj.bak"] {
            let e = WriteFormat::of_path(Path::new(name)).unwrap_err();
            assert!(e.to_string().contains(".ply, .stl"), "{e}");
        }
    }
}
