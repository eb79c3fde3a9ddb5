//! Entropy building blocks with the information-theory conventions of the paper (eq. (6)).

/// `x log2 x`, with `0 log 0 = 0` (the limit), so an unsampled entry never becomes NaN.
pub fn xlog2x(x: f64) -> f64 {
    if x > 0.0 {
        x * x.log2()
    } else {
        0.0
    }
}

/// Eq. (6): Shannon entropy in bits of a discrete distribution (need not be normalised: the weights are
/// divided by their sum). Zero weights contribute nothing; an all-zero input has entropy 0.
pub fn shannon_entropy(weights: impl IntoIterator<Item = f64> + Clone) -> f64 {
    let total: f64 = weights.clone().into_iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    -weights.into_iter().map(|w| xlog2x(w / total)).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_log_zero_is_zero() {
        assert_eq!(xlog2x(0.0), 0.0);
        assert_eq!(shannon_entropy([0.0, 0.0]), 0.0);
    }

    #[test]
    fn uniform_distribution_has_log_n_bits() {
        assert!((shannon_entropy([1.0; 8]) - 3.0).abs() < 1e-15);
        assert!((shannon_entropy([2.0, 2.0, 0.0]) - 1.0).abs() < 1e-15);
    }
}
