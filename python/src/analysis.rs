//! `scx.Analysis`: what a run found, each measure of the library's catalogue a [`Reading`] with its
//! standard error and verdict.

use pyo3::exceptions::{PyAttributeError, PyKeyError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use numpy::{IntoPyArray, PyArray1};
use scene_complexity::report::{
    self, object_table, patch_table, Context, FormFactors, Table, Values,
};
use scene_complexity::{
    Estimate, Family, LineBound, Measure, RadiosityOutcome, Reliability, RunIdentity, RunState,
    Shard, StopReason, Tracing,
};

use crate::errors::{bad_argument, persist_error};
use crate::scene::{path_text, Scene};

/// One entry of the catalogue of measures (``scx.MEASURES``, ``scx.RADIOSITY_MEASURES``).
#[pyclass(module = "scx", frozen, get_all)]
pub struct MeasureInfo {
    /// The key (``"continuous_mutual_information"``): the JSON key of the command line's report.
    pub key: String,
    /// ``"visibility"`` (paper sec. 3) or ``"radiosity"`` (sec. 4).
    pub family: String,
    /// What the report's table calls it.
    pub label: String,
    /// Its symbol (``"I_s^c"``).
    pub symbol: String,
    /// Its unit (``"bit"``, ``"ratio"``, ...).
    pub unit: String,
    /// Where the paper defines it (``"eq. 27"``).
    pub equation: String,
    /// The key of the plug-in reading this one corrects for bias, if it is a corrected reading.
    pub corrects: Option<String>,
    /// Whether a precision target (``target_stderr``) can watch it.
    pub target: bool,
}

#[pymethods]
impl MeasureInfo {
    fn __repr__(&self) -> String {
        format!(
            "<scx.MeasureInfo {}: {} [{}], {}>",
            self.key, self.label, self.unit, self.equation
        )
    }
}

/// The catalogue of one family, key to [`MeasureInfo`], in report order.
pub fn catalogue(py: Python<'_>, family: Family) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    for m in Measure::of_family(family) {
        let i = m.info();
        let info = MeasureInfo {
            key: i.key.into(),
            family: family.name().into(),
            label: i.label.into(),
            symbol: i.symbol.into(),
            unit: i.unit.name().into(),
            equation: i.equation.into(),
            corrects: i.corrects.map(|c| c.key().to_string()),
            target: i.target,
        };
        d.set_item(i.key, info)?;
    }
    Ok(d)
}

/// A measure's reading: its value, standard error and reliability verdict (and, for a plug-in reading
/// with a bias-corrected one, that reading as :attr:`corrected`). ``float(reading)`` is its value.
#[pyclass(module = "scx", frozen, get_all)]
pub struct Reading {
    /// The measure's key.
    pub key: String,
    /// ``"visibility"`` or ``"radiosity"``.
    pub family: String,
    /// What the report's table calls it.
    pub label: String,
    /// Its unit.
    pub unit: String,
    /// The value.
    pub value: f64,
    /// Its standard error (``None`` when it cannot be estimated; 0 for an exact value).
    pub stderr: Option<f64>,
    /// ``"ok"``, ``"undersampled"`` or ``"unusable"`` (``None`` for an exact reading): whether its
    /// standard error covers its error (docs/results.md, "Reading the reliability verdict").
    pub verdict: Option<String>,
    /// The estimated bias (``None``: not estimated).
    pub estimated_bias: Option<f64>,
    /// Roughly how many lines in all would make it ``ok`` (``None``: not estimated, or ok).
    pub lines_needed: Option<u64>,
    /// The bounds of the theory it breaks, as sentences.
    pub flags: Vec<String>,
    /// The 95% interval (Student's t over the groups), or ``None``.
    pub interval_95: Option<(f64, f64)>,
    /// The bias-corrected reading of the same measure, where the catalogue has one.
    pub corrected: Option<Py<Reading>>,
}

#[pymethods]
impl Reading {
    fn __float__(&self) -> f64 {
        self.value
    }

    fn __repr__(&self) -> String {
        let se = self
            .stderr
            .map_or_else(|| " (no stderr)".to_string(), |s| format!(" ± {s:.4}"));
        let verdict = self
            .verdict
            .as_ref()
            .map_or(String::new(), |v| format!(", {v}"));
        format!(
            "<scx.Reading {}: {:.6}{se} {}{verdict}>",
            self.key, self.value, self.unit
        )
    }
}

/// How a run ran, beside what it found: not part of its numbers.
#[derive(Clone, Copy, Debug)]
pub struct RunFacts {
    /// The tracer the report names: the one that cast the lines (for a merge, the states' own, as
    /// `scx merge` reports).
    pub tracing: Tracing,
    pub threads: usize,
    pub build_seconds: f64,
    /// The shard the report names (`scx merge` names none).
    pub shard: Option<Shard>,
}

/// The results of a run (:func:`scx.analyze`, :func:`scx.resume`, :func:`scx.merge`).
///
/// Each measure of ``scx.MEASURES`` by key or as an attribute, a :class:`Reading` (``None`` when the
/// run did not compute it): ``analysis["continuous_mutual_information"]``,
/// ``analysis.mutual_information.corrected``; the radiosity measures in :attr:`radiosity`.
#[pyclass(module = "scx", frozen)]
pub struct Analysis {
    pub inner: scene_complexity::Analysis,
    pub scene: Py<Scene>,
    pub identity: RunIdentity,
    /// The run's state, for :meth:`Analysis.save` (``None`` when it was not kept).
    pub state: Option<RunState>,
    pub facts: RunFacts,
}

impl Analysis {
    /// The per-patch table, or why there is none.
    fn patch_table(&self) -> PyResult<Table> {
        let patches = self.inner.patches.as_ref().ok_or_else(|| {
            bad_argument(
                "this analysis has no per-patch results: run it with per_patch=True (not with \
                 enclose=True, and with the discrete measures)",
            )
        })?;
        Ok(patch_table(&self.scene.get().inner, patches))
    }

    /// The form-factor matrix, or why there is none.
    fn form_factor_entries_of(&self) -> PyResult<FormFactors> {
        let n = self.scene.get().inner.patch_count();
        FormFactors::of(&self.inner, n).ok_or_else(|| {
            bad_argument(
                "no form factors: the run counted no patch pairs (measures without discrete)",
            )
        })
    }

    /// The reading of `measure`, with its corrected reading beside it.
    fn reading(&self, py: Python<'_>, measure: Measure) -> PyResult<Option<Reading>> {
        let Some(e) = self.inner.estimate(measure) else {
            return Ok(None);
        };
        let corrected = match measure.corrected() {
            Some(c) => self.reading(py, c)?.map(|r| Py::new(py, r)).transpose()?,
            None => None,
        };
        Ok(Some(reading_of(
            measure,
            e,
            self.inner.reliability.get(measure),
            self.inner.interval_quantile(),
            corrected,
        )))
    }

    /// The visibility measure with key `key`.
    fn visibility(key: &str) -> Option<Measure> {
        Measure::of_family(Family::Visibility).find(|m| m.key() == key)
    }
}

fn reading_of(
    measure: Measure,
    e: Estimate,
    r: Option<&Reliability>,
    quantile: f64,
    corrected: Option<Py<Reading>>,
) -> Reading {
    let info = measure.info();
    Reading {
        key: info.key.into(),
        family: info.family.name().into(),
        label: info.label.into(),
        unit: info.unit.name().into(),
        value: e.value,
        stderr: e.stderr,
        verdict: r.map(|r| r.verdict.name().to_string()),
        estimated_bias: r.and_then(|r| r.estimated_bias),
        lines_needed: r.and_then(|r| r.lines_needed),
        flags: r.map(|r| r.flags.clone()).unwrap_or_default(),
        interval_95: e
            .interval(quantile)
            .filter(|(lo, hi)| lo.is_finite() && hi.is_finite()),
        corrected,
    }
}

#[pymethods]
impl Analysis {
    /// The reading of the visibility measure ``key`` (a key of ``scx.MEASURES``), or ``None`` when
    /// the run did not compute it.
    ///
    /// Raises:
    ///     KeyError: ``key`` is not a measure's.
    fn __getitem__(&self, py: Python<'_>, key: &str) -> PyResult<Option<Reading>> {
        let m = Analysis::visibility(key).ok_or_else(|| {
            PyKeyError::new_err(format!("{key:?} is not a measure; scx.MEASURES lists them"))
        })?;
        self.reading(py, m)
    }

    fn __getattr__(&self, py: Python<'_>, name: &str) -> PyResult<Option<Reading>> {
        match Analysis::visibility(name) {
            Some(m) => self.reading(py, m),
            None => Err(PyAttributeError::new_err(format!(
                "'Analysis' object has no attribute {name:?}"
            ))),
        }
    }

    fn __contains__(&self, key: &str) -> bool {
        Analysis::visibility(key).is_some_and(|m| self.inner.estimate(m).is_some())
    }

    /// The keys of the visibility measures the run computed, in report order.
    fn keys(&self) -> Vec<&'static str> {
        Measure::of_family(Family::Visibility)
            .filter(|&m| self.inner.estimate(m).is_some())
            .map(Measure::key)
            .collect()
    }

    /// Every computed visibility reading, key to :class:`Reading`.
    fn readings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for m in Measure::of_family(Family::Visibility) {
            if let Some(r) = self.reading(py, m)? {
                d.set_item(m.key(), r)?;
            }
        }
        Ok(d)
    }

    /// The radiosity measures (paper sec. 4), key to :class:`Reading` (keys of
    /// ``scx.RADIOSITY_MEASURES``); ``None`` when they were not computed (nothing emits, or not
    /// asked for): :attr:`radiosity_skipped` says why.
    #[getter]
    fn radiosity<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        if !matches!(self.inner.radiosity, RadiosityOutcome::Computed(_)) {
            return Ok(None);
        }
        let d = PyDict::new(py);
        for m in Measure::of_family(Family::Radiosity) {
            if let Some(r) = self.reading(py, m)? {
                d.set_item(m.key(), r)?;
            }
        }
        Ok(Some(d))
    }

    /// Why the radiosity measures are missing (``None`` when computed).
    #[getter]
    fn radiosity_skipped(&self) -> Option<String> {
        match &self.inner.radiosity {
            RadiosityOutcome::Computed(_) => None,
            RadiosityOutcome::NotRequested => Some("not requested".into()),
            RadiosityOutcome::Skipped(reason) => Some(reason.clone()),
        }
    }

    /// The scene analysed.
    #[getter]
    fn scene(&self, py: Python<'_>) -> Py<Scene> {
        self.scene.clone_ref(py)
    }

    /// Lines cast: drawn through the bound of :attr:`lines_through`.
    #[getter]
    fn lines(&self) -> u64 {
        self.inner.lines
    }

    /// What the lines cast are worth in lines through the bounding sphere, the unit of ``lines=``
    /// (the count asked, when the run cast them all): as many as :attr:`lines` through the sphere, more
    /// through a box or polytope smaller than it.
    #[getter]
    fn sphere_lines(&self) -> u64 {
        let scene = &self.scene.get().inner;
        scene_complexity::sphere_lines_of_drawn(scene, self.inner.spec.bound, self.inner.lines)
    }

    /// Where the lines were drawn: ``"sphere"``, ``"box"`` or ``"polytope"``.
    #[getter]
    fn lines_through(&self) -> &'static str {
        self.inner.spec.bound.name()
    }

    /// The seed of the line streams.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.spec.seed
    }

    /// Wall-clock seconds of tracing, counting and measuring (summed over resumes and merged parts).
    #[getter]
    fn seconds(&self) -> f64 {
        self.inner.seconds
    }

    /// Why the run ended: ``"lines"``, ``"seconds"``, ``"target_stderr"`` or ``"interrupted"``.
    #[getter]
    fn stop_reason(&self) -> &'static str {
        self.inner.stop_reason.name()
    }

    /// Whether the analysis covers every batch of its run (not so for a partial merge).
    #[getter]
    fn complete(&self) -> bool {
        self.inner.is_complete()
    }

    /// The standard-error groups.
    #[getter]
    fn groups(&self) -> usize {
        self.inner.groups
    }

    /// Visible pairs found.
    #[getter]
    fn pairs(&self) -> u64 {
        self.inner.pairs
    }

    /// Segments escaping from a front side (0 in a closed scene).
    #[getter]
    fn escapes(&self) -> u64 {
        self.inner.escapes
    }

    /// The fraction of the segments leaving a front side that escape (``None`` without segments).
    #[getter]
    fn escape_fraction(&self) -> Option<f64> {
        self.inner.escape_fraction()
    }

    /// What the user must know about these numbers (an open scene, unsampled patches, ...).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner
            .warnings
            .iter()
            .map(|w| w.message.clone())
            .collect()
    }

    /// Whether the run gathered the per-patch results (``analyze(..., per_patch=True)``).
    #[getter]
    fn has_patches(&self) -> bool {
        self.inner.patches.is_some()
    }

    /// The run's settings, as its saved state keeps them (seed, lines, groups, estimator, ...).
    #[getter]
    fn spec<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = serde_json::to_string(&self.identity.spec)
            .map_err(|e| crate::errors::runtime_error(e.to_string()))?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The report as a dict: the document of ``scx analyze --format json`` (``scx merge`` for a merge)
    /// for the same run, but for the fields of the process (``command_line``, ``cpu``, ``threads``),
    /// which it leaves out; ``seconds`` and ``build_seconds`` are this run's. docs/results.md
    /// describes the fields.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let scene = &self.scene.get().inner;
        let context = Context {
            scene,
            tracing: self.facts.tracing,
            build_seconds: self.facts.build_seconds,
            shard: self.facts.shard,
            process: None,
        };
        let text = serde_json::to_string(&report::json(&context, &self.inner))
            .map_err(|e| crate::errors::runtime_error(e.to_string()))?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The per-patch results as a dict of numpy arrays, one per column of ``scx analyze --patches``
    /// (the same names; docs/per-patch.md lists them with their units): ``id``, ``object``,
    /// ``material``, ``area``, ``centroid_x``, ..., ``segments``, ``row_entropy``,
    /// ``continuous_mutual_information_term``, ... each quantity followed by its ``_stderr``.
    /// Numbers are float64 (NaN where there is none), counts int64, names str. Row ``k`` is the
    /// scene's patch ``k``.
    ///
    /// Raises:
    ///     ValueError: the run gathered no per-patch results (``analyze(..., per_patch=True)``).
    fn patches<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        table_dict(py, &self.patch_table()?, false)
    }

    /// :meth:`patches` as a pandas DataFrame indexed by ``id`` (``object`` and ``material``
    /// categorical). Needs pandas.
    fn patches_frame<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let frame = table_frame(py, &self.patch_table()?)?;
        frame.call_method1("set_index", ("id",))
    }

    /// Each object's results (``scx analyze --objects``) as a dict of numpy arrays: name, patches,
    /// triangles, area, segments, how lines met its sides and, with per-patch results, its share of
    /// each per-patch quantity.
    fn objects<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        table_dict(py, &object_table(&self.inner), false)
    }

    /// :meth:`objects` as a pandas DataFrame indexed by object name. Needs pandas.
    fn objects_frame<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let frame = table_frame(py, &object_table(&self.inner))?;
        frame.call_method1("set_index", ("object",))
    }

    /// The form factors ``F_ij = N_ij / N_i`` (the share of patch i's segments that end on patch j)
    /// and their standard errors ``sqrt(F (1 - F) / N_i)``, as two ``scipy.sparse.csr_matrix`` of
    /// ``n_p x n_p`` with the same entries: the matrix of ``scx analyze --form-factors``. Rows sum to 1
    /// in a closed scene (less what escapes in an open one). Needs scipy.
    ///
    /// Raises:
    ///     ValueError: the run counted no patch pairs (``measures`` without ``discrete``).
    fn form_factors<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let ff = self.form_factor_entries_of()?;
        let n = ff.patches;
        let mut indptr = vec![0i64; n + 1];
        for &(i, _, _) in &ff.entries {
            indptr[i as usize + 1] += 1;
        }
        for k in 0..n {
            indptr[k + 1] += indptr[k];
        }
        let indices: Vec<i64> = ff.entries.iter().map(|&(_, j, _)| i64::from(j)).collect();
        let (values, errors): (Vec<f64>, Vec<f64>) =
            (0..ff.entries.len()).map(|k| ff.value(k)).unzip();
        let sparse = py.import("scipy.sparse").map_err(|e| {
            pyo3::exceptions::PyImportError::new_err(format!(
                "form_factors needs scipy (pip install scipy): {e}"
            ))
        })?;
        let csr = sparse.getattr("csr_matrix")?;
        let indptr = indptr.into_pyarray(py);
        let indices = indices.into_pyarray(py);
        let matrix = |data: Vec<f64>| {
            csr.call1((
                (data.into_pyarray(py), indices.clone(), indptr.clone()),
                (n, n),
            ))
        };
        Ok((matrix(values)?, matrix(errors)?))
    }

    /// The form factors' entries as numpy arrays, the columns of ``scx analyze --form-factors x.csv``:
    /// ``i``, ``j``, ``n_ij``, ``n_i``, ``f_ij``, ``f_ij_stderr`` (sorted by i, then j).
    fn form_factor_entries<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let ff = self.form_factor_entries_of()?;
        let d = PyDict::new(py);
        let column = |f: &dyn Fn(&(u32, u32, u64)) -> i64| -> Bound<'py, PyArray1<i64>> {
            ff.entries
                .iter()
                .map(f)
                .collect::<Vec<i64>>()
                .into_pyarray(py)
        };
        d.set_item("i", column(&|e| i64::from(e.0)))?;
        d.set_item("j", column(&|e| i64::from(e.1)))?;
        d.set_item("n_ij", column(&|e| e.2 as i64))?;
        d.set_item("n_i", column(&|e| ff.row_totals[e.0 as usize] as i64))?;
        let (values, errors): (Vec<f64>, Vec<f64>) =
            (0..ff.entries.len()).map(|k| ff.value(k)).unzip();
        d.set_item("f_ij", values.into_pyarray(py))?;
        d.set_item("f_ij_stderr", errors.into_pyarray(py))?;
        Ok(d)
    }

    /// Saves the run's state to ``path`` (the command line's state file: ``scx merge`` reports it,
    /// :func:`scx.resume` and ``scx analyze --resume`` continue it). Written atomically.
    ///
    /// Raises:
    ///     ValueError: the analysis keeps no state (``analyze(..., keep_state=False)``), or was
    ///         interrupted; ``OSError``: the file cannot be written.
    fn save(&self, py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<()> {
        let path = path_text(path, "path")?;
        let state = self.state.as_ref().ok_or_else(|| {
            bad_argument(
                "this analysis keeps no run state to save: run it with keep_state=True (the \
                 default), or save while it runs (save=PATH)",
            )
        })?;
        let (identity, seconds) = (&self.identity, self.inner.seconds);
        py.allow_threads(|| {
            scene_complexity::save_state(std::path::Path::new(&path), identity, state, seconds)
        })
        .map_err(persist_error)
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let scene = self.scene.get().inner.name.clone();
        let mut parts = Vec::new();
        for m in [
            Measure::ContinuousMutualInformation,
            Measure::MutualInformationCorrected,
        ] {
            if let Some(r) = self.reading(py, m)? {
                let se = r.stderr.map_or(String::new(), |s| format!(" ± {s:.4}"));
                let v = r.verdict.map_or(String::new(), |v| format!(" {v}"));
                parts.push(format!("{} {:.4}{se}{v}", m.info().symbol, r.value));
            }
        }
        let interrupted = if self.inner.stop_reason == StopReason::Interrupted {
            ", interrupted"
        } else {
            ""
        };
        // The lines as `lines=` counts them (through the sphere), and those drawn when they differ.
        let drawn = match self.inner.spec.bound {
            LineBound::Sphere => String::new(),
            bound => format!(" ({} drawn through the {})", self.inner.lines, bound.name()),
        };
        Ok(format!(
            "<scx.Analysis of {scene:?}: {} lines{drawn}, seed {}{interrupted}; {}>",
            self.sphere_lines(),
            self.inner.spec.seed,
            parts.join(", ")
        ))
    }
}

/// A column's values as a numpy array: float64 numbers (NaN for none), int64 counts (float64 with NaN
/// when some are missing), bool flags, and names as str (or, for a frame, a pandas Categorical).
fn column_array<'py>(
    py: Python<'py>,
    values: &Values,
    categorical: bool,
) -> PyResult<Bound<'py, PyAny>> {
    Ok(match values {
        Values::Numbers(v) => v
            .iter()
            .map(|x| x.unwrap_or(f64::NAN))
            .collect::<Vec<f64>>()
            .into_pyarray(py)
            .into_any(),
        Values::Integers(v) if v.iter().all(Option::is_some) => v
            .iter()
            .map(|x| x.unwrap_or_default() as i64)
            .collect::<Vec<i64>>()
            .into_pyarray(py)
            .into_any(),
        Values::Integers(v) => v
            .iter()
            .map(|x| x.map_or(f64::NAN, |n| n as f64))
            .collect::<Vec<f64>>()
            .into_pyarray(py)
            .into_any(),
        Values::Flags(v) => v.clone().into_pyarray(py).into_any(),
        Values::Labels { names, codes } => {
            let codes: Vec<i64> = codes.iter().map(|&c| i64::from(c)).collect();
            let codes = codes.into_pyarray(py);
            if categorical {
                py.import("pandas")?
                    .getattr("Categorical")?
                    .call_method1("from_codes", (codes, names.clone()))?
            } else {
                let names = py
                    .import("numpy")?
                    .call_method1("array", (names.clone(),))?;
                names.get_item(codes)?
            }
        }
    })
}

/// A table as a dict of column name to numpy array.
fn table_dict<'py>(
    py: Python<'py>,
    table: &Table,
    categorical: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for c in &table.columns {
        d.set_item(&c.name, column_array(py, &c.values, categorical)?)?;
    }
    Ok(d)
}

/// A table as a pandas DataFrame (names as categoricals).
fn table_frame<'py>(py: Python<'py>, table: &Table) -> PyResult<Bound<'py, PyAny>> {
    let pandas = py.import("pandas").map_err(|e| {
        pyo3::exceptions::PyImportError::new_err(format!(
            "a DataFrame needs pandas (pip install pandas): {e}"
        ))
    })?;
    let columns = table_dict(py, table, true)?;
    pandas.getattr("DataFrame")?.call1((columns,))
}
