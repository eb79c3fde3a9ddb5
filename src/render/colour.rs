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

/// Viridis at `t` in [0, 1].
pub fn viridis(t: f64) -> [u8; 3] {
    let c = colorous::VIRIDIS.eval_continuous(t.clamp(0.0, 1.0));
    [c.r, c.g, c.b]
}

#[cfg(test)]
mod tests {
    use super::*;

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
