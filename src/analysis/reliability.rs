//! The reliability verdict of every reading: whether its standard error tells the whole story, and the
//! bounds of the theory it breaks (docs/results.md, "Reading the reliability verdict").
//!
//! The discrete measures of an undersampled run are biased (their standard errors do not include it):
//! * a plug-in reading (H_s, H(X, Y), I_s and the accuracies built on them) is `ok` when the rows' sample
//!   coverage is at least [`COVERAGE_OK`] and its estimated bias, the distance to the bias-corrected
//!   reading, is within half its standard error ([`PLUG_IN_BIAS_SHARE`]; a ratio's bias against the
//!   ratio's own error);
//! * a bias-corrected reading is `ok` when the coverage is at least [`COVERAGE_OK`] and the
//!   delete-a-group jackknife's estimate of its remaining bias is within its standard error (the
//!   jackknife needs at least 2 groups, and is not computed with `--enclose` nor Chao–Shen: the coverage
//!   alone decides there);
//! * any discrete reading is `unusable` below [`COVERAGE_UNUSABLE`]: most of the rows' probability was
//!   never drawn, and no estimator can see what was not drawn;
//! * the plug-in E(MSE) (eq. 22) is `ok` when its estimated bias is within half its standard error; its
//!   unbiased estimate, whatever the coverage, when the jackknife's estimate of its bias (if any) is
//!   within its standard error;
//! * I_s^c (eq. 27) is a mean of independent terms: `ok` with enough pairs in every group.
//!
//! Independently, a reading that breaks a bound the theory guarantees (an entropy or mutual information
//! below 0, I_s above I_s^c (Proposition 2), an accuracy outside [0, 1]) by more than twice its standard
//! error is flagged, and is never `ok`.

use crate::measure::catalogue::{Bound, VerdictRule};
use crate::measure::sampling::Sampling;
use crate::measure::{ByMeasure, Estimate, Family, Measure};

/// Rows whose area-weighted sample coverage is at least this give `ok` bias-corrected readings.
pub const COVERAGE_OK: f64 = 0.99;
/// Below this coverage every discrete reading is `unusable`.
pub const COVERAGE_UNUSABLE: f64 = 0.5;
/// I_s^c needs at least this many pairs in the run to be `ok` (with `--enclose`, pairs with the
/// environment count).
pub const MIN_PAIRS: u64 = 1000;

/// What a reading is worth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verdict {
    /// Its standard error covers its error.
    Ok,
    /// It is biased beyond what its interval allows: cast more lines (see [`Reliability::lines_needed`]).
    Undersampled,
    /// It cannot be trusted at all.
    Unusable,
}

impl Verdict {
    /// The name in reports (`ok`, `undersampled`, `unusable`).
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::Undersampled => "undersampled",
            Verdict::Unusable => "unusable",
        }
    }
}

/// The verdict on one reading, with the numbers behind it.
#[derive(Clone, Debug, PartialEq)]
pub struct Reliability {
    /// The verdict.
    pub verdict: Verdict,
    /// The estimated bias of the reading (bits, or lines for E(MSE)), when there is an estimate.
    pub estimated_bias: Option<f64>,
    /// Roughly how many lines in all would make it `ok` (`None`: not estimated, or already ok).
    pub lines_needed: Option<u64>,
    /// The bounds of the theory it breaks, as sentences.
    pub flags: Vec<String>,
}

impl Reliability {
    fn new(verdict: Verdict) -> Self {
        Reliability {
            verdict,
            estimated_bias: None,
            lines_needed: None,
            flags: Vec::new(),
        }
    }

    /// Flags a broken bound: the reading is then at least undersampled.
    fn flag(&mut self, sentence: String) {
        self.flags.push(sentence);
        self.verdict = self.verdict.max(Verdict::Undersampled);
    }
}

/// How the rows were sampled, for the report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplingReport {
    /// The rows' sampling.
    pub sampling: Sampling,
    /// The lines in all for a coverage of [`COVERAGE_OK`] (`None`: beyond reach of the extrapolation).
    pub lines_for_coverage: Option<u64>,
    /// The same extrapolation from the first half of the run's groups alone, a run of about half the
    /// lines; computed only when the coverage falls short of [`COVERAGE_OK`].
    pub from_half: HalfRun,
    /// What [`SamplingReport::lines_for_coverage`] is worth.
    pub advice: LinesAdvice,
}

/// The extrapolation of the lines for a coverage of [`COVERAGE_OK`] from half a run's groups.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HalfRun {
    /// Not computed: the coverage is reached (or beyond reach) with all the lines, or the run has fewer
    /// than 2 groups.
    NotComputed,
    /// The lines in all it advises.
    Lines(u64),
    /// The coverage was beyond reach of the extrapolation from half the lines.
    BeyondReach,
}

/// The growth of the lines advice from half a run's lines to all of them above which the advice is a
/// lower bound ([`LinesAdvice::LowerBound`]). Where the extrapolation holds it does not grow (1.0 on the
/// icosphere `@sphere:3` at 10^6 and 3 x 10^6 lines).
pub const ADVICE_SETTLED_GROWTH: f64 = 1.25;

/// What the lines advice for a coverage of [`COVERAGE_OK`] ([`SamplingReport::lines_for_coverage`]) is
/// worth. Chao and Jost's extrapolation of a row's coverage is fitted to the outcomes seen once and
/// twice; rows with a long tail of rare outcomes (an object seen from outside: each patch sees a few
/// others often and many rarely) keep revealing new ones as the lines grow, and the advice grows with
/// them. The same extrapolation from half the run's groups (independent replicates: a run of half the
/// lines) shows whether it has settled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinesAdvice {
    /// The coverage is reached: no advice.
    Reached,
    /// An estimate: it did not grow by more than [`ADVICE_SETTLED_GROWTH`] from half the lines (or the
    /// run has too few groups to tell).
    Estimate,
    /// A lower bound: it grew by more than [`ADVICE_SETTLED_GROWTH`] from half the lines, or from half the
    /// lines the coverage was beyond reach; more lines may be needed.
    LowerBound,
    /// The coverage is beyond reach of the extrapolation: no advice.
    BeyondReach,
}

impl LinesAdvice {
    /// The stable code in the JSON report (`lower-bound`).
    pub fn code(self) -> &'static str {
        match self {
            LinesAdvice::Reached => "reached",
            LinesAdvice::Estimate => "estimate",
            LinesAdvice::LowerBound => "lower-bound",
            LinesAdvice::BeyondReach => "beyond-reach",
        }
    }
}

impl SamplingReport {
    /// The report of a run of `lines` lines whose rows' sampling is `sampling`, with the lines advised
    /// for a coverage of [`COVERAGE_OK`] from all the lines and from half of them.
    pub fn new(
        sampling: Sampling,
        lines: u64,
        lines_for_coverage: Option<u64>,
        from_half: HalfRun,
    ) -> Self {
        let mut report = SamplingReport {
            sampling,
            lines_for_coverage,
            from_half,
            advice: LinesAdvice::Estimate,
        };
        report.advice = match (lines_for_coverage, from_half) {
            (None, _) => LinesAdvice::BeyondReach,
            (Some(n), _) if n <= lines => LinesAdvice::Reached,
            (Some(_), HalfRun::BeyondReach) => LinesAdvice::LowerBound,
            _ if report
                .advice_growth()
                .is_some_and(|g| g > ADVICE_SETTLED_GROWTH) =>
            {
                LinesAdvice::LowerBound
            }
            _ => LinesAdvice::Estimate,
        };
        report
    }

    /// How many times the lines advice grew from half the run's lines to all of them, when both were
    /// extrapolated.
    pub fn advice_growth(&self) -> Option<f64> {
        match (self.lines_for_coverage, self.from_half) {
            (Some(all), HalfRun::Lines(half)) if half > 0 => Some(all as f64 / half as f64),
            _ => None,
        }
    }
}

/// Whether `a` exceeds `b` by more than twice their combined standard error.
fn clearly_above(a: Estimate, b: Estimate) -> bool {
    let se = (a.stderr.unwrap_or(0.0).powi(2) + b.stderr.unwrap_or(0.0).powi(2)).sqrt();
    a.value - b.value > 2.0 * se
}

fn stderr(e: Estimate) -> f64 {
    e.stderr.unwrap_or(f64::INFINITY)
}

/// The share of its standard error that a plug-in reading's estimated bias may reach for the reading to
/// be ok. The estimate (plug-in minus bias-corrected) is about the true bias, and a true bias of `b`
/// standard errors lowers the 95% interval's coverage to about `Phi(2.13 - b) - Phi(-2.13 - b)` (with
/// the spread of 16 groups' errors, sd z ~1.1): 95% at 0, 92-93% at 0.5, 85% at 1. With 1, the old
/// share, the ok readings covered 76% (the plug-in accuracy of `@tetrahedron:4` at 1e6 lines, 200
/// seeds) to 90% (the plug-in E(MSE) of `@octahedron:3`). A bias-corrected reading is held to its whole
/// standard error: the jackknife overestimates its remaining bias about twice.
pub const PLUG_IN_BIAS_SHARE: f64 = 0.5;

/// Whether a plug-in reading's estimated bias `bias` is beyond what an ok reading of standard error `se`
/// may carry ([`PLUG_IN_BIAS_SHARE`]).
fn plug_in_bias_too_large(bias: f64, se: f64) -> bool {
    bias.abs() > PLUG_IN_BIAS_SHARE * se
}

/// The lines for a plug-in reading's bias `bias` to fall within [`PLUG_IN_BIAS_SHARE`] of its standard
/// error `se`: the bias falls like 1 / lines, the standard error like 1 / sqrt(lines).
fn lines_for_bias(lines: u64, bias: f64, se: f64) -> Option<u64> {
    (se > 0.0 && se.is_finite() && plug_in_bias_too_large(bias, se))
        .then(|| (lines as f64 * (bias / (PLUG_IN_BIAS_SHARE * se)).powi(2)).ceil() as u64)
}

/// The coverage part of a discrete reading's verdict.
pub(crate) fn coverage_verdict(report: &SamplingReport) -> Reliability {
    let c = report.sampling.coverage;
    let mut r = Reliability::new(if c < COVERAGE_UNUSABLE {
        Verdict::Unusable
    } else if c < COVERAGE_OK {
        Verdict::Undersampled
    } else {
        Verdict::Ok
    });
    if r.verdict != Verdict::Ok {
        r.lines_needed = report.lines_for_coverage;
    }
    r
}

/// The verdict on an estimate unbiased whatever the coverage ([`VerdictRule::UnbiasedEstimate`]): `ok`
/// at a coverage of [`COVERAGE_UNUSABLE`] and above; below it, `ok` only when its standard error is the
/// jackknife's and every row holds two segments (else as the coverage says, `unusable`). A group holds a
/// sixteenth of the lines, and rows of a few segments there make the groups' values scatter far more
/// than 4 times the run's (batch means read 4-6 times the real error on `@cube:10` to `@cube:30`), where
/// the jackknife's replicates, 15/16 of the lines each, scatter like the run (docs/results.md); and a
/// row of one segment has no unbiased estimate at all ([`Sampling::thin_rows`]).
fn unbiased_estimate_verdict(report: &SamplingReport, jackknifed: bool) -> Reliability {
    let s = &report.sampling;
    if s.coverage >= COVERAGE_UNUSABLE || (jackknifed && s.thin_rows == 0) {
        Reliability::new(Verdict::Ok)
    } else {
        coverage_verdict(report)
    }
}

/// A plug-in reading with estimated bias `bias`.
pub(crate) fn plug_in(e: Estimate, bias: f64, report: &SamplingReport, lines: u64) -> Reliability {
    let mut r = coverage_verdict(report);
    r.estimated_bias = Some(bias);
    judge_plug_in_bias(&mut r, bias, stderr(e), lines);
    r
}

/// A plug-in reading of standard error `se` whose estimated bias `bias` exceeds [`PLUG_IN_BIAS_SHARE`]
/// of it is undersampled, and needs the lines that bring the bias within that share.
fn judge_plug_in_bias(r: &mut Reliability, bias: f64, se: f64, lines: u64) {
    if plug_in_bias_too_large(bias, se) {
        r.verdict = r.verdict.max(Verdict::Undersampled);
        r.lines_needed = r.lines_needed.max(lines_for_bias(lines, bias, se));
    }
}

/// A bias-corrected reading whose coverage verdict is `r`, with the delete-a-group jackknife's estimate
/// `bias` of its remaining bias: `ok` needs that estimate within the standard error. The estimators'
/// remaining bias falls like 1 / lines^2, and for such a bias the jackknife's estimate is about
/// (2G - 1) / (G - 1) = 2.07 times the true one (16 groups): within one standard error it means a true
/// bias below about half of one, which keeps the 95% interval's coverage above 93%.
fn corrected(mut r: Reliability, e: Estimate, bias: f64, lines: u64) -> Reliability {
    r.estimated_bias = Some(bias);
    judge_corrected_bias(&mut r, bias, stderr(e), lines);
    r
}

/// A bias-corrected reading of standard error `se` whose remaining bias (the jackknife's estimate,
/// `bias`) exceeds it is undersampled, and needs the lines that bring it within the error.
fn judge_corrected_bias(r: &mut Reliability, bias: f64, se: f64, lines: u64) {
    if bias.abs() > se {
        r.verdict = r.verdict.max(Verdict::Undersampled);
        // bias / se falls like lines^-1.5.
        let for_bias = (se > 0.0 && se.is_finite())
            .then(|| (lines as f64 * (bias.abs() / se).powf(2.0 / 3.0)).ceil() as u64);
        r.lines_needed = r.lines_needed.max(for_bias);
    }
}

/// Flags every reading on corrected rows of a run whose lines are not independent (the Sobol' sampler)
/// and whose corrections the delete-a-group jackknife could not take out (an enclosed scene, Chao–Shen): the
/// entropy estimators' corrections assume independent lines, and such a reading is biased.
pub(crate) fn flag_dependent_lines(verdicts: &mut ByMeasure<Reliability>) {
    for m in Measure::ALL
        .into_iter()
        .filter(|m| m.rests_on_corrected_rows())
    {
        if let Some(r) = verdicts.get_mut(m) {
            r.flag(
                "the lines are randomised quasi-Monte Carlo (sobol): the bias correction assumes \
                 independent lines, and the jackknife that replaces it is not available here (an \
                 enclosed scene, or the Chao-Shen estimator)"
                    .into(),
            );
        }
    }
}

/// Flags a reading below 0 (an entropy or mutual information).
fn flag_negative(r: &mut Reliability, e: Estimate, what: &str) {
    if e.value < -2.0 * e.stderr.unwrap_or(0.0) {
        r.flag(format!("{what} is negative, which no scene allows"));
    }
}

/// Whether a standard error `stderr` of I_s^c is below what f32 tracing resolves: the bias `floor`
/// ([`f32_floor`]) could exceed three quarters of it. A bias of 0.75 standard errors leaves a 95%
/// interval covering 91% of the time; the floor read 1.1 times the bias measured on `@cube:1`.
pub fn below_f32_floor(floor: f64, stderr: f64) -> bool {
    floor > 0.75 * stderr
}

/// Flags an I_s^c whose standard error is so small that the chords f32 tracing loses near edges
/// ([`f32_floor`]) could bias it by more than three quarters of it ([`below_f32_floor`]): more lines
/// would not make it more accurate.
fn flag_below_f32_floor(r: &mut Reliability, e: Estimate, floor: f64) {
    if below_f32_floor(floor, e.stderr.unwrap_or(f64::INFINITY)) {
        r.flag(format!(
            "its standard error is below what f32 tracing resolves: lines crossing a corner within \
             ~1e-6 of its edge are lost, which may read it up to {floor:.1e} bits low"
        ));
    }
}

/// Flags a ratio outside [0, 1].
fn flag_unit_interval(r: &mut Reliability, e: Estimate, what: &str) {
    let se = e.stderr.unwrap_or(0.0);
    if e.value < -2.0 * se || e.value > 1.0 + 2.0 * se {
        r.flag(format!("{what} is outside [0, 1], which no scene allows"));
    }
}

/// Flags a mutual information above I_s^c (Proposition 2 says I_s <= I_s^c).
fn flag_above_continuous(
    r: &mut Reliability,
    e: Estimate,
    continuous: Option<Estimate>,
    what: &str,
) {
    if let Some(c) = continuous.filter(|&c| clearly_above(e, c)) {
        r.flag(format!(
            "{what} {:.4} is above I_s^c {:.4}: Proposition 2 says I_s <= I_s^c; the rows are \
             undersampled",
            e.value, c.value
        ));
    }
}

/// What a run's verdicts are judged from besides its readings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunFacts {
    /// Lines cast, counted as `--lines` counts them (through the bounding sphere): the unit of the lines
    /// advice.
    pub lines: u64,
    /// Visible pairs.
    pub pairs: u64,
    /// Whether segments left front sides and arrived at no front side (escapes, segments to back
    /// sides): the channel is open, and its mutual information may be below 0 ([`Bound`]).
    pub open: bool,
    /// Pairs whose points are [`crate::sample::tally::SHORT_CHORD`] apart ([`f32_floor`]).
    pub short_chords: u64,
    /// Whether the discrete readings' standard errors are the delete-a-group jackknife's
    /// (`--errors jackknife`) rather than batch means of the groups.
    pub jackknifed: bool,
}

/// Bits of eq. (27) lost per short chord counted ([`RunFacts::short_chords`]) when f32 tracing misses the
/// chords across a corner that are shorter than about 2e-6 (a line that close to an edge is put beyond
/// it for both triangles by the watertight test, and reads as a miss). Near an edge the chords' lengths
/// are uniformly distributed (measured: each decade of length below 1e-3 holds a tenth of the one above),
/// so a count over [1e-5, 1e-4) predicts a 45th as many below 2e-6, each carrying about 42 bits
/// (`-2 log2 d` and the cosines). Measured on `@cube:1` at 10^8 lines: I_s^c read 5.5e-5 low; this
/// estimate gives 6.0e-5 (docs/scenes.md, stiff geometry).
pub const BITS_PER_SHORT_CHORD: f64 = 42.0 / 45.0;

/// How low f32 tracing may read I_s^c (eq. 27) on a run of `pairs` visible pairs of which
/// `short_chords` were [`crate::sample::tally::SHORT_CHORD`] long: the chords it loses near edges
/// ([`BITS_PER_SHORT_CHORD`]) over the pairs.
pub fn f32_floor(pairs: u64, short_chords: u64) -> f64 {
    if pairs == 0 {
        return 0.0;
    }
    BITS_PER_SHORT_CHORD * short_chords as f64 / pairs as f64
}

/// What the verdicts of a family's readings are judged from.
struct Evidence<'a> {
    estimates: &'a ByMeasure<Estimate>,
    /// The delete-a-group jackknife's estimate of each discrete reading's bias, when there is one.
    bias: Option<&'a ByMeasure<f64>>,
    /// The rows' sampling, when the pairs were counted.
    sampling: Option<&'a SamplingReport>,
    lines: u64,
    pairs: u64,
    open: bool,
    /// [`RunFacts::jackknifed`].
    jackknifed: bool,
    /// [`f32_floor`].
    f32_floor: f64,
}

impl Evidence<'_> {
    fn estimate(&self, m: Measure) -> Option<Estimate> {
        self.estimates.get(m).copied()
    }

    /// The rows' sampling and the estimated bias of the family's plug-in entropy, when both are known:
    /// every verdict of a discrete reading needs them.
    fn discrete(&self, family: Family) -> Option<(&SamplingReport, f64)> {
        let (plain, corrected) = family.entropies();
        let bias = self.estimate(plain)?.value - self.estimate(corrected)?.value;
        Some((self.sampling?, bias))
    }
}

/// The verdicts on every reading of a run ([`VerdictRule`] of each measure's catalogue entry);
/// `sampling` is the rows' sampling when the pairs were counted. A reading without a standard error (too
/// few groups with lines) is `unusable`: nothing tells how far off it is.
pub fn verdicts(
    estimates: &ByMeasure<Estimate>,
    sampling: Option<&SamplingReport>,
    bias: Option<&ByMeasure<f64>>,
    facts: RunFacts,
) -> ByMeasure<Reliability> {
    let evidence = Evidence {
        estimates,
        bias,
        sampling,
        lines: facts.lines,
        pairs: facts.pairs,
        open: facts.open,
        jackknifed: facts.jackknifed,
        f32_floor: f32_floor(facts.pairs, facts.short_chords),
    };
    let mut out = ByMeasure::default();
    for (m, &e) in estimates.iter() {
        let r = verdict(&evidence, &out, m, e);
        out.set(m, r);
    }
    for (m, e) in estimates.iter() {
        if let (Some(r), None) = (out.get_mut(m), e.stderr) {
            r.verdict = Verdict::Unusable;
        }
    }
    out
}

/// The verdict on reading `e` of measure `m`, given the verdicts `so_far` of the measures before it.
fn verdict(
    evidence: &Evidence,
    so_far: &ByMeasure<Reliability>,
    m: Measure,
    e: Estimate,
) -> Option<Reliability> {
    let info = m.info();
    let continuous = evidence.estimate(Measure::ContinuousMutualInformation);
    let mut r = match info.verdict {
        VerdictRule::Exact => return None,
        VerdictRule::Mean => {
            Reliability::new(if evidence.pairs >= MIN_PAIRS && e.stderr.is_some() {
                Verdict::Ok
            } else {
                Verdict::Unusable
            })
        }
        VerdictRule::PlugIn { sign } => {
            let (report, bias) = evidence.discrete(info.family)?;
            plug_in(e, sign * bias, report, evidence.lines)
        }
        VerdictRule::Corrected => {
            let r = coverage_verdict(evidence.discrete(info.family)?.0);
            match evidence.bias.and_then(|b| b.of(m)) {
                Some(bias) => corrected(r, e, bias, evidence.lines),
                None => r,
            }
        }
        VerdictRule::RatioOf { of, sign } => {
            evidence.discrete(info.family)?;
            // The ratio inherits the verdict of its I_s, not its flags (they are I_s's).
            let mut r = so_far
                .get(of)
                .cloned()
                .unwrap_or_else(|| Reliability::new(Verdict::Unusable));
            r.flags.clear();
            // Nor is the ratio worth more than its denominator.
            if let Some(c) = so_far.get(Measure::ContinuousMutualInformation) {
                r.verdict = r.verdict.max(c.verdict);
            }
            r.estimated_bias = r
                .estimated_bias
                .zip(continuous)
                .map(|(b, c)| sign * b / c.value);
            // The ratio's bias is its I_s's over I_s^c, but its error is smaller than I_s's over I_s^c
            // (the two move together from group to group), so a bias within I_s's error can be beyond
            // the ratio's: judged against the ratio's own error, as its I_s is against its own
            // (`@tetrahedron:4` at 1e6 lines: the ok plug-in accuracies covered 76% when they followed
            // I_s alone).
            if let Some(bias) = r.estimated_bias {
                match of.info().verdict {
                    VerdictRule::Corrected => {
                        judge_corrected_bias(&mut r, bias, stderr(e), evidence.lines)
                    }
                    _ => judge_plug_in_bias(&mut r, bias, stderr(e), evidence.lines),
                }
            }
            r
        }
        VerdictRule::UnbiasedEstimate => {
            let r =
                unbiased_estimate_verdict(evidence.discrete(info.family)?.0, evidence.jackknifed);
            match evidence.bias.and_then(|b| b.of(m)) {
                Some(bias) => corrected(r, e, bias, evidence.lines),
                None => r,
            }
        }
        VerdictRule::Unbiased => {
            let (report, _) = evidence.discrete(info.family)?;
            // The rows' multinomial estimate of the plug-in's bias, unless the jackknife gives one (Sobol'
            // lines or bundles, whose rows are no multinomial samples).
            let bias = evidence
                .bias
                .and_then(|b| b.of(m))
                .unwrap_or(report.sampling.mse_bias);
            let mut r = Reliability::new(if plug_in_bias_too_large(bias, stderr(e)) {
                Verdict::Undersampled
            } else {
                Verdict::Ok
            });
            r.estimated_bias = Some(bias);
            r.lines_needed = lines_for_bias(evidence.lines, bias, stderr(e));
            r
        }
    };
    let closed = !evidence.open;
    match info.bound {
        Bound::None => {}
        Bound::NonNegative => flag_negative(&mut r, e, info.flag_name),
        Bound::MutualInformation => {
            if closed {
                flag_negative(&mut r, e, info.flag_name);
            }
            flag_above_continuous(&mut r, e, continuous, info.flag_name);
        }
        Bound::ContinuousMutualInformation => {
            if closed {
                flag_negative(&mut r, e, info.flag_name);
            }
            flag_below_f32_floor(&mut r, e, evidence.f32_floor);
        }
        Bound::UnitInterval => {
            if closed {
                flag_unit_interval(&mut r, e, info.flag_name);
            }
            // Without a standard error nothing is distinguishable, and the reading is unusable anyway.
            if continuous.is_some_and(|c| c.stderr.is_some() && c.value.abs() <= 3.0 * stderr(c)) {
                r.verdict = Verdict::Unusable;
                r.flags
                    .push("I_s^c is not distinguishable from 0, so the ratio means nothing".into());
            }
        }
    }
    Some(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn est(value: f64, stderr: f64) -> Option<Estimate> {
        Some(Estimate {
            value,
            stderr: Some(stderr),
        })
    }

    fn report(coverage: f64) -> SamplingReport {
        SamplingReport {
            sampling: Sampling {
                rows: 100,
                sampled_rows: 100,
                segments_per_row: 1000.0,
                coverage,
                singleton_share: 0.1,
                mse_bias: -0.001,
                thin_rows: 0,
            },
            lines_for_coverage: Some(5_000_000),
            from_half: HalfRun::NotComputed,
            advice: LinesAdvice::Estimate,
        }
    }

    fn readings(h: f64, hc: f64, isc: f64) -> ByMeasure<Estimate> {
        ByMeasure::from_fn(|m| match m {
            Measure::PositionalEntropy => est(9.0, 0.0),
            Measure::Entropy => est(h, 0.001),
            Measure::EntropyCorrected => est(hc, 0.001),
            Measure::JointEntropy => est(9.0 + h, 0.001),
            Measure::MutualInformation => est(9.0 - h, 0.001),
            Measure::MutualInformationCorrected => est(9.0 - hc, 0.001),
            Measure::ContinuousMutualInformation => est(isc, 0.001),
            Measure::Accuracy => est((9.0 - h) / isc, 0.001),
            Measure::AccuracyCorrected => est((9.0 - hc) / isc, 0.001),
            Measure::RelativeError => est(1.0 - (9.0 - h) / isc, 0.001),
            Measure::MsePerLine => est(500.0, 0.01),
            Measure::MsePerLineCorrected => est(500.001, 0.01),
            _ => None,
        })
    }

    fn closed(lines: u64, pairs: u64) -> RunFacts {
        RunFacts {
            lines,
            pairs,
            open: false,
            short_chords: 0,
            jackknifed: false,
        }
    }

    fn of(r: &ByMeasure<Reliability>, m: Measure) -> Reliability {
        r.get(m).cloned().expect("a verdict")
    }

    /// A bias-corrected reading on well covered rows is ok only while the jackknife's estimate of its
    /// remaining bias is within its standard error (0.001 here); beyond, it is undersampled and the lines
    /// it needs grow like (bias / se)^(2/3) (its bias falls like 1 / lines^2, its error like
    /// 1 / sqrt(lines)); its corrected accuracy follows it.
    #[test]
    fn corrected_readings_need_their_jackknife_bias_within_the_error() {
        let v = readings(7.8, 7.8005, 1.6);
        let bias = |b: f64| {
            ByMeasure::from_fn(|m| (m == Measure::MutualInformationCorrected).then_some(b))
        };
        let small = bias(0.0008);
        let r = verdicts(
            &v,
            Some(&report(0.999)),
            Some(&small),
            closed(1_000_000, 1_000_000),
        );
        let c = of(&r, Measure::MutualInformationCorrected);
        assert_eq!((c.verdict, c.estimated_bias), (Verdict::Ok, Some(0.0008)));
        let large = bias(-0.008);
        let r = verdicts(
            &v,
            Some(&report(0.999)),
            Some(&large),
            closed(1_000_000, 1_000_000),
        );
        let c = of(&r, Measure::MutualInformationCorrected);
        assert_eq!(c.verdict, Verdict::Undersampled);
        assert_eq!(c.lines_needed, Some(4_000_000), "1e6 x 8^(2/3)");
        assert_eq!(
            of(&r, Measure::AccuracyCorrected).verdict,
            Verdict::Undersampled
        );
        // Without a bias estimate (no replicates) the coverage alone decides.
        let r = verdicts(&v, Some(&report(0.999)), None, closed(1_000_000, 1_000_000));
        assert_eq!(
            of(&r, Measure::MutualInformationCorrected).verdict,
            Verdict::Ok
        );
    }

    /// Well sampled rows: every reading ok; a plug-in far from its correction: undersampled, with the
    /// lines to fix it; low coverage: unusable.
    #[test]
    fn verdicts_follow_coverage_and_the_plug_in_bias() {
        let r = verdicts(
            &readings(7.8, 7.8004, 1.6),
            Some(&report(0.999)),
            None,
            closed(1_000_000, 1_000_000),
        );
        assert_eq!(of(&r, Measure::MutualInformation).verdict, Verdict::Ok);
        assert_eq!(
            of(&r, Measure::MutualInformationCorrected).verdict,
            Verdict::Ok
        );
        assert_eq!(
            of(&r, Measure::ContinuousMutualInformation).verdict,
            Verdict::Ok
        );

        let r = verdicts(
            &readings(7.6, 7.8, 1.6),
            Some(&report(0.999)),
            None,
            closed(1_000_000, 1_000_000),
        );
        let mi = of(&r, Measure::MutualInformation);
        assert_eq!(mi.verdict, Verdict::Undersampled);
        assert!((mi.estimated_bias.unwrap() - 0.2).abs() < 1e-12);
        // (0.2 / (0.5 x 0.001))^2 times the lines: the bias within half the error.
        let needed = mi.lines_needed.unwrap() as f64;
        assert!((needed / 1.6e11 - 1.0).abs() < 1e-9, "{needed}");
        assert_eq!(
            of(&r, Measure::MutualInformationCorrected).verdict,
            Verdict::Ok
        );

        let r = verdicts(
            &readings(5.0, 7.5, 1.6),
            Some(&report(0.3)),
            None,
            closed(100_000, 100_000),
        );
        assert_eq!(
            of(&r, Measure::MutualInformationCorrected).verdict,
            Verdict::Unusable
        );
        // E(MSE) has an unbiased estimate whatever the coverage: its bias (0.001) is within 0.01.
        assert_eq!(of(&r, Measure::MsePerLine).verdict, Verdict::Ok);
    }

    /// A plug-in reading is ok while its estimated bias is within half its standard error (a bias of
    /// 0.7 errors leaves the 95% interval covering about 89%), and a ratio's bias is judged against the
    /// ratio's own error: the accuracy's (0.0004 here) is smaller than I_s's over I_s^c (0.001 / 2.5),
    /// so a bias that I_s carries as ok (0.0004, 0.4 of its error) is 0.40 of the accuracy's.
    #[test]
    fn plug_in_readings_are_ok_within_half_their_error_and_ratios_within_their_own() {
        let judged = |h: f64, hc: f64, accuracy_se: f64| {
            let mut v = readings(h, hc, 2.5);
            v.set(Measure::Accuracy, est((9.0 - h) / 2.5, accuracy_se));
            verdicts(&v, Some(&report(0.999)), None, closed(1_000_000, 1_000_000))
        };
        // Estimated bias of I_s: hc - h.
        let r = judged(7.8, 7.8004, 0.001);
        assert_eq!(of(&r, Measure::MutualInformation).verdict, Verdict::Ok);
        assert_eq!(of(&r, Measure::Accuracy).verdict, Verdict::Ok);
        let r = judged(7.8, 7.8007, 0.001);
        let mi = of(&r, Measure::MutualInformation);
        assert_eq!(mi.verdict, Verdict::Undersampled);
        // (0.0007 / 0.0005)^2 = 1.96 times the lines (rounded up).
        let needed = mi.lines_needed.unwrap() as f64;
        assert!((needed / 1.96e6 - 1.0).abs() < 1e-5, "{needed}");
        // I_s ok at 0.4 of its error; the accuracy's bias, 0.0004 / 2.5 = 0.00016, is 0.4 of an error of
        // 0.0004 (ok) but 0.64 of 0.00025 (undersampled, though I_s is ok).
        let r = judged(7.8, 7.8004, 0.0004);
        assert_eq!(of(&r, Measure::Accuracy).verdict, Verdict::Ok);
        let r = judged(7.8, 7.8004, 0.00025);
        assert_eq!(of(&r, Measure::MutualInformation).verdict, Verdict::Ok);
        let accuracy = of(&r, Measure::Accuracy);
        assert_eq!(accuracy.verdict, Verdict::Undersampled);
        assert!((accuracy.estimated_bias.unwrap() - 0.00016).abs() < 1e-12);
    }

    /// The unbiased E(MSE) needs no coverage of the rows, only rows above the `unusable` floor; a
    /// jackknife estimate of its bias beyond its standard error (rows that are no multinomial samples)
    /// makes it `undersampled`.
    #[test]
    fn the_unbiased_e_mse_is_ok_below_the_coverage_of_corrected_entropies() {
        let judged = |coverage: f64, bias: Option<f64>, thin_rows: usize, jackknifed: bool| {
            let bias = bias
                .map(|b| ByMeasure::from_fn(|m| (m == Measure::MsePerLineCorrected).then_some(b)));
            let mut sampling = report(coverage);
            sampling.sampling.thin_rows = thin_rows;
            let r = verdicts(
                &readings(7.6, 7.8, 1.6),
                Some(&sampling),
                bias.as_ref(),
                RunFacts {
                    jackknifed,
                    ..closed(1_000_000, 1_000_000)
                },
            );
            (
                of(&r, Measure::MsePerLineCorrected).verdict,
                of(&r, Measure::EntropyCorrected).verdict,
            )
        };
        let at = |coverage: f64, bias: Option<f64>| judged(coverage, bias, 0, false);
        assert_eq!(at(0.8, None), (Verdict::Ok, Verdict::Undersampled));
        assert_eq!(at(0.999, None), (Verdict::Ok, Verdict::Ok));
        assert_eq!(at(0.4, None), (Verdict::Unusable, Verdict::Unusable));
        assert_eq!(at(0.8, Some(0.005)).0, Verdict::Ok);
        assert_eq!(at(0.8, Some(0.05)).0, Verdict::Undersampled);
        // Below the coverage of 0.5, batch means overstate its error and leave it unusable; the
        // jackknife's error makes it ok, while every row holds the two segments its estimate needs and
        // the jackknife's bias stays within the error.
        let thin = |rows: usize, jackknifed: bool| judged(0.3, Some(0.001), rows, jackknifed).0;
        assert_eq!(thin(0, false), Verdict::Unusable);
        assert_eq!(thin(0, true), Verdict::Ok);
        assert_eq!(thin(3, true), Verdict::Unusable);
        assert_eq!(judged(0.3, Some(0.05), 0, true).0, Verdict::Undersampled);
    }

    /// Readings beyond the theory's bounds are flagged and never ok.
    #[test]
    fn impossible_readings_are_flagged() {
        // I_s = 3 > I_s^c = 1.6: Proposition 2 broken, accuracy 1.9 > 1.
        let r = verdicts(
            &readings(6.0, 6.0, 1.6),
            Some(&report(0.999)),
            None,
            closed(1_000_000, 1_000_000),
        );
        let mi = of(&r, Measure::MutualInformation);
        assert!(
            mi.flags.iter().any(|f| f.contains("Proposition 2")),
            "{mi:?}"
        );
        assert_ne!(mi.verdict, Verdict::Ok);
        assert!(!of(&r, Measure::Accuracy).flags.is_empty());
        // A negative I_s^c, and a ratio over an I_s^c indistinguishable from 0.
        let mut v = readings(7.8, 7.8, -0.5);
        v.set(Measure::ContinuousMutualInformation, est(-0.5, 0.01));
        let r = verdicts(&v, Some(&report(0.999)), None, closed(100, 16));
        assert!(!of(&r, Measure::ContinuousMutualInformation)
            .flags
            .is_empty());
        let mut v = readings(7.8, 7.8, 0.0005);
        v.set(Measure::ContinuousMutualInformation, est(0.0005, 0.001));
        let r = verdicts(&v, Some(&report(0.999)), None, closed(1_000_000, 1_000_000));
        assert_eq!(of(&r, Measure::Accuracy).verdict, Verdict::Unusable);
    }

    /// In an open scene a mutual information below 0 is no broken bound (two small squares far apart
    /// read about -5 bits per pair); I_s above I_s^c still is.
    #[test]
    fn open_scenes_may_read_below_zero() {
        let open = RunFacts {
            open: true,
            ..closed(1_000_000, 1_000_000)
        };
        let mut v = readings(7.8, 7.8, -0.5);
        v.set(Measure::MutualInformation, est(-0.6, 0.01));
        v.set(Measure::MutualInformationCorrected, est(-0.6, 0.01));
        v.set(Measure::ContinuousMutualInformation, est(-0.5, 0.01));
        let r = verdicts(&v, Some(&report(0.999)), None, open);
        assert!(of(&r, Measure::ContinuousMutualInformation)
            .flags
            .is_empty());
        assert!(of(&r, Measure::MutualInformation).flags.is_empty());
        let closed = verdicts(&v, Some(&report(0.999)), None, closed(1_000_000, 1_000_000));
        assert!(!of(&closed, Measure::ContinuousMutualInformation)
            .flags
            .is_empty());
        v.set(Measure::MutualInformation, est(-0.3, 0.01));
        let r = verdicts(&v, Some(&report(0.999)), None, open);
        assert!(of(&r, Measure::MutualInformation)
            .flags
            .iter()
            .any(|f| f.contains("Proposition 2")));
    }

    /// The advice is what its two extrapolations say: none when the coverage is reached or beyond reach,
    /// a lower bound when it grew past 1.25 times from half the lines or the half could not reach the
    /// coverage, an estimate otherwise (and when there was no half to compare with).
    #[test]
    fn lines_advice_from_all_and_half_the_lines() {
        let advice = |all: Option<u64>, half: HalfRun| {
            let r = SamplingReport::new(report(0.95).sampling, 1_000_000, all, half);
            (r.advice, r.advice_growth())
        };
        let m = 1_000_000u64;
        assert_eq!(
            advice(Some(m), HalfRun::NotComputed),
            (LinesAdvice::Reached, None)
        );
        assert_eq!(
            advice(None, HalfRun::BeyondReach),
            (LinesAdvice::BeyondReach, None)
        );
        assert_eq!(
            advice(Some(4 * m), HalfRun::BeyondReach),
            (LinesAdvice::LowerBound, None)
        );
        assert_eq!(
            advice(Some(4 * m), HalfRun::NotComputed),
            (LinesAdvice::Estimate, None)
        );
        assert_eq!(
            advice(Some(4 * m), HalfRun::Lines(2 * m)),
            (LinesAdvice::LowerBound, Some(2.0))
        );
        assert_eq!(
            advice(Some(6 * m), HalfRun::Lines(5 * m)),
            (LinesAdvice::Estimate, Some(1.2))
        );
        // Shrinking from half the lines (a far extrapolation from a low coverage) is no sign of a bound.
        assert_eq!(
            advice(Some(4 * m), HalfRun::Lines(5 * m)),
            (LinesAdvice::Estimate, Some(0.8))
        );
        assert_eq!(LinesAdvice::LowerBound.code(), "lower-bound");
    }

    /// I_s^c is flagged when the chords f32 tracing loses near edges could bias it by more than 3/4 of its
    /// standard error (`@cube:1` at 10^8 Sobol' lines: 6.5e-5 short chords per pair, a floor of 6.0e-5
    /// bits against a standard error of 4e-5); at 10 times the standard error (10^7 lines) it is not.
    #[test]
    fn i_s_c_below_the_f32_floor_is_flagged() {
        let facts = |stderr_lines: u64| RunFacts {
            short_chords: 4132 * stderr_lines / 100_000_000,
            ..closed(stderr_lines, 637 * stderr_lines / 1000)
        };
        let f = facts(100_000_000);
        let floor = f32_floor(f.pairs, f.short_chords);
        assert!((floor - 6.06e-5).abs() < 1e-6, "{floor}");
        for (lines, stderr, flagged) in [(100_000_000, 4e-5, true), (10_000_000, 1.5e-4, false)] {
            let mut v = readings(7.8, 7.8, 1.61);
            v.set(Measure::ContinuousMutualInformation, est(1.61, stderr));
            let r = of(
                &verdicts(&v, Some(&report(0.999)), None, facts(lines)),
                Measure::ContinuousMutualInformation,
            );
            assert_eq!(
                r.flags.iter().any(|f| f.contains("f32 tracing")),
                flagged,
                "{r:?}"
            );
            assert_eq!(r.verdict == Verdict::Ok, !flagged, "{r:?}");
        }
    }
}
