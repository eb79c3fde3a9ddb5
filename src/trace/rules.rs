//! The hit conventions shared by every backend: sorting, and one hit per crossing.
//!
//! The watertight test is exact on the edges and vertices of the f32 sheared triangles
//! (`crate::trace::rust::watertight`, the same test in the Embree shim): a line exactly through an edge
//! or a vertex is crossed by the triangles a line beside it would cross, so neighbours do not report one
//! crossing twice, and the raw reports of a line through a closed mesh are even in number. What is
//! left to merge is rounding of another kind: a line grazing a surface within f32 rounding of its
//! corners meets the f32 mesh, which can fold there where the surface does not (a planar wall crossed
//! two or three times within a few ulps, every report facing the line the same way by the f64
//! normals). Reports within a few ulps that face the line the same way and are joined through shared
//! vertices are one crossing, kept once. That can make the count of a fold's two reports odd; keeping
//! it even instead (one crossing for an odd group, two for an even one) was measured on a fuzz of
//! lines grazing jittered, turned, sliver-meshed rooms and spheres at sines 1e-6..1e-2: 17 times as many
//! lines then met coplanar faces facing the same way (an overlap, which the report warns about) and 4%
//! more met a back side, so the merge stays.

use super::{Hit, Line, LineHits};
use crate::geom::{DVec3, Direction, Normal};
use crate::scene::Scene;

/// How many f32 ulps (at the larger of `t` and the bounding radius) two hits may be apart and still be one
/// crossing (see the module documentation). The watertight test computes `t` per triangle, so
/// neighbouring triangles at one place disagree by an ulp or two; eight leaves room without merging real
/// chords (those never share a vertex *and* a facing sign at such a distance).
pub const DUPLICATE_ULPS: f32 = 8.0;

/// Per-triangle facts needed to canonicalise hits: the f64 patch normal (for the facing sign) and the
/// vertex indices (for "shares a vertex").
#[derive(Clone, Debug)]
pub struct HitRules {
    normals: Vec<Normal>,
    vertices: Vec<[u32; 3]>,
}

/// The side of a triangle a line arrives at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Facing {
    /// Moving against the normal: the line comes from the front side.
    Front,
    /// Moving along the normal: the line comes from the back side.
    Back,
    /// Exactly in the plane.
    Edge,
}

impl HitRules {
    /// Builds the rules for a scene.
    pub fn new(scene: &Scene) -> Self {
        HitRules {
            normals: scene.triangle_normals(),
            vertices: scene.triangles.clone(),
        }
    }

    fn facing(&self, triangle: u32, dir: Direction) -> Facing {
        let d = self.normals[triangle as usize].dot(dir);
        if d < 0.0 {
            Facing::Front
        } else if d > 0.0 {
            Facing::Back
        } else {
            Facing::Edge
        }
    }

    fn share_vertex(&self, a: u32, b: u32) -> bool {
        let va = self.vertices[a as usize];
        let vb = self.vertices[b as usize];
        va.iter().any(|v| vb.contains(v))
    }

    /// Sorts each line's hits by `(t, triangle)` and merges repeated reports of one crossing
    /// (see the [module documentation](self)).
    pub fn canonicalize(&self, lines: &[Line], hits: &mut LineHits) {
        let mut write = 0usize;
        let mut kept: Vec<Hit> = Vec::new();
        let mut new_start = Vec::with_capacity(hits.start.len());
        new_start.push(0u32);
        for (k, line) in lines.iter().enumerate() {
            let (a, b) = (hits.start[k] as usize, hits.start[k + 1] as usize);
            let n = self.canonicalize_row(line, &mut hits.hits[a..b], &mut kept);
            hits.hits.copy_within(a..a + n, write);
            write += n;
            new_start.push(write as u32);
        }
        hits.hits.truncate(write);
        hits.start = new_start;
    }

    /// [`HitRules::canonicalize`] for the hits of one line: sorts `row` and moves the hits it keeps to
    /// its front; returns how many. `kept` is scratch space.
    ///
    /// Most rows hold one or two crossings far apart, which need neither a sort call nor clustering.
    pub fn canonicalize_row(&self, line: &Line, row: &mut [Hit], kept: &mut Vec<Hit>) -> usize {
        let order = |x: &Hit, y: &Hit| x.t.total_cmp(&y.t).then(x.triangle.cmp(&y.triangle));
        match row {
            [] | [_] => return row.len(),
            [a, b] => {
                // The two come in the order a traversal met them, at random: swapped by masks, as a
                // branch would be mispredicted half the time.
                let mask = u32::from(order(a, b).is_gt()).wrapping_neg();
                let pick = |x: u32, y: u32| (x & mask) | (y & !mask);
                let (ta, tb) = (a.t.to_bits(), b.t.to_bits());
                let (ia, ib) = (a.triangle, b.triangle);
                *a = Hit {
                    t: f32::from_bits(pick(tb, ta)),
                    triangle: pick(ib, ia),
                };
                *b = Hit {
                    t: f32::from_bits(pick(ta, tb)),
                    triangle: pick(ia, ib),
                };
                if b.t - a.t > tolerance(a.t) {
                    return 2;
                }
            }
            _ => row.sort_unstable_by(order),
        }
        kept.clear();
        self.merge_row(line, row, kept);
        row[..kept.len()].copy_from_slice(kept);
        kept.len()
    }

    /// Merges a sorted row: clusters of hits closer than the tolerance; within a cluster, hits that face
    /// the line the same way and are connected through shared vertices collapse to their first member.
    fn merge_row(&self, line: &Line, row: &[Hit], kept: &mut Vec<Hit>) {
        let dir = DVec3::from_array(line.dir.map(f64::from));
        let mut i = 0;
        while i < row.len() {
            let mut j = i + 1;
            while j < row.len() && row[j].t - row[j - 1].t <= tolerance(row[j - 1].t) {
                j += 1;
            }
            self.merge_cluster(dir, &row[i..j], kept);
            i = j;
        }
    }

    fn merge_cluster(&self, dir: Direction, cluster: &[Hit], kept: &mut Vec<Hit>) {
        if cluster.len() == 1 {
            kept.push(cluster[0]);
            return;
        }
        let facing: Vec<Facing> = cluster
            .iter()
            .map(|h| self.facing(h.triangle, dir))
            .collect();
        let first = if cluster.len() <= SMALL_CLUSTER {
            self.first_members_pairwise(cluster, &facing)
        } else {
            self.first_members_by_keys(cluster, &facing)
        };
        kept.extend(
            cluster
                .iter()
                .zip(first)
                .filter_map(|(h, is_first)| is_first.then_some(*h)),
        );
    }

    /// Which members of a cluster come first in their component (joined when they are one triangle,
    /// or face the line the same way and share a vertex), by testing every two members: the cheapest
    /// way for the few hits of a cluster in a real scene.
    fn first_members_pairwise(&self, cluster: &[Hit], facing: &[Facing]) -> Vec<bool> {
        let mut parts = Components::new(cluster.len());
        for a in 0..cluster.len() {
            for b in a + 1..cluster.len() {
                let same_crossing = cluster[a].triangle == cluster[b].triangle
                    || (facing[a] == facing[b]
                        && self.share_vertex(cluster[a].triangle, cluster[b].triangle));
                if same_crossing {
                    parts.join(a, b);
                }
            }
        }
        parts.first_members()
    }

    /// [`HitRules::first_members_pairwise`] in O(n log n): members with a key in common (their triangle,
    /// or a vertex with their facing) are joined through the sorted keys. A hostile scene can stack
    /// thousands of coplanar triangles on one line; testing every two of them, on every line, ran for
    /// hours.
    fn first_members_by_keys(&self, cluster: &[Hit], facing: &[Facing]) -> Vec<bool> {
        let mut parts = Components::new(cluster.len());
        let mut keys: Vec<(u64, usize)> = Vec::with_capacity(4 * cluster.len());
        for (m, h) in cluster.iter().enumerate() {
            // Triangles and (vertex, facing) keys kept apart by the top bit.
            keys.push(((1 << 63) | u64::from(h.triangle), m));
            for &v in &self.vertices[h.triangle as usize] {
                keys.push(((u64::from(v) << 2) | facing[m] as u64, m));
            }
        }
        keys.sort_unstable();
        for pair in keys.windows(2) {
            if pair[0].0 == pair[1].0 {
                parts.join(pair[0].1, pair[1].1);
            }
        }
        parts.first_members()
    }
}

/// Clusters up to this many hits are merged by testing every two members.
const SMALL_CLUSTER: usize = 16;

/// The components of a cluster's members (union-find), each led by its first member.
struct Components {
    parent: Vec<usize>,
}

impl Components {
    fn new(n: usize) -> Self {
        Components {
            parent: (0..n).collect(),
        }
    }

    fn root(&mut self, mut m: usize) -> usize {
        while self.parent[m] != m {
            self.parent[m] = self.parent[self.parent[m]];
            m = self.parent[m];
        }
        m
    }

    /// Joins the components of `a` and `b`; the earlier root leads (so a root is its component's first
    /// member).
    fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        self.parent[hi] = lo;
    }

    /// Whether each member is the first of its component.
    fn first_members(mut self) -> Vec<bool> {
        (0..self.parent.len()).map(|m| self.root(m) == m).collect()
    }
}

/// Two hits closer than this along a line may be one crossing.
fn tolerance(t: f32) -> f32 {
    DUPLICATE_ULPS * f32::EPSILON * t.abs().max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two ways of finding a cluster's first members agree, on clusters whose triangles share
    /// vertices from a small pool (many joins, long chains), repeat triangles and mix facings.
    #[test]
    fn merging_by_keys_equals_testing_every_two_members() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        let triangles = 200u32;
        for pool in [4u64, 30, 600] {
            let vertices: Vec<[u32; 3]> = (0..triangles)
                .map(|_| [0; 3].map(|_| next(pool) as u32))
                .collect();
            let normals: Vec<Normal> = (0..triangles)
                .map(|_| DVec3::new(0.0, 0.0, [-1.0, 1.0, 0.0][next(3) as usize]))
                .collect();
            let rules = HitRules { normals, vertices };
            let dir = DVec3::new(0.0, 0.0, 1.0);
            for size in 2..60usize {
                let cluster: Vec<Hit> = (0..size)
                    .map(|_| Hit {
                        t: 0.5,
                        triangle: next(u64::from(triangles)) as u32,
                    })
                    .collect();
                let facing: Vec<Facing> = cluster
                    .iter()
                    .map(|h| rules.facing(h.triangle, dir))
                    .collect();
                assert_eq!(
                    rules.first_members_by_keys(&cluster, &facing),
                    rules.first_members_pairwise(&cluster, &facing),
                    "pool {pool}, cluster {cluster:?}"
                );
            }
        }
    }

    /// Thousands of coplanar triangles stacked on a line, all sharing a vertex, are one crossing, found
    /// without testing every two of them.
    #[test]
    fn a_stack_of_coplanar_triangles_is_one_crossing() {
        let n = 20_000u32;
        let rules = HitRules {
            normals: vec![DVec3::new(0.0, 0.0, 1.0); n as usize],
            vertices: (0..n).map(|k| [0, 1 + 2 * k, 2 + 2 * k]).collect(),
        };
        let line = Line {
            origin: [0.1, 0.1, -1.0],
            dir: [0.0, 0.0, 1.0],
            t_max: 2.0,
        };
        let mut row: Vec<Hit> = (0..n)
            .map(|k| Hit {
                t: 1.0,
                triangle: n - 1 - k,
            })
            .collect();
        let mut kept = Vec::new();
        let kept_count = rules.canonicalize_row(&line, &mut row, &mut kept);
        assert_eq!(kept_count, 1);
        assert_eq!(row[0].triangle, 0, "the first by (t, triangle)");
    }

    /// A row of two hits comes out ordered by `(t, triangle)` whichever order they came in: apart, at
    /// one distance (ordered by triangle), and close enough to be one crossing (the first kept).
    #[test]
    fn two_hits_are_ordered_whichever_comes_first() {
        let rules = HitRules {
            normals: vec![DVec3::new(0.0, 0.0, 1.0); 4],
            vertices: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [7, 8, 9]],
        };
        let line = Line {
            origin: [0.1, 0.1, -1.0],
            dir: [0.0, 0.0, 1.0],
            t_max: 4.0,
        };
        let hit = |t: f32, triangle: u32| Hit { t, triangle };
        let mut kept = Vec::new();
        let cases = [
            // Far apart: both kept, nearer first.
            (hit(0.5, 3), hit(2.5, 2), vec![hit(0.5, 3), hit(2.5, 2)]),
            // At one distance on unconnected triangles: both kept, the lower index first.
            (hit(1.0, 2), hit(1.0, 3), vec![hit(1.0, 2), hit(1.0, 3)]),
            // At one distance on two triangles sharing an edge, facing alike: one crossing.
            (hit(1.0, 0), hit(1.0, 1), vec![hit(1.0, 0)]),
        ];
        for (x, y, want) in cases {
            for row in [[x, y], [y, x]] {
                let mut row = row;
                let n = rules.canonicalize_row(&line, &mut row, &mut kept);
                assert_eq!(row[..n], want[..], "{x:?} {y:?}");
            }
        }
    }
}
