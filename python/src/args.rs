//! The arguments of the Python functions, checked and turned into the library's types with the same
//! ranges and words as the command line's flags (src/cli/args.rs): a bad one is a `ValueError` saying
//! what is allowed.

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyString};

use scene_complexity::{
    EntropyEstimator, ErrorMethod, LineSource, LinesThrough, Measure, Measures, ObjectSet,
    Planarity, Reach, ReadPolicy, SamplerChoice, SceneOptions, DEFAULT_PLANARITY, MAX_BUNDLE_GRID,
};

use crate::errors::bad_argument;

/// The largest count any argument takes (lines, seeds), as on the command line: exact in an f64.
pub const MAX_WHOLE: u64 = 1_000_000_000_000_000;

/// The most worker threads a run may ask for (the command line's bound).
const MAX_THREADS: u64 = 4096;

/// A bound as a reader writes it.
fn shown(n: u64) -> String {
    if n == MAX_WHOLE {
        "1e15".into()
    } else {
        n.to_string()
    }
}

/// A whole number given as a Python int or an integral float (`1e6`), within `[min, max]`; `what`
/// names it in the message, which gives the range.
pub fn whole(value: &Bound<'_, PyAny>, what: &str, min: u64, max: u64) -> PyResult<u64> {
    let range = || {
        bad_argument(format!(
            "{what} must be a whole number from {} to {}, not {}",
            shown(min),
            shown(max),
            repr(value)
        ))
    };
    if value.is_instance_of::<PyBool>() {
        return Err(range());
    }
    let n = if value.is_instance_of::<PyInt>() {
        value.extract::<i128>().map_err(|_| range())?
    } else if value.is_instance_of::<PyFloat>() {
        let x: f64 = value.extract()?;
        if !(x.is_finite() && x.fract() == 0.0 && x.abs() <= 1e18) {
            return Err(range());
        }
        x as i128
    } else {
        // numpy's integers and floats, and anything else that says it is a number.
        match value.call_method0("__index__") {
            Ok(i) => i.extract::<i128>().map_err(|_| range())?,
            Err(_) => return Err(range()),
        }
    };
    if n < i128::from(min) || n > i128::from(max) {
        return Err(range());
    }
    Ok(n as u64)
}

/// A number given as a Python int or float (numpy's too), finite.
pub fn number(value: &Bound<'_, PyAny>, what: &str) -> PyResult<f64> {
    let bad = || bad_argument(format!("{what} must be a number, not {}", repr(value)));
    if value.is_instance_of::<PyBool>() || value.is_instance_of::<PyString>() {
        return Err(bad());
    }
    let x: f64 = value.extract().map_err(|_| bad())?;
    if !x.is_finite() {
        return Err(bad_argument(format!("{what} must be finite, not {x}")));
    }
    Ok(x)
}

/// A positive number (seconds, a standard error).
pub fn positive(value: &Bound<'_, PyAny>, what: &str) -> PyResult<f64> {
    let x = number(value, what)?;
    if x <= 0.0 {
        return Err(bad_argument(format!(
            "{what} must be a positive number, not {x}"
        )));
    }
    Ok(x)
}

/// `repr(value)`, shortened for a message.
pub fn repr(value: &Bound<'_, PyAny>) -> String {
    let text = value
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".into());
    if text.chars().count() > 60 {
        let short: String = text.chars().take(57).collect();
        format!("{short}...")
    } else {
        text
    }
}

/// A line count: a whole number from 1 to 1e15.
pub fn lines(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole(value, "lines", 1, MAX_WHOLE)
}

/// A seed: a whole number from 0 to 1e15.
pub fn seed(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole(value, "seed", 0, MAX_WHOLE)
}

/// Worker threads: 0 (every core) to 4096; the number the run uses.
pub fn threads(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    let n = whole(value, "threads (0: all cores)", 0, MAX_THREADS)? as usize;
    Ok(if n > 0 {
        n
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    })
}

/// Standard-error groups: 2 to 1024.
pub fn groups(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    Ok(whole(value, "groups", 2, 1024)? as usize)
}

/// Lines per side of a bundle (0: independent lines).
pub fn bundle(value: &Bound<'_, PyAny>) -> PyResult<LineSource> {
    let g = whole(
        value,
        "bundle (0: independent lines)",
        0,
        u64::from(MAX_BUNDLE_GRID),
    )?;
    LineSource::bundles(g as u32).map_err(bad_argument)
}

/// The measure families asked for: `None` for all, else a list of `discrete`, `continuous`,
/// `radiosity` (a single name is a list of one).
pub fn measures(value: Option<&Bound<'_, PyAny>>) -> PyResult<Measures> {
    let Some(value) = value.filter(|v| !v.is_none()) else {
        return Ok(Measures::ALL);
    };
    let names: Vec<String> = if let Ok(one) = value.extract::<String>() {
        vec![one]
    } else {
        value.extract().map_err(|_| {
            bad_argument(format!(
                "measures must be a list of `discrete`, `continuous`, `radiosity`, not {}",
                repr(value)
            ))
        })?
    };
    let mut m = Measures {
        discrete: false,
        continuous: false,
        radiosity: false,
    };
    for name in &names {
        match name.as_str() {
            "discrete" => m.discrete = true,
            "continuous" => m.continuous = true,
            "radiosity" => m.radiosity = true,
            other => {
                return Err(bad_argument(format!(
                    "measures: `{other}` is not one of discrete, continuous, radiosity"
                )))
            }
        }
    }
    if names.is_empty() {
        return Err(bad_argument(
            "measures is empty: name at least one of discrete, continuous, radiosity (None: all)",
        ));
    }
    Ok(m)
}

/// The measure a precision target watches, by its key.
pub fn target_measure(key: &str) -> PyResult<Measure> {
    Measure::target_named(key).ok_or_else(|| {
        let keys: Vec<&str> = Measure::targets().map(|m| m.key()).collect();
        bad_argument(format!(
            "target_measure: `{key}` is not one of {}",
            keys.join(", ")
        ))
    })
}

/// Where the lines are drawn, by name (`scx analyze --lines-through`).
pub fn bound(name: &str) -> PyResult<LinesThrough> {
    LinesThrough::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = LinesThrough::NAMES.iter().map(|(n, _)| *n).collect();
        bad_argument(format!(
            "lines_through: `{name}` is not one of {}",
            names.join(", ")
        ))
    })
}

/// A line sampler by name, or `auto` (`scx analyze --sampler`).
pub fn sampler(name: &str) -> PyResult<SamplerChoice> {
    SamplerChoice::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = SamplerChoice::NAMES.iter().map(|(n, _)| *n).collect();
        bad_argument(format!(
            "sampler: `{name}` is not one of {}",
            names.join(", ")
        ))
    })
}

/// An entropy estimator by name.
pub fn estimator(name: &str) -> PyResult<EntropyEstimator> {
    EntropyEstimator::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = EntropyEstimator::ALL.iter().map(|e| e.name()).collect();
        bad_argument(format!(
            "estimator: `{name}` is not one of {}",
            names.join(", ")
        ))
    })
}

/// The standard-error method by name.
pub fn errors(name: &str) -> PyResult<ErrorMethod> {
    ErrorMethod::from_name(name).ok_or_else(|| {
        let names: Vec<&str> = ErrorMethod::NAMES.iter().map(|(n, _)| *n).collect();
        bad_argument(format!(
            "errors: `{name}` is not one of {}",
            names.join(", ")
        ))
    })
}

/// Some objects by name: `False`/`None` none, `True` all, a name or a list of names those.
fn object_set(value: &Bound<'_, PyAny>, what: &str) -> PyResult<ObjectSet> {
    if value.is_none() {
        return Ok(ObjectSet::None);
    }
    if let Ok(b) = value.downcast::<PyBool>() {
        return Ok(if b.is_true() {
            ObjectSet::All
        } else {
            ObjectSet::None
        });
    }
    if let Ok(name) = value.extract::<String>() {
        return Ok(ObjectSet::Named(vec![name]));
    }
    let names: Vec<String> = value.extract().map_err(|_| {
        bad_argument(format!(
            "{what} must be True (every object), False, or a list of object names, not {}",
            repr(value)
        ))
    })?;
    Ok(ObjectSet::Named(names))
}

/// How a scene is read: the command line's `--planarity`, `--strict-planarity`, `--flip-normals`,
/// `--two-sided`.
pub fn scene_options(
    planarity: Option<&Bound<'_, PyAny>>,
    strict_planarity: bool,
    flip_normals: &Bound<'_, PyAny>,
    two_sided: &Bound<'_, PyAny>,
) -> PyResult<SceneOptions> {
    let tolerance = match planarity.filter(|p| !p.is_none()) {
        None => DEFAULT_PLANARITY,
        Some(p) => {
            let t = number(p, "planarity")?;
            if t < 0.0 {
                return Err(bad_argument(format!(
                    "planarity must be a number >= 0 (a fraction of the polygon's size), not {t}"
                )));
            }
            t
        }
    };
    Ok(SceneOptions {
        planarity: Planarity {
            tolerance,
            strict: strict_planarity,
        },
        flip_normals: object_set(flip_normals, "flip_normals")?,
        two_sided: object_set(two_sided, "two_sided")?,
    })
}

/// What reading a scene file may touch: `read_anywhere` lets its references leave its folder,
/// `max_file_size` bounds every file read (bytes).
pub fn read_policy(
    read_anywhere: bool,
    max_file_size: Option<&Bound<'_, PyAny>>,
) -> PyResult<ReadPolicy> {
    let default = ReadPolicy::default();
    Ok(ReadPolicy {
        reach: if read_anywhere {
            Reach::Anywhere
        } else {
            Reach::SceneFolder
        },
        max_bytes: match max_file_size.filter(|m| !m.is_none()) {
            Some(size) => whole(size, "max_file_size (bytes)", 1, 1_000_000_000_000_000_000)?,
            None => default.max_bytes,
        },
    })
}
