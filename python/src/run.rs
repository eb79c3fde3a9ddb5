//! `scx.analyze`, `scx.resume` and `scx.merge`: the runs of the command line's `scx analyze` (with
//! `--save`, `--shard`, `--resume`) and `scx merge`, built from the same `RunSpec` and run by the same
//! library calls (src/cli/analyze.rs, src/cli/merge.rs), so that the same spec gives the same numbers
//! to the bit.
//!
//! The work runs on a thread of its own, in a rayon pool of the threads asked for, with the GIL
//! released; the calling thread wakes every [`POLL`] to run Python's signal handlers (Ctrl-C raises
//! `KeyboardInterrupt` there) and the progress callback. A pending exception asks the run to stop
//! (the library finishes the batches under way), then is raised; a run asked to save its state saves
//! what it cast before.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use scene_complexity::{
    cast, finish, make_tracer, remaining_lines, start, Backend, Budget, CastOptions, LineBound,
    LinesThrough, Query, RunControl, RunIdentity, RunSpec, RunState, SceneRef, Scope, Shard,
    StopReason, Target, Tracing,
};

use crate::analysis::{Analysis, RunFacts};
use crate::args;
use crate::errors::{analysis_error, bad_argument, persist_error, runtime_error, scene_error};
use crate::scene::{path_text, read_scene, warn_all, Scene};

/// How often the calling thread looks at Python's signals and calls the progress callback.
const POLL: Duration = Duration::from_millis(50);

/// The tracer of every run from Python: the pure-Rust one (the wheel has no Embree; both give the same
/// hits, `scx crosscheck`).
const TRACING: Tracing = Tracing {
    backend: Backend::Rust,
    query: Query::Single,
};

/// Runs `work` on a scoped thread with the GIL released, while this thread polls Python's signals and
/// calls `progress(done, total)`; a Python exception raised by either asks `control` to stop and is
/// returned beside `work`'s result (which is awaited: the library finishes the batches under way).
fn watched<T: Send>(
    py: Python<'_>,
    control: &RunControl,
    total: Option<u64>,
    progress: Option<&Py<PyAny>>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<(T, Option<PyErr>)> {
    let call = |py: Python<'_>| -> PyResult<()> {
        py.check_signals()?;
        if let Some(p) = progress {
            p.call1(py, (control.lines_started(), total))?;
        }
        Ok(())
    };
    let waiter = std::thread::current();
    let (result, pending) = py.allow_threads(|| {
        std::thread::scope(|s| {
            let handle = s.spawn(|| {
                let out = work();
                waiter.unpark();
                out
            });
            let mut pending: Option<PyErr> = None;
            while !handle.is_finished() {
                std::thread::park_timeout(POLL);
                if pending.is_none() && !handle.is_finished() {
                    if let Err(e) = Python::with_gil(call) {
                        control.request_stop();
                        pending = Some(e);
                    }
                }
            }
            (handle.join(), pending)
        })
    });
    let result =
        result.map_err(|_| runtime_error("scx: internal error (a panic) during the run"))?;
    let pending = match pending {
        Some(e) => Some(e),
        // The last word: the callback sees the run done.
        None => Python::with_gil(call).err(),
    };
    Ok((result, pending))
}

/// A run about to be cast or finished: the scene, its identity and state, and how to run it.
struct Session {
    scene: Py<Scene>,
    identity: RunIdentity,
    /// The spec the analysis is finished with (its `per_patch` as asked now).
    cfg: RunSpec,
    scope: Scope,
    /// Seconds spent on the run before this session.
    before: f64,
    /// Whether lines are cast (not for a merge).
    casts: bool,
    threads: usize,
    save: Option<PathBuf>,
    keep_state: bool,
    /// The tracer and shard its report names (`scx merge` names the states' tracer and no shard).
    report_tracing: Tracing,
    report_shard: Option<Shard>,
}

/// What the worker thread hands back.
enum Outcome {
    Done(Box<Finished>),
    /// Stopped for a Python exception before its analysis (the state saved when asked).
    Stopped {
        saved: Option<PyErr>,
    },
}

/// A run finished: its analysis, its state when kept, and how its save went.
struct Finished {
    analysis: scene_complexity::Analysis,
    state: Option<RunState>,
    build_seconds: f64,
    saved: Option<PyErr>,
}

/// Saves `bytes` to `path`, as a Python error when it fails.
fn save_bytes(path: &Path, bytes: &[u8]) -> Option<PyErr> {
    scene_complexity::save_state_bytes(path, bytes)
        .err()
        .map(persist_error)
}

/// Casts the session's lines (when it casts) and finishes its analysis, on the calling thread's
/// behalf (see [`watched`]).
fn work(
    s: &Session,
    mut state: RunState,
    scene: &scene_complexity::Scene,
    control: &RunControl,
) -> PyResult<Outcome> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(s.threads)
        .build()
        .map_err(|e| runtime_error(format!("cannot start {} threads: {e}", s.threads)))?;
    let building = Instant::now();
    let tracer = if s.casts {
        Some(make_tracer(TRACING.backend, scene, TRACING.query).map_err(scene_error)?)
    } else {
        None
    };
    let build_seconds = building.elapsed().as_secs_f64();
    let began = Instant::now();
    let stop = match &tracer {
        Some(t) => pool
            .install(|| {
                cast(
                    scene,
                    t.as_ref(),
                    &s.cfg,
                    &mut state,
                    CastOptions {
                        scope: s.scope,
                        round_seconds: None,
                    },
                    control,
                    &mut |_| {},
                )
            })
            .map_err(|e| runtime_error(e.to_string()))?,
        None => StopReason::Lines,
    };
    drop(tracer);
    let seconds = s.before + began.elapsed().as_secs_f64();
    let bytes = s
        .save
        .as_ref()
        .map(|_| scene_complexity::encode_state(&s.identity, &state, seconds));
    let saved = match (&s.save, &bytes) {
        (Some(path), Some(bytes)) if control.stop_requested() => save_bytes(path, bytes),
        _ => None,
    };
    if control.stop_requested() {
        return Ok(Outcome::Stopped { saved });
    }
    let kept = s.keep_state.then(|| state.clone());
    let analysis = pool
        .install(|| finish(scene, &s.cfg, state, stop, seconds))
        .map_err(analysis_error)?;
    let saved = match (&s.save, &bytes) {
        (Some(path), Some(bytes)) => save_bytes(path, bytes),
        _ => None,
    };
    Ok(Outcome::Done(Box::new(Finished {
        analysis,
        state: kept,
        build_seconds,
        saved,
    })))
}

/// Runs a session to its analysis, raising the Python exception that stopped it, or a failed save.
fn run_session(
    py: Python<'_>,
    s: Session,
    state: RunState,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Analysis> {
    if let Some(path) = &s.save {
        py.allow_threads(|| scene_complexity::check_state_save(path))
            .map_err(persist_error)?;
    }
    let scene = Arc::clone(&s.scene.get().inner);
    let control = RunControl::default();
    let total =
        (s.casts && !s.cfg.budget.is_open_ended()).then(|| remaining_lines(&state, s.scope));
    let progress = progress
        .filter(|p| !p.is_none())
        .map(|p| p.clone().unbind());
    let (outcome, pending) = watched(py, &control, total, progress.as_ref(), || {
        work(&s, state, &scene, &control)
    })?;
    if let Some(e) = pending {
        let failed = match &outcome {
            Ok(Outcome::Stopped { saved }) => saved.as_ref(),
            Ok(Outcome::Done(f)) => f.saved.as_ref(),
            Err(_) => None,
        };
        if let Some(failed) = failed {
            // The exception is what the caller sees; the failed save goes beside it as a warning.
            warn_all(py, std::iter::once(failed.to_string().as_str()))?;
        }
        return Err(e);
    }
    match outcome? {
        Outcome::Stopped { saved } => {
            Err(saved.unwrap_or_else(|| runtime_error("scx: the run stopped without a reason")))
        }
        Outcome::Done(finished) => {
            let Finished {
                analysis,
                state,
                build_seconds,
                saved,
            } = *finished;
            warn_all(py, analysis.warnings.iter().map(|w| w.message.as_str()))?;
            if let Some(e) = saved {
                return Err(e);
            }
            Ok(Analysis {
                inner: analysis,
                scene: s.scene,
                identity: s.identity,
                state,
                facts: RunFacts {
                    tracing: s.report_tracing,
                    threads: s.threads,
                    build_seconds,
                    shard: s.report_shard,
                },
            })
        }
    }
}

/// A shard `(k, m)`: shard k (from 1) of m.
fn shard_of(value: &Bound<'_, PyAny>) -> PyResult<Shard> {
    let bad = || {
        bad_argument(format!(
            "shard must be a pair (k, m), shard k (from 1) of m, not {}",
            args::repr(value)
        ))
    };
    let t = value.downcast::<PyTuple>().map_err(|_| bad())?;
    if t.len() != 2 {
        return Err(bad());
    }
    let m = args::whole(&t.get_item(1)?, "the shard count m", 1, u64::from(u32::MAX))?;
    let k = args::whole(&t.get_item(0)?, "the shard k", 1, m)?;
    Ok(Shard {
        index: k as u32,
        count: m as u32,
    })
}

/// An optional argument, `None` when left out or given as `None`.
fn given<'py>(v: Option<&Bound<'py, PyAny>>) -> Option<Bound<'py, PyAny>> {
    v.filter(|v| !v.is_none()).cloned()
}

/// An optional path argument.
fn optional_path(value: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Option<PathBuf>> {
    value
        .filter(|v| !v.is_none())
        .map(|v| path_text(v, what).map(PathBuf::from))
        .transpose()
}

/// Analyses a scene: casts global lines through it and estimates every measure of the paper with its
/// standard error and verdict, exactly as ``scx analyze`` does for the same settings (the same numbers
/// to the bit). See :func:`scx.analyze` for the arguments.
#[pyfunction]
#[pyo3(signature = (scene, lines=None, seed=None, *, threads=None, measures=None,
                    target_stderr=None, target_measure="mutual_information_corrected",
                    seconds=None, enclose=false, groups=None, estimator="chao-wang-jost",
                    errors="groups", bundle=None, sampler="auto", lines_through="auto", per_patch=false,
                    shard=None, save=None,
                    keep_state=true, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn analyze(
    py: Python<'_>,
    scene: Py<Scene>,
    lines: Option<&Bound<'_, PyAny>>,
    seed: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
    measures: Option<&Bound<'_, PyAny>>,
    target_stderr: Option<&Bound<'_, PyAny>>,
    target_measure: &str,
    seconds: Option<&Bound<'_, PyAny>>,
    enclose: bool,
    groups: Option<&Bound<'_, PyAny>>,
    estimator: &str,
    errors: &str,
    bundle: Option<&Bound<'_, PyAny>>,
    sampler: &str,
    lines_through: &str,
    per_patch: bool,
    shard: Option<&Bound<'_, PyAny>>,
    save: Option<&Bound<'_, PyAny>>,
    keep_state: bool,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Analysis> {
    let seconds = given(seconds)
        .map(|s| args::positive(&s, "seconds"))
        .transpose()?;
    let target = match given(target_stderr) {
        Some(t) => Some(Target {
            measure: args::target_measure(target_measure)?,
            stderr: args::positive(&t, "target_stderr")?,
        }),
        None => {
            args::target_measure(target_measure)?;
            None
        }
    };
    let budget = Budget { seconds, target };
    let lines = match given(lines) {
        Some(l) => args::lines(&l)?,
        None if budget.is_open_ended() => 1_000_000_000_000,
        None => 1_000_000,
    };
    let seed = given(seed)
        .map(|s| args::seed(&s))
        .transpose()?
        .unwrap_or(1);
    let threads = match given(threads) {
        Some(t) => args::threads(&t)?,
        None => args::threads(&0u8.into_pyobject(py)?.into_any())?,
    };
    let shard = given(shard).map(|s| shard_of(&s)).transpose()?;
    let save = optional_path(save, "save")?;
    if shard.is_some() && save.is_none() {
        return Err(bad_argument(
            "shard needs save=PATH: a shard's work is only of use saved (scx.merge joins the shards)",
        ));
    }
    if shard.is_some() && budget.is_open_ended() {
        return Err(bad_argument(
            "a shard takes no seconds or target_stderr: every shard must cast its whole share",
        ));
    }
    let through = args::bound(lines_through)?;
    // The command line's spec (src/cli/analyze.rs `spec_of` over `RunOptions::spec`).
    let spec = RunSpec {
        measures: args::measures(measures)?,
        budget,
        source: match given(bundle) {
            Some(b) => args::bundle(&b)?,
            None => scene_complexity::LineSource::Independent,
        },
        enclose,
        per_patch,
        estimator: args::estimator(estimator)?,
        errors: args::errors(errors)?,
        bound: match through {
            // Set for the check's sake; `through` below settles it with the scene.
            LinesThrough::Bound(b) => b,
            LinesThrough::Auto => LineBound::Sphere,
        },
        ..RunSpec::new(lines, seed)
    }
    .drawn_by(args::sampler(sampler)?)
    .grouped(given(groups).map(|g| args::groups(&g)).transpose()?);
    spec.check().map_err(bad_argument)?;
    let (state, identity, spec) = {
        let s = scene.get();
        let spec = spec.through(&s.inner, through);
        let state = start(&s.inner, &spec).map_err(scene_error)?;
        let identity = RunIdentity::new(
            SceneRef::of(&s.inner.name, &s.reading, &s.inner),
            spec.clone(),
            shard,
            TRACING,
        );
        (state, identity, spec)
    };
    let session = Session {
        scene,
        identity,
        cfg: spec,
        scope: Scope::of(shard),
        before: 0.0,
        casts: true,
        threads,
        save,
        keep_state,
        report_tracing: TRACING,
        report_shard: shard,
    };
    run_session(py, session, state, progress)
}

/// The scene of a saved run: the one given (a `Scene`, or a path or built-in read as the run read
/// it), else the one the state names.
fn scene_of_state(
    py: Python<'_>,
    given: Option<&Bound<'_, PyAny>>,
    identity: &RunIdentity,
    policy: &scene_complexity::ReadPolicy,
) -> PyResult<Py<Scene>> {
    let reading = &identity.scene.reading;
    match given.filter(|g| !g.is_none()) {
        Some(g) => match g.downcast::<Scene>() {
            Ok(s) => Ok(s.clone().unbind()),
            Err(_) => {
                let name = path_text(g, "scene")?;
                Py::new(py, read_scene(py, &name, reading, policy)?)
            }
        },
        None => {
            let name = &identity.scene.name;
            let scene = read_scene(py, name, reading, policy).map_err(|e| {
                scene_error(format!(
                    "{e} (a run's scene is read again from the name it was saved with; a scene \
                     built from arrays, or one moved since, must be passed again: scene=...)"
                ))
            })?;
            Py::new(py, scene)
        }
    }
}

/// Checks that a saved run can give per-patch results: the command line's checks of `--patches` after
/// `--resume` or `scx merge` (src/cli/patch_files.rs `check_saved`).
fn check_per_patch(
    py: Python<'_>,
    file: &str,
    identity: &RunIdentity,
    wanted: scene_complexity::Wanted,
    without_sums: &[String],
) -> PyResult<()> {
    if identity.spec.enclose {
        return Err(bad_argument(format!(
            "{file}: the run closed the scene with enclose=True; per_patch describes the scene's own \
             patches"
        )));
    }
    if !wanted.discrete {
        return Err(bad_argument(format!(
            "{file}: the run counted no patch pairs (measures without discrete): it has no per-patch \
             results"
        )));
    }
    if wanted.continuous && !without_sums.is_empty() {
        let message = format!(
            "{}: saved without the per-patch sums of eq. (27) (the run was not asked for per_patch), \
             so the continuous_mutual_information_term and lost_information columns stay empty",
            without_sums.join(", ")
        );
        warn_all(py, std::iter::once(message.as_str()))?;
    }
    Ok(())
}

/// Continues the run saved in ``path`` (by :func:`scx.analyze` with ``save=``, :meth:`Analysis.save`,
/// or ``scx analyze --save/--checkpoint``) with its own settings, up to ``lines``, and saves it back to
/// ``path``. See :func:`scx.resume` for the arguments.
#[pyfunction]
#[pyo3(signature = (path, lines=None, *, scene=None, threads=None, per_patch=false,
                    keep_state=true, progress=None, read_anywhere=false, max_file_size=None))]
#[allow(clippy::too_many_arguments)]
pub fn resume(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    lines: Option<&Bound<'_, PyAny>>,
    scene: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
    per_patch: bool,
    keep_state: bool,
    progress: Option<&Bound<'_, PyAny>>,
    read_anywhere: bool,
    max_file_size: Option<&Bound<'_, PyAny>>,
) -> PyResult<Analysis> {
    let file = PathBuf::from(path_text(path, "path")?);
    let shown = file.display().to_string();
    let policy = args::read_policy(read_anywhere, max_file_size)?;
    let threads = threads_or_all(py, threads)?;
    let lines = lines
        .filter(|l| !l.is_none())
        .map(args::lines)
        .transpose()?;
    let stored = py
        .allow_threads(|| scene_complexity::read_state(&file))
        .map_err(persist_error)?;
    let mut identity = stored.identity().clone();
    identity
        .continuable_here()
        .map_err(|problem| PyValueError::new_err(format!("{shown}: {problem}")))?;
    let scene = scene_of_state(py, scene, &identity, &policy)?;
    identity.tracing = TRACING;
    let lib_scene = Arc::clone(&scene.get().inner);
    let saved = py
        .allow_threads(|| stored.into_run(&lib_scene))
        .map_err(persist_error)?;
    let wanted = saved.state.wanted();
    if per_patch {
        let without: Vec<String> = (!wanted.per_patch)
            .then(|| shown.clone())
            .into_iter()
            .collect();
        check_per_patch(py, &shown, &identity, wanted, &without)?;
    }
    let mut state = saved.state;
    let lines = lines.map(|n| identity.spec.lines_for(&lib_scene, n));
    if let Some(lines) = lines.filter(|&n| n != identity.spec.lines) {
        let bound = identity.spec.bound;
        identity.spec = identity.spec.extended_to(lines).map_err(|e| {
            // Counted as `lines=` counts them, through the bounding sphere.
            let e = e.in_sphere_lines(&lib_scene, bound);
            let unit = match bound {
                scene_complexity::LineBound::Sphere => String::new(),
                other => format!(
                    " (line counts through the bounding sphere, as lines= counts them; the run draws \
                     its lines through the bounding {}, and its batches hold lines drawn)",
                    other.name()
                ),
            };
            bad_argument(format!("{shown}: {e}{unit}"))
        })?;
        state = state.extend(identity.spec.plan());
    }
    let cfg = RunSpec {
        per_patch,
        ..identity.spec.clone()
    };
    let scope = Scope::of(identity.shard);
    let report_shard = identity.shard;
    let session = Session {
        scene,
        identity,
        cfg,
        scope,
        before: saved.seconds,
        casts: true,
        threads,
        save: Some(file),
        keep_state,
        report_tracing: TRACING,
        report_shard,
    };
    run_session(py, session, state, progress)
}

fn threads_or_all(py: Python<'_>, threads: Option<&Bound<'_, PyAny>>) -> PyResult<usize> {
    match threads.filter(|t| !t.is_none()) {
        Some(t) => args::threads(t),
        None => args::threads(&0u8.into_pyobject(py)?.into_any()),
    }
}

/// Refuses a state given twice (`files::repeated_path`).
fn check_distinct(paths: &[PathBuf]) -> PyResult<()> {
    match scene_complexity::files::repeated_path(paths) {
        Some(message) => Err(bad_argument(message)),
        None => Ok(()),
    }
}

/// Joins the saved states of a run's shards (or of any parts of one run) into the analysis of the whole
/// run, identical to the run cast at once, as ``scx merge`` does. See :func:`scx.merge`.
#[pyfunction]
#[pyo3(signature = (paths, *, scene=None, partial=false, threads=None, per_patch=false,
                    save=None, keep_state=true, read_anywhere=false, max_file_size=None))]
#[allow(clippy::too_many_arguments)]
pub fn merge(
    py: Python<'_>,
    paths: &Bound<'_, PyAny>,
    scene: Option<&Bound<'_, PyAny>>,
    partial: bool,
    threads: Option<&Bound<'_, PyAny>>,
    per_patch: bool,
    save: Option<&Bound<'_, PyAny>>,
    keep_state: bool,
    read_anywhere: bool,
    max_file_size: Option<&Bound<'_, PyAny>>,
) -> PyResult<Analysis> {
    if paths.downcast::<pyo3::types::PyString>().is_ok() {
        return Err(bad_argument(
            "paths must be a list of state files, not one path",
        ));
    }
    let paths: Vec<PathBuf> = paths
        .try_iter()?
        .map(|p| path_text(&p?, "paths").map(PathBuf::from))
        .collect::<PyResult<_>>()?;
    if paths.is_empty() {
        return Err(bad_argument(
            "paths is empty: give the state files to merge",
        ));
    }
    check_distinct(&paths)?;
    let policy = args::read_policy(read_anywhere, max_file_size)?;
    let threads = threads_or_all(py, threads)?;
    let save = optional_path(save, "save")?;
    let files = py.allow_threads(|| {
        paths
            .iter()
            .map(|p| scene_complexity::read_state(p))
            .collect::<Result<Vec<_>, _>>()
    });
    let files = files.map_err(persist_error)?;
    let first = &files[0];
    for file in &files[1..] {
        if let Some(d) = first.identity().difference(file.identity(), false) {
            return Err(bad_argument(format!(
                "{} and {} are not parts of one run: their {} differs ({} against {})",
                file.path(),
                first.path(),
                d.setting,
                d.theirs,
                d.ours
            )));
        }
    }
    let first_identity = first.identity().clone();
    let scene = scene_of_state(py, scene, &first_identity, &policy)?;
    let lib_scene = Arc::clone(&scene.get().inner);
    let seconds: f64 = files.iter().map(|f| f.seconds()).sum();
    let mut runs = Vec::new();
    for file in files {
        let name = file.path().to_string();
        let run = py
            .allow_threads(|| file.into_run(&lib_scene))
            .map_err(persist_error)?;
        runs.push((name, run));
    }
    let without_sums: Vec<String> = runs
        .iter()
        .filter(|(_, r)| !r.state.wanted().per_patch)
        .map(|(name, _)| name.clone())
        .collect();
    let (first_name, first) = runs.remove(0);
    let mut state = first.state;
    for (name, run) in runs {
        state
            .absorb(run.state)
            .map_err(|e| bad_argument(format!("{name} cannot join {first_name}: {e}")))?;
    }
    let identity = first.identity;
    check_missing(py, &state, &identity, partial)?;
    if per_patch {
        check_per_patch(py, &first_name, &identity, state.wanted(), &without_sums)?;
    }
    let cfg = RunSpec {
        per_patch,
        ..identity.spec.clone()
    };
    let report_tracing = identity.tracing;
    let session = Session {
        scene,
        identity,
        cfg,
        scope: Scope::All,
        before: seconds,
        casts: false,
        threads,
        save,
        keep_state,
        report_tracing,
        report_shard: None,
    };
    run_session(py, session, state, None)
}

/// Refuses (or, with `partial`, warns about) merged states that miss batches of their run, naming the
/// missing lines (the command line's words).
fn check_missing(
    py: Python<'_>,
    state: &RunState,
    identity: &RunIdentity,
    partial: bool,
) -> PyResult<()> {
    let Some(missing) = state.missing_lines() else {
        return Ok(());
    };
    let message = missing.message(identity.shard.map(|s| s.count));
    if !partial {
        return Err(bad_argument(format!(
            "{message}; merge every shard, or pass partial=True for an analysis of these lines only"
        )));
    }
    warn_all(py, std::iter::once(message.as_str()))
}
