//! Sampling: global lines, the pairing of their hits into mutually visible points, and the accumulation
//! of counts and sums (paper sec. 2.1.1 and 3.2.2).
//!
//! Inside the layer, data flows: [`lines`] draws the lines (through the sphere, or the box or polytope
//! of [`bounds`] and [`polytope`]); [`pairs`] (with `order`) turns a line's canonical hits into segments; [`kernel`] and [`environment`] give a segment's eq. (27) term;
//! [`tally`] adds segments up, with f64 sums kept [`exact`]ly ([`kernel_sums`] per patch, when asked);
//! [`counts`] turns pair keys into the counts N_ij, which [`sparse`] packs eight bytes a pair on large
//! scenes.

pub mod bounds;
pub mod counts;
pub mod environment;
pub mod exact;
pub mod kernel;
pub mod kernel_sums;
pub mod lines;
mod order;
pub mod pairs;
pub mod patch_counts;
pub mod polytope;
pub mod sobol;
pub mod sparse;
pub mod tally;
