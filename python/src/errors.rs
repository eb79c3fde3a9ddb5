//! The library's errors as Python exceptions, with the library's messages.

use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::PyErr;

use scene_complexity::{AnalysisError, PersistError};

pyo3::create_exception!(
    scx,
    SceneError,
    PyValueError,
    "A scene that cannot be read or built: a bad file, a bad built-in name, bad arrays (shapes, \
     non-finite coordinates, indices out of range). A ValueError; its message is the library's."
);

/// A scene error (the library's, or found in the arrays).
pub fn scene_error(message: impl ToString) -> PyErr {
    SceneError::new_err(message.to_string())
}

/// A bad argument.
pub fn bad_argument(message: impl ToString) -> PyErr {
    PyValueError::new_err(message.to_string())
}

/// A state file that cannot be read or written: its contents are bad input (`ValueError`), the file
/// system's refusal an `OSError`.
pub fn persist_error(e: PersistError) -> PyErr {
    if e.is_bad_input() {
        PyValueError::new_err(e.to_string())
    } else {
        PyOSError::new_err(e.to_string())
    }
}

/// An analysis that failed: bad materials are a scene error, a tracer failure a `RuntimeError`.
pub fn analysis_error(e: AnalysisError) -> PyErr {
    if e.is_bad_input() {
        scene_error(e)
    } else {
        PyRuntimeError::new_err(e.to_string())
    }
}

/// A failure of the machinery (a tracer, a thread pool): not the caller's input.
pub fn runtime_error(message: impl ToString) -> PyErr {
    PyRuntimeError::new_err(message.to_string())
}
