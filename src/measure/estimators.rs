//! The entropy estimators for undersampled form-factor rows, and the special functions they need
//! (digamma, Grassberger's G, Chao–Wang–Jost's unseen term). [`super::bias`] explains each estimator;
//! [`super::rows`] and [`super::bias`] apply them.

/// An entropy estimator for the form-factor rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EntropyEstimator {
    /// The plug-in estimate of eq. (17), uncorrected.
    PlugIn,
    /// Miller–Madow's first-order correction.
    MillerMadow,
    /// Grassberger's 2003 estimator.
    Grassberger,
    /// Chao and Shen's coverage-adjusted estimator.
    ChaoShen,
    /// Chao, Wang and Jost's 2013 estimator.
    ChaoWangJost,
}

impl EntropyEstimator {
    /// Every estimator, for comparisons.
    pub const ALL: [EntropyEstimator; 5] = [
        EntropyEstimator::PlugIn,
        EntropyEstimator::MillerMadow,
        EntropyEstimator::Grassberger,
        EntropyEstimator::ChaoShen,
        EntropyEstimator::ChaoWangJost,
    ];

    /// A short name (`chao-wang-jost`).
    pub fn name(self) -> &'static str {
        match self {
            EntropyEstimator::PlugIn => "plug-in",
            EntropyEstimator::MillerMadow => "miller-madow",
            EntropyEstimator::Grassberger => "grassberger",
            EntropyEstimator::ChaoShen => "chao-shen",
            EntropyEstimator::ChaoWangJost => "chao-wang-jost",
        }
    }

    /// Parses a name as printed by [`EntropyEstimator::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.name() == name)
    }
}

/// Grassberger's G(n) = psi(n) + (-1)^n / 2 (psi((n+1)/2) - psi(n/2)).
pub fn grassberger_g(n: f64) -> f64 {
    let sign = if n % 2.0 == 0.0 { 1.0 } else { -1.0 };
    digamma(n) + 0.5 * sign * (digamma((n + 1.0) / 2.0) - digamma(n / 2.0))
}

/// The unseen-outcome term of Chao, Wang and Jost (2013), eq. (7):
/// `f1/N (1-A)^(1-N) (-ln A - sum_{r=1}^{N-1} (1-A)^r / r)`, with
/// `A = 2 f2 / ((N-1) f1 + 2 f2)` (or its f2 = 0 form). Written as the tail `sum_{m>=1} x^m / (m + N - 1)`,
/// `x = 1 - A`, which needs no cancellation: summed directly when it converges fast, otherwise from the
/// complement, and, when both would take more than [`UNSEEN_TERMS`] terms (a row of millions of samples
/// with few repeats, or a forged state), from its integral form (`unseen_tail_of_long_rows`): the
/// work per row is bounded whatever the counts.
pub fn chao_wang_jost_unseen(n: f64, f1: f64, f2: f64) -> f64 {
    if f1 == 0.0 || n < 2.0 {
        return 0.0;
    }
    let a = if f2 > 0.0 {
        2.0 * f2 / ((n - 1.0) * f1 + 2.0 * f2)
    } else {
        2.0 / ((n - 1.0) * (f1 - 1.0) + 2.0)
    };
    if a >= 1.0 {
        return 0.0;
    }
    let x = 1.0 - a;
    let tail = if (40.0 / a).min(n) > UNSEEN_TERMS {
        unseen_tail_of_long_rows(n, a)
    } else if 40.0 / a < n {
        // Geometric decay: ~40/A terms reach 1e-17.
        let mut sum = 0.0;
        let mut power = 1.0;
        let mut m = 1.0;
        loop {
            power *= x;
            let term = power / (m + n - 1.0);
            sum += term;
            if term < 1e-17 * sum {
                break sum;
            }
            m += 1.0;
        }
    } else {
        // tail = x^(1-N) (-ln A - sum_{r=1}^{N-1} x^r / r), summing the N - 1 terms.
        let mut partial = 0.0;
        let mut power = 1.0;
        for r in 1..(n as u64) {
            power *= x;
            partial += power / r as f64;
        }
        (-(a.ln()) - partial).max(0.0) * x.powf(1.0 - n)
    };
    f1 / n * tail
}

/// The most terms [`chao_wang_jost_unseen`] sums; beyond, the sum's integral form is used.
pub const UNSEEN_TERMS: f64 = (1u64 << 20) as f64;

/// The tail `sum_{m>=1} x^m / (m + N - 1)` (`x = 1 - A`) for `N` beyond [`UNSEEN_TERMS`]. With
/// `1/(m + N - 1)` written as an integral, the tail is `x int_0^inf e^(-N u) / (1 - x e^(-u)) du`; the
/// weight `e^(-N u)` confines `u` to a few times `1/N`, where `1 - x e^(-u) = A + x u` to a relative
/// `u/2`, so the tail is `e^c E1(c)` with `c = A N / x` to a relative error of order `1/N` (below
/// `1e-6` here, far below the estimator's own error).
fn unseen_tail_of_long_rows(n: f64, a: f64) -> f64 {
    let c = (a * n / (1.0 - a)).max(f64::MIN_POSITIVE);
    scaled_exponential_integral(c)
}

/// `e^c E1(c)` for `c > 0`: the power series of `E1` below 1, else the continued fraction of
/// `e^c E1(c)` (which never forms `e^c`, so it holds for any `c`).
pub fn scaled_exponential_integral(c: f64) -> f64 {
    const EULER: f64 = 0.577_215_664_901_532_9;
    if c <= 1.0 {
        // E1(c) = -gamma - ln c - sum_{k>=1} (-c)^k / (k k!)
        let (mut sum, mut term) = (0.0, 1.0);
        for k in 1..60 {
            term *= -c / k as f64;
            sum += term / k as f64;
            if term.abs() < 1e-18 {
                break;
            }
        }
        return (-EULER - c.ln() - sum) * c.exp();
    }
    // Lentz's method on e^c E1(c) = 1/(c + 1 - 1^2/(c + 3 - 2^2/(c + 5 - ...))).
    let tiny = 1e-300;
    let mut b = c + 1.0;
    let mut cf = 1.0 / tiny;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..500 {
        let an = -((i * i) as f64);
        b += 2.0;
        d = 1.0 / (an * d + b);
        cf = b + an / cf;
        let delta = cf * d;
        h *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    h
}

/// Integer arguments below this come from a table (counts are mostly small integers, and the estimators
/// need psi of every count).
const DIGAMMA_TABLE: usize = 1 << 16;

/// The digamma function psi(x) for x > 0: a table for small integers (psi(n + 1) = psi(n) + 1/n), else
/// the recurrence up to x >= 10 and the asymptotic series.
pub fn digamma(x: f64) -> f64 {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    if x.fract() == 0.0 && x >= 1.0 && x < DIGAMMA_TABLE as f64 {
        let table = TABLE.get_or_init(|| {
            let mut t = vec![0.0; DIGAMMA_TABLE];
            t[1] = digamma_series(1.0);
            for n in 1..DIGAMMA_TABLE - 1 {
                t[n + 1] = t[n] + 1.0 / n as f64;
            }
            t
        });
        return table[x as usize];
    }
    digamma_series(x)
}

fn digamma_series(mut x: f64) -> f64 {
    let mut result = 0.0;
    while x < 10.0 {
        result -= 1.0 / x;
        x += 1.0;
    }
    let inv = 1.0 / x;
    let inv2 = inv * inv;
    result + x.ln()
        - 0.5 * inv
        - inv2
            * (1.0 / 12.0
                - inv2 * (1.0 / 120.0 - inv2 * (1.0 / 252.0 - inv2 * (1.0 / 240.0 - inv2 / 132.0))))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unseen term's integral form for long rows agrees with the sum it replaces, just past the
    /// threshold, and a row of 2^64 samples with few repeats (a forged state) takes no longer than any.
    #[test]
    fn unseen_term_of_long_rows_is_bounded_and_agrees() {
        let n = UNSEEN_TERMS * 2.0;
        for a in [1e-7, 1e-8, 3e-6] {
            // The complement, summed term by term as for shorter rows.
            let x = 1.0 - a;
            let (mut partial, mut power) = (0.0, 1.0);
            for r in 1..(n as u64) {
                power *= x;
                partial += power / r as f64;
            }
            let summed = (-(a.ln()) - partial).max(0.0) * x.powf(1.0 - n);
            let integral = unseen_tail_of_long_rows(n, a);
            assert!(
                ((integral - summed) / summed).abs() < 1e-5,
                "A {a}: {integral} against {summed}"
            );
        }
        let start = std::time::Instant::now();
        let huge = chao_wang_jost_unseen(18_446_744_073_709_551_615.0, 1e12, 1.0);
        assert!(huge.is_finite() && huge >= 0.0, "{huge}");
        assert!(start.elapsed().as_secs() < 1);
    }

    /// `e^c E1(c)` against tabulated values (Abramowitz and Stegun, table 5.1) and its large-c limit.
    #[test]
    fn scaled_exponential_integral_matches_tables() {
        for (c, e1) in [
            (0.5, 0.559_773_594_8),
            (1.0, 0.219_383_934_4),
            (2.0, 0.048_900_510_7),
        ] {
            let got = scaled_exponential_integral(c) * (-c).exp();
            assert!((got - e1).abs() < 1e-9, "E1({c}) = {got}, not {e1}");
        }
        // e^c E1(c) -> 1/c - 1/c^2 + 2/c^3 for large c.
        let c = 1e6;
        let expected = 1.0 / c - 1.0 / (c * c) + 2.0 / (c * c * c);
        assert!((scaled_exponential_integral(c) - expected).abs() < 1e-18);
    }

    #[test]
    fn digamma_matches_known_values() {
        let euler = 0.577_215_664_901_532_9;
        assert!((digamma(1.0) + euler).abs() < 1e-12);
        assert!((digamma(0.5) + euler + 2.0 * 2f64.ln()).abs() < 1e-12);
        // psi(n) = -gamma + H_{n-1}
        let h: f64 = (1..100).map(|k| 1.0 / k as f64).sum();
        assert!((digamma(100.0) - (-euler + h)).abs() < 1e-12);
    }
}
