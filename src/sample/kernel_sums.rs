//! Per-patch sums of eq. (27)'s terms, for the per-patch results (`scx analyze --patches`).
//!
//! The run's I_s^c is the mean over its visible pairs of `log2(A_T cos_x cos_y / (pi d^2))` (eq. 27).
//! To share it out among the patches, every pair's term is credited to both of its end patches here
//! (its `log2(cos_x cos_y / d^2)` part; the constant `log2(A_T / pi)` is added by the measure). Gathered
//! only when asked for ([`super::tally::Wanted::per_patch`]): it costs one `log2` per pair and two
//! additions into arrays of the patch count, which the hot loop otherwise skips. The sums are exact
//! ([`ExactSum`]), so batches, groups and shards can be added up in any order with the same bits.

use super::counts::split_key;
use super::exact::ExactSum;
use super::kernel::kernel_without_pi;

/// For each patch, the sum of `log2(cos_x cos_y / d^2)` over the visible pairs with an end on it (a
/// pair with both ends on it counts twice), and how many pair ends entered that sum. Degenerate pairs
/// ([`kernel_without_pi`]) are left out, as they are from eq. (27).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PatchKernelSums {
    /// Per patch: the sum of the log kernel over its pair ends.
    pub log2_kernel: Vec<ExactSum>,
    /// Per patch: the pair ends that entered `log2_kernel`.
    pub ends: Vec<u64>,
}

impl PatchKernelSums {
    /// Empty sums for `patches` patches.
    pub fn new(patches: usize) -> Self {
        PatchKernelSums {
            log2_kernel: vec![ExactSum::default(); patches],
            ends: vec![0; patches],
        }
    }

    /// The log kernel of one pair, `NaN` for a degenerate pair (which [`PatchKernelSums::add_pairs`]
    /// then skips): what the hot loop records beside each pair key.
    pub fn pair_term(cos_product: f64, distance: f64) -> f64 {
        kernel_without_pi(cos_product, distance).map_or(f64::NAN, f64::log2)
    }

    /// Credits each pair's term (`terms[k]`, from [`PatchKernelSums::pair_term`], beside `keys[k]`) to
    /// both of its ends, in the order given.
    pub fn add_pairs(&mut self, keys: &[u64], terms: &[f64]) {
        for (&key, &term) in keys.iter().zip(terms) {
            if term.is_nan() {
                continue;
            }
            let (i, j) = split_key(key);
            let term = ExactSum::of(term);
            for p in [i as usize, j as usize] {
                self.log2_kernel[p].add(term);
                self.ends[p] += 1;
            }
        }
    }

    /// Adds another set of lines' sums into these.
    pub fn merge(&mut self, other: &PatchKernelSums) {
        for (a, b) in self.log2_kernel.iter_mut().zip(&other.log2_kernel) {
            a.add(*b);
        }
        for (a, b) in self.ends.iter_mut().zip(&other.ends) {
            *a += b;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample::counts::pair_key;

    #[test]
    fn every_usable_pair_is_credited_to_both_ends_and_a_degenerate_one_to_none() {
        let mut s = PatchKernelSums::new(3);
        let keys = [
            pair_key(0, 1),
            pair_key(2, 1),
            pair_key(0, 2),
            pair_key(1, 1),
        ];
        let terms = [
            PatchKernelSums::pair_term(0.5, 1.0),
            PatchKernelSums::pair_term(1.0, 0.5),
            PatchKernelSums::pair_term(0.5, 0.0),
            PatchKernelSums::pair_term(1.0, 1.0),
        ];
        s.add_pairs(&keys, &terms);
        assert_eq!(s.ends, vec![1, 4, 1]);
        let sums: Vec<f64> = s.log2_kernel.iter().map(|x| x.value()).collect();
        assert_eq!(sums, vec![-1.0, -1.0 + 2.0 + 0.0 + 0.0, 2.0]);
    }
}
