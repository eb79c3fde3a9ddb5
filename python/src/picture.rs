//! `scx.render`: the picture of `scx render` without its colour bar, as a numpy array: the scene seen
//! through a pinhole camera, each patch coloured by a per-patch result through viridis (the library's
//! `render` module: camera, first-hit rays, shading, colour scale), and a PNG when asked.

use std::io::BufWriter;
use std::path::Path;

use numpy::{IntoPyArray, PyArray3, PyArrayMethods};
use pyo3::prelude::*;

use scene_complexity::render::{
    default_camera, noise_summary, trace_view, Camera, ColourScale, Quantity,
};
use scene_complexity::{
    make_tracer, sphere_lines_of_drawn, Backend, PatchMaterials, PatchMeasure, Point, Query, Vector,
};

use crate::analysis::Analysis;
use crate::args::{self, repr};
use crate::errors::{bad_argument, runtime_error, scene_error};
use crate::scene::{path_text, warn_all, Scene};

/// Samples per pixel along each axis (anti-aliasing), as `scx render`.
const SUPERSAMPLING: usize = 2;

/// The colour of every patch of a picture without a quantity: a light grey, shaded by the angle.
const PLAIN: [u8; 3] = [190, 190, 190];

/// The names `color` takes: the quantities of `scx render --color`.
pub fn colour_names() -> Vec<&'static str> {
    Quantity::all().map(Quantity::name).collect()
}

/// The quantity named `name`: `scx render`'s name (`continuous-mutual-information`), with `_` for `-`
/// too, or the per-patch column (`continuous_mutual_information_term`).
fn quantity(name: &str) -> PyResult<Quantity> {
    let dashed = name.replace('_', "-");
    Quantity::from_name(&dashed)
        .or_else(|| {
            PatchMeasure::ALL
                .into_iter()
                .find(|m| m.info().column == name)
                .map(Quantity::Patch)
        })
        .ok_or_else(|| {
            bad_argument(format!(
                "color: `{name}` is not one of {}",
                colour_names().join(", ")
            ))
        })
}

/// A camera from 10 numbers, flat or nested: eye (3), target (3), up (3), vertical field of view in
/// degrees; in the scene's units.
fn camera_of(py: Python<'_>, value: &Bound<'_, PyAny>) -> PyResult<Camera> {
    let bad = |why: String| {
        bad_argument(format!(
            "camera must be (eye, target, up, fov_degrees): 10 numbers in the scene's units, \
             {why}, not {}",
            repr(value)
        ))
    };
    let flat = py
        .import("numpy")?
        .call_method1("asarray", (value, "float64"))
        .and_then(|a| a.call_method0("ravel"))
        .and_then(|a| a.call_method0("tolist"))
        .and_then(|a| a.extract::<Vec<f64>>())
        .map_err(|_| bad("numbers".into()))?;
    if flat.len() != 10 {
        return Err(bad(format!("{} numbers", flat.len())));
    }
    let v = flat;
    let camera = Camera {
        eye: Point::new(v[0], v[1], v[2]),
        target: Point::new(v[3], v[4], v[5]),
        up: Vector::new(v[6], v[7], v[8]),
        fov_degrees: v[9],
    };
    camera
        .validate()
        .map_err(|e| bad_argument(format!("camera: {e}")))?;
    Ok(camera)
}

/// The picture's size: two whole numbers from 16 to 8192.
fn size_of(value: &Bound<'_, PyAny>) -> PyResult<(usize, usize)> {
    let bad = || {
        bad_argument(format!(
            "size must be (width, height) in pixels, not {}",
            repr(value)
        ))
    };
    if value.is_instance_of::<pyo3::types::PyString>() {
        return Err(bad());
    }
    let pair: Vec<Bound<'_, PyAny>> = value.extract().map_err(|_| bad())?;
    let [w, h] = pair.as_slice() else {
        return Err(bad());
    };
    let dim = |d: &Bound<'_, PyAny>, what: &str| args::whole(d, what, 16, 8192);
    Ok((
        dim(w, "the width")? as usize,
        dim(h, "the height")? as usize,
    ))
}

/// Each patch's value of `q`, per unit area fraction when `per_area` (the library's per-patch results;
/// `scx render`'s `patch_values`).
fn values_of(
    a: &Analysis,
    scene: &scene_complexity::Scene,
    q: Quantity,
    per_area: bool,
) -> PyResult<Vec<Option<f64>>> {
    let patches = a.inner.patches.as_ref().ok_or_else(|| {
        bad_argument(
            "this analysis has no per-patch results to colour by: run it with per_patch=True (or \
             pass the scene, which runs one)",
        )
    })?;
    if q.needs_light() {
        let lit = PatchMaterials::of_scene(scene)
            .map_err(scene_error)?
            .any_emission();
        if !lit {
            return Err(bad_argument(format!(
                "{}: color {} needs light, and nothing in this scene emits",
                scene.name,
                q.name()
            )));
        }
    }
    let total = scene.total_area();
    Ok(patches
        .iter()
        .zip(&scene.patches)
        .map(|(p, patch)| {
            let v = q.of(p)?;
            Some(if per_area { v * total / patch.area } else { v })
        })
        .collect())
}

/// The colour scale: `range` when given, else the area quantiles' range (`scx render`'s rules).
fn scale_of(
    values: &[Option<f64>],
    areas: &[f64],
    range: Option<(f64, f64)>,
    log: bool,
    q: Quantity,
) -> PyResult<ColourScale> {
    match range {
        Some((lo, hi)) if !(lo.is_finite() && hi.is_finite() && hi > lo) => Err(bad_argument(
            format!("range must be (low, high) with low < high, not ({lo}, {hi})"),
        )),
        Some((lo, _)) if log && lo <= 0.0 => Err(bad_argument(
            "a logarithmic colour scale needs a positive low end in range",
        )),
        Some((lo, hi)) => Ok(ColourScale { lo, hi, log }),
        None => ColourScale::spanning(values, areas, 0.01, log).ok_or_else(|| {
            bad_argument(format!(
                "no patch has a {}value of {} to show",
                if log { "positive " } else { "" },
                q.name()
            ))
        }),
    }
}

/// Writes RGB pixels as a PNG.
fn write_png(path: &Path, w: usize, h: usize, pixels: &[u8]) -> Result<(), String> {
    let file =
        std::fs::File::create(path).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    let mut encoder = png::Encoder::new(BufWriter::new(file), w as u32, h as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let fail = |e: png::EncodingError| format!("cannot write {}: {e}", path.display());
    let mut writer = encoder.write_header().map_err(fail)?;
    writer.write_image_data(pixels).map_err(fail)?;
    writer.finish().map_err(fail)
}

/// Renders a scene, or the per-patch results of an analysis. See :func:`scx.render`.
#[pyfunction]
#[pyo3(signature = (subject, color=None, *, size=None, camera=None, path=None, threads=None,
                    per_area=false, range=None, scale="auto"))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    subject: &Bound<'py, PyAny>,
    color: Option<&str>,
    size: Option<&Bound<'py, PyAny>>,
    camera: Option<&Bound<'py, PyAny>>,
    path: Option<&Bound<'py, PyAny>>,
    threads: Option<&Bound<'py, PyAny>>,
    per_area: bool,
    range: Option<(f64, f64)>,
    scale: &str,
) -> PyResult<Bound<'py, PyArray3<u8>>> {
    let (scene, analysis) = if let Ok(a) = subject.downcast::<Analysis>() {
        (a.get().scene.clone_ref(py), Some(a.clone()))
    } else if let Ok(s) = subject.downcast::<Scene>() {
        (s.clone().unbind(), None)
    } else {
        return Err(bad_argument(format!(
            "render takes a Scene or an Analysis, not {}",
            repr(subject)
        )));
    };
    let scene = std::sync::Arc::clone(&scene.get().inner);
    let (w, h) = match size.filter(|s| !s.is_none()) {
        Some(s) => size_of(s)?,
        None => (800, 600),
    };
    let path = path
        .filter(|p| !p.is_none())
        .map(|p| path_text(p, "path"))
        .transpose()?;
    if let Some(p) = &path {
        let ext = Path::new(p)
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("");
        if !ext.eq_ignore_ascii_case("png") {
            return Err(bad_argument(format!("{p}: path must name a .png file")));
        }
    }
    let colours: Vec<[u8; 3]> = match color {
        None => vec![PLAIN; scene.patch_count()],
        Some(name) => {
            let q = quantity(name)?;
            if per_area && !q.is_share() {
                return Err(bad_argument(format!(
                    "per_area applies to the shares of a sum over patches, not to {}",
                    q.name()
                )));
            }
            let log = match scale {
                "auto" => q.log_by_default(),
                "linear" => false,
                "log" => true,
                other => {
                    return Err(bad_argument(format!(
                        "scale: `{other}` is not one of auto, linear, log"
                    )))
                }
            };
            let a = analysis.as_ref().ok_or_else(|| {
                bad_argument("color needs an Analysis (scx.render runs one when given a Scene)")
            })?;
            let a = a.get();
            let values = values_of(a, &scene, q, per_area)?;
            let areas: Vec<f64> = scene.patches.iter().map(|p| p.area).collect();
            if let Some(patches) = &a.inner.patches {
                // In lines through the sphere, as `lines=` counts them and the advice gives them.
                let lines = sphere_lines_of_drawn(&scene, a.inner.spec.bound, a.inner.lines);
                let noise = noise_summary(patches, &areas, q, lines);
                if let Some(message) = noise.warning(q.label()) {
                    let message = format!("{}: {message}", scene.name);
                    warn_all(py, std::iter::once(message.as_str()))?;
                }
            }
            let scale = scale_of(&values, &areas, range, log, q)?;
            values.iter().map(|&v| scale.colour(v)).collect()
        }
    };
    let camera = camera
        .filter(|c| !c.is_none())
        .map(|c| camera_of(py, c))
        .transpose()?;
    let threads = match threads.filter(|t| !t.is_none()) {
        Some(t) => args::threads(t)?,
        None => args::threads(&0u8.into_pyobject(py)?.into_any())?,
    };
    let (pw, ph, pixels) = py
        .allow_threads(|| -> Result<_, String> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| format!("cannot start {threads} threads: {e}"))?;
            let tracer =
                make_tracer(Backend::Rust, &scene, Query::Single).map_err(|e| e.to_string())?;
            let camera = match camera {
                Some(c) => c,
                None => default_camera(&scene, tracer.as_ref()).map_err(|e| e.to_string())?,
            };
            let image = pool
                .install(|| {
                    trace_view(
                        &scene,
                        tracer.as_ref(),
                        &camera,
                        w * SUPERSAMPLING,
                        h * SUPERSAMPLING,
                    )
                })
                .map_err(|e| e.to_string())?;
            Ok(image.to_rgb(&colours, SUPERSAMPLING))
        })
        .map_err(runtime_error)?;
    if let Some(p) = &path {
        py.allow_threads(|| write_png(Path::new(p), pw, ph, &pixels))
            .map_err(pyo3::exceptions::PyOSError::new_err)?;
    }
    pixels.into_pyarray(py).reshape([ph, pw, 3])
}
