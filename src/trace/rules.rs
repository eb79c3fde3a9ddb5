//! The hit conventions shared by every backend: sorting, and one hit per crossing.

use super::{Hit, Line, LineHits};
use crate::geom::{DVec3, Direction, Normal};
use crate::scene::Scene;

/// How many f32 ulps (at the larger of `t` and the bounding radius) two hits may be apart and still be the
/// same crossing of a shared edge or vertex. Embree's watertight test and ours compute `t` per triangle, so
/// the two triangles of an edge disagree by an ulp or two; eight leaves room without merging real chords
/// (those never share a vertex *and* a facing sign at such a distance).
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
    /// (see the [module documentation](super)).
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
                if order(a, b).is_gt() {
                    std::mem::swap(a, b);
                }
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
        // Component labels by union over "same facing and shares a vertex" (clusters are tiny).
        let n = cluster.len();
        let mut label: Vec<usize> = (0..n).collect();
        let facing: Vec<Facing> = cluster
            .iter()
            .map(|h| self.facing(h.triangle, dir))
            .collect();
        for a in 0..n {
            for b in a + 1..n {
                let same_crossing = cluster[a].triangle == cluster[b].triangle
                    || (facing[a] == facing[b]
                        && self.share_vertex(cluster[a].triangle, cluster[b].triangle));
                if same_crossing {
                    let (la, lb) = (label[a], label[b]);
                    let (lo, hi) = (la.min(lb), la.max(lb));
                    for l in label.iter_mut() {
                        if *l == hi {
                            *l = lo;
                        }
                    }
                }
            }
        }
        for (m, h) in cluster.iter().enumerate() {
            if label[m] == m {
                kept.push(*h);
            }
        }
    }
}

/// Two hits closer than this along a line may be one crossing.
fn tolerance(t: f32) -> f32 {
    DUPLICATE_ULPS * f32::EPSILON * t.abs().max(1.0)
}
