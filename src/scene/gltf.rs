//! glTF 2.0 scenes (`.gltf` with its buffers, `.glb`), read with the `gltf` crate, and written.
//!
//! Reading: the default scene (or the first, or every root node when there is none) is walked from its
//! root nodes with each node's transform applied (a mirroring transform reverses the triangles' winding,
//! as the specification says). Each node with a mesh is an object, named after the node (or its mesh);
//! each triangle of its primitives is a patch. Materials: `baseColorFactor` (RGB) is the reflectance,
//! `emissiveFactor` times `KHR_materials_emissive_strength` the emission, `doubleSided` makes its
//! triangles two-sided (two patches back to back). Textures are not read (a warning says so). A primitive
//! without a material gets scx's default material (reflectance 0.5), as an OBJ face without one does.
//!
//! Writing ([`write()`]): one node and mesh per object, one primitive per material, f32 positions in the
//! scene's units, every patch's triangles; `.glb` or `.gltf` (the buffer in a data URI) by the extension.

use std::path::Path;

use ::gltf::mesh::Mode;
use ::gltf::Semantic;
use base64::Engine as _;
use serde_json::json;

use super::gltf_data::{self, Budget, Data};
use super::read::Folder;
use super::{Material, Scene, SceneBuilder, SceneError, SceneOptions, SceneWarningKind, Sides};

type Matrix = [[f64; 4]; 4];

const IDENTITY: Matrix = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Loads glTF bytes (JSON or binary); external buffers are read in `folder`, as its policy allows.
pub(crate) fn load_bytes(
    shown: &str,
    bytes: &[u8],
    folder: &Folder,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    // Every range and index is checked before it is used (gltf_data), so nothing here should panic; a
    // reader of untrusted files still keeps a panic in a dependency from taking the program down.
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        load_document(shown, bytes, folder, options)
    }));
    let mut scene = result.unwrap_or_else(|_| {
        Err(SceneError::File {
            path: shown.to_string(),
            message: "malformed glTF: the glTF reader failed on it".into(),
        })
    })?;
    scene.files_read = folder.files_read();
    Ok(scene)
}

fn load_document(
    shown: &str,
    bytes: &[u8],
    folder: &Folder,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    let file_error = |message: String| SceneError::in_file(shown, message);
    check_glb_header(bytes).map_err(|p| file_error(p.to_string()))?;
    let unreadable = |e: ::gltf::Error| file_error(format!("not a readable glTF 2.0 file: {e}"));
    let raw = ::gltf::Gltf::from_slice_without_validation(bytes).map_err(unreadable)?;
    let mut json = raw.document.into_json();
    drop_unknown_attributes(&mut json);
    // gltf-json's validation indexes the accessors with each POSITION attribute unchecked: check
    // those indices first, then validate as `Gltf::from_slice` does.
    check_position_accessors(&json).map_err(|p| file_error(p.to_string()))?;
    let gltf = ::gltf::Gltf {
        document: ::gltf::Document::from_json(json).map_err(unreadable)?,
        blob: raw.blob,
    };
    let root = gltf.document.as_json();
    check_version(&root.asset).map_err(|p| file_error(p.to_string()))?;
    let buffers = gltf_data::buffers(&gltf, folder).map_err(|p| file_error(p.to_string()))?;
    let data = Data {
        root,
        buffers: &buffers,
    };
    let mut budget = Budget::new(folder.policy().max_bytes);

    let mut b = SceneBuilder::new(shown);
    let mut materials: Vec<Option<u32>> = vec![None; gltf.materials().len()];
    let mut default_material = None;
    let mut textured = Vec::new();
    let roots: Vec<usize> = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(scene) => scene.nodes().map(|n| n.index()).collect(),
        None => gltf_data::parentless_nodes(root),
    };
    // Depth first in document order: objects come in the file's order.
    let tree = gltf_data::node_tree(root, &roots).map_err(|p| file_error(p.to_string()))?;
    let nodes: Vec<::gltf::Node> = gltf.nodes().collect();
    check_placed_size(&tree, &nodes, budget.max()).map_err(|p| file_error(p.to_string()))?;
    let mut worlds: Vec<Matrix> = Vec::with_capacity(tree.len());
    let mut primitives_seen = 0usize;
    let mut triangles_read = 0usize;
    let mut skipped = Skipped::default();
    for &(k, parent_at) in &tree {
        let node = &nodes[k];
        check_affine(node).map_err(|p| file_error(p.to_string()))?;
        let parent = parent_at.map_or(IDENTITY, |p| worlds[p]);
        let world = multiply(&parent, &to_f64(node.transform().matrix()));
        worlds.push(world);
        let Some(mesh) = node.mesh() else {
            continue;
        };
        let name = node
            .name()
            .or(mesh.name())
            .map(str::to_string)
            .unwrap_or_else(|| format!("node {}", node.index()));
        b.object(&name);
        let mirrored = determinant3(&world) < 0.0;
        for primitive in mesh.primitives() {
            primitives_seen += 1;
            let m = primitive.material();
            let material = match m.index() {
                Some(k) => *materials[k].get_or_insert_with(|| {
                    if m.pbr_metallic_roughness().base_color_texture().is_some() {
                        textured.push(m.name().unwrap_or("unnamed").to_string());
                    }
                    b.material(convert_material(&m, k))
                }),
                None => *default_material.get_or_insert_with(|| b.material(Material::default())),
            };
            let sides = if m.double_sided() {
                Sides::Both
            } else {
                Sides::Front
            };
            let at = |message: String| {
                file_error(format!(
                    "mesh `{name}` primitive {}: {message}",
                    primitive.index()
                ))
            };
            let Some(positions) = primitive.get(&Semantic::Positions) else {
                return Err(at("no POSITION attribute".into()));
            };
            let points = data
                .positions(positions.index(), &mut budget)
                .map_err(|p| at(p.to_string()))?;
            let ids: Vec<u32> = points
                .iter()
                .map(|&p| b.vertex(transform_point(&world, p)))
                .collect();
            let indices: Vec<u32> = match primitive.indices() {
                Some(i) => data
                    .indices(i.index(), &mut budget)
                    .map_err(|p| at(p.to_string()))?,
                None => (0..ids.len() as u32).collect(),
            };
            let mode = primitive.mode();
            if mode == Mode::Triangles && indices.len() % 3 != 0 {
                let what = if primitive.indices().is_some() {
                    "indices"
                } else {
                    "vertices and no indices"
                };
                return Err(at(format!(
                    "{} {what}: a list of triangles needs a multiple of 3",
                    indices.len()
                )));
            }
            let Some(triangles) = triangles(mode, &indices) else {
                skipped.add(&name, primitive.index(), mode);
                continue;
            };
            triangles_read += triangles.len();
            for (k, t) in triangles.into_iter().enumerate() {
                let mut corners = [0u32; 3];
                for (c, &i) in corners.iter_mut().zip(&t) {
                    *c = *ids
                        .get(i as usize)
                        .ok_or_else(|| at(format!("index {i} past its {} vertices", ids.len())))?;
                    // Checked before the node's transform, which would spread a NaN to every
                    // coordinate.
                    let [x, y, z] = points[i as usize];
                    if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                        return Err(at(format!(
                            "triangle {k}: its vertex {i} (of POSITION accessor {}) has a \
                             non-finite coordinate ({x}, {y}, {z}) (numbered from 0, as glTF \
                             numbers them)",
                            positions.index()
                        )));
                    }
                }
                if mirrored {
                    corners.swap(1, 2);
                }
                let origin = format!("mesh `{name}` primitive {} triangle {k}", primitive.index());
                b.polygon_sided(&corners, material, origin, sides);
            }
        }
    }
    if primitives_seen == 0 {
        return Err(file_error(
            "the scene is empty: no node of its scene has a mesh".into(),
        ));
    }
    if triangles_read == 0 && skipped.count > 0 {
        return Err(file_error(format!(
            "the scene has no triangles: its meshes hold only primitives of points or lines ({}), \
             which scx does not read: they have no area; scx reads triangles (modes 4 TRIANGLES, 5 \
             TRIANGLE_STRIP, 6 TRIANGLE_FAN)",
            skipped.examples()
        )));
    }
    if skipped.count > 0 {
        b.warn(
            SceneWarningKind::NoArea,
            format!(
                "{shown}: ignored {} primitive(s) of points or lines ({}): they have no area",
                skipped.count,
                skipped.examples()
            ),
        );
    }
    if !textured.is_empty() {
        b.warn(
            SceneWarningKind::TexturesIgnored,
            format!(
                "{shown}: textures are not read; the reflectance of material(s) {} is their \
             baseColorFactor alone",
                super::build::list_names(&textured)
            ),
        );
    }
    b.build_with(options)
}

/// The primitives of points or lines skipped (no area): how many, and the first few for messages.
#[derive(Default)]
struct Skipped {
    count: usize,
    examples: Vec<String>,
}

impl Skipped {
    /// How many skipped primitives a message names.
    const SHOWN: usize = 3;

    fn add(&mut self, mesh: &str, primitive: usize, mode: Mode) {
        self.count += 1;
        if self.examples.len() < Self::SHOWN {
            self.examples.push(format!(
                "mesh `{mesh}` primitive {primitive}: mode {} {}",
                mode.as_gl_enum(),
                mode_name(mode)
            ));
        }
    }

    /// The first few skipped primitives, and how many more.
    fn examples(&self) -> String {
        let more = self.count - self.examples.len();
        let mut text = self.examples.join("; ");
        if more > 0 {
            text.push_str(&format!("; and {more} more"));
        }
        text
    }
}

/// A primitive mode's name in the glTF specification.
fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Points => "POINTS",
        Mode::Lines => "LINES",
        Mode::LineLoop => "LINE_LOOP",
        Mode::LineStrip => "LINE_STRIP",
        Mode::Triangles => "TRIANGLES",
        Mode::TriangleStrip => "TRIANGLE_STRIP",
        Mode::TriangleFan => "TRIANGLE_FAN",
    }
}

/// A node's `matrix` must be affine (last row 0 0 0 1), as glTF requires: a projective matrix cannot
/// place a mesh, and applied as if affine it would put it somewhere else without a word.
fn check_affine(node: &::gltf::Node) -> Result<(), DocumentProblem> {
    let ::gltf::scene::Transform::Matrix { matrix } = node.transform() else {
        return Ok(());
    };
    // Column-major: the last row is the fourth value of each column.
    let row = matrix.map(|column| column[3]);
    if row == [0.0, 0.0, 0.0, 1.0] {
        return Ok(());
    }
    Err(DocumentProblem::NotAffine {
        node: node.index(),
        name: node.name().map(str::to_string),
        row,
    })
}

/// What is wrong with a glTF document as a whole, found before its meshes are read.
#[derive(Debug, thiserror::Error)]
enum DocumentProblem {
    /// A POSITION attribute naming an accessor that does not exist.
    #[error(
        "mesh {mesh} primitive {primitive}: its POSITION accessor {accessor} does not exist (the file \
         has {accessors})"
    )]
    NoPositionAccessor {
        /// The mesh's index.
        mesh: usize,
        /// The primitive's index in its mesh.
        primitive: usize,
        /// The accessor it names.
        accessor: usize,
        /// How many accessors the file has.
        accessors: usize,
    },
    /// A .glb shorter than its header: its size.
    #[error("a .glb of {0} bytes, shorter than its 12-byte header")]
    GlbTooShort(usize),
    /// A .glb header giving a length shorter than the header: that length.
    #[error("a .glb whose header gives a length of {0} bytes, less than the header's own 12")]
    GlbLength(u32),
    /// An asset version other than 2.x: the version.
    #[error("glTF version `{0}`: scx reads glTF 2.0")]
    Version(String),
    /// A node whose matrix is not affine: the node, its name and the matrix's last row.
    #[error(
        "node {node}{}: its matrix is not affine (its last row is {} {} {} {}, not 0 0 0 1): a \
         projective matrix cannot place a mesh",
        .name.as_ref().map(|n| format!(" (`{n}`)")).unwrap_or_default(),
        .row[0], .row[1], .row[2], .row[3]
    )]
    NotAffine {
        /// The node's index.
        node: usize,
        /// Its name, if it has one.
        name: Option<String>,
        /// The matrix's last row.
        row: [f32; 4],
    },
    /// A `minVersion` other than 2.0: that version.
    #[error("the file needs a reader of glTF {0} (its minVersion): scx reads glTF 2.0")]
    MinVersion(String),
}

/// Removes the vertex attributes whose names gltf-json does not know: application-specific ones (`_s`,
/// `_TEMPERATURE`: the specification allows any name that starts with `_`) and any other. scx reads
/// POSITION alone, and gltf-json's validation refuses such names as `<invalid semantic name>`, which
/// would turn a valid file away.
fn drop_unknown_attributes(root: &mut ::gltf::json::Root) {
    for mesh in &mut root.meshes {
        for primitive in &mut mesh.primitives {
            primitive.attributes.retain(|semantic, _| {
                matches!(semantic, ::gltf::json::validation::Checked::Valid(_))
            });
        }
    }
}

/// Every POSITION attribute names an accessor that exists.
fn check_position_accessors(root: &::gltf::json::Root) -> Result<(), DocumentProblem> {
    let positions = ::gltf::json::validation::Checked::Valid(Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let Some(k) = primitive.attributes.get(&positions) else {
                continue;
            };
            if k.value() >= root.accessors.len() {
                return Err(DocumentProblem::NoPositionAccessor {
                    mesh: m,
                    primitive: p,
                    accessor: k.value(),
                    accessors: root.accessors.len(),
                });
            }
        }
    }
    Ok(())
}

/// The length a .glb's header gives must cover the header itself (the gltf crate subtracts the one from
/// the other unchecked).
fn check_glb_header(bytes: &[u8]) -> Result<(), DocumentProblem> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let Some(length) = bytes.get(8..12) else {
        return Err(DocumentProblem::GlbTooShort(bytes.len()));
    };
    let length = u32::from_le_bytes([length[0], length[1], length[2], length[3]]);
    if length < 12 {
        return Err(DocumentProblem::GlbLength(length));
    }
    Ok(())
}

/// A glTF 2.x asset: glTF 1.0 is another format (the gltf crate would read its JSON as 2.0 and find
/// nonsense), and a `minVersion` above 2.0 asks for features scx does not know.
fn check_version(asset: &::gltf::json::Asset) -> Result<(), DocumentProblem> {
    let major = |v: &str| v.split('.').next().map(str::to_string);
    if major(&asset.version).as_deref() != Some("2") {
        return Err(DocumentProblem::Version(asset.version.clone()));
    }
    if let Some(min) = asset.min_version.as_deref() {
        if min != "2.0" {
            return Err(DocumentProblem::MinVersion(min.to_string()));
        }
    }
    Ok(())
}

/// The triangles of a primitive's index list (`None` for points and lines).
fn triangles(mode: Mode, indices: &[u32]) -> Option<Vec<[u32; 3]>> {
    Some(match mode {
        Mode::Triangles => indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
        Mode::TriangleStrip => (2..indices.len())
            .map(|k| {
                let (a, b, c) = (indices[k - 2], indices[k - 1], indices[k]);
                if k % 2 == 0 {
                    [a, b, c]
                } else {
                    [b, a, c]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len())
            .map(|k| [indices[0], indices[k - 1], indices[k]])
            .collect(),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => return None,
    })
}

/// A glTF material as scx's: reflectance from `baseColorFactor`, emission from `emissiveFactor` times
/// its strength.
fn convert_material(m: &::gltf::Material, index: usize) -> Material {
    let base = m.pbr_metallic_roughness().base_color_factor();
    let strength = f64::from(m.emissive_strength().unwrap_or(1.0));
    let emissive = m.emissive_factor().map(|e| f64::from(e) * strength);
    let name = m
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("material {index}"));
    Material::rgb(name, [base[0], base[1], base[2]].map(f64::from), emissive)
}

fn to_f64(m: [[f32; 4]; 4]) -> Matrix {
    m.map(|c| c.map(f64::from))
}

/// `a b` for column-major matrices (`m[column][row]`).
fn multiply(a: &Matrix, b: &Matrix) -> Matrix {
    let mut out = [[0.0; 4]; 4];
    for (c, column) in out.iter_mut().enumerate() {
        for (r, value) in column.iter_mut().enumerate() {
            *value = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    out
}

fn transform_point(m: &Matrix, p: [f32; 3]) -> [f64; 3] {
    let p = p.map(f64::from);
    let mut out = [0.0; 3];
    for (r, value) in out.iter_mut().enumerate() {
        *value = m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r];
    }
    out
}

/// The determinant of the linear part: negative for a mirroring transform.
fn determinant3(m: &Matrix) -> f64 {
    let a = |c: usize, r: usize| m[c][r];
    a(0, 0) * (a(1, 1) * a(2, 2) - a(2, 1) * a(1, 2))
        - a(1, 0) * (a(0, 1) * a(2, 2) - a(2, 1) * a(0, 2))
        + a(2, 0) * (a(0, 1) * a(1, 2) - a(1, 1) * a(0, 2))
}

/// Writes a scene as glTF 2.0: binary (`.glb`) when the path ends so, else JSON with the buffer in a
/// data URI (one self-contained file).
pub fn write(scene: &Scene, path: &Path) -> Result<(), SceneError> {
    let binary = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    std::fs::write(path, to_bytes(scene, binary)).map_err(|e| SceneError::File {
        path: path.display().to_string(),
        message: format!("cannot write: {e}"),
    })
}

/// The bytes of a scene as glTF 2.0 (see [`write()`]): binary glTF when `binary`, else JSON with the
/// buffer in a data URI.
pub fn to_bytes(scene: &Scene, binary: bool) -> Vec<u8> {
    let (document, buffer) = document(scene);
    if binary {
        glb(&document, &buffer)
    } else {
        let mut doc = document;
        doc["buffers"][0]["uri"] = json!(format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&buffer)
        ));
        let mut text = serde_json::to_string_pretty(&doc).expect("a JSON value always serialises");
        text.push('\n');
        text.into_bytes()
    }
}

/// The glTF JSON and its one buffer: per object a node and a mesh, per material in it a primitive with
/// its own positions (f32, scene units) and u32 indices.
fn document(scene: &Scene) -> (serde_json::Value, Vec<u8>) {
    let mut buffer: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    for (object, name) in scene.objects.iter().enumerate() {
        let mut primitives = Vec::new();
        for material in 0..scene.materials.len() {
            let tris: Vec<[u32; 3]> = scene
                .patches
                .iter()
                .filter(|p| p.object as usize == object && p.material as usize == material)
                .flat_map(|p| {
                    let first = p.first_triangle as usize;
                    scene.triangles[first..first + p.triangle_count as usize]
                        .iter()
                        .copied()
                })
                .collect();
            if tris.is_empty() {
                continue;
            }
            let (local, positions) = local_vertices(scene, &tris);
            let position_view = push_view(&mut buffer, &mut views, &positions, Some(34962));
            let (lo, hi) = bounds(&positions);
            accessors.push(json!({"bufferView": position_view, "componentType": 5126,
                "count": positions.len() / 3, "type": "VEC3", "min": lo, "max": hi}));
            let index_view = push_view(&mut buffer, &mut views, &local, Some(34963));
            accessors.push(json!({"bufferView": index_view, "componentType": 5125,
                "count": local.len(), "type": "SCALAR"}));
            primitives.push(json!({"attributes": {"POSITION": accessors.len() - 2},
                "indices": accessors.len() - 1, "material": material, "mode": 4}));
        }
        if primitives.is_empty() {
            continue;
        }
        nodes.push(json!({"name": name, "mesh": meshes.len()}));
        meshes.push(json!({"name": name, "primitives": primitives}));
    }
    let materials: Vec<serde_json::Value> = scene.materials.iter().map(material_json).collect();
    let uses_strength = materials.iter().any(|m| m.get("extensions").is_some());
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": format!("scx {}", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"name": scene.name, "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": buffer.len()}],
    });
    if uses_strength {
        doc["extensionsUsed"] = json!(["KHR_materials_emissive_strength"]);
    }
    (doc, buffer)
}

/// A primitive's vertices renumbered from 0, and their f32 positions.
fn local_vertices(scene: &Scene, tris: &[[u32; 3]]) -> (Vec<u32>, Vec<f32>) {
    let mut map = std::collections::HashMap::new();
    let mut positions = Vec::new();
    let mut local = Vec::with_capacity(tris.len() * 3);
    for &v in tris.iter().flatten() {
        let k = *map.entry(v).or_insert_with(|| {
            let p = scene.vertices[v as usize];
            positions.extend([p.x as f32, p.y as f32, p.z as f32]);
            (positions.len() / 3 - 1) as u32
        });
        local.push(k);
    }
    (local, positions)
}

/// Appends little-endian numbers to the buffer (4-byte aligned) as a buffer view; returns its index.
fn push_view<T: ToLeBytes>(
    buffer: &mut Vec<u8>,
    views: &mut Vec<serde_json::Value>,
    data: &[T],
    target: Option<u32>,
) -> usize {
    let offset = buffer.len();
    for x in data {
        buffer.extend_from_slice(&x.le_bytes());
    }
    let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": buffer.len() - offset});
    if let Some(t) = target {
        view["target"] = json!(t);
    }
    views.push(view);
    views.len() - 1
}

/// Little-endian bytes of the numbers a glTF buffer holds.
trait ToLeBytes {
    fn le_bytes(&self) -> [u8; 4];
}

impl ToLeBytes for f32 {
    fn le_bytes(&self) -> [u8; 4] {
        self.to_le_bytes()
    }
}

impl ToLeBytes for u32 {
    fn le_bytes(&self) -> [u8; 4] {
        self.to_le_bytes()
    }
}

fn bounds(positions: &[f32]) -> (Vec<f32>, Vec<f32>) {
    let mut lo = vec![f32::INFINITY; 3];
    let mut hi = vec![f32::NEG_INFINITY; 3];
    for p in positions.chunks_exact(3) {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

/// A material as glTF: `baseColorFactor` from the reflectance, `emissiveFactor` (at most 1 per
/// channel) times `KHR_materials_emissive_strength` from the emission.
fn material_json(m: &Material) -> serde_json::Value {
    let [r, g, b] = m.reflectance_rgb;
    let mut out = json!({
        "name": m.name,
        "pbrMetallicRoughness": {"baseColorFactor": [r, g, b, 1.0], "metallicFactor": 0.0,
                                 "roughnessFactor": 1.0},
    });
    let strength = m.emission_rgb.iter().copied().fold(0.0, f64::max);
    if strength > 0.0 {
        let factor = if strength > 1.0 { strength } else { 1.0 };
        out["emissiveFactor"] = json!(m.emission_rgb.map(|e| e / factor));
        if factor > 1.0 {
            out["extensions"] =
                json!({"KHR_materials_emissive_strength": {"emissiveStrength": factor}});
        }
    }
    out
}

/// A .glb: the 12-byte header, the JSON chunk (padded with spaces) and the binary chunk (padded with
/// zeros).
fn glb(document: &serde_json::Value, buffer: &[u8]) -> Vec<u8> {
    let mut json_bytes = serde_json::to_vec(document).expect("a JSON value always serialises");
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    let mut bin = buffer.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// Refuses, before any mesh is read, nodes that place more bytes of positions and indices (by their
/// accessors' counts) than `max`: the same limit the reading spends against, checked up front, since a
/// small file can place one mesh from a hundred thousand nodes and the scene built up to the limit took
/// gigabytes before the refusal came.
fn check_placed_size(
    tree: &[(usize, Option<usize>)],
    nodes: &[::gltf::Node],
    max: u64,
) -> Result<(), gltf_data::AccessorProblem> {
    let mut placed = 0u64;
    for &(k, _) in tree {
        let Some(mesh) = nodes[k].mesh() else {
            continue;
        };
        for primitive in mesh.primitives() {
            // What the reading spends: each accessor's elements at their size, at most its view's
            // length (an accessor that claims more is refused by the reading, with that reason).
            let bytes = |a: ::gltf::Accessor| {
                let claimed = (a.count() as u64).saturating_mul(a.size() as u64);
                a.view().map_or(claimed, |v| claimed.min(v.length() as u64))
            };
            let positions = primitive.get(&Semantic::Positions).map_or(0, bytes);
            let indices = primitive.indices().map_or(0, bytes);
            placed = placed.saturating_add(positions).saturating_add(indices);
            if placed > max {
                return Err(gltf_data::AccessorProblem::OverBudget { max });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_compose_and_mirrors_are_found() {
        let translate = |x: f64| {
            let mut m = IDENTITY;
            m[3][0] = x;
            m
        };
        let mut scale = IDENTITY;
        scale[0][0] = 2.0;
        // Translate after scaling: p -> 2 p + (1, 0, 0).
        let m = multiply(&translate(1.0), &scale);
        assert_eq!(transform_point(&m, [3.0, 4.0, 5.0]), [7.0, 4.0, 5.0]);
        assert!(determinant3(&m) > 0.0);
        let mut mirror = IDENTITY;
        mirror[2][2] = -1.0;
        assert!(determinant3(&multiply(&m, &mirror)) < 0.0);
    }
}
