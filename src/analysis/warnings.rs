//! What a user must know about a run's numbers, as data: each warning has a kind a program can test and
//! a sentence a person can read.

use super::patch_results::PatchResult;
use crate::measure::{Estimate, PatchMeasure};
use crate::sample::tally::Counters;
use crate::scene::Warning;

/// What a warning is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunWarningKind {
    /// Segments escaped: form-factor rows sum to less than 1 (or the scene was enclosed).
    OpenScene,
    /// Lines met coplanar overlapping faces facing the same way; only the first is seen there.
    CoincidentCrossings,
    /// Some patches were never left by a line: their rows are empty.
    UnsampledPatches,
    /// Some pairs joined coincident points (touching surfaces) and were left out of I_s^c.
    DegeneratePairs,
    /// No segment joined two patches: the visibility measures are undefined (the message says what the
    /// lines met instead: closed solids seen from outside, back sides).
    NoPairs,
    /// Objects whose back sides are seen from outside them and whose front sides only from inside: their
    /// normals face inwards.
    InsideOut,
    /// One-sided surfaces seen from behind: segments from front sides arrive at their back sides.
    OneSided,
    /// Lights seen from behind: their back sides are dark (never advised two-sided).
    LightSeenFromBehind,
    /// Closed solids whose back sides are seen from front sides inside them.
    SeenInsideSolid,
    /// The run had fewer standard-error groups than asked (`--groups`): too few batches to deal.
    FewerGroups,
    /// Per-patch information lost, I_i^c - I_i, below 0 beyond its error on some patches of a closed
    /// scene: the plug-in I_i's bias on undersampled rows (the corrected column has none).
    NegativeLostInformation,
}

impl RunWarningKind {
    /// The stable code of the warning in the JSON report (`open-scene`).
    pub fn code(self) -> &'static str {
        match self {
            RunWarningKind::OpenScene => "open-scene",
            RunWarningKind::CoincidentCrossings => "coincident-crossings",
            RunWarningKind::UnsampledPatches => "unsampled-patches",
            RunWarningKind::DegeneratePairs => "degenerate-pairs",
            RunWarningKind::NoPairs => "no-pairs",
            RunWarningKind::InsideOut => "inside-out",
            RunWarningKind::OneSided => "one-sided",
            RunWarningKind::LightSeenFromBehind => "light-seen-from-behind",
            RunWarningKind::SeenInsideSolid => "seen-inside-solid",
            RunWarningKind::FewerGroups => "fewer-groups",
            RunWarningKind::NegativeLostInformation => "negative-lost-information",
        }
    }
}

/// One warning about a run ([`Warning`] of a [`RunWarningKind`]).
pub type RunWarning = Warning<RunWarningKind>;

/// The fraction of the segments leaving a front side that escape the scene (`None` without segments).
pub fn escape_fraction(counters: &Counters) -> Option<f64> {
    let segments = counters.pairs + counters.escapes + counters.absorbed;
    (segments > 0).then(|| counters.escapes as f64 / segments as f64)
}

/// The warnings of a run of scene `scene`: its counters, its unsampled patches and area fraction (when
/// counted) and the environment's area (when enclosed).
pub(crate) fn of_run(
    scene: &str,
    counters: &Counters,
    unsampled: Option<(usize, f64)>,
    environment_area: Option<Estimate>,
) -> Vec<RunWarning> {
    let mut w = Vec::new();
    let mut push = |kind, message, numbers: &[(&'static str, f64)]| {
        w.push(RunWarning::new(kind, message).with_numbers(numbers))
    };
    if let Some(fraction) = escape_fraction(counters).filter(|&f| f > 0.0) {
        let effect = match environment_area {
            Some(env) => format!(
                "with --enclose they are pairs with the environment patch (area {} scene units^2), and \
                 the measures are those of the enclosed scene",
                crate::scene::quantity_text(env.value)
            ),
            None => "so form-factor rows sum to less than 1 (--enclose closes the scene)".into(),
        };
        push(
            RunWarningKind::OpenScene,
            format!(
                "{scene}: the scene is open: {:.3}% of the segments leaving a front side escape the \
                 scene; {effect}",
                100.0 * fraction
            ),
            &[("escape_fraction", fraction)],
        );
    }
    if counters.coincident_crossings > 0 {
        push(
            RunWarningKind::CoincidentCrossings,
            format!(
                "{scene}: {} line crossing(s) met coplanar overlapping faces facing the same way; only the \
                 face first in the scene is seen there (remove duplicated faces and decals)",
                counters.coincident_crossings
            ),
            &[("crossings", counters.coincident_crossings as f64)],
        );
    }
    if let Some((n, frac)) = unsampled.filter(|u| u.0 > 0) {
        push(
            RunWarningKind::UnsampledPatches,
            format!(
                "{scene}: {n} patch(es) ({:.4}% of the area) were never left by a line: their rows are \
                 empty; cast more lines",
                100.0 * frac
            ),
            &[("patches", n as f64), ("area_fraction", frac)],
        );
    }
    if counters.degenerate_pairs > 0 {
        push(
            RunWarningKind::DegeneratePairs,
            format!(
                "{scene}: {} pair(s) joined coincident points (touching surfaces) and were left out of I_s^c",
                counters.degenerate_pairs
            ),
            &[("pairs", counters.degenerate_pairs as f64)],
        );
    }
    w
}

/// What a run whose lines are `batches` batches gets for standard errors when they fill fewer groups
/// (`used`) than the `asked` ones: a group is made of whole batches. `needed` gives how many lines (as
/// `--lines` counts them) give every group a batch (asked only then). `None` when it has the groups
/// asked for.
pub(crate) fn fewer_groups(
    scene: &str,
    (asked, used): (usize, usize),
    batches: u64,
    needed: impl FnOnce() -> u64,
) -> Option<RunWarning> {
    if used >= asked {
        return None;
    }
    let what = if used == 0 {
        "the run cast no line, so it has no standard errors".to_string()
    } else if used < 2 {
        format!(
            "the run's lines ({batches} batch(es)) fill one group, so it has no standard errors (they \
             are the spread of two groups or more)"
        )
    } else {
        format!(
            "the run's {batches} batches of lines fill {used} groups, not the {asked} asked \
             (--groups), so its standard errors rest on {used} groups and its intervals are wider \
             (Student's t, {} degrees of freedom)",
            used - 1
        )
    };
    let needed = needed();
    let message = format!(
        "{scene}: {what}; a group holds whole batches: {asked} groups need at least {needed} lines"
    );
    Some(
        RunWarning::new(RunWarningKind::FewerGroups, message).with_numbers(&[
            ("asked", asked as f64),
            ("groups", used as f64),
            ("lines_needed", needed as f64),
        ]),
    )
}

/// The patches of a closed scene whose plug-in information lost, I_i^c - I_i, reads below 0 by more than
/// twice its standard error. The log-sum inequality makes every row's I_i^c at least its I_i (coarse
/// graining loses information), so such a reading is no measurement of the patch: it is the plug-in
/// I_i's bias, high on a row sampled too thinly, which the corrected column (`lost_information_corrected`)
/// removes. Open scenes are not judged (their rows do not sum to 1).
pub(crate) fn negative_lost_information(
    scene: &str,
    patches: &[PatchResult],
    closed: bool,
) -> Option<RunWarning> {
    if !closed {
        return None;
    }
    let below = |e: Estimate| e.value < -2.0 * e.stderr.unwrap_or(f64::INFINITY);
    let (mut n, mut fraction) = (0usize, 0.0);
    for p in patches {
        if p.get(PatchMeasure::LostInformation).is_some_and(below) {
            n += 1;
            fraction += p.area_fraction;
        }
    }
    (n > 0).then(|| {
        RunWarning::new(
            RunWarningKind::NegativeLostInformation,
            format!(
                "{scene}: {n} patch(es) ({:.2}% of the area) read a negative information lost \
                 (lost_information below 0 by more than twice its standard error), which no row of a \
                 closed scene allows: the plug-in I_i reads high on rows sampled too thinly; read \
                 lost_information_corrected (--color lost-information-corrected), or cast more lines",
                100.0 * fraction
            ),
        )
        .with_numbers(&[("patches", n as f64), ("area_fraction", fraction)])
    })
}
