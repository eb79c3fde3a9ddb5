//! The point-to-point form factor of eq. (25), `F(x, y) = cos_x cos_y / (pi d^2)`, as eq. (27) and the
//! `information` refinement strategy use it: one definition of which pairs of points have a usable
//! kernel, and a sum of its logarithms that stays exact and cheap over millions of pairs.

/// `cos_x cos_y / d^2` of a pair of points, when it is a finite, normal, positive number. `None` when the
/// pair is degenerate: its points coincide (d = 0, the surfaces touch there), it grazes (a cosine of 0),
/// or the value would overflow or underflow and poison a sum with an infinity.
pub fn kernel_without_pi(cos_product: f64, distance: f64) -> Option<f64> {
    if !(distance > 0.0 && cos_product > 0.0) {
        return None;
    }
    let v = cos_product / (distance * distance);
    v.is_normal().then_some(v)
}

/// The sum over pairs of log2(cos_x cos_y / d^2), the variable part of eq. (27), with one `log2` per
/// run of 32 pairs instead of one per pair: log2 of a product is the sum of the logs, and the
/// product is kept as an f64 mantissa in [1, 2^RUN) and a separate integer exponent, so it can neither
/// overflow nor underflow. The rounding of RUN products costs ~RUN * 1e-16 relative, far below the
/// statistical error.
#[derive(Debug)]
pub struct Log2Sum {
    /// Completed runs.
    sum: f64,
    /// Product of the current run's mantissas.
    mantissa: f64,
    /// Sum of the current run's exponents.
    exponent: i64,
    /// Terms in the current run.
    pending: u32,
    /// Terms in all.
    count: u64,
}

impl Default for Log2Sum {
    fn default() -> Self {
        Log2Sum {
            sum: 0.0,
            mantissa: 1.0,
            exponent: 0,
            pending: 0,
            count: 0,
        }
    }
}

impl Log2Sum {
    /// Mantissas in [1, 2) multiplied per `log2`: the product stays below 2^32.
    const RUN: u32 = 32;

    /// Adds log2(cos_product / d^2); returns false (and adds nothing) for a degenerate pair
    /// ([`kernel_without_pi`]).
    pub fn add(&mut self, cos_product: f64, distance: f64) -> bool {
        let Some(v) = kernel_without_pi(cos_product, distance) else {
            return false;
        };
        let bits = v.to_bits();
        self.exponent += ((bits >> 52) & 0x7ff) as i64 - 1023;
        self.mantissa *= f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
        self.pending += 1;
        self.count += 1;
        if self.pending == Self::RUN {
            self.flush();
        }
        true
    }

    fn flush(&mut self) {
        if self.pending > 0 {
            self.sum += self.exponent as f64 + self.mantissa.log2();
        }
        *self = Log2Sum {
            sum: self.sum,
            count: self.count,
            ..Log2Sum::default()
        };
    }

    /// The sum of the terms `offset + log2(cos cos / d^2)` over the pairs added, and their number; eq.
    /// (27) takes `offset = log2(A_T / pi)`.
    pub fn finish(mut self, offset: f64) -> (f64, u64) {
        self.flush();
        (self.sum + self.count as f64 * offset, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batched sum equals the sum of the logs, over values spanning many orders of magnitude.
    #[test]
    fn log2_sum_matches_term_by_term_logs() {
        let mut s = Log2Sum::default();
        let mut direct = 0.0;
        let mut x = 0.37f64;
        for k in 0..1000 {
            // A deterministic spread of products and distances, from 1e-12 to 1e+3.
            x = (x * 7.13 + 0.1).fract();
            let cos = 0.05 + 0.95 * x;
            let d = 10f64.powf(-6.0 + 7.5 * ((k as f64 * 0.618).fract()));
            assert!(s.add(cos, d));
            direct += (cos / (d * d)).log2() + 1.5;
        }
        assert!(!s.add(0.5, 0.0), "coincident points");
        assert!(!s.add(0.0, 1.0), "a grazing pair");
        assert!(!s.add(0.5, 1e-200), "an infinite term");
        let (sum, n) = s.finish(1.5);
        assert_eq!(n, 1000);
        assert!(
            (sum - direct).abs() < 1e-9 * direct.abs(),
            "{sum} vs {direct}"
        );
    }
}
