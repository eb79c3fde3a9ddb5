//! The labels of a picture's colour bar: both ends always, the round ticks between them, and values the
//! reader must find on the bar (such as 0 where the theory bounds the values).
//!
//! An end of the scale is seldom a round value (it is an area quantile of the patches' values, or what
//! `--range` says), so its label is rounded to three significant digits and, on a linear scale, to the
//! scale's precision too: the decade at or below a thousandth of the span (a bar's pixel is a few
//! thousandths), so that floating-point dust such as `-6.4e-16` on a scale to 0.49 reads `0`.

use super::colour::{log_ticks, nice_ticks, short_number, ColourScale};

/// One label of a colour bar.
#[derive(Clone, Debug, PartialEq)]
pub struct BarLabel {
    /// The value marked.
    pub value: f64,
    /// Where it is on the bar, from 0 (the low end) to 1 (the high end).
    pub position: f64,
    /// What the label says (`≤ 0`, `0.25`, `≥ 0.494`).
    pub text: String,
}

/// The most round ticks a bar carries between its ends.
const MOST_TICKS: usize = 5;

/// The labels of a bar `length` pixels long whose labels need `gap` pixels each: both ends, marked `≤`
/// (`≥`) when values beyond them are drawn in the end's colour (`clipped`: low, high); every value of
/// `marks` within the scale and `gap` from the ends; then evenly spaced round ticks that keep `gap` from
/// every label and each other. Sorted from the low end.
pub fn bar_labels(
    scale: &ColourScale,
    clipped: (bool, bool),
    marks: &[f64],
    length: f64,
    gap: f64,
) -> Vec<BarLabel> {
    let pixel = |p: f64| p * length;
    let mut labels = vec![
        end_label(scale, scale.lo, clipped.0, "≤"),
        end_label(scale, scale.hi, clipped.1, "≥"),
    ];
    let clear_of = |labels: &[BarLabel], p: f64| {
        labels
            .iter()
            .all(|l| (pixel(l.position) - pixel(p)).abs() >= gap)
    };
    for &m in marks {
        let p = scale.position(m);
        if m > scale.lo && m < scale.hi && clear_of(&labels, p) {
            labels.push(BarLabel {
                value: m,
                position: p,
                text: short_number(m),
            });
        }
    }
    let ticks = round_ticks(scale, &labels, length, gap);
    labels.extend(ticks);
    labels.sort_by(|a, b| a.position.total_cmp(&b.position));
    labels
}

/// The round ticks between the labels so far: of the sets of round values [`nice_ticks`] offers (or
/// [`log_ticks`] on a log scale over a decade) whose ticks keep clear of each other, the one that leaves
/// nearest one tick per three label heights clear of the labels, the coarsest on a tie.
fn round_ticks(scale: &ColourScale, placed: &[BarLabel], length: f64, gap: f64) -> Vec<BarLabel> {
    let wanted = ((length / (3.0 * gap)).round() as usize).clamp(1, MOST_TICKS);
    let candidates: Vec<Vec<f64>> = if scale.log && scale.hi / scale.lo > 10.0 {
        let ticks = log_ticks(scale.lo, scale.hi);
        // Coarser: the powers of ten among them, then every second and third.
        let decades: Vec<f64> = ticks
            .iter()
            .copied()
            .filter(|t| (t.log10() - t.log10().round()).abs() < 1e-9)
            .collect();
        let every = |n: usize| decades.iter().copied().step_by(n).collect();
        vec![ticks.clone(), every(1), every(2), every(3)]
    } else {
        (2..=MOST_TICKS + 2)
            .map(|about| nice_ticks(scale.lo, scale.hi, about))
            .collect()
    };
    candidates
        .iter()
        .filter_map(|values| clear_ticks(scale, values, placed, length, gap))
        .min_by_key(|ticks| ticks.len().abs_diff(wanted))
        .unwrap_or_default()
}

/// The label of an end of the scale at `value`, after `mark` when values beyond it are clipped.
fn end_label(scale: &ColourScale, value: f64, clipped: bool, mark: &str) -> BarLabel {
    let text = end_text(scale, value);
    BarLabel {
        value,
        position: scale.position(value),
        text: if clipped {
            format!("{mark} {text}")
        } else {
            text
        },
    }
}

/// `value`, an end of `scale`, rounded to the scale's precision (module documentation).
pub fn end_text(scale: &ColourScale, value: f64) -> String {
    if scale.log {
        return short_number(significant(value, 3));
    }
    let span = scale.hi - scale.lo;
    if !(span > 0.0 && span.is_finite()) {
        return short_number(significant(value, 3));
    }
    let step = 10f64.powf((span / 1000.0).log10().floor());
    let rounded = (significant(value, 3) / step).round() * step;
    // `-0` and dust read 0.
    if rounded.abs() < 0.5 * step {
        "0".into()
    } else {
        short_number(rounded)
    }
}

/// `v` to `digits` significant digits.
fn significant(v: f64, digits: usize) -> f64 {
    format!("{v:.*e}", digits.saturating_sub(1))
        .parse()
        .unwrap_or(v)
}

/// The labels of `values` that keep `gap` pixels from `placed`; `None` when two of them crowd each
/// other (dropping one would leave the ticks unevenly spaced: a coarser set does better).
fn clear_ticks(
    scale: &ColourScale,
    values: &[f64],
    placed: &[BarLabel],
    length: f64,
    gap: f64,
) -> Option<Vec<BarLabel>> {
    let mut kept: Vec<BarLabel> = Vec::new();
    for &value in values {
        let position = scale.position(value);
        let clear = |l: &BarLabel| ((l.position - position) * length).abs() >= gap;
        if !placed.iter().all(clear) {
            continue;
        }
        if !kept.iter().all(clear) {
            return None;
        }
        kept.push(BarLabel {
            value,
            position,
            text: short_number(value),
        });
    }
    Some(kept)
}
