//! `--enclose`: the bounding sphere as a virtual, absorbing environment patch that closes an open scene.
//!
//! Without it, a segment from a front side out of the scene is an *escape*: form-factor rows of an open
//! scene sum to less than 1 and the channel of the paper (sec. 2.2) is not closed. With it, the sphere
//! bounding the scene (radius R, the unit sphere of tracing space) is one more patch whose front side
//! faces inwards: an escape becomes a pair between its patch and the environment, at the point where the
//! line meets the sphere, and a line that meets nothing is a pair of the environment with itself (a chord
//! of the sphere, whose kernel cos cos / (pi d^2) is the constant 1 / (4 pi R^2)). Rows then sum to 1.
//!
//! **Its area.** For the channel to be consistent (reciprocity A_i F_ij = A_j F_ji, the areas being the
//! stationary distribution of F), a patch's area must be proportional to the segment ends on its front
//! side: 1 / (2 pi R^2) per line and unit area for every real patch (Crofton). The environment's area is
//! therefore `2 pi R^2 (escapes + 2 misses) / lines`: the part of the sphere's 4 pi R^2 whose view into
//! the scene ends at a front side or at the sphere itself. For objects in open space (every surface
//! seen from outside is a front side) that is the whole sphere, 4 pi R^2 exactly in expectation; for an
//! open enclosure (one-sided walls whose outsides are back sides) it is smaller, because the segments
//! from the sphere to the walls' backs join nothing (they stay unpaired, as without `--enclose`). Being
//! counted, it carries a statistical error, so H_p does too.
//!
//! **Effects.** H_p gains the environment's share of the area; H_s, I_s and their corrections count the
//! environment's row and column instead of dropping the escaping mass; I_s^c (eq. 27) gets the terms of
//! the environment pairs, with A_T including the environment. A closed scene (nothing escapes) has no
//! environment: the sphere would only see the scene's back sides and itself, a separate channel, so
//! `--enclose` then changes nothing.

use super::pairs::LineF64;
use crate::scene::Scene;
use crate::trace::Line;

/// `(cos cos, d)` of the segment from an escaping patch to the environment sphere: at the sphere's entry
/// (`at_start`: the escape from the line's first hit) or exit (from its last hit).
pub(crate) fn escape(scene: &Scene, line: &Line, patch: u32, at_start: bool) -> (f64, f64) {
    let l = LineF64::from(line);
    let p = &scene.patches[patch as usize];
    let n = p.normal;
    let cos = n.dot(l.dir);
    let t = (p.offset - n.dot(l.origin)) / cos;
    let (t_in, t_out, cos_sphere) = sphere_chord(&l, scene.bounding_radius());
    let distance = if at_start { t - t_in } else { t_out - t };
    (cos.abs() * cos_sphere, distance)
}

/// `(cos cos, d)` of a line that met nothing, a chord of the environment sphere of radius `radius` seen
/// as a pair of the environment with itself: whatever the chord, cos cos / d^2 = 1 / (4 R^2) (module
/// documentation), so it is taken as the diameter's.
pub(crate) fn miss(radius: f64) -> (f64, f64) {
    (1.0, 2.0 * radius)
}

/// Where the line enters and leaves the sphere of radius `r` about the origin, and the cosine between
/// the line and the sphere's normal there (the same at both ends).
fn sphere_chord(l: &LineF64, r: f64) -> (f64, f64, f64) {
    let (o, d) = (l.origin, l.dir);
    let centre_t = -o.dot(d);
    let b2 = o.dot(o) - centre_t * centre_t;
    let half = (r * r - b2).max(0.0).sqrt();
    (centre_t - half, centre_t + half, half / r)
}

/// The environment's area in tracing space: 2 pi R^2 per segment end on it per line (see the module
/// documentation), for `lines` lines of which `escapes` segments escaped and `misses` met nothing; 0
/// without lines.
pub fn area(radius: f64, lines: u64, escapes: u64, misses: u64) -> f64 {
    if lines == 0 {
        return 0.0;
    }
    let ends = escapes as f64 + 2.0 * misses as f64;
    2.0 * std::f64::consts::PI * radius * radius * ends / lines as f64
}
