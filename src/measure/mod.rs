//! The paper's measures, computed from counts and sums (sections 3.1, 3.2, 3.3, and 4 for radiosity).
//!
//! Logarithms are base 2 (bits). `0 log 0 = 0` everywhere ([`entropy::xlog2x`]).
//!
//! [`catalogue`] lists every measure (key, label, unit, equation, how its reliability is judged);
//! [`shares`] shares the visibility measures out among the patches (where the complexity is).

pub mod bias;
pub mod catalogue;
pub mod channel;
pub mod entropy;
pub mod estimate;
pub mod estimators;
pub mod radiosity;
pub mod rows;
pub mod sampling;
pub mod shares;
pub mod visibility;

pub use catalogue::{ByMeasure, Family, Measure, MeasureInfo, PatchMeasure, Unit};
pub use estimate::{student_t_975, Estimate};
pub use visibility::{ContinuousValues, DiscreteValues};
