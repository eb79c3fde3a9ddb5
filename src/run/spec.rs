//! What a run is: the settings that determine its numbers.

use super::control::Budget;
use super::errors::ErrorMethod;
use crate::measure::estimators::EntropyEstimator;
use crate::measure::radiosity::SolveOptions;
use crate::sample::lines::LineSource;

/// Default number of independent groups of lines behind every standard error.
pub const DEFAULT_GROUPS: usize = 16;

/// The entropy estimator behind the bias-corrected H_s and I_s, chosen by measurement against the exact
/// I_s of `@cube:N` (README, "Error against run time").
pub const DEFAULT_ESTIMATOR: EntropyEstimator = EntropyEstimator::ChaoWangJost;

/// Which families of measures a run computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Measures {
    /// The discrete measures from pair counts (H_s, I_s, E(MSE), ..., paper sec. 3.1).
    pub discrete: bool,
    /// The continuous mutual information I_s^c (eq. 27, sec. 3.2).
    pub continuous: bool,
    /// The radiosity measures (sec. 4), when the scene emits; they need the pair counts, which are then
    /// gathered whatever `discrete` says.
    pub radiosity: bool,
}

impl Measures {
    /// Every measure.
    pub const ALL: Measures = Measures {
        discrete: true,
        continuous: true,
        radiosity: true,
    };

    /// The visibility measures only (no radiosity).
    pub const VISIBILITY: Measures = Measures {
        discrete: true,
        continuous: true,
        radiosity: false,
    };
}

/// What to run.
#[derive(Clone, Copy, Debug)]
pub struct AnalysisConfig {
    /// Global lines to cast (a cap when a budget is set).
    pub lines: u64,
    /// Seed of the line streams.
    pub seed: u64,
    /// Which measures to compute.
    pub measures: Measures,
    /// Groups for the standard errors ([`super::errors`]).
    pub groups: usize,
    /// The estimator of the bias-corrected H_s and I_s.
    pub estimator: EntropyEstimator,
    /// How the standard errors of the count-based measures are estimated.
    pub errors: ErrorMethod,
    /// When to stop before `lines`.
    pub budget: Budget,
    /// Independent lines, or bundles of parallel lines ([`LineSource`]); a bundle never straddles two
    /// batches, so the group spread includes the correlation within a bundle.
    pub source: LineSource,
    /// Close an open scene with the environment patch ([`crate::sample::environment`]): escapes become
    /// pairs with it, and every measure is that of the enclosed scene. Changes nothing when nothing
    /// escapes.
    pub enclose: bool,
    /// How the radiosity system is solved.
    pub solve: SolveOptions,
    /// Also share the measures out among the patches ([`Analysis::patches`]); gathers eq. (27)'s terms
    /// per patch, which costs nothing when left off. Not with `enclose` on an open scene.
    pub per_patch: bool,
}

impl AnalysisConfig {
    /// `lines` lines from `seed`, every measure, default groups and estimator, no budget.
    pub fn new(lines: u64, seed: u64) -> Self {
        AnalysisConfig {
            lines,
            seed,
            measures: Measures::ALL,
            groups: DEFAULT_GROUPS,
            estimator: DEFAULT_ESTIMATOR,
            errors: ErrorMethod::Groups,
            budget: Budget::default(),
            source: LineSource::Independent,
            enclose: false,
            solve: SolveOptions::default(),
            per_patch: false,
        }
    }
}
