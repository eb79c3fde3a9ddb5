//! The run engine: one way to cast a run's lines, for every kind of run.
//!
//! * [`spec`]: what a run is (the settings that determine its numbers);
//! * [`plan`]: how lines are cut into batches (a function of the line count, never of the threads) and
//!   batches into rounds;
//! * [`batches`]: the one parallel loop over batches, whose results come back in batch order (analyses,
//!   refinement rounds and cross-checks all use it);
//! * [`state`]: a run's groups as they fill up, a value ([`RunState`]);
//! * [`cast`](mod@cast): the rounds that fill a state until the line count, a budget or a stop request ends
//!   the run;
//! * [`errors`]: standard errors from the groups (batch means, the delete-a-group jackknife);
//! * [`control`]: budgets, stop reasons and the handle that watches and stops a run;
//! * [`persist`]: run states saved to files, to resume or merge;
//! * [`files`]: files written whole or not at all, streams written into, locks beside states.
//!
//! What is computed from a run is [`crate::analysis`]'s.

pub mod batches;
pub mod cast;
mod consistency;
pub mod control;
pub mod errors;
pub mod files;
pub mod persist;
pub mod plan;
pub mod spec;
pub mod state;

pub use batches::{all_batches, map_batches, map_traced_batches, Batch, LineStream, TraceBuffers};
pub use cast::{
    cast, remaining_lines, start, CastHooks, CastOptions, Scope, Shard, StartError, TargetReading,
    TargetWatch,
};
pub use control::{Budget, RunControl, StopReason, Target};
pub use errors::{ErrorMethod, Spread};
pub use persist::{PersistError, RunIdentity, SavedRun, SceneRef, Tracing};
pub use plan::{BatchPlan, BatchSet};
pub use spec::{
    default_groups, ExtendError, LinesThrough, Measures, RunSpec, SamplerChoice, SpecDifference,
    SpecError, DEFAULT_ESTIMATOR, DEFAULT_GROUPS, DEFAULT_SOBOL_GROUPS,
};
pub use state::{FinishedRun, MergeError, MissingLines, RunState, StateParts, TracedBatches};
