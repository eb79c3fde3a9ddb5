//! One-dimensional quadrature rules on [0, 1] and their tensor products, for the exact values of the
//! calibration suite ([`super::kernel`], [`super::rectangles`]).
//!
//! * Gauss–Legendre: exponential convergence for integrands smooth on the closed interval (the form
//!   factor kernel between patches that do not touch).
//! * Tanh–sinh (double exponential, Takahasi and Mori 1974): exponential convergence also when the
//!   integrand has an integrable singularity at an end point, such as `x log x` where a kernel vanishes
//!   on the boundary of its domain (the terms of eq. (27) where a patch meets another's plane). The nodes
//!   crowd towards both ends; none is at an end, so an integrand is never evaluated on the boundary.

use std::f64::consts::PI;

/// A quadrature rule on [0, 1]: `sum_k weights[k] f(nodes[k])` approximates `int_0^1 f`.
#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    /// The nodes, increasing, all strictly inside (0, 1).
    pub nodes: Vec<f64>,
    /// Their weights (positive, summing to 1 up to the rule's error).
    pub weights: Vec<f64>,
}

impl Rule {
    /// The n-point Gauss–Legendre rule on [0, 1] (exact for polynomials of degree 2n - 1), by Newton's
    /// method on the Legendre polynomial from Tricomi's initial guesses.
    pub fn gauss_legendre(n: usize) -> Rule {
        assert!(n >= 1, "a Gauss rule needs a node");
        let mut nodes = vec![0.0; n];
        let mut weights = vec![0.0; n];
        for k in 0..n.div_ceil(2) {
            let mut x = (PI * (k as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 0.0;
            for _ in 0..100 {
                let (p, dp) = legendre_with_derivative(n, x);
                derivative = dp;
                let step = p / dp;
                x -= step;
                if step.abs() < 1e-16 {
                    derivative = legendre_with_derivative(n, x).1;
                    break;
                }
            }
            // On [-1, 1]: node x, weight 2 / ((1 - x^2) P_n'(x)^2); mapped to [0, 1] they halve.
            let w = 1.0 / ((1.0 - x * x) * derivative * derivative);
            nodes[k] = 0.5 * (1.0 - x);
            nodes[n - 1 - k] = 0.5 * (1.0 + x);
            weights[k] = w;
            weights[n - 1 - k] = w;
        }
        Rule { nodes, weights }
    }

    /// The tanh–sinh rule on [0, 1] with step `2^-level` in the transformed variable: nodes
    /// `x(t) = 1 / (1 + exp(-pi sinh t))` for `t = k h`, `|t| <= 3.5` (beyond, the weights are below
    /// 1e-25 of the largest), each weighted `h x'(t)`.
    pub fn tanh_sinh(level: u32) -> Rule {
        let h = 0.5f64.powi(level as i32);
        let half_span = (3.5 / h).round() as i64;
        let (mut nodes, mut weights) = (Vec::new(), Vec::new());
        for k in -half_span..=half_span {
            let t = k as f64 * h;
            let u = 0.5 * PI * t.sinh();
            // x = (1 + tanh u) / 2, dx/dt = (pi / 4) cosh t / cosh^2 u.
            let x = 1.0 / (1.0 + (-2.0 * u).exp());
            let w = h * 0.25 * PI * t.cosh() / u.cosh().powi(2);
            if x > 0.0 && x < 1.0 && w > 0.0 {
                nodes.push(x);
                weights.push(w);
            }
        }
        Rule { nodes, weights }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the rule has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// `int_a^b f` by this rule mapped onto [a, b].
    pub fn integrate(&self, a: f64, b: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
        let span = b - a;
        let sum: f64 = self
            .nodes
            .iter()
            .zip(&self.weights)
            .map(|(&x, &w)| w * f(a + span * x))
            .sum();
        sum * span
    }

    /// `int_[0,1]^2 f` by the tensor product of this rule with itself.
    pub fn integrate_square(&self, mut f: impl FnMut(f64, f64) -> f64) -> f64 {
        self.integrate(0.0, 1.0, |x| self.integrate(0.0, 1.0, |y| f(x, y)))
    }

    /// `int_[0,1]^3 f` by the tensor product of this rule with itself.
    pub fn integrate_cube(&self, mut f: impl FnMut(f64, f64, f64) -> f64) -> f64 {
        self.integrate(0.0, 1.0, |x| {
            self.integrate(0.0, 1.0, |y| self.integrate(0.0, 1.0, |z| f(x, y, z)))
        })
    }
}

/// `(P_n(x), P_n'(x))` by the three-term recurrence.
fn legendre_with_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let k = k as f64;
        let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    let n = n as f64;
    (p1, n * (x * p1 - p0) / (x * x - 1.0))
}

/// The unit triangle `{(p, q) : p, q >= 0, p + q <= 1}` as the image of the unit square under the
/// collapsed (Duffy) map `(s, r) -> (s, (1 - s) r)`, with its Jacobian `1 - s`: a tensor rule on the
/// square becomes a rule on the triangle.
pub fn collapse_to_triangle(s: f64, r: f64) -> (f64, f64, f64) {
    (s, (1.0 - s) * r, 1.0 - s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gauss–Legendre is exact for polynomials of degree 2n - 1 and its weights sum to 1.
    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        for n in [1, 2, 5, 12, 40] {
            let rule = Rule::gauss_legendre(n);
            assert!(
                (rule.weights.iter().sum::<f64>() - 1.0).abs() < 1e-14,
                "n = {n}"
            );
            let degree = 2 * n - 1;
            let got = rule.integrate(0.0, 1.0, |x| x.powi(degree as i32));
            assert!(
                (got - 1.0 / (degree as f64 + 1.0)).abs() < 1e-14,
                "n = {n}: {got}"
            );
        }
    }

    /// Tanh–sinh integrates end-point singularities to near machine precision: `int_0^1 x log x = -1/4`,
    /// `int_0^1 log x = -1`; `int_0^1 1 / sqrt(x) = 2` to the truncation at `|t| = 3.5`, which leaves out
    /// `int_0^(e^-52) x^-1/2 = 1e-11` at each end (the suite's integrands vanish at the ends).
    #[test]
    fn tanh_sinh_integrates_end_point_singularities() {
        let rule = Rule::tanh_sinh(5);
        type Case = (fn(f64) -> f64, f64, f64);
        let cases: [Case; 3] = [
            (|x| x * x.ln(), -0.25, 1e-14),
            (|x| x.ln(), -1.0, 1e-13),
            (|x| 1.0 / x.sqrt(), 2.0, 1e-10),
        ];
        for (f, exact, tolerance) in cases {
            let got = rule.integrate(0.0, 1.0, f);
            assert!((got - exact).abs() < tolerance, "{got} vs {exact}");
        }
        // And converges fast: level 3 is already within 1e-9 on x log x.
        let coarse = Rule::tanh_sinh(3).integrate(0.0, 1.0, |x| x * x.ln());
        assert!((coarse + 0.25).abs() < 1e-9, "{coarse}");
    }

    /// The collapsed map integrates over the triangle: its area is 1/2, `int p = 1/6`.
    #[test]
    fn collapsed_square_covers_the_triangle() {
        let rule = Rule::gauss_legendre(8);
        let area = rule.integrate_square(|s, r| collapse_to_triangle(s, r).2);
        let first_moment = rule.integrate_square(|s, r| {
            let (p, _, jacobian) = collapse_to_triangle(s, r);
            p * jacobian
        });
        assert!((area - 0.5).abs() < 1e-15);
        assert!((first_moment - 1.0 / 6.0).abs() < 1e-15);
    }
}
