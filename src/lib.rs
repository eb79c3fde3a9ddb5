//! scx: the information-theoretic scene complexity framework of Feixas, del Acebo, Bekaert and Sbert,
//! *An information theory framework for the analysis of scene complexity* (Eurographics 1999).
//!
//! Uniformly distributed global lines are cast through a triangle scene; every intersection along a
//! line, in order, gives pairs of mutually visible points; from them come the form factors, the scene's
//! visibility entropy H_s (eq. 17), mutual information I_s (eq. 21), continuous mutual information
//! I_s^c (eq. 27), the discretisation accuracy I_s / I_s^c, E(MSE) (eq. 22) and, when the scene emits
//! light, the radiosity measures of sec. 4, each with its standard error.
//!
//! ```
//! use scene_complexity::{analyze, load, make_tracer, Backend, Measure, Query, RunControl, RunSpec};
//!
//! // The unit cube cut into 4 x 4 patches per face, whose exact I_s is 1.12257 bits.
//! let scene = load("@cube:4")?;
//! let tracer = make_tracer(Backend::Rust, &scene, Query::Single)?;
//! let spec = RunSpec::new(200_000, 1);
//! let a = analyze(&scene, tracer.as_ref(), &spec, &RunControl::default())?;
//! let is = a.estimate(Measure::MutualInformationCorrected).expect("counted");
//! let isc = a.estimate(Measure::ContinuousMutualInformation).expect("summed");
//! println!("I_s = {:.4} ± {:.4} bits, I_s^c = {:.4} ± {:.4} bits", is.value,
//!          is.stderr.unwrap(), isc.value, isc.stderr.unwrap());
//! assert!((is.value - 1.12257).abs() < 5.0 * is.stderr.unwrap());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The API at a glance:
//!
//! * scenes: [`load`] a file or a built-in ([`CATALOGUE`]), or build one with [`SceneBuilder`]; write it
//!   with [`write_scene`] (OBJ, PLY, STL, glTF by the extension, [`WriteFormat`]), [`write_obj`] or
//!   [`write_gltf`];
//! * a run: [`RunSpec`] says what it is (every setting that determines its numbers), [`analyze`] casts
//!   it with a [`Tracer`] from [`make_tracer`] and returns an [`Analysis`], whose readings are indexed by
//!   [`Measure`] (the catalogue of measures, [`MEASURES`]), each an [`Estimate`] with its standard error
//!   and a [`Verdict`];
//! * runs in parts: [`start`], [`cast`] and [`finish`] are [`analyze`]'s three steps; a [`RunState`]
//!   is saved with [`save_state`], read with [`read_state`] and checked against its scene with
//!   [`load_state`], and parts of one run merge with
//!   [`RunState::absorb`];
//! * the applications: [`reproduce`] (the paper's tables), [`mod@refine`] (meshing strategies),
//!   [`render`] (pictures of the per-patch results), [`mod@report`] (the JSON report, per-patch and
//!   per-object tables, the form-factor matrix as data), [`mod@crosscheck`] (the two tracers, hit for
//!   hit) and [`calibrate`] (how often the standard errors' intervals cover exact values).
//!
//! Inside, the layers in the order data flows (each imports only from the layers before it; a test
//! checks it): `geom` (points, directions, shapes), `scene` (the scene model, its builder and readers),
//! `scenes` (the built-in scenes), `trace` (every intersection along a batch of lines, by Embree or the
//! pure-Rust tracer), `sample` (global lines, the pairing of hits, tallies and pair counts), `measure`
//! (the paper's measures from counts and sums, and their catalogue), `run` (the run engine: batches,
//! rounds, groups, budgets, saved states), `analysis` (every measure of a run with its standard error
//! and verdict), then the applications.

#![deny(missing_docs)]
// The JSON report is one `json!` document of some fifty fields.
#![recursion_limit = "256"]
#![deny(unsafe_code)]
#![forbid(unsafe_op_in_unsafe_fn)]

// The layers, private: what a library user needs is re-exported below; scx's own tests, benches and fuzz
// targets reach the rest through `internals`.
mod analysis;
mod geom;
mod measure;
mod run;
mod sample;
mod scene;
mod scenes;
mod trace;

// The applications, public modules of their own.
pub mod calibrate;
pub mod crosscheck;
pub mod refine;
pub mod render;
pub mod report;
pub mod reproduce;

// Scenes: loading (files and built-ins), building from arrays, writing.
pub use geom::{Direction, Normal, Point, Vector};
pub use scene::export::{
    files as scene_files, write as write_scene, UnknownExtension, WriteFormat, WRITE_EXTENSIONS,
};
pub use scene::format::load_stream;
pub use scene::{
    gltf::to_bytes as gltf_bytes, gltf::write as write_gltf, obj::load_text_with as load_obj_text,
    obj::to_text as obj_text, obj::write as write_obj, obj::MaterialSource, obj::MtlError,
    Material, Normalization, ObjectSet, Patch, Planarity, Scene, SceneBuilder, SceneError,
    SceneOptions, DEFAULT_PLANARITY,
};
pub use scene::{quantity_text, Reach, ReadPolicy, SceneWarning, SceneWarningKind, Warning};
pub use scenes::{
    load, load_with, load_with_policy, read_guarded, Builtin, CATALOGUE, MAX_BUILTIN_PATCHES,
};

// Tracing.
pub use trace::{make_tracer, Backend, Query, QueryError, TraceError, Tracer};

// What a run is, and how it is cast, saved, merged and resumed.
pub use measure::estimators::EntropyEstimator;
pub use measure::radiosity::{MaterialError, MaterialProblem, PatchMaterials, SolveOptions};
pub use run::files;
pub use run::persist::{
    check_save as check_state_save, decode as decode_state, encode as encode_state,
    load as load_state, read as read_state, save as save_state, save_bytes as save_state_bytes,
    StateFile,
};
pub use run::{
    default_groups, remaining_lines, start, Budget, CastOptions, ErrorMethod, ExtendError,
    LinesThrough, Measures, MergeError, MissingLines, PersistError, RunControl, RunIdentity,
    RunSpec, RunState, SamplerChoice, SavedRun, SceneRef, Scope, Shard, SpecDifference, SpecError,
    StartError, StopReason, Target, Tracing, DEFAULT_ESTIMATOR, DEFAULT_GROUPS,
    DEFAULT_SOBOL_GROUPS,
};
pub use sample::bounds::{
    lines_to_draw, sphere_lines, sphere_lines_for_drawn, sphere_lines_of_drawn, LineBound,
};
pub use sample::counts::PairCounts;
pub use sample::lines::{BundleError, LineSource, Sampler, MAX_BUNDLE_GRID};
pub use sample::tally::{Tally, Wanted};

// What is computed from a run.
pub use analysis::{
    analyze, cast, finish, Analysis, AnalysisError, HalfRun, LinesAdvice, ObjectResult,
    PatchResult, RadiosityOutcome, RadiositySolve, Reliability, RunWarning, RunWarningKind,
    SamplingReport, SolveFailure, TargetOutcome, Verdict, ADVICE_SETTLED_GROWTH, COVERAGE_OK,
    COVERAGE_UNUSABLE, ENVIRONMENT, MIN_PAIRS,
};
pub use measure::catalogue::{
    Bound, ByMeasure, Family, Measure, MeasureInfo, Needs, PatchMeasure, PatchMeasureInfo, Unit,
    VerdictRule, CATALOGUE as MEASURES, PATCH_CATALOGUE as PATCH_MEASURES,
};
pub use measure::{student_t_975, Estimate};

pub use crosscheck::{crosscheck, CrossCheck, CrossCheckConfig, Tolerance};
pub use refine::{refine, RefineConfig, RefineError, Refinement, Strategy};

/// The door to the layers below the public API, for scx's own tests, benches and fuzz targets (they
/// check internals against independent truth: closed forms, brute force, invariants). Not part of the
/// API: it changes whenever the code does.
#[doc(hidden)]
pub mod internals {
    /// Points, directions and shapes.
    pub mod geom {
        pub use crate::geom::*;
    }
    /// The scene model, its builder and readers.
    pub mod scene {
        pub use crate::scene::*;
    }
    /// The built-in scenes.
    pub mod scenes {
        pub use crate::scenes::*;
    }
    /// The tracers.
    pub mod trace {
        pub use crate::trace::*;
    }
    /// Lines, pairing, tallies and counts.
    pub mod sample {
        pub use crate::sample::*;
    }
    /// The measures from counts and sums.
    pub mod measure {
        pub use crate::measure::*;
    }
    /// The run engine.
    pub mod run {
        pub use crate::run::*;
    }
    /// What is computed from a run.
    pub mod analysis {
        pub use crate::analysis::*;
    }
}
