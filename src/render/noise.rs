//! Whether a picture's colours are mostly noise, and how many lines would make them signal.
//!
//! A fine mesh at a modest line count leaves many patches with a handful of segments: their per-patch
//! terms scatter by tens of percent from run to run, and patches no line left have no value at all,
//! yet the picture looks as confident as a converged one. This module measures that from the run's own
//! standard errors, so that `scx render` can say so.
//!
//! Statistics are area-weighted, because a picture shows area: a few thousand noisy slivers under one
//! well-sampled wall do not make it noisy, and one noisy wall among many small sampled patches does.

use crate::analysis::PatchResult;
use crate::measure::PatchMeasure;

use super::colour::Quantity;

/// The relative standard error the advice aims at: colours within about 10% of their value.
pub const TARGET_RELATIVE_ERROR: f64 = 0.10;
/// Above this area-weighted median relative standard error the colours are called noise: at 20% a
/// patch's colour could as well be its neighbour's on a scale spanning a factor of two.
pub const NOISY_RELATIVE_ERROR: f64 = 0.20;
/// Above this fraction of the area without a value the picture is called mostly unsampled.
pub const NOISY_UNSAMPLED_AREA: f64 = 0.10;
/// Segments a patch should expect before its value means something (the advice for unsampled patches).
pub const SEGMENTS_WANTED: f64 = 10.0;

/// How noisy the values a picture colours its patches by are (from [`noise_summary`]).
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseSummary {
    /// Lines of the run behind the values.
    pub lines: u64,
    /// Patches in the scene.
    pub patches: usize,
    /// Patches without a value: no segment left them.
    pub unsampled_patches: usize,
    /// Their share of the scene's area, 0 to 1.
    pub unsampled_area: f64,
    /// Patches with a value of exactly 0 and no scatter between groups (every segment escaped or met a
    /// back side, so the term is 0 in every group: its relative error is unknown, not small).
    pub zero_patches: usize,
    /// Their share of the scene's area, 0 to 1.
    pub zero_area: f64,
    /// The area-weighted median of `stderr / |value|` over the patches with a nonzero value and a
    /// standard error (`None`: no such patch).
    pub median_relative_error: Option<f64>,
    /// Lines that would bring that median to [`TARGET_RELATIVE_ERROR`] (errors fall as 1/sqrt(lines)).
    pub lines_for_precision: Option<f64>,
    /// The area-weighted median of the segments leaving a sampled patch (`None`: none sampled).
    pub median_segments: Option<f64>,
    /// Whether the quantity is a term of a form-factor row's entropy (plug-in or corrected) and the
    /// median row holds fewer than [`SEGMENTS_WANTED`] segments: such terms are biased by far more than
    /// their standard error says, which measures the scatter only.
    pub sparse_rows: bool,
    /// Lines at which an unsampled patch of the median unsampled area would expect
    /// [`SEGMENTS_WANTED`] segments, from the segments per unit area the run saw (global lines meet
    /// every surface in proportion to its area, seen or hidden).
    pub lines_for_coverage: Option<f64>,
}

impl NoiseSummary {
    /// Whether the picture is mostly noise: the median relative error above [`NOISY_RELATIVE_ERROR`],
    /// or more than [`NOISY_UNSAMPLED_AREA`] of the area without a value.
    /// Also when the rows behind a discrete term are too sparse ([`NoiseSummary::sparse_rows`]).
    pub fn is_noisy(&self) -> bool {
        self.median_relative_error
            .is_some_and(|r| r > NOISY_RELATIVE_ERROR)
            || self.unsampled_area > NOISY_UNSAMPLED_AREA
            || self.sparse_rows
    }

    /// Lines at which the median sampled patch would hold [`SEGMENTS_WANTED`] segments, when the rows
    /// are sparse.
    fn lines_for_rows(&self) -> Option<f64> {
        let median = self.median_segments.filter(|_| self.sparse_rows)?;
        Some(self.lines as f64 * SEGMENTS_WANTED / median)
    }

    /// The lines the advice asks for: enough for the precision wanted and, when the unsampled area is
    /// over [`NOISY_UNSAMPLED_AREA`], for the coverage wanted (a few unsampled slivers would otherwise
    /// ask for orders of magnitude more lines than the picture needs).
    pub fn lines_needed(&self) -> Option<f64> {
        let wanted = [
            self.lines_for_precision,
            self.coverage_wanted(),
            self.lines_for_rows(),
        ];
        wanted
            .into_iter()
            .flatten()
            .filter(|&n| n > self.lines as f64)
            .reduce(f64::max)
    }

    /// [`NoiseSummary::lines_for_coverage`] when the unsampled area makes the picture noisy.
    fn coverage_wanted(&self) -> Option<f64> {
        self.lines_for_coverage
            .filter(|_| self.unsampled_area > NOISY_UNSAMPLED_AREA)
    }

    /// The warning for a person, naming `what` is coloured (`None` when the picture is not noisy).
    pub fn warning(&self, what: &str) -> Option<String> {
        if !self.is_noisy() {
            return None;
        }
        let mut facts = Vec::new();
        if let Some(n) = self.median_segments.filter(|_| self.sparse_rows) {
            facts.push(format!(
                "the median patch was left by {n} segments, too few for a row's entropy: its terms \
                 are biased by more than their standard error"
            ));
        }
        if let Some(r) = self.median_relative_error {
            facts.push(format!(
                "the values have a median relative standard error of {} (area-weighted)",
                percent(r)
            ));
        }
        if self.unsampled_patches > 0 {
            facts.push(format!(
                "{} of the area ({} of {} patches) has no value (no line left it)",
                percent(self.unsampled_area),
                self.unsampled_patches,
                self.patches
            ));
        }
        if self.zero_patches > 0 {
            facts.push(format!(
                "{} ({} patches) shows exactly 0 in every group of lines, so its error is unknown",
                percent(self.zero_area),
                self.zero_patches
            ));
        }
        Some(format!(
            "the colours ({what}) are mostly noise at {} lines: {}{}",
            self.lines,
            facts.join("; "),
            self.advice()
        ))
    }

    /// What more lines would give, for [`NoiseSummary::warning`] (empty when nothing would help).
    fn advice(&self) -> String {
        let Some(n) = self.lines_needed() else {
            return String::new();
        };
        let mut gains = Vec::new();
        if self
            .lines_for_precision
            .is_some_and(|p| p > self.lines as f64)
        {
            gains.push(format!(
                "bring the median error to {}",
                percent(TARGET_RELATIVE_ERROR)
            ));
        }
        if self.lines_for_rows().is_some() {
            gains.push(format!(
                "leave the median patch by about {SEGMENTS_WANTED} segments"
            ));
        }
        if self.coverage_wanted().is_some() {
            gains.push(format!(
                "give a typical unsampled patch about {SEGMENTS_WANTED} segments"
            ));
        }
        format!(
            "; about {} lines would {}",
            round_lines(n),
            gains.join(" and ")
        )
    }
}

/// `x` (0 to 1) as a percentage with two significant digits at most (`54%`, `0.5%`).
fn percent(x: f64) -> String {
    let p = 100.0 * x;
    if p > 0.0 && p < 0.1 {
        "<0.1%".to_string()
    } else if p >= 10.0 || p == 0.0 {
        format!("{p:.0}%")
    } else {
        format!("{p:.1}%")
    }
}

/// A line count to two significant digits, as `--lines` accepts it (`3.2e7`).
fn round_lines(n: f64) -> String {
    let s = format!("{n:.1e}");
    s.replace(".0e", "e")
}

/// How noisy `quantity` is over `patches` (patch `k` of the scene is entry `k`, of area `areas[k]`)
/// after `lines` lines (counted as `--lines` counts them, through the bounding sphere, so that the advice
/// is in that unit too). The segments' own relative error is that of a count, 1/sqrt(N).
pub fn noise_summary(
    patches: &[PatchResult],
    areas: &[f64],
    quantity: Quantity,
    lines: u64,
) -> NoiseSummary {
    let total: f64 = areas.iter().sum();
    let fraction = |a: f64| if total > 0.0 { a / total } else { 0.0 };
    let mut s = NoiseSummary {
        lines,
        patches: patches.len(),
        unsampled_patches: 0,
        unsampled_area: 0.0,
        zero_patches: 0,
        zero_area: 0.0,
        median_relative_error: None,
        median_segments: None,
        sparse_rows: false,
        lines_for_precision: None,
        lines_for_coverage: None,
    };
    let mut relative: Vec<(f64, f64)> = Vec::new();
    let mut unsampled_areas: Vec<f64> = Vec::new();
    for (p, &area) in patches.iter().zip(areas) {
        match relative_error(p, quantity) {
            Spread::Unsampled => {
                s.unsampled_patches += 1;
                s.unsampled_area += fraction(area);
                unsampled_areas.push(area);
            }
            Spread::Zero => {
                s.zero_patches += 1;
                s.zero_area += fraction(area);
            }
            Spread::Relative(r) => relative.push((r, area)),
            Spread::Unknown => {}
        }
    }
    s.median_relative_error = weighted_median(&mut relative);
    let mut segments: Vec<(f64, f64)> = patches
        .iter()
        .zip(areas)
        .filter(|(p, _)| p.sampled())
        .map(|(p, &a)| (p.segments as f64, a))
        .collect();
    s.median_segments = weighted_median(&mut segments);
    s.sparse_rows =
        is_row_entropy_term(quantity) && s.median_segments.is_some_and(|n| n < SEGMENTS_WANTED);
    s.lines_for_precision = s
        .median_relative_error
        .map(|r| lines as f64 * (r / TARGET_RELATIVE_ERROR).powi(2));
    s.lines_for_coverage = lines_for_coverage(patches, areas, &mut unsampled_areas, lines);
    s
}

/// Whether `quantity` is computed from a form-factor row's entropy (plug-in or corrected), whose bias
/// on sparse rows its standard error does not show.
fn is_row_entropy_term(quantity: Quantity) -> bool {
    matches!(
        quantity,
        Quantity::Patch(
            PatchMeasure::RowEntropy
                | PatchMeasure::RowEntropyCorrected
                | PatchMeasure::MutualInformationTerm
                | PatchMeasure::MutualInformationTermCorrected
                | PatchMeasure::LostInformation
                | PatchMeasure::LostInformationCorrected
        )
    )
}

/// What one patch's value says about its own precision.
enum Spread {
    /// No segment left the patch: no value.
    Unsampled,
    /// 0 in every group: the relative error is unknown.
    Zero,
    /// `stderr / |value|`.
    Relative(f64),
    /// No value or no standard error for this quantity (not computed, too few groups).
    Unknown,
}

fn relative_error(p: &PatchResult, quantity: Quantity) -> Spread {
    if !p.sampled() {
        return Spread::Unsampled;
    }
    let (value, stderr) = match quantity {
        Quantity::Segments => (p.segments as f64, Some((p.segments as f64).sqrt())),
        Quantity::Patch(m) => match p.get(m) {
            Some(e) => (e.value, e.stderr),
            None => return Spread::Unknown,
        },
    };
    match stderr {
        Some(e) if value != 0.0 => Spread::Relative(e / value.abs()),
        Some(0.0) => Spread::Zero,
        Some(_) => Spread::Relative(f64::INFINITY),
        None => Spread::Unknown,
    }
}

/// The median of `(value, weight)` pairs by weight (sorts them).
fn weighted_median(v: &mut [(f64, f64)]) -> Option<f64> {
    let total: f64 = v.iter().map(|x| x.1).sum();
    if v.is_empty() || total <= 0.0 {
        return None;
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut acc = 0.0;
    for &(x, w) in v.iter() {
        acc += w;
        if acc >= 0.5 * total {
            return Some(x);
        }
    }
    v.last().map(|x| x.0)
}

/// Lines for an unsampled patch of the median unsampled area to expect [`SEGMENTS_WANTED`]
/// segments, at the segments per unit area per line the sampled patches got.
fn lines_for_coverage(
    patches: &[PatchResult],
    areas: &[f64],
    unsampled_areas: &mut [f64],
    lines: u64,
) -> Option<f64> {
    if unsampled_areas.is_empty() || lines == 0 {
        return None;
    }
    let (segments, area) = patches
        .iter()
        .zip(areas)
        .filter(|(p, _)| p.sampled())
        .fold((0.0, 0.0), |(n, a), (p, &x)| (n + p.segments as f64, a + x));
    if segments == 0.0 || area <= 0.0 {
        return None;
    }
    let per_area_per_line = segments / area / lines as f64;
    unsampled_areas.sort_by(f64::total_cmp);
    let median = unsampled_areas[unsampled_areas.len() / 2];
    (median > 0.0).then(|| SEGMENTS_WANTED / (per_area_per_line * median))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_is_by_area() {
        let mut v = vec![(0.5, 1.0), (0.1, 3.0), (2.0, 0.5)];
        assert_eq!(weighted_median(&mut v), Some(0.1));
        let mut v = vec![(0.5, 3.0), (0.1, 1.0), (2.0, 0.5)];
        assert_eq!(weighted_median(&mut v), Some(0.5));
        assert_eq!(weighted_median(&mut []), None);
    }

    #[test]
    fn numbers_read_as_people_write_them() {
        assert_eq!(percent(0.54), "54%");
        assert_eq!(percent(0.005), "0.5%");
        assert_eq!(percent(0.0), "0%");
        assert_eq!(percent(1e-5), "<0.1%");
        assert_eq!(round_lines(3.24e7), "3.2e7");
        assert_eq!(round_lines(4.0e6), "4e6");
    }

    #[test]
    fn thresholds_decide_and_lines_follow_the_square_law() {
        let s = NoiseSummary {
            lines: 1_000_000,
            patches: 100,
            unsampled_patches: 0,
            unsampled_area: 0.0,
            zero_patches: 0,
            zero_area: 0.0,
            median_relative_error: Some(0.4),
            median_segments: Some(200.0),
            sparse_rows: false,
            lines_for_precision: Some(1e6 * 16.0),
            lines_for_coverage: None,
        };
        assert!(s.is_noisy());
        assert_eq!(s.lines_needed(), Some(1.6e7));
        let text = s.warning(PatchMeasure::RowEntropy.info().label).unwrap();
        assert_eq!(
            text,
            "the colours (row entropy H_i (plug-in)) are mostly noise at 1000000 lines: the values have a \
             median relative standard error of 40% (area-weighted); about 1.6e7 lines would bring \
             the median error to 10%"
        );
        let quiet = NoiseSummary {
            median_relative_error: Some(0.08),
            lines_for_precision: Some(0.64e6),
            unsampled_area: 0.05,
            ..s
        };
        assert!(!quiet.is_noisy() && quiet.warning("x").is_none());
        // Unsampled slivers do not drive the advice; an unsampled third of the area does.
        let slivers = NoiseSummary {
            unsampled_patches: 3,
            unsampled_area: 0.001,
            lines_for_coverage: Some(1e12),
            ..s.clone()
        };
        assert_eq!(slivers.lines_needed(), Some(1.6e7));
        let unsampled = NoiseSummary {
            unsampled_patches: 30,
            unsampled_area: 0.3,
            lines_for_coverage: Some(5e6),
            ..quiet
        };
        assert!(unsampled.is_noisy());
        assert_eq!(unsampled.lines_needed(), Some(5e6));
        let text = unsampled.warning("x").unwrap();
        assert!(
            text.ends_with(
                "30% of the area (30 of 100 patches) has no value (no line left it); about 5e6 \
                 lines would give a typical unsampled patch about 10 segments"
            ),
            "{text}"
        );
    }
}
