//! The readings of a run: every visibility measure with its standard error.

use crate::measure::Estimate;
use crate::run::TargetMeasure;

/// The visibility measures of a run, each with its standard error; `None` when not computed.
#[derive(Clone, Debug, Default)]
pub struct VisibilityEstimates {
    /// Eq. (19), exact.
    pub positional_entropy: Option<Estimate>,
    /// Eq. (17), plug-in.
    pub entropy: Option<Estimate>,
    /// Eq. (17) with bias-corrected row entropies ([`crate::measure::bias`]).
    pub entropy_corrected: Option<Estimate>,
    /// H(X, Y).
    pub joint_entropy: Option<Estimate>,
    /// Eq. (21), plug-in.
    pub mutual_information: Option<Estimate>,
    /// Eq. (20) with the bias-corrected H_s.
    pub mutual_information_corrected: Option<Estimate>,
    /// Eq. (27).
    pub continuous_mutual_information: Option<Estimate>,
    /// Sec. 3.3: discretisation accuracy I_s / I_s^c (plug-in I_s).
    pub accuracy: Option<Estimate>,
    /// Sec. 3.3 with the bias-corrected I_s.
    pub accuracy_corrected: Option<Estimate>,
    /// Sec. 3.3: discretisation relative error (I_s^c - I_s) / I_s^c.
    pub relative_error: Option<Estimate>,
    /// Eq. (22), per line.
    pub mse_per_line: Option<Estimate>,
}

impl VisibilityEstimates {
    /// The estimate a precision target watches.
    pub fn of(&self, measure: TargetMeasure) -> Option<Estimate> {
        match measure {
            TargetMeasure::Entropy => self.entropy,
            TargetMeasure::EntropyCorrected => self.entropy_corrected,
            TargetMeasure::MutualInformation => self.mutual_information,
            TargetMeasure::MutualInformationCorrected => self.mutual_information_corrected,
            TargetMeasure::ContinuousMutualInformation => self.continuous_mutual_information,
            TargetMeasure::Accuracy => self.accuracy,
            TargetMeasure::AccuracyCorrected => self.accuracy_corrected,
        }
    }
}
