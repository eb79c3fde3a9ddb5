//! The scene model: triangles grouped into planar patches, each with an area, a normal and a material.
//!
//! Every scene is centred and scaled to a unit bounding sphere when it is built ("tracing space"): all
//! measures are scale invariant, and f32 tracing is most precise there. Geometry is kept twice: f32 vertex
//! positions for the tracers, and f64 patch planes, normals and areas for the measures, computed from the
//! original f64 coordinates.

mod build;
pub mod export;
pub mod format;
pub mod gltf;
mod gltf_data;
pub mod obj;
mod obj_check;
pub mod ply;
pub mod read;
pub mod stl;
mod warning;

pub use build::{ObjectSet, Planarity, SceneBuilder, SceneOptions, Sides, DEFAULT_PLANARITY};
pub use read::{Reach, ReadPolicy, DEFAULT_MAX_BYTES};
pub use warning::{quantity_text, SceneWarning, SceneWarningKind, Warning};

use std::fmt;

use crate::geom::{Normal, Point};

/// Diffuse material of a patch (paper eq. (2)): emission `E_i` and reflectance `R_i`, one channel each,
/// and the RGB triples they come from.
///
/// The single value is the mean of the three RGB channels (exactly the value of a grey triple): the
/// response to an equal-energy white light with every channel weighted alike. The radiosity measures
/// (paper sec. 4) use these values; they require `0 <= R_i <= 1` and `E_i >= 0` (see
/// [`crate::measure::radiosity::PatchMaterials`]). The triples are kept so that a scene written back
/// (`scx export`, `scx refine`) keeps its colours. Build materials with [`Material::grey`] or
/// [`Material::rgb`], which keep the scalars the means of the triples.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name as in the scene file, or a built-in name.
    pub name: String,
    /// Emitted radiosity `E_i` (>= 0): the mean of [`Material::emission_rgb`].
    pub emission: f64,
    /// Diffuse reflectance `R_i` (in [0, 1] for a physical material): the mean of
    /// [`Material::reflectance_rgb`].
    pub reflectance: f64,
    /// Emission per channel (red, green, blue): MTL `Ke`, glTF `emissiveFactor` times its strength.
    pub emission_rgb: [f64; 3],
    /// Reflectance per channel (red, green, blue): MTL `Kd`, glTF `baseColorFactor`, PLY face colour.
    pub reflectance_rgb: [f64; 3],
}

impl Material {
    /// A grey material: every channel the same.
    pub fn grey(name: impl Into<String>, reflectance: f64, emission: f64) -> Self {
        Material {
            name: name.into(),
            emission,
            reflectance,
            emission_rgb: [emission; 3],
            reflectance_rgb: [reflectance; 3],
        }
    }

    /// A coloured material; its single values are the means of the triples ([`grey_value`]).
    pub fn rgb(name: impl Into<String>, reflectance: [f64; 3], emission: [f64; 3]) -> Self {
        Material {
            name: name.into(),
            emission: grey_value(emission),
            reflectance: grey_value(reflectance),
            emission_rgb: emission,
            reflectance_rgb: reflectance,
        }
    }

    /// The first channel of `Kd` (reflectance) outside [0, 1], or of `Ke` (emission) below 0 or not
    /// finite, described for a message (`None` when every channel is physical).
    pub fn unphysical_channel(&self) -> Option<String> {
        const CHANNELS: [&str; 3] = ["red", "green", "blue"];
        for (k, &r) in self.reflectance_rgb.iter().enumerate() {
            if !(r.is_finite() && (0.0..=1.0).contains(&r)) {
                return Some(format!(
                    "reflectance (Kd) {} channel is {r}; each channel must be in [0, 1]",
                    CHANNELS[k]
                ));
            }
        }
        for (k, &e) in self.emission_rgb.iter().enumerate() {
            if !(e.is_finite() && e >= 0.0) {
                return Some(format!(
                    "emission (Ke) {} channel is {e}; each channel must be finite and >= 0",
                    CHANNELS[k]
                ));
            }
        }
        None
    }
}

/// One channel from RGB: the plain mean (the value seen under an equal-energy white light, the same
/// weight for each channel). A grey triple gives its value exactly, so that a file written by scx reads
/// back bit-identical (the mean of three equal values can be off by an ulp).
pub fn grey_value(c: [f64; 3]) -> f64 {
    if c[0] == c[1] && c[1] == c[2] {
        c[0]
    } else {
        (c[0] + c[1] + c[2]) / 3.0
    }
}

impl Default for Material {
    fn default() -> Self {
        Material::grey("default", 0.5, 0.0)
    }
}

/// A patch: one or more coplanar triangles, the unit of the discretisation (`i` in F_ij).
#[derive(Clone, Debug)]
pub struct Patch {
    /// Area in tracing space (the scene scaled to its unit bounding sphere).
    pub area: f64,
    /// Unit normal in tracing space; the *front* side is the side it points to.
    pub normal: Normal,
    /// Plane offset: points `x` of the patch satisfy `normal . x = offset` (tracing space).
    pub offset: f64,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Index into [`Scene::objects`]: the part of the scene it belongs to.
    pub object: u32,
    /// The range of this patch's triangles in [`Scene::triangles`].
    pub first_triangle: u32,
    /// How many triangles the patch has.
    pub triangle_count: u32,
    /// Where the polygon's vertices start in [`Scene::corners`] ([`Scene::polygon`]).
    pub first_corner: u32,
    /// How many vertices the polygon has.
    pub corner_count: u32,
}

/// The object name of a single-object file (PLY, STL): its name without the extension.
pub(crate) fn object_name(path: &std::path::Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "object".into())
}

/// How tracing space relates to the scene's own units: `original = center + scale * traced`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normalization {
    /// Centre of the bounding sphere, scene units.
    pub center: Point,
    /// Radius of the bounding sphere, scene units.
    pub scale: f64,
}

/// A triangle scene ready for tracing and measuring.
#[derive(Clone, Debug)]
pub struct Scene {
    /// A name for reports (`@cube:10`, or the file path).
    pub name: String,
    /// Vertex positions in tracing space (f32, for the tracers).
    pub positions: Vec<[f32; 3]>,
    /// The same vertices in the scene's own units (f64, as loaded).
    pub vertices: Vec<Point>,
    /// Triangles as vertex indices, ordered so that each patch's triangles are contiguous.
    pub triangles: Vec<[u32; 3]>,
    /// The patch of each triangle.
    pub triangle_patch: Vec<u32>,
    /// The patches' polygons one after the other (see [`Scene::polygon`]): one list for all, as a list
    /// per patch would take a scene of millions of patches more memory than its corners.
    pub corners: Vec<u32>,
    /// The patches.
    pub patches: Vec<Patch>,
    /// The materials patches refer to.
    pub materials: Vec<Material>,
    /// The names of the scene's objects (OBJ `o`/`g`, glTF node or mesh, the file name for PLY and STL,
    /// the scene's name for a built-in), which patches refer to by index.
    pub objects: Vec<String>,
    /// Mapping back to the scene's own units.
    pub normalization: Normalization,
    /// Total area in the scene's own units, from the original f64 coordinates.
    pub area_scene_units: f64,
    /// Non-fatal problems found while loading (missing MTL, dropped degenerate triangles, ...).
    pub warnings: Vec<SceneWarning>,
    /// The files the scene's own file named and that were read (MTL libraries, glTF buffers), as
    /// canonical paths: inputs as much as the scene file, so nothing a run writes may replace them.
    pub files_read: Vec<std::path::PathBuf>,
}

impl Scene {
    /// A patch's polygon: its vertices (indices into [`Scene::vertices`]), in order, front side
    /// counter-clockwise.
    pub fn polygon(&self, patch: &Patch) -> &[u32] {
        let start = patch.first_corner as usize;
        &self.corners[start..start + patch.corner_count as usize]
    }

    /// Number of patches `n_p`.
    pub fn patch_count(&self) -> usize {
        self.patches.len()
    }

    /// Total area `A_T` in tracing space.
    pub fn total_area(&self) -> f64 {
        self.patches.iter().map(|p| p.area).sum()
    }

    /// Total area in the scene's own units (computed from the original coordinates).
    pub fn total_area_scene_units(&self) -> f64 {
        self.area_scene_units
    }

    /// Radius of the bounding sphere in tracing space (1 by construction).
    pub fn bounding_radius(&self) -> f64 {
        1.0
    }

    /// A SHA-256 fingerprint of the loaded geometry and materials (hex): the same scene, however it was
    /// loaded, gives the same fingerprint; any change of a vertex, a face or a material another. Saved
    /// run states carry it, so that states of different scenes are never merged.
    pub fn fingerprint(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut h = Sha256::new();
        for p in &self.positions {
            for c in p {
                h.update(c.to_bits().to_le_bytes());
            }
        }
        for (t, &patch) in self.triangles.iter().zip(&self.triangle_patch) {
            for v in t {
                h.update(v.to_le_bytes());
            }
            h.update(patch.to_le_bytes());
        }
        for p in &self.patches {
            for c in p.normal.to_array() {
                h.update(c.to_bits().to_le_bytes());
            }
            h.update(p.offset.to_bits().to_le_bytes());
            h.update(p.area.to_bits().to_le_bytes());
            h.update(p.material.to_le_bytes());
        }
        for m in &self.materials {
            h.update((m.name.len() as u64).to_le_bytes());
            h.update(m.name.as_bytes());
            h.update(m.emission.to_bits().to_le_bytes());
            h.update(m.reflectance.to_bits().to_le_bytes());
        }
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The f64 unit normal of each triangle's patch, indexed by triangle.
    pub fn triangle_normals(&self) -> Vec<Normal> {
        self.triangle_patch
            .iter()
            .map(|&p| self.patches[p as usize].normal)
            .collect()
    }
}

/// A scene that could not be loaded or built.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read or parsed.
    #[error("{path}: {message}")]
    File {
        /// The file.
        path: String,
        /// What is wrong with it.
        message: String,
    },
    /// The geometry is unusable (empty, non-finite, ...).
    #[error("{scene}: {message}")]
    Geometry {
        /// The scene's name or file.
        scene: String,
        /// What is wrong.
        message: String,
    },
    /// A built-in scene name or parameter is unknown or out of range.
    #[error("{0}")]
    Builtin(String),
}

impl SceneError {
    /// A problem with the file shown to the user as `path`.
    pub fn in_file(path: &str, message: String) -> Self {
        SceneError::File {
            path: path.to_string(),
            message,
        }
    }
}

impl fmt::Display for Normalization {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "centre ({:.6}, {:.6}, {:.6}), radius {:.6}",
            self.center.x, self.center.y, self.center.z, self.scale
        )
    }
}
