//! Sampling: global lines, hit pairing, and accumulation of counts and sums.

pub mod counts;
pub mod environment;
pub mod lines;
mod order;
pub mod pairs;
pub mod tally;
