//! `scx calibrate`: the calibration suite, the instrument every estimator change is judged by.
//!
//! The project's standard is that every estimate carries a standard error, and that a reading marked
//! `ok` has an interval that covers the truth at the stated rate. One run cannot show that; many runs of
//! scenes whose exact values are known can. A *cell* is one scene at one line count (or one precision
//! target), run once per seed; for each measure of the catalogue ([`Measure`]) and each exact value of it
//! the suite counts how often the stated 95% interval, `value ± t se` (Student's t for the groups less
//! one), holds the exact value, how often the reading is `ok` and how often an `ok` reading covers, and
//! the mean and spread of `(value - exact) / se` ([`summary`]).
//!
//! * [`mod@truth`]: the exact values, from closed-form form factors ([`rectangles`]) and quadrature of the
//!   point-to-point form factor over pairs of triangles ([`kernel`], [`quadrature`]);
//! * [`scenes`]: the scenes with exact values, built-ins and four made here (open scenes, a flipped
//!   face, an emitting face);
//! * [`mod@suite`]: cells and the built-in lists (`small`, `standard`, `full`);
//! * [`driver`]: the only module that touches the run engine: a cell in, per-seed readings out;
//! * [`summary`] and [`report`]: coverage per cell and measure, as Markdown and CSV.

pub mod driver;
pub mod kernel;
pub mod quadrature;
pub mod rectangles;
pub mod report;
pub mod scenes;
pub mod suite;
pub mod summary;
pub mod truth;

use std::collections::HashMap;
use std::time::Instant;

pub use driver::{Reading, SeedReadings};
pub use scenes::CalibrationScene;
pub use suite::{suite, Cell, CellMeasures, CellTarget, SuiteLevel};
pub use summary::Summary;
pub use truth::{check_computable, truth, Basis, ExactValue, Truth, TruthError};

use crate::analysis::AnalysisError;
use crate::measure::Measure;
use crate::scene::SceneError;
use crate::trace::{make_tracer, Backend, Query, TraceError};

/// Why the suite could not run.
#[derive(Debug, thiserror::Error)]
pub enum CalibrationError {
    /// A scene could not be built.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Its exact values could not be computed.
    #[error(transparent)]
    Truth(#[from] TruthError),
    /// Its tracer could not be built.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// A run failed.
    #[error(transparent)]
    Analysis(#[from] AnalysisError),
}

impl CalibrationError {
    /// Whether the input (a scene name) is at fault, not the machinery.
    pub fn is_bad_input(&self) -> bool {
        match self {
            CalibrationError::Scene(_) => true,
            CalibrationError::Truth(TruthError::Scene(_)) => true,
            CalibrationError::Analysis(e) => e.is_bad_input(),
            _ => false,
        }
    }
}

/// A cell run: its readings and their judgement.
#[derive(Clone, Debug)]
pub struct CellReport {
    /// The cell.
    pub cell: Cell,
    /// Every run's readings, in seed order.
    pub runs: Vec<SeedReadings>,
    /// One summary per measure and basis, in catalogue order.
    pub summaries: Vec<Summary>,
    /// Wall-clock seconds of the runs (not of the exact values).
    pub seconds: f64,
}

/// Runs the cells in order with the tracer `backend` in the current thread pool, calling `on_cell` as
/// each finishes (the exact values of a scene are computed once, when its first cell comes).
pub fn run_cells(
    cells: &[Cell],
    backend: Backend,
    on_cell: &mut dyn FnMut(&CellReport),
) -> Result<Vec<CellReport>, CalibrationError> {
    let mut truths: HashMap<String, Truth> = HashMap::new();
    let mut reports = Vec::with_capacity(cells.len());
    for cell in cells {
        let name = cell.scene.name();
        if !truths.contains_key(&name) {
            truths.insert(name.clone(), truth(&cell.scene)?);
        }
        let report = run_cell(cell, &truths[&name], backend)?;
        on_cell(&report);
        reports.push(report);
    }
    Ok(reports)
}

/// Runs one cell against its exact values.
pub fn run_cell(
    cell: &Cell,
    truth: &Truth,
    backend: Backend,
) -> Result<CellReport, CalibrationError> {
    let scene = cell.scene.build()?;
    let tracer = make_tracer(backend, &scene, Query::Single)?;
    let started = Instant::now();
    let runs = driver::cell_readings(cell, &scene, tracer.as_ref())?;
    let seconds = started.elapsed().as_secs_f64();
    Ok(CellReport {
        cell: *cell,
        summaries: summary::summarize(cell, truth, &runs),
        runs,
        seconds,
    })
}

impl CellReport {
    /// The summary of `measure` against its exact value under `basis`, when the cell has one.
    pub fn summary(&self, measure: Measure, basis: Basis) -> Option<&Summary> {
        self.summaries
            .iter()
            .find(|s| s.measure == measure && s.basis == basis)
    }
}
