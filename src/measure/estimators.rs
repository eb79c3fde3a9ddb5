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
/// complement.
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
    let tail = if 40.0 / a < n {
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
