//! Exact form factors between axis-aligned rectangles (closed forms from Howell's catalogue of radiation
//! configuration factors, C-11, C-14, C-16 and C-17), and the pair integrals of eq. (25) over unit squares
//! reduced to smooth integrals by hand: the independent truth behind `@cube:N` and the open scenes of two
//! squares.

use std::f64::consts::{LN_2, PI};

use super::kernel::Integrand;
use super::quadrature::Rule;
use crate::scene::Scene;

/// Form factor between two identical, directly opposed parallel rectangles `a x b` at distance `c`
/// (Howell C-11).
pub fn ff_parallel(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    2.0 / (PI * x * y)
        * (((1.0 + x2) * (1.0 + y2) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// Form factor from a rectangle `w x l` to a perpendicular rectangle `h x l` sharing the edge of length
/// `l` (Howell C-14).
pub fn ff_perpendicular(w: f64, h: f64, l: f64) -> f64 {
    let (ww, hh) = (w / l, h / l);
    let (w2, h2) = (ww * ww, hh * hh);
    let s = (w2 + h2).sqrt();
    let a = (1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2);
    let b = (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).powf(w2);
    let c = (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).powf(h2);
    1.0 / (PI * ww)
        * (ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan() - s * (1.0 / s).atan()
            + 0.25 * (a * b * c).ln())
}

/// An axis-aligned rectangle: `coord[fixed] = level`, spanning `lo..hi` on the two other axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisRect {
    /// The axis the rectangle is perpendicular to.
    pub fixed: usize,
    /// Its coordinate on that axis.
    pub level: f64,
    /// The smallest corner.
    pub lo: [f64; 3],
    /// The largest corner.
    pub hi: [f64; 3],
}

impl AxisRect {
    /// The rectangle of a patch whose polygon is an axis-aligned rectangle (scene units); `None` when it
    /// is not one.
    pub fn of_patch(scene: &Scene, p: usize) -> Option<AxisRect> {
        let pts: Vec<[f64; 3]> = scene
            .polygon(&scene.patches[p])
            .iter()
            .map(|&v| scene.vertices[v as usize].to_array())
            .collect();
        let lo = [0, 1, 2].map(|a| pts.iter().map(|q| q[a]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1, 2].map(|a| pts.iter().map(|q| q[a]).fold(f64::NEG_INFINITY, f64::max));
        let fixed = (0..3).find(|&a| hi[a] - lo[a] == 0.0)?;
        let is_rectangle = pts.len() == 4
            && pts.iter().all(|q| {
                (0..3)
                    .filter(|&a| a != fixed)
                    .all(|a| q[a] == lo[a] || q[a] == hi[a])
            });
        is_rectangle.then_some(AxisRect {
            fixed,
            level: lo[fixed],
            lo,
            hi,
        })
    }

    /// Its area.
    pub fn area(&self) -> f64 {
        (0..3)
            .filter(|&a| a != self.fixed)
            .map(|a| self.hi[a] - self.lo[a])
            .product()
    }
}

/// `A_1 F_12` between two axis-aligned rectangles that see each other over no obstacle (parallel planes,
/// or perpendicular planes on the same side of each other), by the superposition of corner terms
/// (Howell C-16 and C-17). Zero for coplanar rectangles.
pub fn area_form_factor(r1: &AxisRect, r2: &AxisRect) -> f64 {
    if r1.fixed == r2.fixed {
        parallel_area_form_factor(r1, r2)
    } else {
        perpendicular_area_form_factor(r1, r2)
    }
}

fn parallel_area_form_factor(r1: &AxisRect, r2: &AxisRect) -> f64 {
    let c = (r1.level - r2.level).abs();
    if c == 0.0 {
        return 0.0;
    }
    let (u, v) = ((r1.fixed + 1) % 3, (r1.fixed + 2) % 3);
    let g = |x: f64, y: f64| {
        let (sy, sx) = ((y * y + c * c).sqrt(), (x * x + c * c).sqrt());
        (x * sy * (x / sy).atan() + y * sx * (y / sx).atan()
            - 0.5 * c * c * (x * x + y * y + c * c).ln())
            / (2.0 * PI)
    };
    corner_sum(|i, j, k, l| {
        g(
            corner(r1, u, i) - corner(r2, u, k),
            corner(r1, v, j) - corner(r2, v, l),
        )
    })
}

fn perpendicular_area_form_factor(r1: &AxisRect, r2: &AxisRect) -> f64 {
    // Common axis b; x: distance of r1's points from r2's plane, xi: of r2's points from r1's plane.
    let b = 3 - r1.fixed - r2.fixed;
    let g = |x: f64, y: f64, xi: f64, eta: f64| {
        let r2 = x * x + xi * xi;
        let d = y - eta;
        let t1 = if r2 > 0.0 {
            d * r2.sqrt() * (d / r2.sqrt()).atan()
        } else {
            0.0
        };
        let q = r2 + d * d;
        let t2 = if q > 0.0 {
            0.25 * (r2 - d * d) * q.ln()
        } else {
            0.0
        };
        (t1 - t2) / (2.0 * PI)
    };
    // Distances from the common line, in increasing order so the alternating sum keeps its sign.
    let dist = |r: &AxisRect, axis: usize, level: f64| {
        let (p, q) = ((r.lo[axis] - level).abs(), (r.hi[axis] - level).abs());
        [p.min(q), p.max(q)]
    };
    let (x, xi) = (dist(r1, r2.fixed, r2.level), dist(r2, r1.fixed, r1.level));
    corner_sum(|i, j, k, l| g(x[i], corner(r1, b, j), xi[k], corner(r2, b, l)))
}

fn corner(r: &AxisRect, axis: usize, which: usize) -> f64 {
    if which == 0 {
        r.lo[axis]
    } else {
        r.hi[axis]
    }
}

/// The alternating sum over the 16 corner combinations of two rectangles.
fn corner_sum(f: impl Fn(usize, usize, usize, usize) -> f64) -> f64 {
    let mut s = 0.0;
    for i in 0..2 {
        for j in 0..2 {
            for k in 0..2 {
                for l in 0..2 {
                    let sign = if (i + j + k + l) % 2 == 0 { 1.0 } else { -1.0 };
                    s += sign * f(i, j, k, l);
                }
            }
        }
    }
    s
}

/// The exact form factors `F_ij` of row `i` between axis-aligned rectangles that all see each other
/// unobstructed unless coplanar (the patches of `@cube:N`, of two facing squares).
pub fn form_factor_row(rects: &[AxisRect], i: usize) -> Vec<f64> {
    let a = rects[i].area();
    rects
        .iter()
        .map(|r| area_form_factor(&rects[i], r) / a)
        .collect()
}

/// `int int g(K)` over two unit squares facing each other at distance `c` (ordered pair, x on one and y
/// on the other): with `(u, v) = x - y` in the plane, the pairs at offset `(u, v)` have measure
/// `(1 - |u|)(1 - |v|)`, and K is even in both, so it is `4 int_[0,1]^2 (1-u)(1-v) g(K(u, v))` with
/// `K = c^2 / (pi (u^2 + v^2 + c^2)^2)`, smooth: Gauss–Legendre with `nodes` per dimension.
pub fn parallel_squares_integral(c: f64, integrand: Integrand, nodes: usize) -> f64 {
    let rule = Rule::gauss_legendre(nodes);
    4.0 * rule.integrate_square(|u, v| {
        let q = u * u + v * v + c * c;
        let k = c * c / (PI * q * q);
        (1.0 - u) * (1.0 - v) * value_of(integrand, k)
    })
}

/// `int int g(K)` over two unit squares meeting at a right angle along a common edge (ordered pair).
///
/// With `p` and `q` the distances of x and y from the common edge and `t` their offset along it, the
/// pairs at `(p, q, t)` have measure `1 - |t|`, `K = p q / (pi (p^2 + q^2 + t^2)^2)`, and the integral
/// is `2 int_[0,1]^3 (1 - t) g(K)`. The unit cube of `(p, q, t)` is cut into the three cones where `p`,
/// `q` or `t` is the largest; on each, `(p, q, t) = lambda w` with that coordinate of `w` equal to 1,
/// Jacobian `lambda^2`, and the radial integral is closed-form (`K` is homogeneous of degree -2):
/// `int_0^1 (1 - lambda tau) K dlambda = K (1 - tau / 2)` and, for `K log2 K`,
/// `K ((1 - tau / 2) log2 K + (2 - tau / 2) / ln 2)`, with `tau = w_t`. What is left is integrated by
/// tanh–sinh at `level` over the unit square (K log K behaves like `x log x` at `p = 0` and `q = 0`).
pub fn perpendicular_squares_integral(integrand: Integrand, level: u32) -> f64 {
    let rule = Rule::tanh_sinh(level);
    let radial = |p: f64, q: f64, tau: f64| {
        let s = p * p + q * q + tau * tau;
        let k = p * q / (PI * s * s);
        match integrand {
            Integrand::Kernel => k * (1.0 - 0.5 * tau),
            Integrand::KernelLog if k > 0.0 => {
                k * ((1.0 - 0.5 * tau) * k.log2() + (2.0 - 0.5 * tau) / LN_2)
            }
            Integrand::KernelLog => 0.0,
        }
    };
    let p_largest = rule.integrate_square(|q, t| radial(1.0, q, t));
    let q_largest = rule.integrate_square(|p, t| radial(p, 1.0, t));
    let t_largest = rule.integrate_square(|p, q| radial(p, q, 1.0));
    2.0 * (p_largest + q_largest + t_largest)
}

/// `g(k)` with `0 log 0 = 0`.
fn value_of(integrand: Integrand, k: f64) -> f64 {
    match integrand {
        Integrand::Kernel => k,
        Integrand::KernelLog if k > 0.0 => k * k.log2(),
        Integrand::KernelLog => 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::kernel::{pair_integral, Precision, Triangle};
    use crate::geom::{DVec3, Point};

    fn square_triangles(corners: [Point; 4]) -> [Triangle; 2] {
        let [a, b, c, d] = corners;
        [Triangle::new([a, b, c]), Triangle::new([a, c, d])]
    }

    fn sum_over(
        first: &[Triangle],
        second: &[Triangle],
        integrand: Integrand,
        precision: Precision,
    ) -> f64 {
        first
            .iter()
            .flat_map(|t1| second.iter().map(move |t2| (t1, t2)))
            .map(|(t1, t2)| pair_integral(t1, t2, integrand, precision).unwrap())
            .sum()
    }

    /// Unit squares sharing an edge (F = 0.2000437, Howell C-14) and facing each other at distance 1
    /// (F = 0.1998244, C-11), each cut into two triangles so that every kind of pair occurs: a common
    /// edge, a common vertex, and separate triangles.
    #[test]
    fn form_factors_of_unit_squares_match_closed_forms() {
        let o = DVec3::ZERO;
        let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
        let floor = square_triangles([o, x, x + y, y]);
        let wall = square_triangles([o, y, y + z, z]);
        let ceiling = square_triangles([z, z + x, z + x + y, z + y]);
        let perpendicular = sum_over(&floor, &wall, Integrand::Kernel, Precision::STANDARD);
        let parallel = sum_over(&floor, &ceiling, Integrand::Kernel, Precision::STANDARD);
        let exact_perpendicular = ff_perpendicular(1.0, 1.0, 1.0);
        let exact_parallel = ff_parallel(1.0, 1.0, 1.0);
        assert!(
            (perpendicular - exact_perpendicular).abs() < 1e-12,
            "{perpendicular} vs {exact_perpendicular}"
        );
        assert!(
            (parallel - exact_parallel).abs() < 1e-12,
            "{parallel} vs {exact_parallel}"
        );
    }

    /// The hand reductions integrate K to the closed-form form factors of unit squares.
    #[test]
    fn square_reductions_integrate_the_kernel_to_the_closed_forms() {
        let parallel = parallel_squares_integral(1.0, Integrand::Kernel, 30);
        assert!(
            (parallel - ff_parallel(1.0, 1.0, 1.0)).abs() < 1e-14,
            "{parallel}"
        );
        let far = parallel_squares_integral(2.5, Integrand::Kernel, 30);
        assert!((far - ff_parallel(1.0, 1.0, 2.5)).abs() < 1e-14, "{far}");
        let perpendicular = perpendicular_squares_integral(Integrand::Kernel, 5);
        let exact = ff_perpendicular(1.0, 1.0, 1.0);
        assert!(
            (perpendicular - exact).abs() < 1e-13,
            "{perpendicular} vs {exact}"
        );
    }

    /// The corner superposition reproduces the one-piece closed forms.
    #[test]
    fn corner_superposition_matches_howell() {
        let floor = AxisRect {
            fixed: 2,
            level: 0.0,
            lo: [0.0, 0.0, 0.0],
            hi: [1.0, 2.0, 0.0],
        };
        let ceiling = AxisRect {
            level: 0.5,
            lo: [0.0, 0.0, 0.5],
            hi: [1.0, 2.0, 0.5],
            ..floor
        };
        let wall = AxisRect {
            fixed: 0,
            level: 0.0,
            lo: [0.0, 0.0, 0.0],
            hi: [0.0, 2.0, 3.0],
        };
        let f_parallel = area_form_factor(&floor, &ceiling) / floor.area();
        assert!((f_parallel - ff_parallel(1.0, 2.0, 0.5)).abs() < 1e-12);
        let f_perpendicular = area_form_factor(&floor, &wall) / floor.area();
        assert!((f_perpendicular - ff_perpendicular(1.0, 3.0, 2.0)).abs() < 1e-12);
    }
}
