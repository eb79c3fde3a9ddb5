//! The one place where the suite calls the run engine: a cell and a seed in, that run's readings out.
//!
//! Everything else in [`super`] works on [`SeedReadings`], so that a change of the run API (how a run is
//! specified, how its readings are held) is adapted here and nowhere else: [`run_spec`] says how a cell
//! becomes a run, [`readings_of`] how a finished run becomes readings.

use rayon::prelude::*;

use super::suite::{Cell, CellMeasures};
use crate::analysis::{analyze, Analysis, AnalysisError, Verdict};
use crate::measure::{ByMeasure, Estimate, Measure};
use crate::run::{Measures, RunControl, RunSpec, Target};
use crate::sample::bounds::sphere_lines_of_drawn;
use crate::scene::Scene;
use crate::trace::Tracer;

/// The standard-error groups of a run when nothing else is asked: the suite's runs use them, and the
/// table's header names the Student-t multiplier they give.
pub const GROUPS: usize = crate::run::DEFAULT_GROUPS;

/// One measure of one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// Its value and standard error.
    pub estimate: Estimate,
    /// The 95% interval the run states for it ([`Analysis::interval_95`]: value ± Student's t for the
    /// groups less one, times the standard error); `None` without a standard error. The suite judges
    /// this interval, the one users read, rather than one of its own making.
    pub interval_95: Option<(f64, f64)>,
    /// The run's verdict on it (`None`: the run gives none, as for the radiosity H_p, exact given the
    /// solution).
    pub verdict: Option<Verdict>,
}

/// The readings of one run of a cell.
#[derive(Clone, Debug, PartialEq)]
pub struct SeedReadings {
    /// The run's seed.
    pub seed: u64,
    /// The lines it cast, counted through the bounding sphere as the cell's lines are (what the lines
    /// drawn through a box or polytope are worth).
    pub lines: u64,
    /// The standard-error groups that had lines: the interval's Student-t multiplier has one degree of
    /// freedom less (a standard error from G groups is itself estimated from G values).
    pub groups: usize,
    /// The half-width of its stated intervals in standard errors ([`Analysis::interval_quantile`]).
    pub interval_quantile: f64,
    /// With a precision target: whether the run declared it met.
    pub target_met: Option<bool>,
    /// Every reading the run gave, by measure.
    pub readings: ByMeasure<Reading>,
}

impl SeedReadings {
    /// The reading of `measure`, if the run gave one.
    pub fn of(&self, measure: Measure) -> Option<&Reading> {
        self.readings.get(measure)
    }
}

/// Runs of at most this many lines are run side by side, one seed per thread; longer ones one after the
/// other, each with every thread (their own batches keep the threads busy, and two long runs at once
/// would hold two runs' counts in memory).
pub const SIDE_BY_SIDE_MAX_LINES: u64 = 4_000_000;

/// The runs of a cell, one per seed, in seed order (the same seeds give the same readings, whatever the
/// threads).
pub fn cell_readings(
    cell: &Cell,
    scene: &Scene,
    tracer: &dyn Tracer,
) -> Result<Vec<SeedReadings>, AnalysisError> {
    let run = |seed: u64| run_seed(cell, scene, tracer, seed);
    if cell.lines <= SIDE_BY_SIDE_MAX_LINES {
        cell.seeds().into_par_iter().map(run).collect()
    } else {
        cell.seeds().map(run).collect()
    }
}

/// One run of a cell.
pub fn run_seed(
    cell: &Cell,
    scene: &Scene,
    tracer: &dyn Tracer,
    seed: u64,
) -> Result<SeedReadings, AnalysisError> {
    let spec = run_spec(cell, seed, scene);
    let analysis = analyze(scene, tracer, &spec, &RunControl::default())?;
    Ok(readings_of(&analysis, scene))
}

/// The run of `cell` with `seed` on `scene`: the cell's lines (a cap when it has a target; lines through
/// the sphere, drawn where the cell says), measures and target; everything else the defaults of `scx
/// analyze`, so that the table judges what users get.
pub fn run_spec(cell: &Cell, seed: u64, scene: &Scene) -> RunSpec {
    let mut spec = RunSpec::new(cell.lines, seed);
    spec.measures = match cell.measures {
        CellMeasures::All => Measures::ALL,
        CellMeasures::ContinuousOnly => Measures {
            discrete: false,
            continuous: true,
            radiosity: false,
        },
    };
    spec.sampler = cell.sampler;
    spec.groups = cell.groups;
    spec.budget.target = cell.target.map(|t| Target {
        measure: t.measure,
        stderr: t.stderr,
    });
    spec.through(scene, cell.through)
}

/// The readings of a finished run: every measure with a value, its verdict, the groups behind the
/// standard errors and whether a precision target was met.
pub fn readings_of(a: &Analysis, scene: &Scene) -> SeedReadings {
    SeedReadings {
        seed: a.spec.seed,
        lines: sphere_lines_of_drawn(scene, a.spec.bound, a.lines),
        groups: a.groups,
        interval_quantile: a.interval_quantile(),
        target_met: a.target.map(|t| t.met()),
        readings: ByMeasure::from_fn(|m| {
            Some(Reading {
                estimate: a.estimate(m)?,
                interval_95: a.interval_95(m),
                verdict: a.verdict(m),
            })
        }),
    }
}
