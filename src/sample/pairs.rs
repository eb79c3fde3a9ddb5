//! Pairing: consecutive hits along a global line that see each other (paper sec. 3.2.2).
//!
//! A segment between consecutive hits `k` and `k + 1` joins two mutually visible surface points when the
//! line *leaves the front side* of `k`'s patch and *arrives at the front side* of `k + 1`'s patch (front:
//! the side the patch normal points to). The end segments, from the bounding sphere to the first hit and
//! from the last hit to the sphere, are *escapes* when they touch a front side: that surface sees out of
//! the scene (an open scene). Every other segment (inside a solid, behind an enclosure, between a front and
//! a back side) is *unpaired*; of those, a segment between a front side and a back side is reported as
//! [`Segment::BackSeen`]: a surface seen from behind, which a closed, consistently oriented scene never
//! shows (a one-sided surface meant to be seen from both sides, or normals facing the wrong way). A
//! segment of no length between overlapping surfaces facing the same way (a decal on a wall) is no such
//! thing: the covered surface is hidden, not seen from behind, and the segment stays unpaired.
//!
//! Facing is decided from our own f64 patch normals, identically for every tracer; a line exactly in a
//! patch's plane faces neither side and makes its segments unpaired.

use super::order::{self, Crossing};
use crate::geom::{unit_vector, DVec3, Direction, Normal, Point};
use crate::scene::Scene;
use crate::trace::{Hit, Line, LineHits};

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
        /// Whether the segment is the line's first (from the sphere to the first hit), not its last.
        at_start: bool,
    },
    /// An unpaired segment between the front side of `front` and the back side of `patch` (either way
    /// along the line): that patch is seen from behind, and what leaves `front` that way arrives at no
    /// front side (it is absorbed, as an escape is lost).
    BackSeen {
        /// The patch whose back side the segment touches.
        patch: u32,
        /// The patch whose front side the segment leaves.
        front: u32,
    },
    /// A segment joining no front sides (inside a solid, behind a wall, broken geometry).
    Unpaired,
}

/// How a line's ends met the scene: the patches of its first and last crossings and whether the line
/// met their back sides there (it arrived at a back side from open space, or left one into it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LineEnds {
    /// Crossings of coplanar overlapping surfaces facing the same way (see [`segments_counting_overlaps`]).
    pub overlaps: u64,
    /// The first crossing's patch when the line arrives there at its back side.
    pub back_first: Option<u32>,
    /// The last crossing's patch when the line leaves its back side there.
    pub back_last: Option<u32>,
}

/// The line in f64, with a unit direction: what pairing works on.
#[derive(Clone, Copy, Debug)]
pub struct LineF64 {
    /// Origin (the traced f32 origin, exactly).
    pub origin: Point,
    /// Unit direction (the traced f32 direction, renormalised in f64).
    pub dir: Direction,
}

impl From<&Line> for LineF64 {
    fn from(l: &Line) -> Self {
        LineF64 {
            origin: DVec3::from_array(l.origin.map(f64::from)),
            dir: unit_vector(DVec3::from_array(l.dir.map(f64::from))),
        }
    }
}

/// Calls `visit` for every segment of a line's canonical hit list, in order along the line.
pub fn segments(scene: &Scene, line: &Line, hits: &[Hit], visit: impl FnMut(Segment)) {
    segments_counting_overlaps(scene, line, hits, visit);
}

/// Every segment of every line of a batch ([`segments`]), with the index of its line in the batch.
pub fn batch_segments(
    scene: &Scene,
    lines: &[Line],
    hits: &LineHits,
    mut visit: impl FnMut(usize, Segment),
) {
    for (k, line) in lines.iter().enumerate() {
        segments(scene, line, hits.of_line(k), |seg| visit(k, seg));
    }
}

/// [`segments`], also returning how many crossings met two coplanar overlapping surfaces facing the same
/// way (of which only the first in the scene is seen).
///
/// Hits too close for their f32 order to be trusted (surfaces almost or exactly touching) are first put
/// in their true order (by their f64 plane distances); other lines pair their hits as they come.
pub fn segments_counting_overlaps(
    scene: &Scene,
    line: &Line,
    hits: &[Hit],
    visit: impl FnMut(Segment),
) -> u64 {
    segments_and_ends(scene, line, hits, visit).overlaps
}

/// [`segments_counting_overlaps`], also returning how the line's ends met back sides ([`LineEnds`]).
pub fn segments_and_ends(
    scene: &Scene,
    line: &Line,
    hits: &[Hit],
    visit: impl FnMut(Segment),
) -> LineEnds {
    let patch_plane = |_: usize, h: &Hit| {
        let patch = scene.triangle_patch[h.triangle as usize];
        let p = &scene.patches[patch as usize];
        (patch, (p.normal, p.offset))
    };
    ends_of(scene, patch_plane, line, hits, visit)
}

/// The patch planes of a scene (normal and offset, `n . x = offset`), for the pairing of many lines: a
/// crossing reads its patch's plane, and in a large mesh those reads miss the cache. The planes are kept
/// 32 bytes each (one cache line holds a plane), and when many patches share a plane bit for bit, as the
/// patches of a wall meshed for radiosity do, each distinct plane is kept once, and each triangle's patch
/// and plane index side by side: one read of 8 bytes per crossing, where the patch of the triangle and
/// then the plane of the patch were two dependent reads, each missing the cache in a large mesh. Either
/// way it holds the scene's own numbers: pairing with it gives the same segments, to the bit.
#[derive(Clone, Debug)]
pub struct PatchPlanes {
    /// The distinct planes (or every patch's, when `by_triangle` is empty).
    planes: Vec<[f64; 4]>,
    /// Each triangle's patch and that patch's plane in `planes`; empty when `planes` holds one plane
    /// per patch.
    by_triangle: Vec<[u32; 2]>,
}

impl PatchPlanes {
    /// A table of planes this large stays in a core's first-level data cache (32 KiB and more on
    /// current x86 and ARM cores); a larger one is read from the second level or beyond at every
    /// crossing.
    const CACHED_BYTES: usize = 32 << 10;

    /// The planes of `scene`'s patches, shared when the full table would not fit in a core's cache
    /// (32 KiB, `CACHED_BYTES`: more than 1,024 patches) and at most a quarter of them are distinct. Otherwise the shared table
    /// would only add to what a crossing reads.
    pub fn of(scene: &Scene) -> Self {
        let plane = |p: &crate::scene::Patch| [p.normal.x, p.normal.y, p.normal.z, p.offset];
        let every = || PatchPlanes {
            planes: scene.patches.iter().map(plane).collect(),
            by_triangle: Vec::new(),
        };
        let n = scene.patch_count();
        if n * std::mem::size_of::<[f64; 4]>() <= Self::CACHED_BYTES {
            return every();
        }
        // The distinct planes are looked for before the full table is made, which is made only when they
        // are too many: a large mesh never holds both (its table alone is 32 bytes a patch).
        let mut seen: std::collections::HashMap<[u64; 4], u32> = std::collections::HashMap::new();
        let mut planes = Vec::new();
        let mut index = Vec::with_capacity(n);
        for p in &scene.patches {
            let next = planes.len() as u32;
            let at = *seen.entry(plane(p).map(f64::to_bits)).or_insert(next);
            if at == next {
                planes.push(plane(p));
            }
            index.push(at);
            if planes.len() > n / 4 {
                drop((seen, planes, index));
                return every();
            }
        }
        let by_triangle = scene
            .triangle_patch
            .iter()
            .map(|&patch| [patch, index[patch as usize]])
            .collect();
        PatchPlanes {
            planes,
            by_triangle,
        }
    }

    /// Whether patches share their planes (see [`PatchPlanes::of`]).
    pub fn shares_planes(&self) -> bool {
        !self.by_triangle.is_empty()
    }

    /// [`segments_and_ends`] with the planes read from this table (made from `scene`). The two layouts
    /// get a pairing loop each, so the direct one pays nothing for the shared one.
    pub fn segments_and_ends(
        &self,
        scene: &Scene,
        line: &Line,
        hits: &[Hit],
        visit: impl FnMut(Segment),
    ) -> LineEnds {
        let planes = &self.planes;
        if self.by_triangle.is_empty() {
            let patch_plane = |_: usize, h: &Hit| {
                let patch = scene.triangle_patch[h.triangle as usize];
                (patch, as_plane(planes[patch as usize]))
            };
            ends_of(scene, patch_plane, line, hits, visit)
        } else {
            let by_triangle = &self.by_triangle;
            let patch_plane = |_: usize, h: &Hit| {
                let [patch, plane] = by_triangle[h.triangle as usize];
                (patch, as_plane(planes[plane as usize]))
            };
            ends_of(scene, patch_plane, line, hits, visit)
        }
    }

    /// Each hit's triangle record (its patch and plane index), read for a whole batch of hits in one
    /// pass into `out` (emptied first), when patches share planes and the records outgrow half a
    /// core's second-level cache (`GATHERED_BYTES`); left empty otherwise. The reads are independent, so
    /// their cache misses overlap, where read one crossing at a time, between the pairing's arithmetic,
    /// each waits alone; [`PatchPlanes::segments_and_ends_of_records`] then reads them in order. A
    /// smaller table is read from the cache at each crossing for less than the extra pass costs.
    pub fn records_of(&self, hits: &[Hit], out: &mut Vec<[u32; 2]>) {
        out.clear();
        if std::mem::size_of_val(self.by_triangle.as_slice()) > Self::GATHERED_BYTES {
            out.extend(hits.iter().map(|h| self.by_triangle[h.triangle as usize]));
        }
    }

    /// Half the second-level data cache of one core of current x86 cores (512 KiB and more).
    const GATHERED_BYTES: usize = 256 << 10;

    /// [`PatchPlanes::segments_and_ends`] with the line's triangle records already read
    /// ([`PatchPlanes::records_of`], `records[i]` that of `hits[i]`; empty when it read none): the
    /// same segments, to the bit.
    pub fn segments_and_ends_of_records(
        &self,
        scene: &Scene,
        line: &Line,
        hits: &[Hit],
        records: &[[u32; 2]],
        visit: impl FnMut(Segment),
    ) -> LineEnds {
        if records.is_empty() {
            return self.segments_and_ends(scene, line, hits, visit);
        }
        let planes = &self.planes;
        let records = &records[..hits.len()];
        let patch_plane = |i: usize, _: &Hit| {
            let [patch, plane] = records[i];
            (patch, as_plane(planes[plane as usize]))
        };
        ends_of(scene, patch_plane, line, hits, visit)
    }
}

/// A plane as the table keeps it, `[x, y, z, offset]`, as a normal and an offset.
fn as_plane([x, y, z, offset]: [f64; 4]) -> (Normal, f64) {
    (DVec3::new(x, y, z), offset)
}

/// [`segments_and_ends`], with the patch of hit `i` and that patch's plane from `patch_plane(i, hit)`.
fn ends_of(
    scene: &Scene,
    patch_plane: impl Fn(usize, &Hit) -> (u32, (Normal, f64)),
    line: &Line,
    hits: &[Hit],
    mut visit: impl FnMut(Segment),
) -> LineEnds {
    if hits.is_empty() {
        return LineEnds::default();
    }
    let l = LineF64::from(line);
    let crossing = |(i, h): (usize, &Hit)| {
        let (patch, plane) = patch_plane(i, h);
        crossing(patch, plane, &l, h)
    };
    if !order::has_close_hits(hits) {
        return pair_crossings(hits.iter().enumerate().map(crossing), &mut visit);
    }
    let mut crossings: Vec<Crossing> = hits.iter().enumerate().map(crossing).collect();
    let overlaps = order::reorder(&mut crossings, hits, |c| on_its_triangle(scene, &l, c));
    LineEnds {
        overlaps,
        ..pair_crossings(crossings.into_iter(), &mut visit)
    }
}

/// How far outside its triangle (tracing units, the bounding sphere's radius being 1) a crossing's f64
/// point may lie and still be on it: far above the f64 rounding of the point (~1e-16), far below the
/// gaps an f32 watertight test closes (~1e-7), so a line that misses an edge by more is told apart.
const ON_TRIANGLE: f64 = 1e-12;

/// Whether the point where `l` crosses the plane of `c`'s triangle, in f64, lies on that triangle (to
/// [`ON_TRIANGLE`]): what tells a line that passes through the wedge at an edge from one that only
/// touches the edge ([`order::reorder`]).
fn on_its_triangle(scene: &Scene, l: &LineF64, c: &Crossing) -> bool {
    let [a, b, d] = scene.triangles[c.triangle as usize].map(|v| scene.vertices[v as usize]);
    let p = l.origin + l.dir * c.t;
    let n = (b - a).cross(d - a);
    // A degenerate triangle has no inside (the scene drops them; NaN-safe all the same).
    let length = n.length();
    if length.is_nan() || length <= 0.0 {
        return false;
    }
    let n = n / length;
    [(a, b), (b, d), (d, a)].iter().all(|&(from, to)| {
        let edge = to - from;
        let side = edge.cross(p - from).dot(n);
        side >= -ON_TRIANGLE * edge.length()
    })
}

/// A hit on `patch`, whose plane is `(n, offset)`, as a crossing: its patch, the facing and the f64
/// distance to the patch's plane.
fn crossing(patch: u32, (n, offset): (Normal, f64), l: &LineF64, h: &Hit) -> Crossing {
    let cos = n.dot(l.dir);
    let t = if cos != 0.0 {
        (offset - n.dot(l.origin)) / cos
    } else {
        // In the plane: no plane distance; the traced one orders it.
        f64::from(h.t)
    };
    Crossing {
        patch,
        triangle: h.triangle,
        cos,
        t,
        normal: n,
    }
}

/// Pairs consecutive crossings (see the module documentation); returns how the line's ends met back
/// sides.
fn pair_crossings(
    mut crossings: impl Iterator<Item = Crossing>,
    visit: &mut impl FnMut(Segment),
) -> LineEnds {
    let Some(first) = crossings.next() else {
        return LineEnds::default();
    };
    if first.cos < 0.0 {
        visit(Segment::Escape {
            patch: first.patch,
            at_start: true,
        });
    }
    let mut prev = first;
    for next in crossings {
        // Leaving prev's front side: moving along its normal. Arriving at next's front: moving against it.
        if prev.cos > 0.0 && next.cos < 0.0 {
            visit(Segment::Pair {
                from: prev.patch,
                to: next.patch,
                distance: (next.t - prev.t).abs(),
                cos_from: prev.cos,
                cos_to: -next.cos,
            });
        } else if prev.cos * next.cos > 0.0 && order::at_one_place(&prev, &next) {
            // Overlapping surfaces facing the same way: the one behind is covered, not seen from behind.
            visit(Segment::Unpaired);
        } else if prev.cos > 0.0 && next.cos > 0.0 {
            visit(Segment::BackSeen {
                patch: next.patch,
                front: prev.patch,
            });
        } else if prev.cos < 0.0 && next.cos < 0.0 {
            visit(Segment::BackSeen {
                patch: prev.patch,
                front: next.patch,
            });
        } else {
            visit(Segment::Unpaired);
        }
        prev = next;
    }
    if prev.cos > 0.0 {
        visit(Segment::Escape {
            patch: prev.patch,
            at_start: false,
        });
    }
    LineEnds {
        overlaps: 0,
        back_first: (first.cos > 0.0).then_some(first.patch),
        back_last: (prev.cos < 0.0).then_some(prev.patch),
    }
}
