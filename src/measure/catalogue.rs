//! The catalogue of measures: one entry per quantity a run reports, with everything the rest of scx
//! needs to know about it (its key in reports, its label and unit, the paper's equation, its family, what
//! it is computed from, how its reliability is judged, whether a precision target can watch it).
//!
//! The report's rows, the JSON keys, the CSV rows, the measures a precision target accepts, the
//! reliability verdicts, the readings `scx convergence` follows and the per-patch columns all come from
//! here: adding a measure is one entry here plus its estimator (in the analysis layer, `analysis::values` and `analysis::radiosity`).
//!
//! Two tables: [`Measure`] for the measures of the whole scene (sec. 3 and 4 of the paper), and
//! [`PatchMeasure`] for their shares per patch (where the complexity is).

use serde::{Deserialize, Serialize};

/// A reading's unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// Entropies and mutual information.
    Bit,
    /// Accuracies and relative errors.
    Ratio,
    /// E(MSE) of a single line.
    PerLine,
    /// A count of segments.
    Segments,
    /// Radiosity, in the units of the scene's emissions.
    Radiosity,
}

impl Unit {
    /// The unit's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Unit::Bit => "bit",
            Unit::Ratio => "ratio",
            Unit::PerLine => "per line",
            Unit::Segments => "segments",
            Unit::Radiosity => "same units as the emission Ke",
        }
    }
}

/// The two families of measures: of visibility (paper sec. 3) and of radiosity (sec. 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// From the form factors and the kernel of eq. (27).
    Visibility,
    /// From the radiosity solution on the estimated form factors.
    Radiosity,
}

impl Family {
    /// The family's entropy, plug-in and bias-corrected: their distance estimates the bias of the
    /// family's plug-in readings.
    pub const fn entropies(self) -> (Measure, Measure) {
        match self {
            Family::Visibility => (Measure::Entropy, Measure::EntropyCorrected),
            Family::Radiosity => (
                Measure::RadiosityEntropy,
                Measure::RadiosityEntropyCorrected,
            ),
        }
    }

    /// The family's name in reports (the JSON object and the CSV `family` column).
    pub fn name(self) -> &'static str {
        match self {
            Family::Visibility => "visibility",
            Family::Radiosity => "radiosity",
        }
    }
}

/// What a measure is computed from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Needs {
    /// The patches' areas only: exact.
    Areas,
    /// The pair counts `N_ij` (the discrete measures).
    Counts,
    /// The sums of eq. (27)'s kernel (the continuous measure).
    Kernel,
    /// Both.
    CountsAndKernel,
    /// The pair counts and an emitting material (a radiosity solution).
    Solution,
}

impl Needs {
    /// Whether a run gathering pair counts (`counts`) and kernel sums (`kernel`) can compute it.
    pub fn met_by(self, counts: bool, kernel: bool) -> bool {
        match self {
            Needs::Areas => true,
            Needs::Counts | Needs::Solution => counts,
            Needs::Kernel => kernel,
            Needs::CountsAndKernel => counts && kernel,
        }
    }
}

/// How a reading's reliability is judged (docs/results.md, "Reading the reliability verdict").
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VerdictRule {
    /// Exact (from the areas): no verdict.
    Exact,
    /// A mean of independent terms (eq. 27): `ok` with enough pairs and a standard error.
    Mean,
    /// A plug-in reading: the rows' coverage, and its estimated bias, `sign` times the distance from the
    /// plug-in to the corrected entropy of its family ([`Family::entropies`]: the plug-in H_s reads low
    /// by about its correction, so I_s = H_p - H_s reads high by as much), within half its standard
    /// error (`reliability::PLUG_IN_BIAS_SHARE`).
    PlugIn {
        /// +1 when the reading moves with the entropy, -1 when against it.
        sign: f64,
    },
    /// A bias-corrected reading: the rows' coverage.
    Corrected,
    /// A ratio to I_s^c of the reading `of`: that reading's verdict (not its flags) or I_s^c's, whichever
    /// is worse, its bias divided by I_s^c times `sign` judged against the ratio's own standard error as
    /// `of`'s is against its own, and `unusable` when I_s^c is not distinguishable from 0.
    RatioOf {
        /// The reading in the numerator.
        of: Measure,
        /// +1, or -1 for `1 - ratio`.
        sign: f64,
    },
    /// A plug-in reading with an unbiased estimate whatever the coverage (eq. 22's); `ok` when its
    /// estimated bias (from the rows' sampling) is within half its standard error, as a plug-in
    /// entropy's.
    Unbiased,
    /// That unbiased estimate (each row's `sum_j x_j (x_j - 1) / (N_i (N_i - 1))` for `sum_j F_ij^2`):
    /// it needs no coverage of the rows, only rows of at least two segments, which any coverage above
    /// the `unusable` floor gives; like a corrected reading it assumes each row a multinomial sample,
    /// and the jackknife's estimate of its bias, when there is one, must be within its standard error.
    UnbiasedEstimate,
}

/// The bounds of the theory a reading must respect; one broken by more than twice the standard error
/// is flagged, and the reading is then never `ok`.
///
/// In an open scene (segments leave front sides and arrive at no front side: escapes, back sides) the
/// channel loses part of every row, and a mutual information, discrete or continuous, is a Kullback-
/// Leibler divergence of a measure of less than 1 from one of 1: it may be below 0 (two small squares
/// far apart). Proposition 2 (I_s <= I_s^c) still holds, both being on the same footing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// No bound checked.
    None,
    /// An entropy: at least 0.
    NonNegative,
    /// A discrete mutual information: at most I_s^c (Proposition 2), and at least 0 in a closed scene.
    MutualInformation,
    /// I_s^c: at least 0 in a closed scene.
    ContinuousMutualInformation,
    /// A ratio of I_s to I_s^c: within [0, 1] in a closed scene.
    UnitInterval,
}

/// One entry of the catalogue.
#[derive(Clone, Copy, Debug)]
pub struct MeasureInfo {
    /// The measure.
    pub measure: Measure,
    /// Its family.
    pub family: Family,
    /// Its key: the JSON key in its family's object, the CSV `measure`, the name a precision target
    /// takes (`--target-measure`); for a bias-corrected reading, the key of its plug-in reading with
    /// `_corrected`.
    pub key: &'static str,
    /// Its label in the report's table.
    pub label: &'static str,
    /// Its symbol in plots and summaries (`I_s`, `I_s corrected`).
    pub symbol: &'static str,
    /// Its unit.
    pub unit: Unit,
    /// Where the paper defines it.
    pub equation: &'static str,
    /// What it is computed from.
    pub needs: Needs,
    /// The plug-in reading this one corrects for bias: reports show them side by side in one row.
    pub corrects: Option<Measure>,
    /// How its reliability is judged.
    pub verdict: VerdictRule,
    /// The bound of the theory it must respect.
    pub bound: Bound,
    /// What its flags call it (`the corrected I_s`).
    pub flag_name: &'static str,
    /// Whether a precision target (`--target-stderr`) can watch it.
    pub target: bool,
    /// Its column in `scx convergence`'s table, when that command follows it.
    pub followed: Option<u8>,
}

/// The measures of a scene, in report order (a bias-corrected reading right after its plug-in one).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Measure {
    /// H_p, eq. (19).
    PositionalEntropy,
    /// H_s, eq. (17), plug-in.
    Entropy,
    /// H_s with bias-corrected row entropies.
    EntropyCorrected,
    /// H(X, Y), eq. (7).
    JointEntropy,
    /// I_s, eq. (21), plug-in.
    MutualInformation,
    /// I_s = H_p - H_s with the bias-corrected H_s.
    MutualInformationCorrected,
    /// I_s^c, eq. (27).
    ContinuousMutualInformation,
    /// The discretisation accuracy I_s / I_s^c (sec. 3.3), plug-in I_s.
    Accuracy,
    /// The same with the bias-corrected I_s.
    AccuracyCorrected,
    /// The discretisation relative error (I_s^c - I_s) / I_s^c (sec. 3.3).
    RelativeError,
    /// The form factors' E(MSE) of one line, eq. (22), plug-in.
    MsePerLine,
    /// Eq. (22) with each row's `sum_j F_ij^2` estimated without bias.
    MsePerLineCorrected,
    /// The radiosity positional entropy, eq. (33).
    RadiosityPositionalEntropy,
    /// The radiosity entropy, eq. (34), plug-in.
    RadiosityEntropy,
    /// Eq. (34) with bias-corrected rows.
    RadiosityEntropyCorrected,
    /// The radiosity mutual information, eq. (35), plug-in.
    RadiosityMutualInformation,
    /// Eq. (35) with bias-corrected rows.
    RadiosityMutualInformationCorrected,
}

const fn entry(measure: Measure, family: Family, key: &'static str) -> MeasureInfo {
    MeasureInfo {
        measure,
        family,
        key,
        label: "",
        symbol: "",
        unit: Unit::Bit,
        equation: "",
        needs: Needs::Counts,
        corrects: None,
        verdict: VerdictRule::Exact,
        bound: Bound::None,
        flag_name: "",
        target: false,
        followed: None,
    }
}

const fn plug_in(sign: f64) -> VerdictRule {
    VerdictRule::PlugIn { sign }
}

use Family::{Radiosity, Visibility};

/// Every measure, in [`Measure`] order.
pub const CATALOGUE: [MeasureInfo; Measure::COUNT] = [
    MeasureInfo {
        label: "positional entropy H_p",
        symbol: "H_p",
        equation: "eq. 19",
        needs: Needs::Areas,
        ..entry(Measure::PositionalEntropy, Visibility, "positional_entropy")
    },
    MeasureInfo {
        label: "visibility entropy H_s",
        symbol: "H_s",
        equation: "eq. 17",
        verdict: plug_in(1.0),
        bound: Bound::NonNegative,
        flag_name: "H_s",
        target: true,
        followed: Some(2),
        ..entry(Measure::Entropy, Visibility, "entropy")
    },
    MeasureInfo {
        label: "visibility entropy H_s, corrected",
        symbol: "H_s corrected",
        equation: "eq. 17",
        corrects: Some(Measure::Entropy),
        verdict: VerdictRule::Corrected,
        bound: Bound::NonNegative,
        flag_name: "the corrected H_s",
        target: true,
        followed: Some(3),
        ..entry(Measure::EntropyCorrected, Visibility, "entropy_corrected")
    },
    MeasureInfo {
        label: "joint entropy H(X,Y)",
        symbol: "H(X,Y)",
        equation: "eq. 7",
        verdict: plug_in(1.0),
        ..entry(Measure::JointEntropy, Visibility, "joint_entropy")
    },
    MeasureInfo {
        label: "mutual information I_s",
        symbol: "I_s",
        equation: "eq. 21",
        verdict: plug_in(-1.0),
        bound: Bound::MutualInformation,
        flag_name: "I_s",
        target: true,
        followed: Some(0),
        ..entry(Measure::MutualInformation, Visibility, "mutual_information")
    },
    MeasureInfo {
        label: "mutual information I_s, corrected",
        symbol: "I_s corrected",
        equation: "eq. 21",
        corrects: Some(Measure::MutualInformation),
        verdict: VerdictRule::Corrected,
        bound: Bound::MutualInformation,
        flag_name: "the corrected I_s",
        target: true,
        followed: Some(1),
        ..entry(
            Measure::MutualInformationCorrected,
            Visibility,
            "mutual_information_corrected",
        )
    },
    MeasureInfo {
        label: "continuous mutual information I_s^c",
        symbol: "I_s^c",
        equation: "eq. 27",
        needs: Needs::Kernel,
        verdict: VerdictRule::Mean,
        bound: Bound::ContinuousMutualInformation,
        flag_name: "I_s^c",
        target: true,
        followed: Some(4),
        ..entry(
            Measure::ContinuousMutualInformation,
            Visibility,
            "continuous_mutual_information",
        )
    },
    MeasureInfo {
        label: "discretisation accuracy I_s/I_s^c",
        symbol: "I_s/I_s^c",
        unit: Unit::Ratio,
        equation: "sec. 3.3",
        needs: Needs::CountsAndKernel,
        verdict: VerdictRule::RatioOf {
            of: Measure::MutualInformation,
            sign: 1.0,
        },
        bound: Bound::UnitInterval,
        flag_name: "the accuracy",
        target: true,
        ..entry(Measure::Accuracy, Visibility, "accuracy")
    },
    MeasureInfo {
        label: "discretisation accuracy I_s/I_s^c, corrected",
        symbol: "I_s/I_s^c corrected",
        unit: Unit::Ratio,
        equation: "sec. 3.3",
        needs: Needs::CountsAndKernel,
        corrects: Some(Measure::Accuracy),
        verdict: VerdictRule::RatioOf {
            of: Measure::MutualInformationCorrected,
            sign: 1.0,
        },
        bound: Bound::UnitInterval,
        flag_name: "the corrected accuracy",
        target: true,
        ..entry(Measure::AccuracyCorrected, Visibility, "accuracy_corrected")
    },
    MeasureInfo {
        label: "discretisation relative error",
        symbol: "1 - I_s/I_s^c",
        unit: Unit::Ratio,
        equation: "sec. 3.3",
        needs: Needs::CountsAndKernel,
        verdict: VerdictRule::RatioOf {
            of: Measure::MutualInformation,
            sign: -1.0,
        },
        bound: Bound::UnitInterval,
        flag_name: "the relative error",
        ..entry(Measure::RelativeError, Visibility, "relative_error")
    },
    MeasureInfo {
        label: "form-factor E(MSE)",
        symbol: "E(MSE)",
        unit: Unit::PerLine,
        equation: "eq. 22",
        verdict: VerdictRule::Unbiased,
        ..entry(Measure::MsePerLine, Visibility, "mse_per_line")
    },
    MeasureInfo {
        label: "form-factor E(MSE), corrected",
        symbol: "E(MSE) corrected",
        unit: Unit::PerLine,
        equation: "eq. 22",
        corrects: Some(Measure::MsePerLine),
        verdict: VerdictRule::UnbiasedEstimate,
        ..entry(
            Measure::MsePerLineCorrected,
            Visibility,
            "mse_per_line_corrected",
        )
    },
    MeasureInfo {
        label: "radiosity positional entropy H_p",
        symbol: "radiosity H_p",
        equation: "eq. 33",
        needs: Needs::Solution,
        ..entry(
            Measure::RadiosityPositionalEntropy,
            Radiosity,
            "positional_entropy",
        )
    },
    MeasureInfo {
        label: "radiosity entropy H_s",
        symbol: "radiosity H_s",
        equation: "eq. 34",
        needs: Needs::Solution,
        verdict: plug_in(1.0),
        ..entry(Measure::RadiosityEntropy, Radiosity, "entropy")
    },
    MeasureInfo {
        label: "radiosity entropy H_s, corrected",
        symbol: "radiosity H_s corrected",
        equation: "eq. 34",
        needs: Needs::Solution,
        corrects: Some(Measure::RadiosityEntropy),
        verdict: VerdictRule::Corrected,
        ..entry(
            Measure::RadiosityEntropyCorrected,
            Radiosity,
            "entropy_corrected",
        )
    },
    MeasureInfo {
        label: "radiosity mutual information I_s",
        symbol: "radiosity I_s",
        equation: "eq. 35",
        needs: Needs::Solution,
        verdict: plug_in(-1.0),
        ..entry(
            Measure::RadiosityMutualInformation,
            Radiosity,
            "mutual_information",
        )
    },
    MeasureInfo {
        label: "radiosity mutual information I_s, corrected",
        symbol: "radiosity I_s corrected",
        equation: "eq. 35",
        needs: Needs::Solution,
        corrects: Some(Measure::RadiosityMutualInformation),
        verdict: VerdictRule::Corrected,
        ..entry(
            Measure::RadiosityMutualInformationCorrected,
            Radiosity,
            "mutual_information_corrected",
        )
    },
];

impl Measure {
    /// How many measures the catalogue has.
    pub const COUNT: usize = 17;

    /// Every measure, in report order.
    pub const ALL: [Measure; Measure::COUNT] = {
        let mut all = [Measure::PositionalEntropy; Measure::COUNT];
        let mut k = 0;
        while k < Measure::COUNT {
            all[k] = CATALOGUE[k].measure;
            k += 1;
        }
        all
    };

    /// The precision target's measure when none is named: the better reading of I_s.
    pub const DEFAULT_TARGET: Measure = Measure::MutualInformationCorrected;

    /// Its catalogue entry.
    pub const fn info(self) -> &'static MeasureInfo {
        &CATALOGUE[self as usize]
    }

    /// Its key (see [`MeasureInfo::key`]).
    pub const fn key(self) -> &'static str {
        self.info().key
    }

    /// Whether the reading rests on bias-corrected row entropies: a corrected reading, or a ratio to
    /// I_s^c of one. Their corrections assume each row a multinomial sample, which independent lines
    /// give and randomised quasi-Monte Carlo lines do not.
    pub const fn rests_on_corrected_rows(self) -> bool {
        match self.info().verdict {
            VerdictRule::Corrected | VerdictRule::UnbiasedEstimate => true,
            VerdictRule::RatioOf { of, .. } => matches!(of.info().verdict, VerdictRule::Corrected),
            _ => false,
        }
    }

    /// The measures of `family`, in report order.
    pub fn of_family(family: Family) -> impl Iterator<Item = Measure> {
        Measure::ALL
            .into_iter()
            .filter(move |m| m.info().family == family)
    }

    /// The measures a precision target can watch.
    pub fn targets() -> impl Iterator<Item = Measure> {
        Measure::ALL.into_iter().filter(|m| m.info().target)
    }

    /// The measure a precision target names by its key (`mutual_information_corrected`).
    pub fn target_named(key: &str) -> Option<Measure> {
        Measure::targets().find(|m| m.key() == key)
    }

    /// The bias-corrected reading of this plug-in one, when it has one.
    pub fn corrected(self) -> Option<Measure> {
        Measure::ALL
            .into_iter()
            .find(|m| m.info().corrects == Some(self))
    }
}

impl std::fmt::Display for Measure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.key())
    }
}

/// A value for every measure of the catalogue (`None` where a run has none), indexed by [`Measure`].
#[derive(Clone, Debug, PartialEq)]
pub struct ByMeasure<T> {
    values: [Option<T>; Measure::COUNT],
}

impl<T> Default for ByMeasure<T> {
    fn default() -> Self {
        ByMeasure {
            values: std::array::from_fn(|_| None),
        }
    }
}

impl<T> ByMeasure<T> {
    /// The value of `measure`.
    pub fn get(&self, measure: Measure) -> Option<&T> {
        self.values[measure as usize].as_ref()
    }

    /// The value of `measure`, to change.
    pub fn get_mut(&mut self, measure: Measure) -> Option<&mut T> {
        self.values[measure as usize].as_mut()
    }

    /// Sets (or clears) the value of `measure`.
    pub fn set(&mut self, measure: Measure, value: Option<T>) {
        self.values[measure as usize] = value;
    }

    /// Every measure that has a value, with it, in report order.
    pub fn iter(&self) -> impl Iterator<Item = (Measure, &T)> {
        Measure::ALL
            .into_iter()
            .zip(&self.values)
            .filter_map(|(m, v)| Some((m, v.as_ref()?)))
    }

    /// The values of a function of every measure.
    pub fn from_fn(mut f: impl FnMut(Measure) -> Option<T>) -> Self {
        ByMeasure {
            values: std::array::from_fn(|k| f(Measure::ALL[k])),
        }
    }
}

impl<T: Copy> ByMeasure<T> {
    /// A copy of the value of `measure`.
    pub fn of(&self, measure: Measure) -> Option<T> {
        self.values[measure as usize]
    }
}

/// A share of a measure per patch: the columns of `--patches` and the colours of `scx render`, in
/// column order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PatchMeasure {
    /// `H_i = -sum_j F_ij log2 F_ij`, the plug-in row entropy (eq. (17)'s inner sum).
    RowEntropy,
    /// `H_i` by the run's bias-correcting estimator.
    RowEntropyCorrected,
    /// `a_i sum_j F_ij log2(F_ij / a_j)`, the patch's term of eq. (21).
    MutualInformationTerm,
    /// The same with the corrected `H_i`.
    MutualInformationTermCorrected,
    /// The patch's share of eq. (27).
    ContinuousTerm,
    /// The information the discretisation loses at the patch: its I_s^c share less its I_s term
    /// (sec. 3.3).
    LostInformation,
    /// The same with the corrected I_s term.
    LostInformationCorrected,
    /// `B_i`, the radiosity (eq. (2)), when the scene emits.
    Radiosity,
    /// `B_i^in = sum_j F_ij B_j`, the radiosity arriving, when the scene emits.
    IncomingRadiosity,
}

/// One entry of the per-patch catalogue.
#[derive(Clone, Copy, Debug)]
pub struct PatchMeasureInfo {
    /// The quantity.
    pub measure: PatchMeasure,
    /// Its column in `--patches` (its standard error is the column with `_stderr`).
    pub column: &'static str,
    /// Its name for `scx render --color`.
    pub colour: &'static str,
    /// What the colour bar says it is.
    pub label: &'static str,
    /// Its unit.
    pub unit: Unit,
    /// Whether it is a patch's share of a sum over patches (a term of I_s or I_s^c, or their
    /// difference): then dividing by the patch's area fraction makes sense.
    pub share: bool,
}

/// Every per-patch quantity, in [`PatchMeasure`] order.
pub const PATCH_CATALOGUE: [PatchMeasureInfo; PatchMeasure::COUNT] = [
    PatchMeasureInfo {
        measure: PatchMeasure::RowEntropy,
        column: "row_entropy",
        colour: "row-entropy",
        label: "row entropy H_i (plug-in)",
        unit: Unit::Bit,
        share: false,
    },
    PatchMeasureInfo {
        measure: PatchMeasure::RowEntropyCorrected,
        column: "row_entropy_corrected",
        colour: "row-entropy-corrected",
        label: "row entropy H_i (bias-corrected)",
        unit: Unit::Bit,
        share: false,
    },
    PatchMeasureInfo {
        measure: PatchMeasure::MutualInformationTerm,
        column: "mutual_information_term",
        colour: "mutual-information",
        label: "term of I_s, a_i sum_j F_ij log2(F_ij/a_j)",
        unit: Unit::Bit,
        share: true,
    },
    PatchMeasureInfo {
        measure: PatchMeasure::MutualInformationTermCorrected,
        column: "mutual_information_term_corrected",
        colour: "mutual-information-corrected",
        label: "term of I_s (bias-corrected)",
        unit: Unit::Bit,
        share: true,
    },
    PatchMeasureInfo {
        measure: PatchMeasure::ContinuousTerm,
        column: "continuous_mutual_information_term",
        colour: "continuous-mutual-information",
        label: "share of I_s^c (eq. 27)",
        unit: Unit::Bit,
        share: true,
    },
    PatchMeasureInfo {
        measure: PatchMeasure::LostInformation,
        column: "lost_information",
        colour: "lost-information",
        label: "information lost, I_i^c - I_i",
        unit: Unit::Bit,
        share: true,
    },
    PatchMeasureInfo {
        measure: PatchMeasure::LostInformationCorrected,
        column: "lost_information_corrected",
        colour: "lost-information-corrected",
        label: "information lost, I_i^c - I_i (corrected)",
        unit: Unit::Bit,
        share: true,
    },
    PatchMeasureInfo {
        measure: PatchMeasure::Radiosity,
        column: "radiosity",
        colour: "radiosity",
        label: "radiosity B_i",
        unit: Unit::Radiosity,
        share: false,
    },
    PatchMeasureInfo {
        measure: PatchMeasure::IncomingRadiosity,
        column: "incoming_radiosity",
        colour: "incoming-radiosity",
        label: "incoming radiosity B_i^in",
        unit: Unit::Radiosity,
        share: false,
    },
];

impl PatchMeasure {
    /// How many per-patch quantities the catalogue has.
    pub const COUNT: usize = 9;

    /// Every per-patch quantity, in column order.
    pub const ALL: [PatchMeasure; PatchMeasure::COUNT] = {
        let mut all = [PatchMeasure::RowEntropy; PatchMeasure::COUNT];
        let mut k = 0;
        while k < PatchMeasure::COUNT {
            all[k] = PATCH_CATALOGUE[k].measure;
            k += 1;
        }
        all
    };

    /// Its catalogue entry.
    pub const fn info(self) -> &'static PatchMeasureInfo {
        &PATCH_CATALOGUE[self as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each entry sits at its measure's index, keys are unique within a family, and every corrected
    /// reading follows its plug-in reading in the same family.
    #[test]
    fn the_catalogue_is_consistent() {
        for (k, info) in CATALOGUE.iter().enumerate() {
            assert_eq!(info.measure as usize, k, "{}", info.key);
            assert!(
                !info.label.is_empty() && !info.symbol.is_empty(),
                "{}",
                info.key
            );
            if let Some(plain) = info.corrects {
                assert_eq!(plain as usize + 1, k, "{}", info.key);
                assert_eq!(plain.info().family, info.family);
                assert_eq!(info.key, format!("{}_corrected", plain.key()));
            }
        }
        for a in Measure::ALL {
            for b in Measure::ALL {
                if a != b && a.info().family == b.info().family {
                    assert_ne!(a.key(), b.key());
                }
            }
        }
        for (k, info) in PATCH_CATALOGUE.iter().enumerate() {
            assert_eq!(info.measure as usize, k, "{}", info.column);
        }
        assert_eq!(
            Measure::target_named("mutual_information_corrected"),
            Some(Measure::DEFAULT_TARGET)
        );
        assert_eq!(Measure::target_named("radiosity_entropy"), None);
    }
}
