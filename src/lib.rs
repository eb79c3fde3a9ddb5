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
//! use scene_complexity::{analyze, load, make_tracer, RunSpec, Backend, Query, RunControl};
//!
//! // The unit cube cut into 4 x 4 patches per face, whose exact I_s is 1.12257 bits.
//! let scene = load("@cube:4")?;
//! let tracer = make_tracer(Backend::Rust, &scene, Query::Single)?;
//! let config = RunSpec::new(200_000, 1);
//! let a = analyze(&scene, tracer.as_ref(), &config, &RunControl::default())?;
//! let is = a.visibility.mutual_information_corrected.expect("counted");
//! let isc = a.visibility.continuous_mutual_information.expect("summed");
//! println!("I_s = {:.4} ± {:.4} bits, I_s^c = {:.4} ± {:.4} bits", is.value,
//!          is.stderr.unwrap(), isc.value, isc.stderr.unwrap());
//! assert!((is.value - 1.12257).abs() < 5.0 * is.stderr.unwrap());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The layers, in the order data flows (each imports only from the layers before it; a test checks it):
//!
//! * [`geom`]: points, directions, normals and shapes;
//! * [`scene`]: the scene model (patches, materials), its builder and the file loaders;
//! * [`scenes`]: the catalogue of built-in scenes (`@cube:10`, `@cornell`, the paper's figures);
//! * [`trace`]: every intersection along a batch of lines (Embree, or the pure-Rust tracer);
//! * [`sample`]: global lines, pairing of hits into mutually visible points, tallies and pair counts;
//! * [`measure`]: the paper's measures from counts and sums (sec. 3 and 4);
//! * [`run`]: the run engine (batches, rounds, groups and standard errors, budgets, saved states);
//! * [`analysis`]: what is computed from a run: every measure with its standard error and verdict,
//!   [`analyze`];
//! * the applications: [`reproduce`] (the paper's tables), [`mod@refine`] (meshing strategies),
//!   [`render`] (pictures of the per-patch results) and [`mod@crosscheck`] (the two tracers, hit for
//!   hit).

#![deny(missing_docs)]
#![deny(unsafe_code)]
#![forbid(unsafe_op_in_unsafe_fn)]

pub mod analysis;
pub mod crosscheck;
pub mod geom;
pub mod measure;
pub mod refine;
pub mod render;
pub mod reproduce;
pub mod run;
pub mod sample;
pub mod scene;
pub mod scenes;
pub mod trace;

pub use analysis::{
    analyze, Analysis, AnalysisError, RadiosityOutcome, RadiositySolve, Reliability, RunWarning,
    RunWarningKind, Verdict,
};
pub use crosscheck::{crosscheck, CrossCheck, CrossCheckConfig, Tolerance};
pub use geom::{Direction, Normal, Point, Vector};
pub use measure::estimators::EntropyEstimator;
pub use measure::radiosity::SolveOptions;
pub use measure::{ByMeasure, Estimate, Family, Measure, PatchMeasure, Unit};
pub use refine::{refine, RefineConfig, RefineError, Refinement, Strategy};
pub use run::{Budget, ErrorMethod, Measures, RunControl, RunSpec, StopReason, Target};
pub use sample::lines::LineSource;
pub use scene::{
    Material, ObjectSet, Patch, Planarity, Scene, SceneBuilder, SceneError, SceneOptions,
};
pub use scenes::{load, load_with};
pub use trace::{make_tracer, Backend, Query, TraceError, Tracer};
