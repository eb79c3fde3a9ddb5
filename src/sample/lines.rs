//! Uniformly distributed global lines through the bounding sphere (paper sec. 2.1.1, fig. 1b).
//!
//! A line is drawn as a uniform direction on the unit sphere, then a uniform point on the disc of radius
//! R through the sphere's centre and perpendicular to that direction. Lines drawn so are uniformly
//! distributed in the invariant measure of integral geometry: the number hitting a convex patch is
//! proportional to its area (Crofton: a planar patch of area A is met by a fraction A / (2 pi R^2) of them).
//!
//! Randomness: PCG-64 (`rand_pcg::Pcg64`, a fixed algorithm, so its output never changes with crate
//! versions) with one *stream* per batch of lines, seeded from `(seed, batch index)`. A batch's lines are
//! therefore the same whatever thread draws them, and results never depend on the number of threads.

use rand::RngCore;
use rand_pcg::Pcg64;

use crate::trace::Line;

/// The traced segment reaches this factor beyond the bounding sphere on both sides, so that f32 rounding
/// never clips a vertex lying exactly on the sphere.
const SPHERE_MARGIN: f64 = 1.001;

/// The random stream for one batch of lines.
pub fn batch_rng(seed: u64, batch: u64) -> Pcg64 {
    let state =
        (u128::from(splitmix64(seed)) << 64) | u128::from(splitmix64(seed ^ 0x5eed_5eed_5eed_5eed));
    Pcg64::new(state, u128::from(batch))
}

/// Appends the `count` lines of batch `batch` to `out` (tracing space, bounding radius `radius`).
pub fn batch_lines(seed: u64, batch: u64, count: usize, radius: f64, out: &mut Vec<Line>) {
    let mut rng = batch_rng(seed, batch);
    out.extend((0..count).map(|_| global_line(&mut rng, radius)));
}

/// One uniformly distributed global line through the sphere of radius `radius` centred at the origin.
///
/// Both draws use rejection from the unit disc instead of trigonometry (sin/cos cost more than the
/// 4/pi expected tries): Marsaglia's method for the direction, then the disc point itself.
pub fn global_line(rng: &mut impl RngCore, radius: f64) -> Line {
    let (x, y, s) = point_in_unit_disc(rng);
    // Marsaglia (1972): (2x sqrt(1-s), 2y sqrt(1-s), 1-2s) is uniform on the sphere.
    let k = 2.0 * (1.0 - s).sqrt();
    let dir = [x * k, y * k, 1.0 - 2.0 * s];
    let (e1, e2) = orthonormal_basis(dir);
    let (px, py, _) = point_in_unit_disc(rng);
    let reach = radius * SPHERE_MARGIN;
    let origin = [0, 1, 2].map(|a| radius * (px * e1[a] + py * e2[a]) - reach * dir[a]);
    Line {
        origin: origin.map(|x| x as f32),
        dir: dir.map(|x| x as f32),
        t_max: (2.0 * reach) as f32,
    }
}

/// A point uniform in the unit disc, by rejection from the square, and its squared radius.
fn point_in_unit_disc(rng: &mut impl RngCore) -> (f64, f64, f64) {
    loop {
        let x = 2.0 * unit(rng) - 1.0;
        let y = 2.0 * unit(rng) - 1.0;
        let s = x * x + y * y;
        if s < 1.0 {
            return (x, y, s);
        }
    }
}

/// A direction uniform on the unit sphere from two uniforms in [0, 1).
pub fn uniform_direction(u1: f64, u2: f64) -> [f64; 3] {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u2;
    let (s, c) = phi.sin_cos();
    [r * c, r * s, z]
}

/// Two unit vectors completing the unit vector `n` to a right-handed orthonormal basis
/// (Duff et al., "Building an orthonormal basis, revisited", JCGT 2017: no branch on a near-pole).
pub fn orthonormal_basis(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let sign = 1.0f64.copysign(n[2]);
    let a = -1.0 / (sign + n[2]);
    let b = n[0] * n[1] * a;
    (
        [1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]],
        [b, sign + n[1] * n[1] * a, -n[1]],
    )
}

/// A uniform double in [0, 1) from the top 53 bits of a 64-bit draw (fixed here, not left to a crate).
pub fn unit(rng: &mut impl RngCore) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// SplitMix64's finaliser: spreads a seed over all 64 bits.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal_near_both_poles() {
        for n in [
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.6, 0.0, -0.8],
            [1e-9, 0.0, -1.0],
        ] {
            let len: f64 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
            let n = n.map(|c: f64| c / len.sqrt());
            let (a, b) = orthonormal_basis(n);
            let d = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
            assert!((d(a, a) - 1.0).abs() < 1e-12 && (d(b, b) - 1.0).abs() < 1e-12);
            assert!(d(a, b).abs() < 1e-12 && d(a, n).abs() < 1e-12 && d(b, n).abs() < 1e-12);
        }
    }

    #[test]
    fn batches_are_reproducible_and_distinct() {
        let mut a = Vec::new();
        let mut b = Vec::new();
        let mut c = Vec::new();
        batch_lines(7, 3, 16, 1.0, &mut a);
        batch_lines(7, 3, 16, 1.0, &mut b);
        batch_lines(7, 4, 16, 1.0, &mut c);
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn lines_span_the_sphere() {
        let mut lines = Vec::new();
        batch_lines(1, 0, 1000, 1.0, &mut lines);
        for l in &lines {
            let d = l.dir.map(f64::from);
            let o = l.origin.map(f64::from);
            let dn = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            assert!((dn - 1.0).abs() < 1e-6);
            // The origin is outside the unit sphere and the segment ends outside it on the other side.
            let on = (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt();
            assert!(on >= 1.0);
            let end = [0, 1, 2].map(|a| o[a] + l.t_max as f64 * d[a]);
            assert!((end[0] * end[0] + end[1] * end[1] + end[2] * end[2]).sqrt() >= 1.0);
        }
    }
}
