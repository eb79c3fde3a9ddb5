//! Sums of f64 values that give the same bits in any order: a run's batches can then be added up by
//! any number of threads, in rounds, in shards on other machines, or after a resume, and the result is
//! that of one sequential run to the last bit.
//!
//! Each value is turned into a fixed-point integer with 2^-`FRACTION_BITS` resolution, exactly for
//! every value whose last mantissa bit is at least that (any |x| >= 2^-8: the batch sums of eq. (27)'s
//! terms, thousands of bits each, always are), and integers add associatively. An i128 holds sums up
//! to 2^67, far beyond 10^12 lines of eq. (27) terms.

use serde::{Deserialize, Serialize};

/// Fractional bits of the fixed point.
const FRACTION_BITS: i32 = 60;

/// An exact sum of f64 values (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ExactSum(i128);

impl ExactSum {
    /// The sum of one value.
    pub fn of(x: f64) -> Self {
        ExactSum(to_fixed(x))
    }

    /// Adds another sum.
    pub fn add(&mut self, other: ExactSum) {
        self.0 += other.0;
    }

    /// This sum without `part`, a sum of some of its terms.
    pub fn minus(self, part: ExactSum) -> ExactSum {
        ExactSum(self.0 - part.0)
    }

    /// The sum as an f64 (rounded once, to nearest).
    pub fn value(self) -> f64 {
        self.0 as f64 * (-FRACTION_BITS as f64).exp2()
    }
}

/// `x` in fixed point, rounded to nearest (ties away from zero) below the resolution; non-finite values
/// are not expected (eq. (27)'s terms are kept finite) and count as 0.
fn to_fixed(x: f64) -> i128 {
    if !x.is_finite() || x == 0.0 {
        return 0;
    }
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1u64 << 52) - 1);
    // x = mantissa * 2^(shift - FRACTION_BITS) in fixed-point units.
    let (mantissa, power) = if exponent == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1u64 << 52), exponent - 1075)
    };
    let shift = power + FRACTION_BITS;
    let magnitude = if shift >= 0 {
        assert!(shift < 74, "{x} is beyond the fixed point's range");
        i128::from(mantissa) << shift
    } else if shift > -64 {
        let m = i128::from(mantissa);
        (m + (1 << (-shift - 1))) >> -shift
    } else {
        0
    };
    if x < 0.0 {
        -magnitude
    } else {
        magnitude
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values from 2^-8 up are held exactly, and a sum does not depend on the order of its terms.
    #[test]
    fn exact_and_order_independent() {
        for x in [1.0, -2.5, 0.1, 1e10, -7.25e-3, 123456.789, 2f64.powi(-8)] {
            assert_eq!(ExactSum::of(x).value(), x, "{x}");
        }
        let terms: Vec<f64> = (0..1000)
            .map(|k| ((k as f64) * 0.7318).sin() * 10f64.powi(k % 7))
            .collect();
        let forward = terms.iter().fold(ExactSum::default(), |mut s, &x| {
            s.add(ExactSum::of(x));
            s
        });
        let backward = terms.iter().rev().fold(ExactSum::default(), |mut s, &x| {
            s.add(ExactSum::of(x));
            s
        });
        assert_eq!(forward, backward);
        let naive: f64 = terms.iter().sum();
        assert!((forward.value() - naive).abs() <= 1e-9 * naive.abs().max(1.0));
        assert_eq!(forward.minus(ExactSum::of(terms[0])).value(), {
            let mut s = ExactSum::default();
            terms[1..].iter().for_each(|&x| s.add(ExactSum::of(x)));
            s.value()
        });
        // Below the resolution a value rounds; zero and the tiniest vanish.
        assert_eq!(ExactSum::of(0.0).value(), 0.0);
        assert_eq!(ExactSum::of(1e-300).value(), 0.0);
    }
}
