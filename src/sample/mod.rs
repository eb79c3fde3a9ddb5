//! Sampling: global lines, hit pairing, and accumulation of counts and sums.

pub mod counts;
pub mod lines;
pub mod pairs;
pub mod tally;
