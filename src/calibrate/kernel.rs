//! Integrals of the point-to-point form factor over pairs of triangles of a convex enclosure, where every
//! two points on different faces see each other: the exact form factors `A_i F_ij = int int K` (eq. 3)
//! and the terms `int int K log2 K` of the continuous mutual information (eq. 25), with
//! `K(x, y) = cos(theta_x) cos(theta_y) / (pi |x - y|^2)`.
//!
//! K depends on `x` and `y` only through `W = y - x` (both triangles are flat) and is homogeneous of
//! degree -2 in it. Triangles that share an edge or a vertex make K singular there (`|W| -> 0`); the
//! integral is taken in coordinates centred on what they share, where the radial variable is integrated
//! in closed form and what is left is smooth inside its domain (a Duffy-type split of the domain into
//! cones on which the radial range is linear, as in the Sauter–Schwab rules of boundary elements):
//!
//! * **a common edge** `PQ`, `x = P + a E + b U1`, `y = P + c E + d U2` (`E = Q - P`): with `t = a - c`,
//!   the points with given `(t, b, d)` fill an interval of `a` of length `1 - m(t, b, d)`, `m` linear on
//!   four cones; on each, `(t, b, d) = lambda w` with `m(w) = 1` and `w` on a square or a triangle, and
//!   `int_0^1 lambda^2 (1 - lambda) g(lambda W) dlambda` is closed-form: `K(W) / 2` for `g = K`,
//!   `K(W) (log2 K(W) / 2 + 3 / (2 ln 2))` for `g = K log2 K`;
//! * **a common vertex** `P`: the 4D barycentric offsets `z = (u1, v1, u2, v2)` split into the cones where
//!   `u1 + v1` or `u2 + v2` is the larger, `z = lambda w` with the larger sum 1, and
//!   `int_0^1 lambda^3 g(lambda W) dlambda` is `K(W) / 2`, or `K(W) (log2 K(W) / 2 + 1 / (2 ln 2))`;
//! * **nothing in common**: Gauss–Legendre on both triangles (collapsed squares), two orders compared,
//!   the larger triangle cut into four until they agree.
//!
//! What remains is integrated by tensor rules on the unit square or cube ([`super::quadrature`]):
//! Gauss–Legendre for K (smooth up to the boundary), tanh–sinh for `K log2 K` (which behaves like
//! `x log x` where `W` lies in one of the two planes, on the boundary of the domain). Over two unit
//! squares at a right angle (cut into triangles: one common edge, two common vertices, one separate
//! pair) this gives the closed-form form factor to 1e-16 with 20 nodes, and `int int K log2 K` of
//! [`super::rectangles::perpendicular_squares_integral`], a different reduction, to 1e-16.

use std::f64::consts::{LN_2, PI};

use super::quadrature::{collapse_to_triangle, Rule};
use crate::geom::{DVec3, Point};

/// What is integrated over the pairs of points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrand {
    /// The point-to-point form factor K: its integral over two patches is `A_i F_ij` (eq. 3).
    Kernel,
    /// `K log2 K`, the part of eq. (25) that depends on the pair's geometry.
    KernelLog,
}

impl Integrand {
    /// `g(K)`, with `0 log 0 = 0`.
    fn of(self, k: f64) -> f64 {
        match self {
            Integrand::Kernel => k,
            Integrand::KernelLog if k > 0.0 => k * k.log2(),
            Integrand::KernelLog => 0.0,
        }
    }

    /// `int_0^1 lambda^2 (1 - lambda) g(K / lambda^2) dlambda`: the radial integral of a common edge.
    fn radial_edge(self, k: f64) -> f64 {
        match self {
            Integrand::Kernel => 0.5 * k,
            Integrand::KernelLog if k > 0.0 => k * (0.5 * k.log2() + 1.5 / LN_2),
            Integrand::KernelLog => 0.0,
        }
    }

    /// `int_0^1 lambda^3 g(K / lambda^2) dlambda`: the radial integral of a common vertex.
    fn radial_vertex(self, k: f64) -> f64 {
        match self {
            Integrand::Kernel => 0.5 * k,
            Integrand::KernelLog if k > 0.0 => k * (0.5 * k.log2() + 0.5 / LN_2),
            Integrand::KernelLog => 0.0,
        }
    }
}

/// How finely the integrals are taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Precision {
    /// Tanh–sinh level (step `2^-level`) for `K log2 K` over touching triangles.
    pub tanh_sinh_level: u32,
    /// Gauss–Legendre nodes per dimension for K over touching triangles.
    pub touching_nodes: usize,
    /// Gauss–Legendre nodes per dimension of each triangle, the lower of the two orders compared over
    /// separate triangles (the higher has 4 more).
    pub separate_nodes: usize,
    /// Two orders over separate triangles agree when they differ by at most this fraction.
    pub relative_tolerance: f64,
}

impl Precision {
    /// Enough for every value of the calibration suite, whose standard errors are 1e-5 and more: the
    /// form factors of unit squares within 1e-13 of their closed forms, the I_s^c of the regular solids
    /// within 1e-9 of [`Precision::FINE`] (the tests).
    pub const STANDARD: Precision = Precision {
        tanh_sinh_level: 3,
        touching_nodes: 20,
        separate_nodes: 6,
        relative_tolerance: 1e-9,
    };

    /// Finer in every respect, to show convergence.
    pub const FINE: Precision = Precision {
        tanh_sinh_level: 4,
        touching_nodes: 30,
        separate_nodes: 9,
        relative_tolerance: 1e-11,
    };

    fn rule(self, integrand: Integrand) -> Rule {
        match integrand {
            Integrand::Kernel => Rule::gauss_legendre(self.touching_nodes),
            Integrand::KernelLog => Rule::tanh_sinh(self.tanh_sinh_level),
        }
    }
}

/// A flat triangle with its unit normal (either orientation: K uses |cos|).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The corners.
    pub corners: [Point; 3],
    normal: DVec3,
    area: f64,
}

impl Triangle {
    /// The triangle with these corners (not degenerate).
    pub fn new(corners: [Point; 3]) -> Triangle {
        let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        let length = cross.length();
        Triangle {
            corners,
            normal: cross / length,
            area: 0.5 * length,
        }
    }

    /// Its area.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Its longest edge.
    fn size(&self) -> f64 {
        let c = &self.corners;
        (c[1] - c[0])
            .length()
            .max((c[2] - c[1]).length())
            .max((c[0] - c[2]).length())
    }

    /// The same triangle with its corners rotated to start at corner `k` (orientation kept).
    fn starting_at(&self, k: usize) -> Triangle {
        let c = self.corners;
        Triangle {
            corners: [c[k], c[(k + 1) % 3], c[(k + 2) % 3]],
            ..*self
        }
    }

    /// The four triangles between its corners and its edge midpoints.
    fn quarters(&self) -> [Triangle; 4] {
        let [a, b, c] = self.corners;
        let (ab, bc, ca) = ((a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5);
        [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]].map(|corners| Triangle {
            corners,
            normal: self.normal,
            area: 0.25 * self.area,
        })
    }

    /// The point at collapsed-square coordinates `(s, r)` and the area element there.
    fn point_at(&self, s: f64, r: f64) -> (Point, f64) {
        let (p, q, jacobian) = collapse_to_triangle(s, r);
        let [o, a, b] = self.corners;
        (o + p * (a - o) + q * (b - o), 2.0 * self.area * jacobian)
    }
}

/// A pair of triangles the integrals cannot take.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum KernelError {
    /// A corner of one lies on the other without being one of its corners (a T-junction): the meshes of
    /// two faces do not match along their common edge.
    #[error("triangles touch at a point that is not a corner of both (non-matching meshes)")]
    NonMatchingMeshes,
    /// Separate triangles whose integral did not settle (a pair far too close for its size).
    #[error("the integral over two separate triangles did not converge")]
    NoConvergence,
}

/// `K` for the offset `w = y - x` between points of planes with unit normals `n1` and `n2`.
fn kernel(w: DVec3, n1: DVec3, n2: DVec3) -> f64 {
    let d2 = w.length_squared();
    (w.dot(n1) * w.dot(n2)).abs() / (PI * d2 * d2)
}

/// `int_T1 int_T2 g(K(x, y)) dy dx` for two triangles of a convex enclosure (every point of one sees
/// every point of the other unless they are coplanar, which gives 0).
pub fn pair_integral(
    t1: &Triangle,
    t2: &Triangle,
    integrand: Integrand,
    precision: Precision,
) -> Result<f64, KernelError> {
    let scale = t1.size().max(t2.size());
    if coplanar(t1, t2, scale) {
        return Ok(0.0);
    }
    let shared = shared_corners(t1, t2, 1e-9 * scale);
    match shared.as_slice() {
        [] if touches(t1, t2, 1e-9 * scale) => Err(KernelError::NonMatchingMeshes),
        [] => separate(t1, t2, integrand, precision),
        [(i, j)] => Ok(common_vertex(
            &t1.starting_at(*i),
            &t2.starting_at(*j),
            integrand,
            &precision.rule(integrand),
        )),
        _ => {
            let (a, b) = (shared[0], shared[1]);
            Ok(common_edge(
                t1,
                t2,
                a,
                b,
                integrand,
                &precision.rule(integrand),
            ))
        }
    }
}

fn coplanar(t1: &Triangle, t2: &Triangle, scale: f64) -> bool {
    t1.normal.cross(t2.normal).length() < 1e-12
        && t2
            .corners
            .iter()
            .all(|&c| (c - t1.corners[0]).dot(t1.normal).abs() < 1e-9 * scale)
}

/// The pairs `(corner of t1, corner of t2)` at the same place.
fn shared_corners(t1: &Triangle, t2: &Triangle, tolerance: f64) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            if (t1.corners[i] - t2.corners[j]).length() <= tolerance {
                out.push((i, j));
            }
        }
    }
    out
}

/// Whether a corner of one triangle lies on the other (they have no corner in common).
fn touches(t1: &Triangle, t2: &Triangle, tolerance: f64) -> bool {
    let on = |p: Point, t: &Triangle| distance_to_triangle(p, t) <= tolerance;
    t1.corners.iter().any(|&p| on(p, t2)) || t2.corners.iter().any(|&p| on(p, t1))
}

/// The distance from `p` to a triangle (its plane inside, else its nearest edge).
fn distance_to_triangle(p: Point, t: &Triangle) -> f64 {
    let [a, b, c] = t.corners;
    let height = (p - a).dot(t.normal);
    let foot = p - height * t.normal;
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(foot - u).dot(t.normal) >= 0.0);
    if inside {
        return height.abs();
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|&(u, v)| {
            let e = v - u;
            let s = ((p - u).dot(e) / e.length_squared()).clamp(0.0, 1.0);
            (p - (u + s * e)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Triangles sharing the edge between corners `a.0, b.0` of `t1` and `a.1, b.1` of `t2`.
fn common_edge(
    t1: &Triangle,
    t2: &Triangle,
    a: (usize, usize),
    b: (usize, usize),
    integrand: Integrand,
    rule: &Rule,
) -> f64 {
    let p = t1.corners[a.0];
    let e = t1.corners[b.0] - p;
    let u1 = t1.corners[3 - a.0 - b.0] - p;
    let u2 = t2.corners[3 - a.1 - b.1] - p;
    let (n1, n2) = (t1.normal, t2.normal);
    // W = y - x = -t E - b U1 + d U2 at (t, b, d).
    let radial =
        |t: f64, b: f64, d: f64| integrand.radial_edge(kernel(-t * e - b * u1 + d * u2, n1, n2));
    let on_triangle = |f: &dyn Fn(f64, f64) -> f64| {
        rule.integrate_square(|s, r| {
            let (x, y, jacobian) = collapse_to_triangle(s, r);
            jacobian * f(x, y)
        })
    };
    // The four cones on which m(t, b, d) = max(b, d - t) + max(0, t) is linear, each with m = 1.
    let cone_1 = rule.integrate_square(|s, d| radial(s, 1.0 - s, d)); // t >= 0, b >= d - t
    let cone_2 = on_triangle(&|t, b| radial(t, b, 1.0)); // t >= 0, b <= d - t
    let cone_3 = on_triangle(&|tau, d| radial(-tau, 1.0, d)); // t < 0, b >= d - t
    let cone_4 = rule.integrate_square(|s, b| radial(-s, b, 1.0 - s)); // t < 0, b <= d - t
    4.0 * t1.area * t2.area * (cone_1 + cone_2 + cone_3 + cone_4)
}

/// Triangles sharing their first corners (`t1.corners[0] == t2.corners[0]`) and nothing else.
fn common_vertex(t1: &Triangle, t2: &Triangle, integrand: Integrand, rule: &Rule) -> f64 {
    let p = t1.corners[0];
    let (u1, v1) = (t1.corners[1] - p, t1.corners[2] - p);
    let (u2, v2) = (t2.corners[1] - p, t2.corners[2] - p);
    let (n1, n2) = (t1.normal, t2.normal);
    let cone = |larger_on_first: bool| {
        rule.integrate_cube(|sigma, s, r| {
            let (mu, nu, jacobian) = collapse_to_triangle(s, r);
            let w = if larger_on_first {
                mu * u2 + nu * v2 - sigma * u1 - (1.0 - sigma) * v1
            } else {
                sigma * u2 + (1.0 - sigma) * v2 - mu * u1 - nu * v1
            };
            jacobian * integrand.radial_vertex(kernel(w, n1, n2))
        })
    };
    4.0 * t1.area * t2.area * (cone(true) + cone(false))
}

/// The most subdivisions of a pair of separate triangles.
const MAX_DEPTH: u32 = 12;

/// Separate triangles, to an absolute tolerance of `precision.relative_tolerance` times the value.
fn separate(
    t1: &Triangle,
    t2: &Triangle,
    integrand: Integrand,
    precision: Precision,
) -> Result<f64, KernelError> {
    let estimate = product(t1, t2, integrand, precision, Order::Fine);
    let floor = 1e-15 * t1.area * t2.area / (PI * distance_squared_between(t1, t2));
    let tolerance = precision.relative_tolerance * estimate.abs() + floor;
    separate_within(t1, t2, integrand, precision, tolerance, 0)
}

/// Two orders of the product rule ([`product`]); when they differ by more than `tolerance`, the larger
/// triangle is cut into four, each quarter given a quarter of the tolerance.
fn separate_within(
    t1: &Triangle,
    t2: &Triangle,
    integrand: Integrand,
    precision: Precision,
    tolerance: f64,
    depth: u32,
) -> Result<f64, KernelError> {
    let low = product(t1, t2, integrand, precision, Order::Coarse);
    let high = product(t1, t2, integrand, precision, Order::Fine);
    if (high - low).abs() <= tolerance {
        return Ok(high);
    }
    if depth >= MAX_DEPTH {
        return Err(KernelError::NoConvergence);
    }
    let mut sum = 0.0;
    if t2.size() > t1.size() {
        for quarter in t2.quarters() {
            sum += separate_within(
                t1,
                &quarter,
                integrand,
                precision,
                tolerance / 4.0,
                depth + 1,
            )?;
        }
    } else {
        for quarter in t1.quarters() {
            sum += separate_within(
                &quarter,
                t2,
                integrand,
                precision,
                tolerance / 4.0,
                depth + 1,
            )?;
        }
    }
    Ok(sum)
}

/// The lower or the higher of the two orders compared over separate triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Order {
    Coarse,
    Fine,
}

/// The product rule over two separate triangles, each sampled on its collapsed square: Gauss–Legendre
/// (`separate_nodes`, 4 more when fine), or, for `K log2 K` on a triangle with a corner in the other's
/// plane, tanh–sinh (`tanh_sinh_level`, one more when fine) across K's zero. There K vanishes (a point of the common
/// line of two faces, met by a triangle of the other face that does not reach it) and `K log2 K`
/// behaves like `x log x`, which Gauss rules take only algebraically and tanh–sinh exponentially once
/// the zero is on the square's boundary ([`facing_corner`]).
fn product(
    t1: &Triangle,
    t2: &Triangle,
    integrand: Integrand,
    precision: Precision,
    order: Order,
) -> f64 {
    let scale = 1e-9 * t1.size().max(t2.size());
    let points = |t: &Triangle, other: &Triangle| {
        let in_plane = corners_in_plane(t, other, scale);
        let nodes = precision.separate_nodes + if order == Order::Fine { 4 } else { 0 };
        let gauss = Rule::gauss_legendre(nodes);
        let count = in_plane.iter().filter(|&&c| c).count();
        if integrand == Integrand::Kernel || count == 0 {
            return sample_points(t, &gauss, &gauss);
        }
        let level = precision.tanh_sinh_level + u32::from(order == Order::Fine);
        let tanh_sinh = Rule::tanh_sinh(level);
        let across = if count == 1 { &gauss } else { &tanh_sinh };
        sample_points(&facing_corner(t, in_plane), &tanh_sinh, across)
    };
    let (first, second) = (points(t1, t2), points(t2, t1));
    let (n1, n2) = (t1.normal, t2.normal);
    first
        .iter()
        .map(|&(x, wx)| {
            wx * second
                .iter()
                .map(|&(y, wy)| wy * integrand.of(kernel(y - x, n1, n2)))
                .sum::<f64>()
        })
        .sum()
}

/// Which corners of `t` lie in the plane of `other`.
fn corners_in_plane(t: &Triangle, other: &Triangle, tolerance: f64) -> [bool; 3] {
    t.corners
        .map(|c| (c - other.corners[0]).dot(other.normal).abs() <= tolerance)
}

/// `t` with its corners rotated so that K's zero is separable on the collapsed square: a single corner in
/// the other plane goes to the collapsed corner (`s = 1`), where `y - corner = (1 - s) v(r)` and K is
/// `(1 - s)` times a smooth function; with an edge in the plane, the corner off it goes first, and K is
/// `(1 - s)(1 - r)` times a smooth function.
fn facing_corner(t: &Triangle, in_plane: [bool; 3]) -> Triangle {
    let count = in_plane.iter().filter(|&&c| c).count();
    let first = if count == 1 {
        // The corner in the plane at index 1.
        (in_plane.iter().position(|&c| c).unwrap_or(0) + 2) % 3
    } else {
        in_plane.iter().position(|&c| !c).unwrap_or(0)
    };
    t.starting_at(first)
}

/// The points of a triangle at the tensor product of `along` (for `s`) and `across` (for `r`) on its
/// collapsed square, with their weights times the area element.
fn sample_points(t: &Triangle, along: &Rule, across: &Rule) -> Vec<(Point, f64)> {
    let mut out = Vec::with_capacity(along.len() * across.len());
    for (&s, &ws) in along.nodes.iter().zip(&along.weights) {
        for (&r, &wr) in across.nodes.iter().zip(&across.weights) {
            let (x, da) = t.point_at(s, r);
            out.push((x, ws * wr * da));
        }
    }
    out
}

/// A lower bound of the squared distance between the triangles' points (from their corners; only sets
/// the scale of a negligible absolute tolerance).
fn distance_squared_between(t1: &Triangle, t2: &Triangle) -> f64 {
    let d = t1
        .corners
        .iter()
        .map(|&p| distance_to_triangle(p, t2))
        .chain(t2.corners.iter().map(|&p| distance_to_triangle(p, t1)))
        .fold(f64::INFINITY, f64::min);
    (d * d).max(1e-300)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form radial integrals against a tanh–sinh quadrature of the radial variable.
    #[test]
    fn radial_integrals_are_the_closed_forms() {
        let rule = Rule::tanh_sinh(6);
        for k in [1e-6, 0.03, 0.7, 5.0] {
            let edge = rule.integrate(0.0, 1.0, |l| {
                l * l * (1.0 - l) * Integrand::KernelLog.of(k / (l * l))
            });
            let vertex = rule.integrate(0.0, 1.0, |l| {
                l.powi(3) * Integrand::KernelLog.of(k / (l * l))
            });
            let closed_edge = Integrand::KernelLog.radial_edge(k);
            let closed_vertex = Integrand::KernelLog.radial_vertex(k);
            assert!(
                (edge - closed_edge).abs() < 1e-12 * (1.0 + closed_edge.abs()),
                "{k}"
            );
            assert!(
                (vertex - closed_vertex).abs() < 1e-12 * (1.0 + closed_vertex.abs()),
                "{k}"
            );
        }
    }

    /// A T-junction is refused rather than integrated wrongly.
    #[test]
    fn non_matching_meshes_are_refused() {
        let o = DVec3::ZERO;
        let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
        let floor = Triangle::new([o, x, y]);
        let wall = Triangle::new([0.5 * x, x + z, z]);
        assert_eq!(
            pair_integral(&floor, &wall, Integrand::Kernel, Precision::STANDARD),
            Err(KernelError::NonMatchingMeshes)
        );
    }
}
