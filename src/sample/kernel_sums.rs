//! Per-patch sums of eq. (27)'s terms, for the per-patch results (`scx analyze --patches`).
//!
//! The run's I_s^c is the mean over its visible pairs of `log2(A_T cos_x cos_y / (pi d^2))` (eq. 27).
//! To share it out among the patches, every pair's term is credited to both of its end patches here
//! (its `log2(cos_x cos_y / d^2)` part; the constant `log2(A_T / pi)` is added by the measure). Gathered
//! only when asked for ([`super::tally::Wanted::per_patch`]): it costs one `log2` per pair and two
//! additions into arrays of the patch count, which the hot loop otherwise skips. The sums are exact
//! ([`ExactSum`]), so batches, groups and shards can be added up in any order with the same bits.
//!
//! With `--enclose` ([`super::environment`]) an escape is a pair of its patch with the environment, and
//! the enclosed scene's I_s^c has its term too. Per patch, the terms of its escapes are then summed
//! apart ([`PatchKernelSums::environment_log2_kernel`]): apart, because a run not enclosed has no such
//! pairs, and because the environment's own row (every escape's other end, and both ends of every line
//! that met nothing) follows from them and the run's misses ([`PatchKernelSums::enclosed`]).

use super::counts::split_key;
use super::environment;
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
    /// Per patch, for `--enclose`: the sum of the log kernel over its escapes (the segments from its
    /// front side to the environment sphere, `environment::escape`), degenerate ones left out; empty
    /// when not gathered ([`super::tally::Wanted::environment`]).
    pub environment_log2_kernel: Vec<ExactSum>,
    /// Per patch: the escapes that entered `environment_log2_kernel` (empty when not gathered).
    pub environment_ends: Vec<u64>,
}

impl PatchKernelSums {
    /// Empty sums for `patches` patches, without the environment's.
    pub fn new(patches: usize) -> Self {
        PatchKernelSums {
            log2_kernel: vec![ExactSum::default(); patches],
            ends: vec![0; patches],
            environment_log2_kernel: Vec::new(),
            environment_ends: Vec::new(),
        }
    }

    /// Empty sums for `patches` patches, the escapes' terms summed too (`--enclose`).
    pub fn with_environment(patches: usize) -> Self {
        PatchKernelSums {
            environment_log2_kernel: vec![ExactSum::default(); patches],
            environment_ends: vec![0; patches],
            ..PatchKernelSums::new(patches)
        }
    }

    /// Whether the escapes' terms are summed too.
    pub fn has_environment(&self) -> bool {
        !self.environment_ends.is_empty()
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

    /// Credits each escape's term (`terms[k]`, from [`PatchKernelSums::pair_term`] of
    /// `environment::escape`, `NaN` when degenerate) to its patch `patches[k]`; kept only when the
    /// environment's sums are.
    pub fn add_escapes(&mut self, patches: &[u32], terms: &[f64]) {
        if !self.has_environment() {
            return;
        }
        for (&p, &term) in patches.iter().zip(terms) {
            if term.is_nan() {
                continue;
            }
            self.environment_log2_kernel[p as usize].add(ExactSum::of(term));
            self.environment_ends[p as usize] += 1;
        }
    }

    /// Adds another set of lines' sums into these. The environment's sums stay only when both have
    /// them (sums of only some of the lines would be silently wrong).
    pub fn merge(&mut self, other: &PatchKernelSums) {
        add_sums(
            &mut self.log2_kernel,
            &mut self.ends,
            (&other.log2_kernel, &other.ends),
        );
        if other.has_environment() {
            add_sums(
                &mut self.environment_log2_kernel,
                &mut self.environment_ends,
                (&other.environment_log2_kernel, &other.environment_ends),
            );
        } else {
            self.environment_log2_kernel.clear();
            self.environment_ends.clear();
        }
    }

    /// The sums of the enclosed scene, whose patch `n` (after the scene's `n`) is the environment, for
    /// lines of which `misses` met nothing: each patch's pair ends and its escapes, and the environment's
    /// ends, every escape's other end (its term is the escape's: the kernel is symmetric) and both ends
    /// of each line that met nothing (a chord of the sphere, `environment::miss`). `None` without the
    /// environment's sums.
    pub fn enclosed(&self, misses: u64, radius: f64) -> Option<PatchKernelSums> {
        if !self.has_environment() {
            return None;
        }
        let mut log2_kernel = self.log2_kernel.clone();
        let mut ends = self.ends.clone();
        let mut env_sum = ExactSum::default();
        let mut env_ends = 0u64;
        for (i, (&s, &e)) in self
            .environment_log2_kernel
            .iter()
            .zip(&self.environment_ends)
            .enumerate()
        {
            log2_kernel[i].add(s);
            ends[i] += e;
            env_sum.add(s);
            env_ends += e;
        }
        if misses > 0 {
            let (cos_product, chord) = environment::miss(radius);
            let term = PatchKernelSums::pair_term(cos_product, chord);
            for _ in 0..2 {
                env_sum.add(ExactSum::of(term * misses as f64));
            }
            env_ends += 2 * misses;
        }
        log2_kernel.push(env_sum);
        ends.push(env_ends);
        Some(PatchKernelSums {
            log2_kernel,
            ends,
            environment_log2_kernel: Vec::new(),
            environment_ends: Vec::new(),
        })
    }
}

/// Adds per-patch sums and counts `other` into `sums` and `ends`, element by element.
fn add_sums(sums: &mut [ExactSum], ends: &mut [u64], other: (&[ExactSum], &[u64])) {
    for (a, b) in sums.iter_mut().zip(other.0) {
        a.add(*b);
    }
    for (a, b) in ends.iter_mut().zip(other.1) {
        *a += b;
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

    /// The enclosed sums: each patch's escapes join its pair ends; the environment (last) has every
    /// escape's term once and the chord's, log2(1 / (2 R)^2) = -2 for R = 1, twice per miss; a
    /// degenerate escape enters nothing. Without the escapes' sums there are none, and a merge with sums
    /// without them drops them.
    #[test]
    fn enclosed_sums_add_the_escapes_and_the_environments_row() {
        let mut s = PatchKernelSums::with_environment(2);
        s.add_pairs(&[pair_key(0, 1)], &[3.0]);
        s.add_escapes(&[1, 1, 0], &[-1.0, 0.5, f64::NAN]);
        assert_eq!(s.environment_ends, vec![0, 2]);
        let e = s.enclosed(3, 1.0).unwrap();
        assert_eq!(e.ends, vec![1, 3, 2 + 6]);
        let sums: Vec<f64> = e.log2_kernel.iter().map(|x| x.value()).collect();
        assert_eq!(sums, vec![3.0, 3.0 - 0.5, -0.5 - 2.0 * 2.0 * 3.0]);
        assert!(!e.has_environment());

        let plain = PatchKernelSums::new(2);
        assert!(plain.enclosed(3, 1.0).is_none());
        let mut merged = s.clone();
        merged.merge(&s);
        assert_eq!(merged.environment_ends, vec![0, 4]);
        merged.merge(&plain);
        assert!(!merged.has_environment());
        let mut ignored = plain.clone();
        ignored.add_escapes(&[0], &[1.0]);
        assert_eq!(ignored, plain);
    }
}
