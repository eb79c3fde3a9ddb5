//! `scx._native`: the scene-complexity library from Python (issue 30). The public API is the package
//! `scx` (python/scx/__init__.py), which re-exports what is defined here and adds what is pure Python
//! (tqdm progress, trimesh scenes); python/scx/_native.pyi types it.
//!
//! Every function checks its arguments and arrays before the library sees them, so that bad input is a
//! Python exception (`SceneError`, a `ValueError`, for scenes and arrays; `ValueError` for other
//! arguments) and never a panic across the FFI boundary; the long parts (reading a scene, tracing,
//! measuring, rendering) run with the GIL released.

use pyo3::prelude::*;

mod analysis;
mod args;
mod arrays;
mod errors;
mod picture;
mod run;
mod scene;

/// The module `scx._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<analysis::Analysis>()?;
    m.add_class::<analysis::Reading>()?;
    m.add_class::<analysis::MeasureInfo>()?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(scene::builtins, m)?)?;
    m.add_function(wrap_pyfunction!(run::analyze, m)?)?;
    m.add_function(wrap_pyfunction!(run::resume, m)?)?;
    m.add_function(wrap_pyfunction!(run::merge, m)?)?;
    m.add_function(wrap_pyfunction!(picture::render, m)?)?;
    m.add(
        "MEASURES",
        analysis::catalogue(py, scene_complexity::Family::Visibility)?,
    )?;
    m.add(
        "RADIOSITY_MEASURES",
        analysis::catalogue(py, scene_complexity::Family::Radiosity)?,
    )?;
    m.add("COLORS", picture::colour_names())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("TRACER", "rust")?;
    Ok(())
}
