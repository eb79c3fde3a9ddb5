//! The readings of an analysis, one row per measure: what every report (table, JSON, CSV) lists.

use crate::analysis::{Analysis, Reliability};
use crate::measure::catalogue::{Family, Measure, Unit};
use crate::measure::Estimate;

/// One row of a report: JSON key, table label, unit, paper reference, plug-in and bias-corrected
/// estimates, and their verdicts.
pub struct Row<'a> {
    /// The measure's key (the JSON report's, the CSV's `measure` column).
    pub key: &'static str,
    /// The measure's name for people.
    pub label: &'static str,
    /// The measure's unit.
    pub unit: Unit,
    /// Where the paper defines it (its equation).
    pub reference: &'static str,
    /// The plug-in reading (`None`: not computed).
    pub estimate: Option<Estimate>,
    /// The bias-corrected reading, for measures that have one.
    pub corrected: Option<Estimate>,
    /// The plug-in reading's reliability.
    pub reliability: Option<&'a Reliability>,
    /// The corrected reading's reliability.
    pub corrected_reliability: Option<&'a Reliability>,
}

/// The rows of `family`'s measures, in the catalogue's order: one per plug-in reading, with its
/// bias-corrected reading beside it.
pub fn rows(a: &Analysis, family: Family) -> Vec<Row<'_>> {
    Measure::of_family(family)
        .filter(|m| m.info().corrects.is_none())
        .map(|m| {
            let info = m.info();
            let corrected = m.corrected();
            Row {
                key: info.key,
                label: info.label,
                unit: info.unit,
                reference: info.equation,
                estimate: a.estimate(m),
                corrected: corrected.and_then(|c| a.estimate(c)),
                reliability: a.reliability.get(m),
                corrected_reliability: corrected.and_then(|c| a.reliability.get(c)),
            }
        })
        .collect()
}

/// `-0.0` as `0.0`, so that no report shows a negative zero.
pub fn positive_zero(x: f64) -> f64 {
    x + 0.0
}

/// A finite number for a report (`None`, JSON's `null`, otherwise).
pub fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(positive_zero(x))
}
