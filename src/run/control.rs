//! When a run ends: its budget (time, precision), why it stopped, and the handle a watcher holds to
//! follow and stop it.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use crate::measure::Measure;

/// Limits that end a run before its line count.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Budget {
    /// Stop when this much wall-clock time is spent.
    pub seconds: Option<f64>,
    /// Stop when a measure's standard error is this small.
    pub target: Option<Target>,
}

impl Budget {
    /// Whether the run's length is not known in advance (a time or precision budget).
    pub fn is_open_ended(&self) -> bool {
        self.seconds.is_some() || self.target.is_some()
    }
}

/// A precision target: run until `measure`'s standard error is at most `stderr`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Target {
    /// The measure watched (one of [`Measure::targets`]).
    pub measure: Measure,
    /// The standard error to reach.
    pub stderr: f64,
}

/// Shared between a run and whoever watches it: a stop request (Ctrl-C) and a progress counter.
#[derive(Debug, Default)]
pub struct RunControl {
    stop: AtomicBool,
    lines_started: AtomicU64,
}

impl RunControl {
    /// Asks the run to stop; it finishes the batches under way and reports what it gathered.
    pub fn request_stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Lines whose tracing has started so far (for a progress display).
    pub fn lines_started(&self) -> u64 {
        self.lines_started.load(Ordering::Relaxed)
    }

    /// Whether a stop was requested.
    pub fn stop_requested(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Counts `lines` more lines as started.
    pub(crate) fn started(&self, lines: u64) {
        self.lines_started.fetch_add(lines, Ordering::Relaxed);
    }
}

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// All the requested lines were cast.
    Lines,
    /// The time budget was spent.
    Seconds,
    /// The precision target was reached.
    Target,
    /// The precision target's reading reached the floor of f32 tracing (its standard error is so small
    /// that the chords lost near edges could bias it by more): more lines would not make it reliable.
    Floor,
    /// A stop was requested (Ctrl-C).
    Interrupted,
}

impl StopReason {
    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            StopReason::Lines => "lines",
            StopReason::Seconds => "seconds",
            StopReason::Target => "target_stderr",
            StopReason::Floor => "f32_floor",
            StopReason::Interrupted => "interrupted",
        }
    }
}
