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
/// `x = 1 - A`: for a long row with `A N` up to 4 (the usual case, from thinly to well sampled rows) from
/// its series in `A` (`unseen_tail_near_one`, about 40 terms); otherwise summed directly when it converges
/// fast, else from the complement, and, when both would take more than [`UNSEEN_TERMS`] terms (a row of
/// millions of samples with few repeats, or a forged state), from its integral form
/// (`unseen_tail_of_long_rows`): the work per row is bounded whatever the counts.
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
    let tail = if a * n <= SERIES_A_N && n > SERIES_MIN_N {
        unseen_tail_near_one(n - 1.0, a)
    } else if (40.0 / a).min(n) > UNSEEN_TERMS {
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

/// Up to this `A N`, and from this `N` on, [`chao_wang_jost_unseen`] takes its tail from the series in `A`
/// ([`unseen_tail_near_one`]): about 40 terms where the sums take `min(N, 40/A)`, and accurate to about
/// `e^(A N)` roundings (1e-13 at the bound).
const SERIES_A_N: f64 = 4.0;
const SERIES_MIN_N: f64 = 128.0;

/// The tail `sum_{m>=1} x^m / (m + n)` (`x = 1 - A`, `n = N - 1`) as a series in `A`: the tail is
/// `x / (n + 1) 2F1(1, n + 1; n + 2; x)`, and 2F1(a, b; a + b; z) near z = 1 has the logarithmic
/// expansion of Abramowitz and Stegun 15.3.10, here
/// `x sum_k (n + 1)_k / k! A^k [psi(k + 1) - psi(n + 1 + k) - ln A]`. The coefficients peak near
/// `k = A n` and then fall like `(A n)^k / k!`.
fn unseen_tail_near_one(n: f64, a: f64) -> f64 {
    const EULER: f64 = 0.577_215_664_901_532_9;
    let ln_a = a.ln();
    // psi(n + 1 + k) - psi(k + 1), from k = 0 (the harmonic number H_n).
    let mut harmonic = digamma_series(n + 1.0) + EULER;
    let (mut coefficient, mut sum, mut k) = (1.0f64, 0.0f64, 0.0f64);
    loop {
        sum += coefficient * (-ln_a - harmonic);
        let largest_left = coefficient * (ln_a.abs() + harmonic + 1.0);
        if (k > a * (n + 1.0) && largest_left < 1e-17 * sum.abs()) || k >= 1000.0 {
            break;
        }
        harmonic += 1.0 / (n + 1.0 + k) - 1.0 / (k + 1.0);
        coefficient *= a * (n + 1.0 + k) / (k + 1.0);
        k += 1.0;
    }
    (1.0 - a) * sum
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

    /// The series in `A` agrees with the tail summed term by term (its complement, compensated, each
    /// power from the logarithm), over
    /// rows of 129 to 10^5 segments and `A N` from 1e-6 to the bound, the cancelling `A N` near
    /// `e^-gamma` included.
    #[test]
    fn unseen_tail_near_one_agrees_with_the_sum() {
        let summed = |n: f64, a: f64| {
            // sum_{m>=1} x^m / (m + n) = x^(-n) (-ln A - sum_{r=1}^{n} x^r / r), compensated, each power
            // from the logarithm (a power multiplied up term by term drifts by r roundings).
            let ln_x = (-a).ln_1p();
            let (mut partial, mut carry) = (0.0f64, 0.0f64);
            for r in 1..=(n as u64) {
                let power = (r as f64 * ln_x).exp();
                let y = power / r as f64 - carry;
                let t = partial + y;
                carry = (t - partial) - y;
                partial = t;
            }
            (-(a.ln()) - partial) * (-n * ln_x).exp()
        };
        let mut worst = 0.0f64;
        for n in [128.0, 300.0, 1000.0, 12_345.0, 100_000.0] {
            for an in [
                1e-6,
                1e-3,
                0.1,
                0.5,
                0.561_459_483_566_885,
                1.0,
                2.0,
                3.0,
                3.99,
            ] {
                let a = an / (n + 1.0);
                let (series, exact) = (unseen_tail_near_one(n, a), summed(n, a));
                worst = worst.max(((series - exact) / exact).abs());
            }
        }
        assert!(worst < 1e-12, "{worst}");
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
