//! PCG-64 draws, bit for bit those of `rand_pcg::Pcg64` (`Lcg128Xsl64`), made in blocks by interleaved
//! copies of its LCG.
//!
//! Why: `Pcg64::next_u64` first steps a 128-bit LCG (`state = state * MUL + inc`, about three dependent
//! 64-bit multiplies), then returns the XSL-RR output of the new state. Draw after draw, every step waits
//! for the previous one. Here lane `k` of [`LANES`] holds the state of draw `n + k` and jumps `LANES` draws
//! at a time (`state * MUL^LANES + inc_LANES`, the composed step, computed once), so the lanes' multiplies
//! are independent and overlap in the CPU. The draws come out in the stream's order: a block is written
//! round by round, lane by lane.
//!
//! The algorithm (not the code) is O'Neill's PCG as `rand_pcg` 0.3 implements it: `new(state, stream)`
//! takes the increment `2 * stream + 1`, adds it to the state and steps once; each draw steps, then
//! outputs `rotr64(hi ^ lo, state >> 122)`. The tests compare with `rand_pcg` itself.

/// The multiplier of PCG-64's 128-bit LCG (O'Neill's default for 128-bit state).
const PCG_MULTIPLIER: u128 = 0x2360_ED05_1FC6_5DA4_4385_DF64_9FCC_F645;

/// Interleaved LCGs: enough independent multiply chains to keep the multiplier busy, few enough that
/// their states (two registers each) stay in registers.
pub const LANES: usize = 4;

/// One affine map `x -> mul * x + add` mod 2^128: a number of LCG steps composed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Affine {
    mul: u128,
    add: u128,
}

impl Affine {
    /// `x` carried through the map.
    #[inline(always)]
    fn apply(self, x: u128) -> u128 {
        x.wrapping_mul(self.mul).wrapping_add(self.add)
    }

    /// This map followed by `next`.
    fn then(self, next: Affine) -> Affine {
        Affine {
            mul: self.mul.wrapping_mul(next.mul),
            add: next.apply(self.add),
        }
    }
}

/// PCG-64's stream `(state, stream)` (the arguments of `Pcg64::new`) as [`LANES`] interleaved LCGs.
#[derive(Clone, Debug)]
pub struct PcgLanes {
    /// Lane `k` holds the state whose output is the stream's next draw number `k` (counting from 0).
    states: [u128; LANES],
    /// [`LANES`] steps of the LCG composed: a lane's jump to its next draw.
    jump: Affine,
}

impl PcgLanes {
    /// The draws `Pcg64::new(state, stream)` would give.
    pub fn new(state: u128, stream: u128) -> Self {
        let step = Affine {
            mul: PCG_MULTIPLIER,
            add: (stream << 1) | 1,
        };
        // `Pcg64::new`'s own start: the increment added, one step; a draw then steps before its output.
        let mut current = step.apply(state.wrapping_add(step.add));
        let states = std::array::from_fn(|_| {
            current = step.apply(current);
            current
        });
        let jump = (1..LANES).fold(step, |acc, _| acc.then(step));
        PcgLanes { states, jump }
    }

    /// Fills `out` with the stream's next `out.len()` draws (a whole number of rounds of [`LANES`]).
    #[inline]
    pub fn fill(&mut self, out: &mut [u64]) {
        debug_assert_eq!(out.len() % LANES, 0, "whole rounds");
        let jump = self.jump;
        for round in out.chunks_exact_mut(LANES) {
            for (draw, state) in round.iter_mut().zip(&mut self.states) {
                *draw = xsl_rr(*state);
                *state = jump.apply(*state);
            }
        }
    }
}

/// PCG's XSL-RR output of a 128-bit state: the xor of its halves, rotated right by its top six bits.
#[inline(always)]
fn xsl_rr(state: u128) -> u64 {
    let folded = (state >> 64) as u64 ^ state as u64;
    folded.rotate_right((state >> 122) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngCore;
    use rand_pcg::Pcg64;

    #[test]
    fn lanes_draw_what_pcg64_draws() {
        let seeds = [
            (0u128, 0u128),
            (1, 1),
            (u128::MAX, 12345),
            (0xcafef00dd15ea5e5, 7 << 100),
        ];
        for (state, stream) in seeds {
            let mut reference = Pcg64::new(state, stream);
            let mut lanes = PcgLanes::new(state, stream);
            let mut block = [0u64; 16 * LANES];
            for _ in 0..50 {
                lanes.fill(&mut block);
                for &draw in &block {
                    assert_eq!(draw, reference.next_u64());
                }
            }
        }
    }
}
