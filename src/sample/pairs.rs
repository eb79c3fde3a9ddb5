//! Pairing: consecutive hits along a global line that see each other (paper sec. 3.2.2).
//!
//! A segment between consecutive hits `k` and `k + 1` joins two mutually visible surface points when the
//! line *leaves the front side* of `k`'s patch and *arrives at the front side* of `k + 1`'s patch (front:
//! the side the patch normal points to). The end segments, from the bounding sphere to the first hit and
//! from the last hit to the sphere, are *escapes* when they touch a front side: that surface sees out of
//! the scene (an open scene). Every other segment (inside a solid, behind an enclosure, between a front and
//! a back side) is *unpaired*.
//!
//! Facing is decided from our own f64 patch normals, identically for every tracer; a line exactly in a
//! patch's plane faces neither side and makes its segments unpaired.

use crate::scene::Scene;
use crate::trace::{Hit, Line};

/// Where a segment of a line leads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Segment {
    /// Patches `from` and `to` see each other along the line; `distance` and the cosines are recomputed
    /// in f64 from the patch planes (an f32 `t` loses the distance when surfaces almost touch).
    Pair {
        /// The patch the line leaves.
        from: u32,
        /// The patch it arrives at.
        to: u32,
        /// Distance between the two points, tracing units (may be 0 when the planes touch there).
        distance: f64,
        /// |cos| of the angle between the line and `from`'s normal.
        cos_from: f64,
        /// |cos| of the angle between the line and `to`'s normal.
        cos_to: f64,
    },
    /// A front side that sees out of the scene.
    Escape {
        /// The patch whose front side sees the bounding sphere.
        patch: u32,
    },
    /// A segment joining no front sides (inside a solid, behind a wall, broken geometry).
    Unpaired,
}

/// The line in f64, with a unit direction: what pairing works on.
#[derive(Clone, Copy, Debug)]
pub struct LineF64 {
    /// Origin (the traced f32 origin, exactly).
    pub origin: [f64; 3],
    /// Unit direction (the traced f32 direction, renormalised in f64).
    pub dir: [f64; 3],
}

impl From<&Line> for LineF64 {
    fn from(l: &Line) -> Self {
        let d = l.dir.map(f64::from);
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        LineF64 {
            origin: l.origin.map(f64::from),
            dir: d.map(|c| c / len),
        }
    }
}

/// Calls `visit` for every segment of a line's canonical hit list, in order along the line.
pub fn segments(scene: &Scene, line: &Line, hits: &[Hit], mut visit: impl FnMut(Segment)) {
    if hits.is_empty() {
        return;
    }
    let l = LineF64::from(line);
    let patch_of = |h: &Hit| scene.triangle_patch[h.triangle as usize];
    let cos_of = |p: u32| {
        let n = scene.patches[p as usize].normal;
        n[0] * l.dir[0] + n[1] * l.dir[1] + n[2] * l.dir[2]
    };

    let first = patch_of(&hits[0]);
    if cos_of(first) < 0.0 {
        visit(Segment::Escape { patch: first });
    }
    for w in hits.windows(2) {
        let (p, q) = (patch_of(&w[0]), patch_of(&w[1]));
        let (cp, cq) = (cos_of(p), cos_of(q));
        // Leaving p's front side: moving along its normal. Arriving at q's front: moving against it.
        if cp > 0.0 && cq < 0.0 {
            let tp = plane_t(scene, p, &l, cp);
            let tq = plane_t(scene, q, &l, cq);
            visit(Segment::Pair {
                from: p,
                to: q,
                distance: (tq - tp).abs(),
                cos_from: cp,
                cos_to: -cq,
            });
        } else {
            visit(Segment::Unpaired);
        }
    }
    let last = patch_of(&hits[hits.len() - 1]);
    if cos_of(last) > 0.0 {
        visit(Segment::Escape { patch: last });
    }
}

/// Where the f64 line crosses patch `p`'s plane (`cos` = normal . dir, non-zero).
fn plane_t(scene: &Scene, p: u32, l: &LineF64, cos: f64) -> f64 {
    let patch = &scene.patches[p as usize];
    let n = patch.normal;
    let no = n[0] * l.origin[0] + n[1] * l.origin[1] + n[2] * l.origin[2];
    (patch.offset - no) / cos
}
