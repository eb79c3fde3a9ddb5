//! Geometry: the lowest layer, depending on nothing else in the crate.
//!
//! Points, vectors, directions and normals are glam's `DVec3` (f64: the measures are computed in f64,
//! only the tracers work in f32), under names that say which is which. Every formula here keeps the
//! arithmetic the measures were first computed with (a unit vector is divided by its length, not
//! multiplied by the reciprocal as `DVec3::normalize` does), so that results stay bit-identical.

pub mod polygon;
pub mod shapes;

use rand::RngCore;

pub use glam::DVec3;

/// A position (scene units, or tracing space: the scene scaled to its unit bounding sphere).
pub type Point = DVec3;
/// A difference of points.
pub type Vector = DVec3;
/// A unit vector along a line.
pub type Direction = DVec3;
/// A unit surface normal; its surface's *front* side is the side it points to.
pub type Normal = DVec3;

/// `v / |v|`, dividing each component by the length (the zero vector gives NaNs: callers check).
pub fn unit_vector(v: Vector) -> Direction {
    v / v.length()
}

/// Two unit vectors completing the unit vector `n` to a right-handed orthonormal basis
/// (Duff et al., "Building an orthonormal basis, revisited", JCGT 2017: no branch on a near-pole).
pub fn orthonormal_basis(n: Direction) -> (Direction, Direction) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// A direction uniform on the unit sphere from two uniforms in [0, 1).
pub fn uniform_direction(u1: f64, u2: f64) -> Direction {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u2;
    let (s, c) = phi.sin_cos();
    DVec3::new(r * c, r * s, z)
}

/// A uniform double in [0, 1) from the top 53 bits of a 64-bit draw (fixed here, not left to a crate,
/// so that random scenes and lines never change with a crate's version).
pub fn uniform01(rng: &mut impl RngCore) -> f64 {
    unit_from_draw(rng.next_u64())
}

/// [`uniform01`] of a draw already made: for code that makes its draws in blocks
/// ([`crate::sample::lines::batch_lines`]) and must turn them into the very same doubles.
#[inline(always)]
pub fn unit_from_draw(draw: u64) -> f64 {
    (draw >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The mean of some points (each coordinate summed in order, then divided).
pub fn centroid(points: &[Point]) -> Point {
    let sum = points.iter().fold(DVec3::ZERO, |acc, &p| acc + p);
    sum / points.len() as f64
}

/// Newell's normal of a polygon and its area: exact for a planar polygon; for a non-planar one, the
/// normal of the plane that fits it best and the area of its projection there. The zero normal and area
/// 0 for a degenerate polygon.
pub fn newell(points: &[Point]) -> (Normal, f64) {
    let c = centroid(points);
    let mut n = DVec3::ZERO;
    for k in 0..points.len() {
        let a = points[k] - c;
        let b = points[(k + 1) % points.len()] - c;
        n += a.cross(b);
    }
    let len = n.length();
    if len > 0.0 {
        (n / len, 0.5 * len)
    } else {
        (DVec3::ZERO, 0.0)
    }
}

/// The area of a triangle.
pub fn triangle_area(a: Point, b: Point, c: Point) -> f64 {
    0.5 * (b - a).cross(c - a).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal_near_both_poles() {
        for n in [
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.0, 0.0, -1.0),
            unit_vector(DVec3::new(1e-9, 0.0, -1.0)),
            unit_vector(DVec3::new(0.3, -0.4, 0.5)),
        ] {
            let (e1, e2) = orthonormal_basis(n);
            for (a, b) in [(e1, e2), (e1, n), (e2, n)] {
                assert!(a.dot(b).abs() < 1e-12);
            }
            for v in [e1, e2] {
                assert!((v.length() - 1.0).abs() < 1e-12);
            }
            assert!((e1.cross(e2) - n).length() < 1e-12, "right-handed");
        }
    }

    #[test]
    fn newell_gives_the_area_and_normal_of_a_planar_polygon() {
        let square = [
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(3.0, 0.0, 2.0),
            DVec3::new(3.0, 3.0, 2.0),
            DVec3::new(0.0, 3.0, 2.0),
        ];
        let (n, area) = newell(&square);
        assert_eq!(n, DVec3::Z);
        assert_eq!(area, 9.0);
        assert_eq!(triangle_area(square[0], square[1], square[2]), 4.5);
    }
}
