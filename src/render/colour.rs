//! What a picture colours its patches by, and how: a per-patch quantity of the run mapped through
//! viridis (perceptually uniform, readable with the common colour-vision deficiencies and in grey).

use crate::analysis::PatchResult;
use crate::measure::{PatchMeasure, Unit};

/// A per-patch quantity a picture can show: one of the per-patch catalogue ([`PatchMeasure`]), or the
/// segments that left the patch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// A per-patch estimate.
    Patch(PatchMeasure),
    /// `N_i`, the segments that left the patch.
    Segments,
}

/// The name and label of [`Quantity::Segments`].
const SEGMENTS: (&str, &str) = ("segments", "segments leaving the patch, N_i");

impl Quantity {
    /// Every quantity, the catalogue's first.
    pub fn all() -> impl Iterator<Item = Quantity> {
        PatchMeasure::ALL
            .into_iter()
            .map(Quantity::Patch)
            .chain([Quantity::Segments])
    }

    /// Parses a command-line name ([`Quantity::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Quantity::all().find(|q| q.name() == name)
    }

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Patch(m) => m.info().colour,
            Quantity::Segments => SEGMENTS.0,
        }
    }

    /// What the colour bar says the colours mean.
    pub fn label(self) -> &'static str {
        match self {
            Quantity::Patch(m) => m.info().label,
            Quantity::Segments => SEGMENTS.1,
        }
    }

    /// The unit of the values (of the values per unit area fraction when `per_area`).
    pub fn unit(self, per_area: bool) -> &'static str {
        match self {
            Quantity::Segments => Unit::Segments.name(),
            Quantity::Patch(m) if per_area && m.info().share => "bit per unit area fraction",
            Quantity::Patch(m) => m.info().unit.name(),
        }
    }

    /// Whether dividing by the patch's area fraction makes sense (the terms of a sum over patches).
    pub fn is_share(self) -> bool {
        matches!(self, Quantity::Patch(m) if m.info().share)
    }

    /// Whether a logarithmic colour scale suits the quantity by default (it spans orders of magnitude).
    pub fn log_by_default(self) -> bool {
        self.needs_light()
    }

    /// Whether the run must have light for the quantity.
    pub fn needs_light(self) -> bool {
        matches!(self, Quantity::Patch(m) if m.info().unit == Unit::Radiosity)
    }

    /// The least value the theory allows a patch, when it bounds the quantity: in a closed scene every
    /// row's I_i^c is at least its I_i (the log-sum inequality: averaging the kernel over a pair of
    /// patches loses information), so the information lost is at least 0 there, and a reading below 0
    /// is the estimate's error (the plug-in I_i's bias on a thinly sampled row), not the patch's. Open
    /// scenes' rows do not sum to 1, and the bound does not hold for them.
    pub fn least_in_theory(self, closed: bool) -> Option<f64> {
        let lost = [
            PatchMeasure::LostInformation,
            PatchMeasure::LostInformationCorrected,
        ];
        matches!(self, Quantity::Patch(m) if closed && lost.contains(&m)).then_some(0.0)
    }

    /// The patch's value; `None` when the run has none (an unsampled patch, no light, no I_s^c).
    pub fn of(self, p: &PatchResult) -> Option<f64> {
        match self {
            Quantity::Segments => Some(p.segments as f64),
            Quantity::Patch(_) if !p.sampled() => None,
            Quantity::Patch(m) => p.get(m).map(|e| e.value),
        }
    }
}

/// The colour of a patch without a value (unsampled, or the quantity does not apply): a light grey,
/// lighter than any back side and not in viridis.
pub const NO_DATA: [u8; 3] = [205, 205, 205];

/// Values mapped to colours through viridis from `lo` (dark blue) to `hi` (yellow), linearly or by
/// their logarithm; values outside are clipped to the ends.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourScale {
    /// The value at the dark end.
    pub lo: f64,
    /// The value at the bright end.
    pub hi: f64,
    /// Logarithmic (`lo > 0`): equal ratios get equal steps of colour, for quantities spanning orders
    /// of magnitude such as radiosity (a light and the walls it lights).
    pub log: bool,
}

impl ColourScale {
    /// The range of the values between the area-weighted `tail` and `1 - tail` quantiles: a few small
    /// patches with extreme values (a light, a corner) then saturate instead of squeezing every other
    /// patch into one colour. `None` without values.
    /// With `log`, only positive values count, and `None` when there is none.
    pub fn spanning(values: &[Option<f64>], areas: &[f64], tail: f64, log: bool) -> Option<Self> {
        let usable = |x: &f64| x.is_finite() && (!log || *x > 0.0);
        let mut v: Vec<(f64, f64)> = values
            .iter()
            .zip(areas)
            .filter_map(|(v, &a)| v.filter(usable).map(|x| (x, a)))
            .collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        let total: f64 = v.iter().map(|p| p.1).sum();
        let quantile = |q: f64| {
            let mut acc = 0.0;
            for &(x, a) in &v {
                acc += a;
                if acc >= q * total {
                    return x;
                }
            }
            v[v.len() - 1].0
        };
        let (lo, hi) = (quantile(tail), quantile(1.0 - tail));
        Some(if hi > lo {
            ColourScale { lo, hi, log }
        } else if log {
            ColourScale {
                lo: lo / 1.1,
                hi: hi * 1.1,
                log,
            }
        } else {
            // One value everywhere: centre it.
            let pad = if lo == 0.0 { 1.0 } else { 0.01 * lo.abs() };
            ColourScale {
                lo: lo - pad,
                hi: hi + pad,
                log,
            }
        })
    }

    /// Where `value` falls on the scale, 0 to 1 (clipped; on a log scale a value <= 0 is at 0).
    pub fn position(&self, value: f64) -> f64 {
        let t = if self.log {
            if value <= 0.0 {
                return 0.0;
            }
            (value / self.lo).ln() / (self.hi / self.lo).ln()
        } else {
            (value - self.lo) / (self.hi - self.lo)
        };
        t.clamp(0.0, 1.0)
    }

    /// The value at position `t` (0 to 1) of the scale: where the colour bar's ticks go.
    pub fn value_at(&self, t: f64) -> f64 {
        if self.log {
            self.lo * (self.hi / self.lo).powf(t)
        } else {
            self.lo + t * (self.hi - self.lo)
        }
    }

    /// The colour of a value ([`NO_DATA`] for none).
    pub fn colour(&self, value: Option<f64>) -> [u8; 3] {
        match value.filter(|v| v.is_finite()) {
            Some(v) => viridis(self.position(v)),
            None => NO_DATA,
        }
    }
}

/// A labelled mark on a colour bar.
#[derive(Clone, Debug, PartialEq)]
pub struct Tick {
    /// The value marked.
    pub value: f64,
    /// The value as the bar shows it: as few digits as give it exactly (`0.025`, `2e-5`, `1000`).
    pub label: String,
}

/// About how many ticks a colour bar carries.
const TICKS: usize = 6;

impl ColourScale {
    /// The colour bar's ticks, on round values within the scale: 1, 2, 2.5 or 5 x 10^k apart on a
    /// linear scale (or a log scale under a decade); 1, 2 and 5 x 10^k on a log scale over a few
    /// decades, powers of ten (every few) over more.
    pub fn ticks(&self) -> Vec<Tick> {
        let values = if self.log && self.hi / self.lo > 10.0 {
            log_ticks(self.lo, self.hi)
        } else {
            nice_ticks(self.lo, self.hi, TICKS)
        };
        values
            .into_iter()
            .map(|value| Tick {
                value,
                label: short_number(value),
            })
            .collect()
    }
}

/// Round values from `lo` to `hi`, about `about` of them: the multiples of a step among 1, 2, 2.5 and
/// 5 x 10^k, the step whose count is nearest `about`, a step of 2.5 counting as one further (its
/// ticks take a digit more: 0.0375); on a tie, not 2.5, then the fewer ticks.
pub fn nice_ticks(lo: f64, hi: f64, about: usize) -> Vec<f64> {
    let raw = (hi - lo) / about.max(1) as f64;
    if !(raw > 0.0 && raw.is_finite()) {
        return vec![lo];
    }
    let magnitude = 10f64.powf(raw.log10().floor());
    let steps = [0.1, 1.0, 10.0].into_iter().flat_map(|scale| {
        [(1.0, 0), (2.0, 0), (2.5, 1), (5.0, 0)].map(|(m, extra)| (m * scale * magnitude, extra))
    });
    let ticks = |step: f64| -> Vec<f64> {
        // Whole multiples of the step, each from its index (no sum drifting off the round value).
        let first = (lo / step - 1e-9).ceil() as i64;
        let last = (hi / step + 1e-9).floor() as i64;
        (first..=last).map(|k| k as f64 * step).collect()
    };
    steps
        .map(|(step, extra)| (ticks(step), extra))
        .min_by_key(|(t, extra)| (t.len().abs_diff(about) + extra, *extra, t.len()))
        .map_or_else(|| vec![lo], |(t, _)| t)
}

/// 1, 2 and 5 x 10^k from `lo` to `hi` (`0 < lo < hi`) when they span at most three decades; powers of
/// ten over more, every second, third... so that at most about `TICKS` + 2 remain.
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let decades = last - first;
    let within = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    if decades <= 3 {
        return (first..=last)
            .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
            .filter(within)
            .collect();
    }
    let every = (decades as usize).div_ceil(TICKS + 1).max(1);
    (first..=last)
        .filter(|k| (k - first) as usize % every == 0)
        .map(|k| 10f64.powi(k))
        .filter(within)
        .collect()
}

/// `v` with as few digits as give it back to 1e-9 relative: `0.025`, `1000`, exponents beyond 1e5 and
/// under 1e-3 (`2.5e-5`).
pub fn short_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 { "0".into() } else { v.to_string() };
    }
    let close = |s: &str| {
        s.parse::<f64>()
            .is_ok_and(|x| (x - v).abs() <= 1e-9 * v.abs())
    };
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        (0..=9)
            .map(|d| format!("{v:.d$}"))
            .find(|s| close(s))
            .unwrap_or_else(|| format!("{v:.9}"))
    } else {
        (0..=9)
            .map(|d| format!("{v:.d$e}"))
            .find(|s| close(s))
            .unwrap_or_else(|| format!("{v:.9e}"))
    }
}

/// Viridis at `t` in [0, 1].
pub fn viridis(t: f64) -> [u8; 3] {
    let c = colorous::VIRIDIS.eval_continuous(t.clamp(0.0, 1.0));
    [c.r, c.g, c.b]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bar (0.01368 to 0.0389) gets ticks 0.015 to 0.035, 0.005 apart; other ranges get
    /// 1, 2, 2.5 or 5 x 10^k steps, labels without spurious digits.
    #[test]
    fn ticks_fall_on_round_values() {
        let labels =
            |s: ColourScale| -> Vec<String> { s.ticks().into_iter().map(|t| t.label).collect() };
        let linear = |lo, hi| ColourScale { lo, hi, log: false };
        assert_eq!(
            labels(linear(0.01368, 0.0389)),
            ["0.015", "0.02", "0.025", "0.03", "0.035"]
        );
        assert_eq!(
            labels(linear(0.0, 1.0)),
            ["0", "0.2", "0.4", "0.6", "0.8", "1"]
        );
        assert_eq!(
            labels(linear(4.674, 6.141)),
            ["4.8", "5", "5.2", "5.4", "5.6", "5.8", "6"]
        );
        assert_eq!(labels(linear(0.0, 2.203)), ["0", "0.5", "1", "1.5", "2"]);
        assert_eq!(labels(linear(-1.0, 1.0)), ["-1", "-0.5", "0", "0.5", "1"]);
        assert_eq!(labels(linear(0.0, 11.0)), ["0", "2", "4", "6", "8", "10"]);
        assert_eq!(
            labels(linear(1e-5, 5.2e-5)),
            ["1e-5", "2e-5", "3e-5", "4e-5", "5e-5"]
        );
        assert_eq!(
            labels(linear(0.0, 1.2e6)),
            ["0", "2e5", "4e5", "6e5", "8e5", "1e6", "1.2e6"]
        );
        let log = |lo, hi| ColourScale { lo, hi, log: true };
        assert_eq!(labels(log(0.0118, 0.4888)), ["0.02", "0.05", "0.1", "0.2"]);
        assert_eq!(labels(log(0.035, 0.05)), ["0.035", "0.04", "0.045", "0.05"]);
        assert_eq!(
            labels(log(1e-6, 10.0)),
            ["1e-6", "1e-5", "1e-4", "0.001", "0.01", "0.1", "1", "10"]
        );
        assert_eq!(labels(log(1e-9, 1e9)).len(), 7);
        for s in [linear(0.01368, 0.0389), log(0.0118, 0.4888)] {
            for t in s.ticks() {
                assert!(t.value >= s.lo && t.value <= s.hi, "{t:?} within {s:?}");
            }
        }
        assert_eq!(short_number(0.1 + 0.2), "0.3");
        assert_eq!(short_number(1234.0), "1234");
        assert_eq!(short_number(2.5e-5), "2.5e-5");
    }

    #[test]
    fn quantity_names_round_trip() {
        for q in Quantity::all() {
            assert_eq!(Quantity::from_name(q.name()), Some(q));
        }
        assert_eq!(Quantity::from_name("entropy"), None);
    }

    /// A small patch with an extreme value saturates; the rest spans the scale.
    #[test]
    fn the_scale_spans_the_bulk_of_the_area() {
        let values = [Some(1.0), Some(2.0), Some(3.0), Some(100.0), None];
        let areas = [1.0, 1.0, 1.0, 0.001, 5.0];
        let s = ColourScale::spanning(&values, &areas, 0.01, false).unwrap();
        assert_eq!((s.lo, s.hi), (1.0, 3.0));
        assert_eq!(s.colour(Some(100.0)), viridis(1.0));
        assert_eq!(s.colour(None), NO_DATA);
        assert_eq!(viridis(0.0), [68, 1, 84]);
        let flat = ColourScale::spanning(&[Some(0.0)], &[1.0], 0.01, false).unwrap();
        assert!(flat.lo < 0.0 && flat.hi > 0.0);
        let log = ColourScale::spanning(&values, &areas, 0.01, true).unwrap();
        assert!((log.position(f64::sqrt(3.0)) - 0.5).abs() < 1e-12);
        assert!((log.value_at(0.5) - f64::sqrt(3.0)).abs() < 1e-12);
        assert_eq!(log.position(-1.0), 0.0);
        assert!(ColourScale::spanning(&[Some(0.0)], &[1.0], 0.01, true).is_none());
    }
}
