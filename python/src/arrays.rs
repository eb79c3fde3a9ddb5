//! numpy arrays in and out: checked for kind and shape before their numbers are read, so that a wrong
//! array is a `SceneError` naming it and never a panic.

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::args::repr;
use crate::errors::scene_error;

/// `obj` as a numpy array (a view when it is one already), or a `SceneError` naming `what`.
fn as_array<'py>(
    py: Python<'py>,
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyAny>> {
    py.import("numpy")?
        .call_method1("asarray", (obj,))
        .map_err(|e| scene_error(format!("{what} is not an array of numbers ({e})")))
}

/// The kind of an array's dtype: `f` float, `i`/`u` integer, `b` bool, `U`/`O` text and objects, ...
fn kind(array: &Bound<'_, PyAny>) -> PyResult<char> {
    let k: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    Ok(k.chars().next().unwrap_or('?'))
}

/// The shape of an array, as a reader writes it: `(5, 2)`.
fn shape_text(array: &Bound<'_, PyAny>) -> String {
    array
        .getattr("shape")
        .map(|s| repr(&s))
        .unwrap_or_else(|_| "?".into())
}

/// Converts a checked array to a C-contiguous one of `dtype` (no copy when it is one already).
fn contiguous<'py>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    dtype: &str,
) -> PyResult<Bound<'py, PyAny>> {
    py.import("numpy")?
        .call_method1("ascontiguousarray", (array, dtype))
}

/// Checks an array's number of dimensions and, for a matrix, its number of columns.
fn check_shape(
    array: &Bound<'_, PyAny>,
    what: &str,
    expected: &str,
    ndim: usize,
    columns: Option<usize>,
) -> PyResult<()> {
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    let ok = shape.len() == ndim && columns.is_none_or(|c| shape.get(1) == Some(&c));
    if !ok {
        return Err(scene_error(format!(
            "{what} must have shape {expected}, not {}",
            shape_text(array)
        )));
    }
    Ok(())
}

/// An `(n, columns)` array of floats (integers are converted), read-only.
pub fn floats2<'py>(
    py: Python<'py>,
    obj: &Bound<'py, PyAny>,
    what: &str,
    columns: usize,
) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let a = as_array(py, obj, what)?;
    let k = kind(&a)?;
    if !matches!(k, 'f' | 'i' | 'u') {
        return Err(scene_error(format!(
            "{what} must hold real numbers, not {} (dtype {})",
            kind_name(k),
            a.getattr("dtype").map(|d| repr(&d)).unwrap_or_default()
        )));
    }
    check_shape(&a, what, &format!("(n, {columns})"), 2, Some(columns))?;
    let c = contiguous(py, &a, "float64")?;
    Ok(c.downcast_into::<PyArray2<f64>>()?.readonly())
}

/// An `(m, columns)` array of integers, read-only.
pub fn ints2<'py>(
    py: Python<'py>,
    obj: &Bound<'py, PyAny>,
    what: &str,
    columns: usize,
) -> PyResult<PyReadonlyArray2<'py, i64>> {
    let a = as_array(py, obj, what)?;
    check_integers(&a, what)?;
    check_shape(&a, what, &format!("(m, {columns})"), 2, Some(columns))?;
    let c = contiguous(py, &a, "int64")?;
    Ok(c.downcast_into::<PyArray2<i64>>()?.readonly())
}

/// An `(m,)` array of integers, read-only.
pub fn ints1<'py>(
    py: Python<'py>,
    obj: &Bound<'py, PyAny>,
    what: &str,
    expected: &str,
) -> PyResult<PyReadonlyArray1<'py, i64>> {
    let a = as_array(py, obj, what)?;
    check_integers(&a, what)?;
    check_shape(&a, what, expected, 1, None)?;
    let c = contiguous(py, &a, "int64")?;
    Ok(c.downcast_into::<PyArray1<i64>>()?.readonly())
}

/// Refuses an array that does not hold integers (floats such as `1.0` included: an index is a whole
/// number by its type, not by luck); an unsigned array beyond `i64` would not convert.
fn check_integers(a: &Bound<'_, PyAny>, what: &str) -> PyResult<()> {
    let k = kind(a)?;
    if !matches!(k, 'i' | 'u') {
        return Err(scene_error(format!(
            "{what} must hold integers, not {} (dtype {})",
            kind_name(k),
            a.getattr("dtype").map(|d| repr(&d)).unwrap_or_default()
        )));
    }
    Ok(())
}

fn kind_name(k: char) -> &'static str {
    match k {
        'f' => "floats",
        'b' => "booleans",
        'c' => "complex numbers",
        'U' | 'S' => "text",
        'O' => "Python objects",
        'M' | 'm' => "dates or times",
        _ => "values of another kind",
    }
}

/// Per-triangle values: a scalar (every triangle), an `(m,)` array (grey) or an `(m, 3)` array (RGB),
/// each finite; as one RGB triple per triangle, or one for all.
pub enum PerTriangle {
    /// The same triple for every triangle.
    All([f64; 3]),
    /// One triple per triangle.
    Each(Vec<[f64; 3]>),
}

impl PerTriangle {
    /// Triangle `t`'s triple.
    pub fn get(&self, t: usize) -> [f64; 3] {
        match self {
            PerTriangle::All(c) => *c,
            PerTriangle::Each(v) => v[t],
        }
    }
}

/// Reads `obj` as per-triangle values for `m` triangles (see [`PerTriangle`]).
pub fn per_triangle(
    py: Python<'_>,
    obj: &Bound<'_, PyAny>,
    what: &str,
    m: usize,
) -> PyResult<PerTriangle> {
    let a = as_array(py, obj, what)?;
    let k = kind(&a)?;
    if !matches!(k, 'f' | 'i' | 'u') {
        return Err(scene_error(format!(
            "{what} must hold real numbers, not {}",
            kind_name(k)
        )));
    }
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    let c = contiguous(py, &a, "float64")?;
    let expected = || {
        scene_error(format!(
            "{what} must be a number, or have shape ({m},) or ({m}, 3) (one value or RGB triple per \
             triangle), not {}",
            shape_text(&a)
        ))
    };
    let values: Vec<f64> = match shape.as_slice() {
        [] => vec![a
            .call_method1("astype", ("float64",))?
            .call_method0("item")?
            .extract::<f64>()?],
        [n] if *n == m => c
            .downcast::<PyArray1<f64>>()?
            .readonly()
            .as_slice()?
            .to_vec(),
        [n, 3] if *n == m => c
            .downcast::<PyArray2<f64>>()?
            .readonly()
            .as_slice()?
            .to_vec(),
        _ => return Err(expected()),
    };
    if let Some(k) = values.iter().position(|x| !x.is_finite()) {
        let t = if shape.len() == 2 { k / 3 } else { k };
        return Err(scene_error(format!(
            "{what}[{t}] is not finite ({})",
            values[k]
        )));
    }
    Ok(match shape.len() {
        0 => PerTriangle::All([values[0]; 3]),
        1 => PerTriangle::Each(values.iter().map(|&x| [x; 3]).collect()),
        _ => PerTriangle::Each(values.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()),
    })
}
