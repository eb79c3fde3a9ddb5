//! The pure-Rust tracer: a compressed wide BVH from the `obvhs` crate proposes candidate triangles, our
//! watertight test ([`super::watertight`]) decides each of them.
//!
//! # Why obvhs, and its CWBVH
//!
//! We need a well-kept BVH crate with an *all-hits* traversal, since a global line keeps every
//! intersection. `obvhs` (0.4, MIT/Apache-2.0, maintained, edition 2024: it needs Rust >= 1.85 and builds
//! on our 1.95; pure Rust, no `unsafe` needed on our side) has `ray_traverse_anyhit`, which calls a
//! closure for every primitive whose box the ray crosses and never shortens the ray: exactly "propose
//! candidates, let us decide". It builds two layouts from the same boxes:
//!
//! * `Bvh2`, a binary BVH;
//! * `CwBvh`, the 8-wide compressed BVH of Ylitie, Karras and Laine (HPG 2017), traversed with SSE.
//!
//! Measured (`cargo bench --bench bvh_layouts`: 10^6 global lines on one thread, every
//! candidate decided by the watertight test, shared machine), M lines/s:
//!
//! | scene       | CWBVH, leaves <= 3 | CWBVH, leaves <= 1 | Bvh2, leaves <= 3 | Bvh2, leaves <= 1 |
//! |-------------|-------------------:|-------------------:|------------------:|------------------:|
//! | `@cube:30`  | 3.83               | 3.48               | 2.81              | 2.82              |
//! | `@cubes512` | 2.66               | 2.14               | 2.06              | 1.95              |
//!
//! with about 2.6 (`@cube:30`) and 7.7 (`@cubes512`) candidates per line whatever the layout: traversal,
//! not the triangle test, is the cost, and the CWBVH with leaves of up to 3 triangles traverses fastest,
//! so that is what we use. The `bvh` crate (nalgebra-based) was the other candidate; it offers only a
//! binary BVH, the layout that loses here, so it was not measured.
//!
//! # Exactness
//!
//! A box test in f32 can miss a triangle that a line grazes (a wall is a box of zero thickness), so each
//! triangle's box is inflated by [`margin`] on every side before the build, far beyond f32 rounding of the
//! slab test, as the Embree backend inflates its triangles: the candidates are then a superset of the true
//! hits, and every hit (and its `t`) comes from the watertight test on the original triangle, in the same
//! operations as the brute-force tracer and the Embree filter. No spatial splits are used, so a triangle is
//! proposed at most once per line; repeats would be harmless anyway ([`crate::trace::HitRules`] removes
//! exact `(t, triangle)` repeats).

use std::time::Duration;

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::cwbvh::{builder::build_cwbvh, CwBvh};
use obvhs::ray::{Ray, RayHit};
use obvhs::BvhBuildParams;

use super::watertight::ShearedRay;
use crate::scene::Scene;
use crate::trace::{Hit, HitRules, Line, RawHit, TraceError, Tracer};

/// The name in reports and errors.
const BACKEND: &str = "rust";

/// Every triangle's box grows by this fraction of the scene's extent on each side (the Embree backend
/// inflates its triangles by the same amount). In tracing space (unit bounding sphere) that is ~3e-5,
/// a few hundred f32 ulps: the slab test can never round a crossed box into a missed one. Also, obvhs
/// replaces a direction component below f32 epsilon by +-1/epsilon in the slab test; a line parallel to a
/// wall then sees the wall's box only within `margin * 2^23 > 2 * t_max` of its origin when it passes
/// inside the margin, so no true candidate is lost.
pub fn margin(scene: &Scene) -> f32 {
    let (lo, hi) = extent(scene);
    let size = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f32, f32::max);
    (if size > 0.0 { size } else { 1.0 }) / 65536.0
}

fn extent(scene: &Scene) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in &scene.positions {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

/// All hits (the [`Tracer`] trait) and first hits through an obvhs CWBVH, decided by the watertight test.
///
/// Queries take `&self` and run on any number of threads at once.
pub struct BvhTracer {
    bvh: CwBvh,
    /// Triangles in BVH primitive order (`bvh.primitive_indices`), for locality during traversal.
    triangles: Vec<[[f32; 3]; 3]>,
    /// The scene's index of each triangle in `triangles`.
    ids: Vec<u32>,
    rules: HitRules,
}

impl BvhTracer {
    /// Builds the BVH of `scene`'s triangles (inflated boxes, see the module documentation).
    ///
    /// Errors when the tree is too deep for obvhs's fixed traversal stack ([`MAX_DEPTH`]), which would
    /// silently drop candidates: only degenerate geometry (thousands of triangles piled in one place) does
    /// that.
    pub fn new(scene: &Scene) -> Result<Self, TraceError> {
        let m = margin(scene);
        let boxes: Vec<Aabb> = scene
            .triangles
            .iter()
            .map(|t| inflated_box(t.map(|v| scene.positions[v as usize]), m))
            .collect();
        let bvh = if boxes.is_empty() {
            CwBvh::default()
        } else {
            build_cwbvh(&boxes, build_params(), &mut Duration::default())
        };
        let depth = tree_depth(&bvh);
        if depth > MAX_DEPTH {
            return Err(error(format!(
                "{}: the BVH is {depth} levels deep, more than the {MAX_DEPTH} its traversal can hold; \
                 the scene has too many triangles piled in one place",
                scene.name
            )));
        }
        let ids = bvh.primitive_indices.clone();
        let triangles = ids
            .iter()
            .map(|&i| scene.triangles[i as usize].map(|v| scene.positions[v as usize]))
            .collect();
        Ok(BvhTracer {
            bvh,
            triangles,
            ids,
            rules: HitRules::new(scene),
        })
    }

    /// Calls `visit(t, triangle)` for every hit of one line, in traversal order.
    fn line_hits(&self, line: &Line, mut visit: impl FnMut(f32, u32)) {
        if self.triangles.is_empty() {
            return;
        }
        let sheared = ShearedRay::new(line.origin, line.dir);
        self.bvh.ray_traverse_anyhit(to_ray(line), |_, slot| {
            let [a, b, c] = self.triangles[slot];
            if let Some(t) = sheared.intersect(a, b, c, 0.0, line.t_max) {
                visit(t, self.ids[slot]);
            }
        });
    }

    /// The nearest hit of one line: the least `t`, ties to the lower triangle index (the first hit of the
    /// canonical list, and what the Embree backend's first-hit query returns).
    fn line_first_hit(&self, line: &Line) -> Option<Hit> {
        if self.triangles.is_empty() {
            return None;
        }
        let sheared = ShearedRay::new(line.origin, line.dir);
        let mut best: Option<Hit> = None;
        let mut ray_hit = RayHit::none();
        self.bvh
            .ray_traverse(to_ray(line), &mut ray_hit, |_, slot| {
                let [a, b, c] = self.triangles[slot];
                // Only as far as the nearest hit so far, inclusive: an equal-t tie is still seen. (obvhs also
                // shortens its ray to the returned distance, which only prunes boxes beyond it.)
                let t_max = best.map_or(line.t_max, |h| h.t);
                let Some(t) = sheared.intersect(a, b, c, 0.0, t_max) else {
                    return f32::INFINITY;
                };
                let triangle = self.ids[slot];
                // The canonical order: `total_cmp` on t (so -0 before +0, as the sorted hit lists have it).
                if best.is_none_or(|h| t.total_cmp(&h.t).then(triangle.cmp(&h.triangle)).is_lt()) {
                    best = Some(Hit { t, triangle });
                }
                t + RAY_BACKUP
            });
        best
    }
}

/// The deepest tree obvhs's traversal stack holds (it pushes at most one entry per level, into 32 slots,
/// and on overflow overwrites its last slot instead of failing).
pub const MAX_DEPTH: usize = 30;

/// Levels of internal nodes below the root (a root alone: 0).
fn tree_depth(bvh: &CwBvh) -> usize {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    let mut todo = vec![(0usize, 0usize)];
    while let Some((node, depth)) = todo.pop() {
        deepest = deepest.max(depth);
        let n = &bvh.nodes[node];
        // Internal children are stored contiguously from `child_base_idx`, one per set bit of `imask`.
        for k in 0..n.imask.count_ones() as usize {
            todo.push((n.child_base_idx as usize + k, depth + 1));
        }
    }
    deepest
}

/// Triangles per leaf, at most (obvhs's CWBVH allows 1 to 3).
const LEAF_PRIMITIVES: u32 = 3;

/// The build: obvhs's medium preset (about Embree's build time, better traversal), no spatial splits.
fn build_params() -> BvhBuildParams {
    BvhBuildParams {
        pre_split: false,
        max_prims_per_leaf: LEAF_PRIMITIVES,
        ..BvhBuildParams::medium_build()
    }
}

fn inflated_box(tri: [[f32; 3]; 3], margin: f32) -> Aabb {
    let v = tri.map(Vec3A::from_array);
    let lo = v[0].min(v[1]).min(v[2]) - Vec3A::splat(margin);
    let hi = v[0].max(v[1]).max(v[2]) + Vec3A::splat(margin);
    Aabb::new(lo, hi)
}

/// How far back (in units of `t`) the BVH's ray starts before the line's origin: obvhs's box test ignores
/// boxes closer than 1e-4 along the ray, so the ray starts early enough that a line starting on a triangle
/// still gets it proposed. Hits are decided, and `t` measured, from the line's own origin.
const RAY_BACKUP: f32 = 1.0;

fn to_ray(line: &Line) -> Ray {
    let o = Vec3A::from_array(line.origin);
    let d = Vec3A::from_array(line.dir);
    Ray::new(o - d * RAY_BACKUP, d, 0.0, line.t_max + RAY_BACKUP)
}

/// Lines the BVH can trace: finite numbers, a non-zero direction and `t_max >= 0` (obvhs assumes them).
fn check_lines(lines: &[Line]) -> Result<(), TraceError> {
    if lines.len() > u32::MAX as usize {
        return Err(error(format!(
            "{} lines in one batch; at most 2^32 - 1 fit",
            lines.len()
        )));
    }
    for (k, l) in lines.iter().enumerate() {
        let finite = l.origin.iter().chain(&l.dir).all(|c| c.is_finite()) && l.t_max.is_finite();
        if !finite || l.t_max < 0.0 || l.dir == [0.0; 3] {
            return Err(error(format!(
                "line {k} cannot be traced: {l:?} (needs finite values, a direction and t_max >= 0)"
            )));
        }
    }
    Ok(())
}

fn error(message: String) -> TraceError {
    TraceError::Backend {
        backend: BACKEND,
        message,
    }
}

impl Tracer for BvhTracer {
    fn name(&self) -> &'static str {
        BACKEND
    }

    fn rules(&self) -> &HitRules {
        &self.rules
    }

    fn raw_hits(&self, lines: &[Line], out: &mut Vec<RawHit>) -> Result<(), TraceError> {
        check_lines(lines)?;
        out.clear();
        for (k, line) in lines.iter().enumerate() {
            self.line_hits(line, |t, triangle| {
                out.push(RawHit {
                    t,
                    triangle,
                    line: k as u32,
                })
            });
        }
        Ok(())
    }

    fn first_hits(&self, lines: &[Line], out: &mut Vec<Option<Hit>>) -> Result<(), TraceError> {
        check_lines(lines)?;
        out.clear();
        out.extend(lines.iter().map(|l| self.line_first_hit(l)));
        Ok(())
    }
}

impl std::fmt::Debug for BvhTracer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BvhTracer")
            .field("triangles", &self.triangles.len())
            .field("nodes", &self.bvh.nodes.len())
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inflated_boxes_contain_the_triangle_with_room() {
        let b = inflated_box([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], 0.5);
        assert_eq!(b.min.to_array(), [-0.5, -0.5, -0.5]);
        assert_eq!(b.max.to_array(), [1.5, 1.5, 0.5]);
    }

    #[test]
    fn bad_lines_are_errors() {
        let ok = Line {
            origin: [0.0; 3],
            dir: [0.0, 0.0, 1.0],
            t_max: 1.0,
        };
        assert!(check_lines(&[ok]).is_ok());
        for bad in [
            Line { t_max: -1.0, ..ok },
            Line {
                dir: [0.0; 3],
                ..ok
            },
            Line {
                origin: [f32::NAN, 0.0, 0.0],
                ..ok
            },
        ] {
            assert!(check_lines(&[bad]).is_err(), "{bad:?}");
        }
    }
}
