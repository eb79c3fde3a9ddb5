//! OBJ + MTL scenes, read with `tobj`.
//!
//! Each polygon face of the OBJ is one patch (a quad is one patch of two triangles, not two patches).
//! Materials: `Kd` (mean of RGB) is the reflectance, `Ke` (mean of RGB) the emission; faces without a
//! material get [`Material::default`]. A missing or unreadable MTL file is a warning, not a failure.

use std::path::Path;

use super::obj_check::NotText;
use super::read::{self, Escape, Fetched, Folder, ReadError, ReadPolicy, RefError};
use super::{Material, Scene, SceneBuilder, SceneError, SceneOptions, SceneWarningKind};

/// Loads an OBJ file (and its MTL library, if any, beside it) as a scene.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    load_with(path, &SceneOptions::default())
}

/// [`load`] with options (planarity, flipped and two-sided objects).
pub fn load_with(path: &Path, options: &SceneOptions) -> Result<Scene, SceneError> {
    load_with_policy(path, options, &ReadPolicy::default())
}

/// [`load_with`] under a reading policy: the OBJ and its libraries are regular files within the size
/// limit, and its libraries are read inside its folder unless the policy reaches further.
pub fn load_with_policy(
    path: &Path,
    options: &SceneOptions,
    policy: &ReadPolicy,
) -> Result<Scene, SceneError> {
    let shown = path.display().to_string();
    let file_error = |message: String| SceneError::in_file(&shown, message);
    let bytes =
        read::read_scene_file(path, policy.max_bytes).map_err(|e| file_error(e.to_string()))?;
    let text = text_of(&bytes).map_err(|e| e.in_file(&shown))?;
    load_obj_text(&shown, &text, &Folder::of_file(path, *policy), options)
}

/// Loads OBJ text whose MTL libraries are read in `folder`.
pub(crate) fn load_obj_text(
    shown: &str,
    text: &str,
    folder: &Folder,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    let mut scene = load_text_with(
        shown,
        without_bom(text),
        &|mtl: &Path| read_libraries(folder, mtl),
        options,
    )?;
    scene.files_read = folder.files_read();
    Ok(scene)
}

/// OBJ bytes as text: names and comments in another encoding than UTF-8 are read (see
/// [`super::obj_check::text_of`]); any other byte that is not text is an error naming its line.
pub(crate) fn text_of(bytes: &[u8]) -> Result<std::borrow::Cow<'_, str>, NotText> {
    super::obj_check::text_of(bytes, super::obj_check::OBJ_NAMES)
}

/// Text without the byte-order mark some editors put first: left in, it would glue itself to the first
/// statement's keyword (`\u{feff}mtllib`), and that statement would be dropped unseen.
fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// The MTL text an `mtllib` statement names, read in the OBJ's folder. The statement may list several
/// files (a space inside a name escaped as `\ `); `tobj` hands over the whole list, so when it is no
/// file, each listed file that exists is read and their texts are joined. A library read before gives
/// no text (its materials are there already). `Err` says why nothing was read.
fn read_libraries(folder: &Folder, mtl: &Path) -> Result<(String, String), MtlError> {
    let whole = match read_library(folder, &mtl.to_string_lossy()) {
        Ok(found) => return Ok(found),
        Err(why) => why,
    };
    let listed = mtl.to_string_lossy().replace("\\ ", "\u{0}");
    let mut refused = None;
    let mut found: Vec<(String, String)> = Vec::new();
    for name in listed.split_whitespace() {
        match read_library(folder, &name.replace('\u{0}', " ")) {
            Ok(library) => found.push(library),
            Err(why) if !why.is_missing() => {
                refused.get_or_insert(why);
            }
            Err(_) => {}
        }
    }
    if found.is_empty() {
        return Err(refused.unwrap_or(whole));
    }
    let names: Vec<&str> = found.iter().map(|(n, _)| n.as_str()).collect();
    let texts: Vec<&str> = found.iter().map(|(_, t)| t.as_str()).collect();
    Ok((names.join(" + "), texts.join("\n")))
}

/// One MTL library: the name as written, in the OBJ's folder, else (as other readers of OBJ do, for
/// files written with another machine's paths) its base name there. `Err` is [`MtlError::missing`]
/// when neither exists, else why it was not read.
fn read_library(folder: &Folder, written: &str) -> Result<(String, String), MtlError> {
    let shown = |name: &str| folder.shown(Path::new(name)).display().to_string();
    let as_written = match folder.fetch(Path::new(written)) {
        Ok(fetched) => return library_text(fetched),
        Err(RefError::Missing(_)) => MtlErrorKind::Missing {
            tried: vec![shown(written)],
        },
        Err(e) => MtlErrorKind::refused(written, e),
    };
    let Some(base) = read::base_name(written).filter(|&b| b != written) else {
        return Err(as_written.into());
    };
    match folder.fetch(Path::new(base)) {
        Ok(fetched) => library_text(fetched),
        Err(RefError::Missing(_)) if matches!(as_written, MtlErrorKind::Missing { .. }) => {
            Err(MtlErrorKind::Missing {
                tried: vec![shown(written), shown(base)],
            }
            .into())
        }
        Err(RefError::Missing(_)) => Err(MtlErrorKind::NoBaseName {
            written: Box::new(as_written),
            base: base.to_string(),
        }
        .into()),
        Err(e) => Err(MtlErrorKind::refused(base, e).into()),
    }
}

/// A library's name for messages and its text (empty when the scene named it before).
fn library_text(fetched: Fetched) -> Result<(String, String), MtlError> {
    let name = fetched.shown.display().to_string();
    if !fetched.first {
        return Ok((name, String::new()));
    }
    match super::obj_check::text_of(&fetched.bytes, super::obj_check::MTL_NAMES) {
        Ok(text) => Ok((name, without_bom(&text).to_string())),
        Err(problem) => Err(MtlErrorKind::NotText { problem, name }.into()),
    }
}

/// Where an OBJ's MTL library comes from: given the name in `mtllib`, the library's name for messages
/// and its text, or why it cannot be read.
pub type MaterialSource<'a> = dyn Fn(&Path) -> Result<(String, String), MtlError> + 'a;

/// Why an MTL library an OBJ names was not read: the reason its warning gives (the faces that use its
/// materials get the default material). A [`MaterialSource`] returns [`MtlError::missing`] when there
/// is no such library, or [`MtlError::other`] with a reason of its own; scx's own readers say what kept
/// the file out (the reading policy, its size or kind, its encoding).
#[derive(Debug, thiserror::Error)]
#[error(transparent)]
pub struct MtlError {
    kind: MtlErrorKind,
}

impl MtlError {
    /// No library of that name exists.
    pub fn missing() -> Self {
        MtlErrorKind::Missing { tried: Vec::new() }.into()
    }

    /// The library could not be read, for a reason of the source's own (its message is the reason).
    pub fn other(reason: impl Into<Box<dyn std::error::Error + Send + Sync>>) -> Self {
        MtlErrorKind::Other(reason.into()).into()
    }

    /// Whether no library of that name exists (not that one exists and was refused or unreadable).
    pub fn is_missing(&self) -> bool {
        matches!(self.kind, MtlErrorKind::Missing { .. })
    }
}

/// What kept an MTL library from being read.
#[derive(Debug, thiserror::Error)]
enum MtlErrorKind {
    /// No such file (neither the name as written nor its base name): the paths tried, when known.
    #[error("{}", missing_text(tried))]
    Missing {
        /// The paths looked for, as shown in messages (empty: a source that did not say).
        tried: Vec<String>,
    },
    /// The reading policy keeps the name out of reach.
    #[error(transparent)]
    Outside(Escape),
    /// The file is there but was not read (not a regular file, too large, a failure to read): the
    /// name as written.
    #[error("`{name}`: {error}")]
    Unreadable {
        /// The name as written.
        name: String,
        /// Why.
        #[source]
        error: ReadError,
    },
    /// The name as written was not read, and its base name is no file in the scene's folder.
    #[error("{written}; and there is no `{base}` in the scene's folder")]
    NoBaseName {
        /// Why the name as written was not read.
        #[source]
        written: Box<MtlErrorKind>,
        /// The base name looked for.
        base: String,
    },
    /// The file is not text where it must be: its name for messages, and where.
    #[error("`{name}` line {}: {problem}", .problem.line)]
    NotText {
        /// The library's name for messages.
        name: String,
        /// The line and byte that are not text.
        problem: NotText,
    },
    /// A reason a [`MaterialSource`] gave.
    #[error(transparent)]
    Other(Box<dyn std::error::Error + Send + Sync>),
}

impl MtlErrorKind {
    /// Why the library named `name` (as written) was not fetched.
    fn refused(name: &str, e: RefError) -> Self {
        match e {
            RefError::Missing(_) => MtlErrorKind::Missing { tried: Vec::new() },
            RefError::Outside(escape) => MtlErrorKind::Outside(escape),
            RefError::Unreadable(error) => MtlErrorKind::Unreadable {
                name: name.to_string(),
                error,
            },
        }
    }
}

/// The reason of a missing library: the paths tried (as written, then its base name in the scene's
/// folder), so that a user sees where scx looked.
fn missing_text(tried: &[String]) -> String {
    match tried {
        [] => "cannot open the file".into(),
        [one] => format!("no file `{one}`"),
        [written, base] => {
            format!("no file `{written}`, nor `{base}` (its base name in the scene's folder)")
        }
        more => format!("no file among {}", more.join(", ")),
    }
}

impl From<MtlErrorKind> for MtlError {
    fn from(kind: MtlErrorKind) -> Self {
        MtlError { kind }
    }
}

/// Loads OBJ text as a scene called `shown` (messages name it), with `materials` giving the text of an
/// MTL library from the name in the OBJ (a missing library is a warning, a malformed one an error).
pub fn load_text(shown: &str, text: &str, materials: &MaterialSource) -> Result<Scene, SceneError> {
    load_text_with(shown, text, materials, &SceneOptions::default())
}

/// [`load_text`] with options (planarity, flipped and two-sided objects).
pub fn load_text_with(
    shown: &str,
    text: &str,
    materials: &MaterialSource,
    options: &SceneOptions,
) -> Result<Scene, SceneError> {
    let shown = shown.to_string();
    let file_error = |message: String| SceneError::in_file(&shown, message);
    let prepared = super::obj_check::prepare(&shown, text)?;
    if prepared.faces.is_empty() {
        return Err(no_faces(&shown, &prepared));
    }
    let face_lines = &prepared.faces;
    let options_tobj = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj panics on some malformed MTL statements: the pre-scan refuses those first, and its error
    // (with the line) comes out of tobj's callback this way.
    let mtl_error: std::cell::RefCell<Option<SceneError>> = std::cell::RefCell::new(None);
    // Where each material is defined (library and line), for messages about it.
    let defined: std::cell::RefCell<Vec<(String, String, usize)>> = Default::default();
    // Why libraries were not read, for the warning (tobj keeps only that one failed).
    let unread: std::cell::RefCell<Vec<MtlError>> = Default::default();
    let load_mtl = |name: &Path| match materials(name) {
        Err(why) => {
            unread.borrow_mut().push(why);
            Err(tobj::LoadError::OpenFileFailed)
        }
        Ok((mtl_shown, mtl_text)) => match super::obj_check::scan_mtl(&mtl_shown, &mtl_text) {
            Err(e) => {
                mtl_error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::MaterialParseError)
            }
            Ok(()) => {
                let lines = super::obj_check::material_lines(&mtl_text);
                defined.borrow_mut().extend(
                    lines
                        .into_iter()
                        .map(|(m, line)| (m, mtl_shown.clone(), line)),
                );
                tobj::load_mtl_buf(&mut mtl_text.as_bytes())
            }
        },
    };
    let loaded = tobj::load_obj_buf(&mut prepared.text.as_bytes(), &options_tobj, load_mtl);
    if let Some(e) = mtl_error.take() {
        return Err(e);
    }
    let (models, materials) = loaded.map_err(|e| file_error(describe_tobj_error(&e)))?;
    let defined = defined.take();
    let total_faces: usize = models.iter().map(|m| face_count(&m.mesh)).sum();
    // Faces as tobj gives them are the `f` statements in file order; name their lines when that holds.
    let face_line = |k: usize| (total_faces == face_lines.len()).then(|| face_lines[k]);
    let mut global_face = 0usize;

    let mut b = SceneBuilder::new(shown.clone());
    let any_library_read = materials.is_ok();
    let material_base = match materials {
        Ok(mats) => {
            let base = 0u32;
            for m in &mats {
                b.material(convert_material(m));
            }
            check_used_materials(&shown, &mats, &models, &defined)?;
            warn_undefined_materials(&mut b, &shown, &prepared.usemtl, &mats);
            warn_lights_in_other_conventions(&mut b, &shown, &mats);
            if mats.is_empty() {
                None
            } else {
                Some(base)
            }
        }
        Err(e) => {
            let why = match e {
                tobj::LoadError::OpenFileFailed => unread.borrow().first().map(MtlError::to_string),
                _ => None,
            };
            b.warn(
                SceneWarningKind::MaterialLibrary,
                format!(
                "{shown}: material library not loaded ({}); every face gets the default material \
                 (reflectance 0.5, no emission)",
                why.unwrap_or_else(|| describe_tobj_error(&e))
            ),
            );
            None
        }
    };
    warn_refused_libraries(&mut b, &shown, &unread.take(), any_library_read);
    warn_ignored_statements(&mut b, &shown, &prepared);
    let default_material = b.material(Material::default());

    for model in &models {
        let mesh = &model.mesh;
        if mesh.positions.len() % 3 != 0 {
            return Err(file_error(format!(
                "object `{}`: vertex positions are not triples",
                model.name
            )));
        }
        b.object(&model.name);
        let ids: Vec<u32> = mesh
            .positions
            .chunks_exact(3)
            .map(|p| b.vertex([p[0], p[1], p[2]]))
            .collect();
        let material = match (material_base, mesh.material_id) {
            (Some(base), Some(id)) => base + id as u32,
            _ => default_material,
        };
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut at = 0usize;
        for (face, &arity) in arities.iter().enumerate() {
            let Some(corners) = mesh.indices.get(at..at + arity) else {
                return Err(file_error(format!(
                    "object `{}`: face {} refers past the end of the index list",
                    model.name,
                    face + 1
                )));
            };
            let verts: Result<Vec<u32>, SceneError> = corners
                .iter()
                .map(|&i| {
                    ids.get(i as usize).copied().ok_or_else(|| {
                        file_error(format!(
                            "object `{}`: face {} uses vertex {} that does not exist",
                            model.name,
                            face + 1,
                            i + 1
                        ))
                    })
                })
                .collect();
            let origin = match face_line(global_face) {
                Some(line) => format!(
                    "line {line}: face {} (object `{}`)",
                    global_face + 1,
                    model.name
                ),
                None => format!("object `{}` face {}", model.name, face + 1),
            };
            b.polygon(&verts?, material, origin);
            global_face += 1;
            at += arity;
        }
    }
    b.build_with(options)
}

/// The error for OBJ text without faces, naming the lines and points it has instead, if any.
fn no_faces(shown: &str, prepared: &super::obj_check::Prepared) -> SceneError {
    let (count, line) = prepared.lines_and_points;
    if count > 0 {
        return SceneError::File {
            path: format!("{shown}:{line}"),
            message: format!(
                "the scene is empty: no faces (`f`); its {count} line and point statement(s) (`l`, `p`, \
                 the first here) have no area"
            ),
        };
    }
    match prepared.text.lines().count() {
        0 => SceneError::Geometry {
            scene: shown.to_string(),
            message: "the scene is empty: no faces".into(),
        },
        lines => SceneError::File {
            path: format!("{shown}:{lines}"),
            message: format!(
                "the scene is empty: no faces (`f`) in its {lines} line(s), up to this last one"
            ),
        },
    }
}

/// One warning for each library that was refused (outside the folder, not a regular file, too large)
/// while other libraries were read: the faces that use its materials get the default material. When no
/// library was read, the warning about that says why already.
fn warn_refused_libraries(b: &mut SceneBuilder, shown: &str, unread: &[MtlError], any_read: bool) {
    if !any_read {
        return;
    }
    for why in unread.iter().filter(|w| !w.is_missing()) {
        b.warn(
            SceneWarningKind::MaterialLibrary,
            format!(
            "{shown}: a material library was not read ({why}); faces using its materials get the \
             default material (reflectance 0.5, no emission)"
        ),
        );
    }
}

/// Every channel of a used material's `Kd` in [0, 1] and of its `Ke` finite and >= 0: an error naming
/// the library, the material's line and the channel.
fn check_used_materials(
    shown: &str,
    materials: &[tobj::Material],
    models: &[tobj::Model],
    defined: &[(String, String, usize)],
) -> Result<(), SceneError> {
    let mut used = vec![false; materials.len()];
    for m in models {
        if let Some(id) = m.mesh.material_id.filter(|&id| id < used.len()) {
            used[id] = true;
        }
    }
    for (m, _) in materials.iter().zip(&used).filter(|(_, &u)| u) {
        let Some(problem) = convert_material(m).unphysical_channel() else {
            continue;
        };
        let path = match defined.iter().find(|(name, _, _)| *name == m.name) {
            Some((_, library, line)) => format!("{library}:{line}"),
            None => shown.to_string(),
        };
        return Err(SceneError::File {
            path,
            message: format!("material `{}`: {problem}", m.name),
        });
    }
    Ok(())
}

/// One warning naming the `usemtl` statements whose material no library defines (their faces get the
/// default material).
fn warn_undefined_materials(
    b: &mut SceneBuilder,
    shown: &str,
    usemtl: &[(usize, String)],
    materials: &[tobj::Material],
) {
    let mut undefined: Vec<(usize, &str)> = Vec::new();
    for (line, name) in usemtl {
        let known = materials.iter().any(|m| m.name == *name);
        if !known && !undefined.iter().any(|(_, n)| n == name) {
            undefined.push((*line, name));
        }
    }
    if undefined.is_empty() {
        return;
    }
    let named: Vec<String> = undefined
        .iter()
        .map(|(line, name)| format!("`{name}` (line {line})"))
        .collect();
    b.warn(
        SceneWarningKind::UndefinedMaterials,
        format!(
        "{shown}: `usemtl` names material(s) no library defines: {}; their faces get the default \
         material (reflectance 0.5, no emission)",
        named.join(", ")
    ),
    );
}

/// Warnings about what the loader left out: `w` weights and line or point statements.
fn warn_ignored_statements(
    b: &mut SceneBuilder,
    shown: &str,
    prepared: &super::obj_check::Prepared,
) {
    let (weights, line) = prepared.weights;
    if weights > 0 {
        b.warn(SceneWarningKind::VertexWeights, format!(
            "{shown}: ignored the weight `w` of {weights} vertex statement(s) `v x y z w` (first at line \
             {line}): it applies to rational curves and surfaces only"
        ));
    }
    let (count, line) = prepared.lines_and_points;
    if count > 0 {
        b.warn(SceneWarningKind::NoArea, format!(
            "{shown}: ignored {count} line and point statement(s) (`l`, `p`; first at line {line}): they \
             have no area"
        ));
    }
}

/// One warning naming the materials that look like lights in another convention than `Ke`: an ambient
/// `Ka` above 1 (tinyobjloader's Cornell box marks its light with `Ka 20 20 20`) with no emission. scx
/// reads emission from `Ke` only, so their faces do not emit, and the radiosity measures may then be left
/// out ("nothing emits").
fn warn_lights_in_other_conventions(b: &mut SceneBuilder, shown: &str, mats: &[tobj::Material]) {
    let looks_lit = |m: &tobj::Material| {
        let ambient = m.ambient.unwrap_or([0.0; 3]);
        convert_material(m).emission == 0.0 && ambient.iter().any(|&a| a > 1.0)
    };
    let lit: Vec<&tobj::Material> = mats.iter().filter(|m| looks_lit(m)).collect();
    if lit.is_empty() {
        return;
    }
    let named: Vec<String> = lit
        .iter()
        .map(|m| {
            let [r, g, bl] = m.ambient.unwrap_or([0.0; 3]);
            format!("`{}` (Ka {r} {g} {bl})", m.name)
        })
        .collect();
    b.warn(
        SceneWarningKind::LightInOtherConvention,
        format!(
            "{shown}: material(s) {} have an ambient colour above 1, as some files mark lights, but no \
             emission: scx takes emission from `Ke` only, so their faces do not emit; add `Ke r g b` to \
             the library to make them lights",
            named.join(", ")
        ),
    );
}

/// Faces of a tobj mesh (triangles when it gives no arities).
fn face_count(mesh: &tobj::Mesh) -> usize {
    if mesh.face_arities.is_empty() {
        mesh.indices.len() / 3
    } else {
        mesh.face_arities.len()
    }
}

fn convert_material(m: &tobj::Material) -> Material {
    // tobj 4 parses `Ke` into `emissive`; the key-value fallback covers readers that leave it unknown.
    let emission = m
        .emissive
        .or_else(|| m.unknown_param.get("Ke").and_then(|s| parse_rgb(s)))
        .unwrap_or([0.0; 3]);
    let reflectance = m.diffuse.unwrap_or(Material::default().reflectance_rgb);
    Material::rgb(m.name.clone(), reflectance, emission)
}

fn parse_rgb(s: &str) -> Option<[f64; 3]> {
    let v: Vec<f64> = s
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    match v.as_slice() {
        [r, g, b] => Some([*r, *g, *b]),
        [g] => Some([*g, *g, *g]),
        _ => None,
    }
}

fn describe_tobj_error(e: &tobj::LoadError) -> String {
    use tobj::LoadError::*;
    match e {
        OpenFileFailed => "cannot open the file".into(),
        ReadError => "cannot read the file".into(),
        UnrecognizedCharacter => "unrecognised character".into(),
        PositionParseError => "malformed vertex position (`v` line)".into(),
        NormalParseError => "malformed normal (`vn` line)".into(),
        TexcoordParseError => "malformed texture coordinate (`vt` line)".into(),
        FaceParseError => "malformed face (`f` line)".into(),
        MaterialParseError => "malformed material".into(),
        InvalidObjectName => "invalid object name".into(),
        FaceVertexOutOfBounds => "a face refers to a vertex that does not exist".into(),
        FaceTexCoordOutOfBounds => {
            "a face refers to a texture coordinate that does not exist".into()
        }
        FaceNormalOutOfBounds => "a face refers to a normal that does not exist".into(),
        FaceColorOutOfBounds => "a face refers to a colour that does not exist".into(),
        InvalidLoadOptionConfig => "invalid load options".into(),
        ScalingByZeroError => "a scale of zero".into(),
        ColorParseError => "malformed vertex colour".into(),
        InvalidPolygon => "invalid polygon".into(),
        GenericFailure => "malformed OBJ".into(),
    }
}

/// Writes a scene as OBJ (scene units, one polygon face per patch) plus an MTL library beside it
/// (`Kd` = reflectance, `Ke` = emission, RGB), so that [`load`] reads back the same patches and
/// materials. A scene of several objects gets an `o` statement per object, so that they keep their names.
pub fn write(scene: &Scene, path: &Path) -> Result<(), SceneError> {
    let io_error = |p: &Path, e: std::io::Error| SceneError::File {
        path: p.display().to_string(),
        message: format!("cannot write: {e}"),
    };
    let mtl_path = path.with_extension("mtl");
    let mtl_name = mtl_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene.mtl".into());
    let (obj, mtl) = to_text(scene, &mtl_name);
    std::fs::write(&mtl_path, mtl).map_err(|e| io_error(&mtl_path, e))?;
    std::fs::write(path, obj).map_err(|e| io_error(path, e))?;
    Ok(())
}

/// The OBJ text of a scene and the text of its MTL library, which the OBJ names `mtl_name` (see
/// [`write()`]), for a caller that writes the files its own way.
pub fn to_text(scene: &Scene, mtl_name: &str) -> (String, String) {
    use std::fmt::Write as _;
    let mut mtl = String::from("# written by scx\n");
    for (k, m) in scene.materials.iter().enumerate() {
        let [r, g, b] = m.reflectance_rgb;
        let [er, eg, eb] = m.emission_rgb;
        let _ = writeln!(
            mtl,
            "newmtl {}\nKd {r} {g} {b}\nKe {er} {eg} {eb}\n",
            material_label(k, m)
        );
    }
    let mut obj = format!(
        "# {} written by scx {}: {} patches\nmtllib {mtl_name}\n",
        scene.name,
        env!("CARGO_PKG_VERSION"),
        scene.patch_count()
    );
    for v in &scene.vertices {
        let _ = writeln!(obj, "v {:?} {:?} {:?}", v[0], v[1], v[2]);
    }
    let mut current = None;
    let mut current_object = None;
    for p in &scene.patches {
        // Every object is named, a scene of one too: read back, it keeps its name (`--flip-normals NAME`).
        if current_object != Some(p.object) {
            let name = scene.objects[p.object as usize].trim();
            let _ = writeln!(obj, "o {}", if name.is_empty() { "unnamed" } else { name });
            current_object = Some(p.object);
            // tobj starts a new model at `o`: say the material again.
            current = None;
        }
        if current != Some(p.material) {
            let k = p.material as usize;
            let _ = writeln!(obj, "usemtl {}", material_label(k, &scene.materials[k]));
            current = Some(p.material);
        }
        let idx: Vec<String> = scene
            .polygon(p)
            .iter()
            .map(|v| (v + 1).to_string())
            .collect();
        let _ = writeln!(obj, "f {}", idx.join(" "));
    }
    (obj, mtl)
}

/// A material name safe for MTL (no spaces), unique by index.
fn material_label(k: usize, m: &Material) -> String {
    let clean: String = m
        .name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("m{k}_{clean}")
}
