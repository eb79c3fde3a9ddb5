//! The run engine: one way to cast a run's lines, for every kind of run.
//!
//! * [`plan`]: how lines are cut into batches (a function of the line count, never of the threads) and
//!   batches into rounds;
//! * [`batches`]: the one parallel loop over batches, whose results come back in batch order (analyses,
//!   refinement rounds and cross-checks all use it);
//! * [`state`]: a run's groups as they fill up, a value ([`RunState`]);
//! * [`errors`]: standard errors from the groups (batch means, the delete-a-group jackknife);
//! * [`control`]: budgets, stop reasons and the handle that watches and stops a run;
//! * [`analysis`]: the analysis of a scene, [`analyze`], with [`radiosity`], [`warnings`] and the
//!   per-patch results ([`patches`]).

pub mod analysis;
pub mod batches;
pub mod control;
pub mod errors;
mod orientation;
pub mod patches;
pub mod persist;
pub mod plan;
pub mod radiosity;
pub mod readings;
pub mod reliability;
pub mod state;
pub mod warnings;

pub use analysis::TargetOutcome;
pub use analysis::{
    analyze, cast, finish, plan_of, remaining_lines, start, Analysis, AnalysisConfig,
    AnalysisError, CastOptions, Measures, Scope, DEFAULT_ESTIMATOR, DEFAULT_GROUPS,
};
pub use batches::{all_batches, map_batches, map_traced_batches, Batch, LineStream, TraceBuffers};
pub use control::{Budget, RunControl, StopReason, Target, TargetMeasure};
pub use errors::{ErrorMethod, Spread};
pub use patches::{PatchEstimate, PatchLight};
pub use persist::{PersistError, RunIdentity, SavedRun};
pub use plan::{BatchPlan, BatchSet};
pub use radiosity::{
    RadiosityEstimates, RadiosityOutcome, RadiosityReliability, SolveFailure, NOTHING_EMITS,
};
pub use readings::VisibilityEstimates;
pub use reliability::{Reliability, SamplingReport, Verdict, VisibilityReliability};
pub use state::{FinishedRun, MergeError, RunState, StateParts, TracedBatches};
pub use warnings::{RunWarning, RunWarningKind};
