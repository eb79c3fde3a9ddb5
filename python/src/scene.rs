//! `scx.Scene`: a scene read by the library's readers (`scx.load`) or built from numpy arrays with its
//! `SceneBuilder` (`Scene.from_arrays`), and what Python can read of it.

use std::collections::HashMap;
use std::sync::Arc;

use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyString;

use scene_complexity::{
    load_with_policy, write_scene, Material, ReadPolicy, SceneBuilder, SceneOptions, CATALOGUE,
};

use crate::args::{self, repr};
use crate::arrays::{self, PerTriangle};
use crate::errors::scene_error;

/// A triangle scene ready to analyse: its patches (the unit of the discretisation, `i` in F_ij), each
/// one or more coplanar triangles with an area, a normal, a material and an object.
///
/// Made by :func:`scx.load` (a file or a built-in), :meth:`Scene.from_arrays` (numpy arrays) or
/// :meth:`Scene.from_trimesh`. Immutable. Patch ``k`` of every per-patch result is ``scene``'s patch
/// ``k``; :attr:`triangle_patch` maps the scene's triangles to them.
#[pyclass(module = "scx", frozen)]
pub struct Scene {
    pub inner: Arc<scene_complexity::Scene>,
    /// How it was read (a saved run keeps it, so that a resume reads the file the same way).
    pub reading: SceneOptions,
}

impl Scene {
    fn new(inner: scene_complexity::Scene, reading: SceneOptions) -> Self {
        Scene {
            inner: Arc::new(inner),
            reading,
        }
    }

    /// Emits each of the scene's loading warnings as a Python warning (`scx.ScxWarning`).
    fn warn(&self, py: Python<'_>) -> PyResult<()> {
        warn_all(py, self.inner.warnings.iter().map(|w| w.message.as_str()))
    }
}

/// Emits `messages` as `scx.ScxWarning`s (imported from the package, so that a filter on it applies).
pub fn warn_all<'a>(py: Python<'_>, messages: impl Iterator<Item = &'a str>) -> PyResult<()> {
    let mut messages = messages.peekable();
    if messages.peek().is_none() {
        return Ok(());
    }
    let category = py.import("scx")?.getattr("ScxWarning")?;
    let warnings = py.import("warnings")?;
    for m in messages {
        warnings.call_method1("warn", (m, &category, 2))?;
    }
    Ok(())
}

/// Reads the scene `spec` (a file or a built-in) as `options` ask, under `policy`, with the GIL
/// released; its warnings are emitted.
pub fn read_scene(
    py: Python<'_>,
    spec: &str,
    options: &SceneOptions,
    policy: &ReadPolicy,
) -> PyResult<Scene> {
    let scene = py
        .allow_threads(|| {
            scene_complexity::read_guarded(spec, || load_with_policy(spec, options, policy))
        })
        .map_err(scene_error)?;
    let scene = Scene::new(scene, options.clone());
    scene.warn(py)?;
    Ok(scene)
}

/// A path or a built-in name as text: `str`, or any `os.PathLike`.
pub fn path_text(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<String> {
    if let Ok(s) = obj.downcast::<PyString>() {
        return Ok(s.to_string());
    }
    let fspath = obj.py().import("os")?.getattr("fspath")?;
    fspath
        .call1((obj,))
        .and_then(|p| p.extract::<String>())
        .map_err(|_| {
            crate::errors::bad_argument(format!(
                "{what} must be a path or a built-in name such as '@cube:10', not {}",
                repr(obj)
            ))
        })
}

/// Reads a scene: a file in OBJ, glTF/GLB, PLY or STL (told by its content), or a built-in such as
/// ``"@cube:10"`` (:func:`scx.builtins` lists them).
///
/// Args:
///     path: the file (``str`` or ``os.PathLike``) or the built-in's name.
///     planarity: a polygon whose corners leave its plane by at most this fraction of its size is
///         planar (one patch); a less planar one is split into planar triangles, with a warning.
///         Default 1e-4.
///     strict_planarity: refuse non-planar polygons instead of splitting them.
///     flip_normals: reverse the normals of these objects: ``True`` for every object, or a list of
///         object names (OBJ ``o``/``g``, glTF node or mesh, the file name for PLY and STL).
///     two_sided: make these objects two-sided (two patches back to back, one per side): ``True`` or a
///         list of names.
///     read_anywhere: let the scene's references (glTF buffers, OBJ ``mtllib``) name files outside
///         its folder.
///     max_file_size: the largest file read, in bytes (default 256 MiB).
///
/// Returns:
///     Scene: the scene; its loading warnings are emitted as :class:`scx.ScxWarning`.
///
/// Raises:
///     SceneError: a missing or bad file, a bad built-in name, unusable geometry; with the same
///         message as the command line's.
#[pyfunction]
#[pyo3(signature = (path, *, planarity=None, strict_planarity=false, flip_normals=None,
                    two_sided=None, read_anywhere=false, max_file_size=None))]
#[allow(clippy::too_many_arguments)]
pub fn load(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    planarity: Option<&Bound<'_, PyAny>>,
    strict_planarity: bool,
    flip_normals: Option<&Bound<'_, PyAny>>,
    two_sided: Option<&Bound<'_, PyAny>>,
    read_anywhere: bool,
    max_file_size: Option<&Bound<'_, PyAny>>,
) -> PyResult<Scene> {
    let spec = path_text(path, "path")?;
    let none = py.None().into_bound(py);
    let options = args::scene_options(
        planarity,
        strict_planarity,
        flip_normals.unwrap_or(&none),
        two_sided.unwrap_or(&none),
    )?;
    let policy = args::read_policy(read_anywhere, max_file_size)?;
    read_scene(py, &spec, &options, &policy)
}

/// The built-in scenes: a dict from each usage (``"@cube[:N]"``) to what it is.
#[pyfunction]
pub fn builtins() -> Vec<(String, String)> {
    CATALOGUE
        .iter()
        .map(|b| (b.usage.to_string(), b.description.to_string()))
        .collect()
}

/// Checks every vertex index of `triangles` (flat, 3 per triangle) against the vertex count `n`.
fn check_indices(triangles: &[i64], n: usize) -> PyResult<()> {
    if n == 0 {
        return Err(scene_error(
            "vertices is empty: the triangles name vertices that are not there",
        ));
    }
    match triangles
        .iter()
        .position(|&v| v < 0 || v as u64 >= n as u64)
    {
        None => Ok(()),
        Some(k) => Err(scene_error(format!(
            "triangles[{}] names vertex {}, but the vertices are numbered from 0 to {}",
            k / 3,
            triangles[k],
            n.saturating_sub(1)
        ))),
    }
}

/// The objects of the triangles: names and each triangle's object, from an integer array (objects
/// named `object K`) or a sequence of names.
fn objects_of(
    py: Python<'_>,
    obj: &Bound<'_, PyAny>,
    m: usize,
) -> PyResult<(Vec<String>, Vec<u32>)> {
    let numpy = py.import("numpy")?;
    let a = numpy.call_method1("asarray", (obj,))?;
    let kind: String = a.getattr("dtype")?.getattr("kind")?.extract()?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    if shape != [m] {
        return Err(scene_error(format!(
            "objects must have shape ({m},) (one object per triangle), not {}",
            repr(&a.getattr("shape")?)
        )));
    }
    // numpy.unique sorts the objects: their order is that of their names (or numbers).
    let (names, codes): (Vec<String>, Vec<i64>) = match kind.as_str() {
        "i" | "u" => {
            let ids = arrays::ints1(py, &a, "objects", &format!("({m},)"))?;
            let ids = ids.as_slice()?;
            let mut seen: Vec<i64> = ids.to_vec();
            seen.sort_unstable();
            seen.dedup();
            let index: HashMap<i64, i64> = seen
                .iter()
                .enumerate()
                .map(|(k, &id)| (id, k as i64))
                .collect();
            (
                seen.iter().map(|id| format!("object {id}")).collect(),
                ids.iter().map(|id| index[id]).collect(),
            )
        }
        "U" | "O" | "S" => {
            let names: Vec<String> = a
                .call_method0("tolist")?
                .extract()
                .map_err(|_| scene_error("objects must be integers or names (str)"))?;
            let mut seen = names.clone();
            seen.sort_unstable();
            seen.dedup();
            let index: HashMap<&str, i64> = seen
                .iter()
                .enumerate()
                .map(|(k, n)| (n.as_str(), k as i64))
                .collect();
            let codes = names.iter().map(|n| index[n.as_str()]).collect();
            (seen, codes)
        }
        _ => {
            return Err(scene_error(
                "objects must be an array of integers or of names (str), one per triangle",
            ))
        }
    };
    Ok((names, codes.into_iter().map(|c| c as u32).collect()))
}

/// A material per RGB reflectance and emission: one library material for each distinct pair.
struct Materials {
    by_value: HashMap<[u64; 6], u32>,
}

impl Materials {
    fn index(&mut self, b: &mut SceneBuilder, reflectance: [f64; 3], emission: [f64; 3]) -> u32 {
        let key = [
            reflectance[0].to_bits(),
            reflectance[1].to_bits(),
            reflectance[2].to_bits(),
            emission[0].to_bits(),
            emission[1].to_bits(),
            emission[2].to_bits(),
        ];
        let next = self.by_value.len();
        *self.by_value.entry(key).or_insert_with(|| {
            let name = format!("material {next}");
            b.material(Material::rgb(name, reflectance, emission))
        })
    }
}

/// The outline of the triangles `tris` of one patch, counter-clockwise as they are: the edges that
/// no other triangle of the patch shares (in the opposite direction), walked as one loop. `None` when
/// they are not one simple polygon (pieces apart, a hole, corners touching).
fn outline(tris: &[[u32; 3]]) -> Option<Vec<u32>> {
    if let [t] = tris {
        return Some(t.to_vec());
    }
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::new();
    for (&(a, b), &count) in &edges {
        if count > 1 {
            return None;
        }
        if edges.contains_key(&(b, a)) {
            continue;
        }
        if next.insert(a, b).is_some() {
            return None;
        }
    }
    let &start = next.keys().min()?;
    let mut corners = vec![start];
    let mut at = next[&start];
    while at != start {
        corners.push(at);
        at = *next.get(&at)?;
        if corners.len() > next.len() {
            return None;
        }
    }
    (corners.len() == next.len()).then_some(corners)
}

/// The triangles in order of their patch id (ascending, each patch's in the triangles' order): the
/// patches are the runs of equal ids.
fn by_patch(ids: &[i64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..ids.len()).collect();
    order.sort_by_key(|&t| ids[t]);
    order
}

/// What a patch's triangles share: the material and the object of its first triangle, which every
/// other must have.
fn shared<T: PartialEq + Copy>(
    group: &[usize],
    of: impl Fn(usize) -> T,
    what: &str,
    id: i64,
) -> PyResult<T> {
    let first = of(group[0]);
    if let Some(&t) = group.iter().find(|&&t| of(t) != first) {
        return Err(scene_error(format!(
            "patch {id}: triangles {} and {t} have different {what}; a patch has one",
            group[0]
        )));
    }
    Ok(first)
}

#[pymethods]
impl Scene {
    /// A scene from numpy arrays, built by the library's ``SceneBuilder``: every patch a planar
    /// polygon, vertices at the same position welded, the scene measured in its own units.
    ///
    /// Args:
    ///     vertices: ``(n, 3)`` float coordinates.
    ///     triangles: ``(m, 3)`` integer vertex indices (from 0), counter-clockwise seen from the
    ///         triangle's front side (the side that is a surface).
    ///     patches: ``(m,)`` integer patch id of each triangle; the triangles of one id must form one
    ///         planar polygon without holes, and share a material and an object. Patches are
    ///         numbered by ascending id. Default: each triangle its own patch, in order.
    ///     reflectance: diffuse reflectance in [0, 1]: a number, ``(m,)`` (grey) or ``(m, 3)`` (RGB)
    ///         per triangle. Default 0.5.
    ///     emission: emitted radiosity >= 0 in the same shapes (a light makes the radiosity
    ///         measures). Default 0.
    ///     objects: ``(m,)`` object of each triangle: integers (named ``"object K"``) or names.
    ///         Default: one object named after the scene.
    ///     name: the scene's name in reports and saved runs.
    ///     planarity, strict_planarity, flip_normals, two_sided: as for :func:`scx.load`.
    ///
    /// Raises:
    ///     SceneError: wrong shapes or kinds, non-finite coordinates, indices out of range, patches
    ///         that are not one polygon, unphysical materials, a scene without area.
    #[staticmethod]
    #[pyo3(signature = (vertices, triangles, patches=None, reflectance=None, emission=None,
                        objects=None, *, name="<arrays>", planarity=None, strict_planarity=false,
                        flip_normals=None, two_sided=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        triangles: &Bound<'_, PyAny>,
        patches: Option<&Bound<'_, PyAny>>,
        reflectance: Option<&Bound<'_, PyAny>>,
        emission: Option<&Bound<'_, PyAny>>,
        objects: Option<&Bound<'_, PyAny>>,
        name: &str,
        planarity: Option<&Bound<'_, PyAny>>,
        strict_planarity: bool,
        flip_normals: Option<&Bound<'_, PyAny>>,
        two_sided: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Scene> {
        let none = py.None().into_bound(py);
        let options = args::scene_options(
            planarity,
            strict_planarity,
            flip_normals.unwrap_or(&none),
            two_sided.unwrap_or(&none),
        )?;
        let v = arrays::floats2(py, vertices, "vertices", 3)?;
        let t = arrays::ints2(py, triangles, "triangles", 3)?;
        let (v, t) = (v.as_slice()?, t.as_slice()?);
        let (n, m) = (v.len() / 3, t.len() / 3);
        if m == 0 {
            return Err(scene_error(
                "triangles is empty: a scene needs at least one triangle",
            ));
        }
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            let i = k / 3;
            return Err(scene_error(format!(
                "vertices[{i}] has a non-finite coordinate ({}, {}, {})",
                v[3 * i],
                v[3 * i + 1],
                v[3 * i + 2]
            )));
        }
        check_indices(t, n)?;
        let grey = |x: f64| PerTriangle::All([x; 3]);
        let shade = |obj: Option<&Bound<'_, PyAny>>, what: &str, default: f64| match obj {
            Some(o) if !o.is_none() => arrays::per_triangle(py, o, what, m),
            _ => Ok(grey(default)),
        };
        let reflectance = shade(reflectance, "reflectance", Material::default().reflectance)?;
        let emission = shade(emission, "emission", 0.0)?;
        let objects = match objects.filter(|o| !o.is_none()) {
            Some(o) => Some(objects_of(py, o, m)?),
            None => None,
        };
        let ids = patches
            .filter(|p| !p.is_none())
            .map(|p| arrays::ints1(py, p, "patches", &format!("({m},)")))
            .transpose()?;
        let ids = ids.as_ref().map(|a| a.as_slice()).transpose()?;
        if let Some(ids) = ids.filter(|ids| ids.len() != m) {
            return Err(scene_error(format!(
                "patches must have shape ({m},) (one patch id per triangle), not ({},)",
                ids.len()
            )));
        }

        let mut b = SceneBuilder::new(name);
        let index: Vec<u32> = (0..n)
            .map(|i| b.vertex([v[3 * i], v[3 * i + 1], v[3 * i + 2]]))
            .collect();
        let corners = |k: usize| [0, 1, 2].map(|c| index[t[3 * k + c] as usize]);
        let mut materials = Materials {
            by_value: HashMap::new(),
        };
        let default_material = (reflectance_is_default(&reflectance) && is_zero(&emission))
            .then(|| b.material(Material::default()));
        let mut current_object = None;
        let mut add = |b: &mut SceneBuilder, first: usize, polygon: &[u32], origin: String| {
            if let Some((names, codes)) = &objects {
                let o = codes[first];
                if current_object != Some(o) {
                    b.object(&names[o as usize]);
                    current_object = Some(o);
                }
            }
            let material = default_material
                .unwrap_or_else(|| materials.index(b, reflectance.get(first), emission.get(first)));
            b.polygon(polygon, material, origin);
        };
        match ids {
            None => {
                for k in 0..m {
                    add(&mut b, k, &corners(k), format!("triangle {k}"));
                }
            }
            Some(ids) => {
                let order = by_patch(ids);
                for group in order.chunk_by(|&a, &b| ids[a] == ids[b]) {
                    let id = ids[group[0]];
                    shared(
                        group,
                        |t| reflectance.get(t).map(f64::to_bits),
                        "reflectance",
                        id,
                    )?;
                    shared(group, |t| emission.get(t).map(f64::to_bits), "emission", id)?;
                    if let Some((_, codes)) = &objects {
                        shared(group, |t| codes[t], "objects", id)?;
                    }
                    let tris: Vec<[u32; 3]> = group.iter().map(|&t| corners(t)).collect();
                    let polygon = outline(&tris).ok_or_else(|| {
                        scene_error(format!(
                            "{name}: patch {id}: its {} triangles are not one polygon (pieces \
                             apart, a hole, or corners that touch); a patch is a planar polygon",
                            group.len()
                        ))
                    })?;
                    add(&mut b, group[0], &polygon, format!("patch {id}"));
                }
            }
        }
        let scene = py
            .allow_threads(|| scene_complexity::read_guarded(name, || b.build_with(&options)))
            .map_err(scene_error)?;
        let scene = Scene::new(scene, options);
        scene.warn(py)?;
        Ok(scene)
    }

    /// A scene from a trimesh ``Trimesh`` (its vertices and faces; each face a patch) or ``Scene``
    /// (every geometry placed by its transform, each node an object). Needs trimesh installed.
    ///
    /// Args:
    ///     mesh: a ``trimesh.Trimesh`` or ``trimesh.Scene``.
    ///     name: the scene's name (default: the mesh's own, or ``"<trimesh>"``).
    ///     **kwargs: the other arguments of :meth:`from_arrays` (``reflectance``, ``two_sided``, ...).
    #[staticmethod]
    #[pyo3(signature = (mesh, *, name=None, **kwargs))]
    fn from_trimesh(
        py: Python<'_>,
        mesh: &Bound<'_, PyAny>,
        name: Option<&str>,
        kwargs: Option<&Bound<'_, pyo3::types::PyDict>>,
    ) -> PyResult<Py<PyAny>> {
        let helper = py.import("scx._trimesh")?.getattr("from_trimesh")?;
        Ok(helper.call((mesh, name), kwargs)?.unbind())
    }

    /// The scene's name (a file path as given, a built-in's name, or the name given to
    /// :meth:`from_arrays`).
    #[getter]
    fn name(&self) -> &str {
        &self.inner.name
    }

    /// The number of patches ``n_p``.
    #[getter]
    fn patch_count(&self) -> usize {
        self.inner.patch_count()
    }

    /// The number of triangles.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.inner.triangles.len()
    }

    /// Each patch's area in the scene's units, ``(n_p,)`` float.
    #[getter]
    fn areas<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let s = self.inner.normalization.scale;
        let areas: Vec<f64> = self.inner.patches.iter().map(|p| p.area * s * s).collect();
        areas.into_pyarray(py)
    }

    /// Each patch's unit normal (its front side), ``(n_p, 3)`` float.
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let normals: Vec<Vec<f64>> = self
            .inner
            .patches
            .iter()
            .map(|p| p.normal.to_array().to_vec())
            .collect();
        Ok(PyArray2::from_vec2(py, &normals)?)
    }

    /// The total area in the scene's units.
    #[getter]
    fn area(&self) -> f64 {
        self.inner.total_area_scene_units()
    }

    /// The scene's vertices in its own units, ``(n, 3)`` float (welded: vertices at one position are
    /// one, unused ones dropped).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat: Vec<f64> = self
            .inner
            .vertices
            .iter()
            .flat_map(|p| p.to_array())
            .collect();
        flat.into_pyarray(py)
            .reshape([self.inner.vertices.len(), 3])
    }

    /// The scene's triangles as indices into :attr:`vertices`, ``(t, 3)`` int64, each patch's
    /// triangles together.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let flat: Vec<i64> = self
            .inner
            .triangles
            .iter()
            .flat_map(|t| t.map(i64::from))
            .collect();
        flat.into_pyarray(py)
            .reshape([self.inner.triangles.len(), 3])
    }

    /// The patch of each of :attr:`triangles`, ``(t,)`` int64.
    #[getter]
    fn triangle_patch<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let v: Vec<i64> = self
            .inner
            .triangle_patch
            .iter()
            .map(|&p| i64::from(p))
            .collect();
        v.into_pyarray(py)
    }

    /// The names of the scene's objects (OBJ groups, glTF nodes, ...).
    #[getter]
    fn objects(&self) -> Vec<String> {
        self.inner.objects.clone()
    }

    /// The object of each patch, as an index into :attr:`objects`, ``(n_p,)`` int64.
    #[getter]
    fn patch_object<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let v: Vec<i64> = self
            .inner
            .patches
            .iter()
            .map(|p| i64::from(p.object))
            .collect();
        v.into_pyarray(py)
    }

    /// What loading found wrong but not fatal (dropped zero-area triangles, split polygons, ...).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner
            .warnings
            .iter()
            .map(|w| w.message.clone())
            .collect()
    }

    /// A SHA-256 fingerprint of the geometry and materials (hex): saved runs carry it, and a resume or
    /// merge checks it.
    #[getter]
    fn fingerprint(&self) -> String {
        self.inner.fingerprint()
    }

    /// Writes the scene to ``path`` in the format its extension names: ``.obj`` (with an ``.mtl``),
    /// ``.ply``, ``.stl``, ``.gltf`` or ``.glb`` (the library's ``write_scene``, as ``scx export``).
    ///
    /// Raises:
    ///     SceneError: an unknown extension, or a file that cannot be written.
    fn export(&self, py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<()> {
        let path = path_text(path, "path")?;
        let scene = Arc::clone(&self.inner);
        py.allow_threads(|| write_scene(&scene, std::path::Path::new(&path)))
            .map_err(scene_error)
    }

    fn __len__(&self) -> usize {
        self.inner.patch_count()
    }

    fn __repr__(&self) -> String {
        format!(
            "<scx.Scene {:?}: {} patches, {} triangles, area {}>",
            self.inner.name,
            self.inner.patch_count(),
            self.inner.triangles.len(),
            short(self.inner.total_area_scene_units())
        )
    }
}

/// A number to 6 significant digits.
fn short(x: f64) -> String {
    let s = format!("{x:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

fn reflectance_is_default(r: &PerTriangle) -> bool {
    matches!(r, PerTriangle::All(c) if *c == [Material::default().reflectance; 3])
}

fn is_zero(e: &PerTriangle) -> bool {
    matches!(e, PerTriangle::All(c) if *c == [0.0; 3])
}
