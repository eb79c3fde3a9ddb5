//! The pure-Rust tracer: an 8-wide BVH built by the `obvhs` crate proposes candidate triangles, our
//! watertight test ([`super::watertight`]) decides each of them.
//!
//! # Why obvhs's build, and our own traversal
//!
//! We need a well-kept BVH builder. `obvhs` (0.2, MIT/Apache-2.0, maintained; 0.3 and 0.4 need Rust
//! 1.88, 0.2 builds with Debian 13's 1.85; pure Rust, no `unsafe` needed on our side) builds a binary BVH
//! (`Bvh2`) and from it the 8-wide compressed BVH of Ylitie, Karras and Laine (HPG 2017, `CwBvh`), and traverses
//! both with `ray_traverse`, which offers every primitive whose box the ray crosses. That
//! traversal is made for nearest hits: at every node it decodes 8-bit quantized child boxes and orders
//! the children by the ray's octant. A global line keeps every intersection, so order is worthless to us;
//! we keep obvhs's CWBVH *topology* (its SAH collapse into 8-wide nodes and leaves of up to 3 triangles)
//! but store exact f32 child boxes in SSE lanes and traverse with a plain unordered stack. The tree is
//! obvhs's to the bit, built with less memory: two of its steps are ours, its PLOC (`ploc.rs`) and
//! its collapse (`collapse.rs`), which on a large mesh were the peak of a run's memory.
//!
//! Measured (`cargo bench --bench bvh_layouts`: 10^6 global lines on one thread, every candidate decided
//! by the watertight test, M lines per CPU-second, shared machine):
//!
//! | scene       | obvhs CWBVH, leaves <= 3 | obvhs Bvh2, leaves <= 3 | ours, leaves <= 1 | ours, leaves <= 3 |
//! |-------------|-------------------------:|------------------------:|------------------:|------------------:|
//! | `@cube:30`  | 3.69                     | 2.95                    | 5.98              | 6.45              |
//! | `@cubes512` | 2.44                     | 2.02                    | 3.27              | 4.12              |
//!
//! with about 2.6 (`@cube:30`) and 7.7 (`@cubes512`) candidates per line whatever the layout: traversal,
//! not the triangle test, is the cost. Leaves of up to 3 triangles traverse fastest, so that is what we
//! use; leaves of 2, and obvhs's fast and slow build presets instead of the medium one, were within the
//! noise (+-5%). The `bvh` crate (nalgebra-based) was the other candidate builder; it offers only a
//! binary BVH, the layout that loses here, so it was not measured.
//!
//! # Walls meshed into many patches: grids
//!
//! The triangles of a plane holding many of them (a radiosity mesh's walls) are not in the tree: each
//! such plane has a 2D grid ([`super::grids`]) that proposes the few triangles under a line's crossing,
//! tested four at a time ([`ShearedRay::intersect4`], the same bits as the scalar test). The grids'
//! candidates are a superset of the hits as the tree's are, so the hits are the same to the bit
//! ([`BvhTracer::tree_only`] keeps every triangle in the tree, for benchmarks and tests).
//!
//! # Exactness
//!
//! A box test in f32 can miss a triangle that a line grazes (a wall is a box of zero thickness), so each
//! triangle's box is inflated by [`margin`] on every side before the build, far beyond f32 rounding of the
//! slab test (the Embree backend proposes from the same grown boxes); a node's boxes are exact f32 unions of these
//! (min and max round nothing): the candidates are then a superset of the true hits, and every hit (and
//! its `t`) comes from the watertight test on the original triangle, in the same operations as the
//! brute-force tracer and the Embree filter. The tree uses no spatial splits, so it proposes a
//! triangle at most once per line; a grid proposes a triangle entered in two cells under the line twice,
//! and the repeat is harmless ([`crate::trace::HitRules`] removes exact `(t, triangle)` repeats).

use glam::{DVec3, Vec3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::bvh2::{Bvh2, Bvh2Node};
use obvhs::ploc::{PlocSearchDistance, SortPrecision};
use obvhs::ray::safe_inverse;
use obvhs::BvhBuildParams;

use super::collapse::Collapse;
use super::grids::Grids;
use super::ploc::{self, Pending};
use super::watertight::ShearedRay;
use crate::scene::Scene;
use crate::trace::{Hit, HitRules, Line, LineHits, RawHit, TraceError, Tracer};

/// The name in reports and errors.
const BACKEND: &str = "rust";

/// Every triangle's box grows by this fraction of the scene's extent on each side (the Embree backend
/// grows its boxes by the same amount, in the same operations). In tracing space (unit bounding sphere)
/// that is ~3e-5, a few hundred f32 ulps: the slab test can never round a crossed box into a missed one. Also, the slab
/// test replaces a direction component below f32 epsilon by +-1/epsilon (as obvhs does); a line parallel
/// to a wall then sees the wall's box only within `margin * 2^23 > 2 * t_max` of its origin when it passes
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

/// All hits (the [`Tracer`] trait) and first hits through an 8-wide BVH, decided by the watertight test.
///
/// Queries take `&self` and run on any number of threads at once.
pub struct BvhTracer {
    /// The tree; the root is `nodes[0]`.
    nodes: Vec<Node>,
    /// Triangles in BVH primitive order (leaves refer to runs of them).
    triangles: Vec<[[f32; 3]; 3]>,
    /// The scene's index of each triangle in `triangles`.
    ids: Vec<u32>,
    /// The large planes' grids ([`Grids`]); the tree holds the other triangles.
    grids: Grids,
    rules: HitRules,
}

/// Children per node.
const WIDTH: usize = 8;

/// A child reference with this bit set is a leaf: `LEAF_COUNT` bits of triangle count above
/// `LEAF_START` bits of its first triangle. Otherwise it is a node index.
const LEAF: u32 = 1 << 31;
const LEAF_START_BITS: u32 = 28;
const LEAF_START: u32 = (1 << LEAF_START_BITS) - 1;

/// One node of the tree: the f32 boxes of up to 8 children, in lanes of 4 for SSE slab tests.
#[derive(Clone, Copy, Debug)]
struct Node {
    /// `bounds[half][axis][side]`: the lower (`side` 0) or upper (1) bound along `axis` of children
    /// `4 * half..4 * half + 4`. An unused slot holds the empty box (lower +inf, upper -inf), whose slab
    /// interval is empty whatever the ray, so it is never entered.
    bounds: [[[Vec4; 2]; 3]; 2],
    /// Child references (see [`LEAF`]); unused slots are never read.
    children: [u32; WIDTH],
    /// Whether children 4..8 exist (else their half is not tested).
    wide: bool,
}

/// The tree of `scene`'s triangles (their boxes grown by `margin`): obvhs's `build_cwbvh` (PLOC,
/// reinsertion, collapse to 8-wide nodes with leaves of at most 3), the same steps on the same boxes, with
/// less memory, since on a large scene the build is the peak of a run's memory: PLOC starts from leaves
/// made straight from the triangles (no list of boxes beside them), and the collapse is ours
/// ([`Collapse`]: one byte per decision where obvhs keeps eight, and no compressed nodes) and writes
/// our [`Node`]s directly. Returns the nodes and the scene's index of each triangle in BVH order.
fn build(
    scene: &Scene,
    margin: f32,
    params: &BvhBuildParams,
    in_tree: impl Fn(usize) -> bool,
) -> (Vec<Node>, Vec<u32>) {
    let mut bvh2 = binary_bvh(scene, margin, params, in_tree);
    if bvh2.nodes.is_empty() {
        return (Vec::new(), Vec::new());
    }
    ReinsertionOptimizer::run(&mut bvh2, params.reinsertion_batch_ratio, None);
    let collapse = Collapse::new(&bvh2, params.max_prims_per_leaf);
    let mut nodes = Vec::with_capacity(collapse.node_count());
    let mut ids = Vec::with_capacity(scene.triangles.len());
    if !bvh2.nodes.is_empty() {
        emit(&collapse, 0, &mut nodes, &mut ids);
    }
    (nodes, ids)
}

/// obvhs's PLOC build (`build_ploc`, one triangle per leaf, the triangle's index as its primitive; our
/// [`ploc`] in its memory) from leaves made here: the same boxes and the same bounds of them all, in
/// the same operations.
fn binary_bvh(
    scene: &Scene,
    margin: f32,
    params: &BvhBuildParams,
    in_tree: impl Fn(usize) -> bool,
) -> Bvh2 {
    let mut total = Aabb::empty();
    let leaves: Vec<Pending> = scene
        .triangles
        .iter()
        .enumerate()
        .filter(|&(i, _)| in_tree(i))
        .map(|(i, t)| {
            let aabb = inflated_box(t.map(|v| scene.positions[v as usize]), margin);
            total.extend(aabb.min);
            total.extend(aabb.max);
            Pending::leaf(&aabb, i as u32)
        })
        .collect();
    type Ploc = fn(Vec<Pending>, Aabb, SortPrecision, usize) -> Vec<Bvh2Node>;
    let ploc: Ploc = match params.ploc_search_distance {
        PlocSearchDistance::Minimum => ploc::build::<1>,
        PlocSearchDistance::VeryLow => ploc::build::<2>,
        PlocSearchDistance::Low => ploc::build::<6>,
        PlocSearchDistance::Medium => ploc::build::<14>,
        PlocSearchDistance::High => ploc::build::<24>,
        PlocSearchDistance::VeryHigh => ploc::build::<32>,
    };
    if leaves.is_empty() {
        return Bvh2 {
            nodes: Vec::new(),
            primitive_indices: Vec::new(),
            max_depth: None,
        };
    }
    Bvh2 {
        nodes: ploc(
            leaves,
            total,
            params.sort_precision,
            params.search_depth_threshold,
        ),
        // The leaves hold the triangles' indices themselves (neither reinsertion nor the collapse reads
        // this mapping).
        primitive_indices: Vec::new(),
        max_depth: None,
    }
}

/// Writes the 8-wide node made of binary node `index` (and its subtree) into `nodes` in depth-first
/// order, and its leaves' triangles into `ids` in obvhs's order (each node's leaves before its
/// subtrees), with exact f32 boxes: the union of the children's boxes, down to the triangles' grown
/// boxes (the binary leaves'). Returns the node's box.
fn emit(collapse: &Collapse, index: u32, nodes: &mut Vec<Node>, ids: &mut Vec<u32>) -> Aabb {
    let empty = Vec4::splat(f32::INFINITY);
    let at = nodes.len();
    nodes.push(Node {
        bounds: [[[empty, -empty]; 3]; 2],
        children: [0; WIDTH],
        wide: false,
    });
    let mut slots = [(0, Aabb::empty()); WIDTH];
    let (mut inner, mut inner_count) = ([(0, 0); WIDTH], 0);
    let mut used = 0;
    for child in collapse.children(index).into_iter().flatten() {
        if collapse.is_leaf(child) {
            let first = ids.len() as u32;
            let mut bounds = Aabb::empty();
            collapse.leaves(child, &mut |leaf| {
                ids.push(leaf.first_index);
                bounds = bounds.union(&leaf.aabb);
            });
            slots[used] = (
                LEAF | (ids.len() as u32 - first) << LEAF_START_BITS | first,
                bounds,
            );
        } else {
            inner[inner_count] = (used, child);
            inner_count += 1;
        }
        used += 1;
    }
    // Subtrees after the node's leaves, in slot order: the triangles' order of obvhs's collapse.
    for &(slot, child) in &inner[..inner_count] {
        let reference = nodes.len() as u32;
        slots[slot] = (reference, emit(collapse, child, nodes, ids));
    }
    let node = &mut nodes[at];
    let mut whole = Aabb::empty();
    for (k, (child, bounds)) in slots[..used].iter().enumerate() {
        node.children[k] = *child;
        for (axis, [lower, upper]) in node.bounds[k / 4].iter_mut().enumerate() {
            lower[k % 4] = bounds.min[axis];
            upper[k % 4] = bounds.max[axis];
        }
        whole = whole.union(bounds);
    }
    node.wide = used > 4;
    whole
}

/// A line prepared for the slab tests of [`Node`]s.
struct BoxRay {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    /// Per axis, whether the direction is negative: the upper bound is then met first.
    negative: [bool; 3],
}

impl BoxRay {
    fn new(line: &Line) -> Self {
        let inv = line.dir.map(safe_inverse);
        BoxRay {
            origin: line.origin.map(Vec4::splat),
            inv_dir: inv.map(Vec4::splat),
            negative: inv.map(f32::is_sign_negative),
        }
    }

    /// Which of the 4 boxes of `half` the ray crosses within `[0, t_max]`: bit `k` for box `k`. A line
    /// starting on a triangle starts inside its inflated box, so the box's interval reaches below 0 and the
    /// triangle is still proposed.
    #[inline(always)]
    fn crossed(&self, half: &[[Vec4; 2]; 3], t_max: Vec4) -> u32 {
        let t =
            |a: usize, upper: bool| (half[a][upper as usize] - self.origin[a]) * self.inv_dir[a];
        let [nx, ny, nz] = self.negative;
        let near = t(0, nx).max(t(1, ny)).max(t(2, nz)).max(Vec4::ZERO);
        let far = t(0, !nx).min(t(1, !ny)).min(t(2, !nz)).min(t_max);
        near.cmple(far).bitmask()
    }
}

impl BvhTracer {
    /// Builds the BVH of `scene`'s triangles (inflated boxes, see the module documentation).
    ///
    /// Errors when the scene has more triangles than a leaf reference can address (2^28).
    pub fn new(scene: &Scene) -> Result<Self, TraceError> {
        Self::with_params(scene, build_params())
    }

    /// The tracer without grids: every triangle in the BVH (for benchmarks and for tests that hold the
    /// grids to the tree's hits).
    pub fn tree_only(scene: &Scene) -> Result<Self, TraceError> {
        Self::build_with(scene, build_params(), false)
    }

    /// [`BvhTracer::new`] with other obvhs build parameters (for benchmarks); `pre_split` is ignored, spatial
    /// splits are never used.
    pub fn with_params(scene: &Scene, params: BvhBuildParams) -> Result<Self, TraceError> {
        Self::build_with(scene, params, true)
    }

    fn build_with(
        scene: &Scene,
        params: BvhBuildParams,
        use_grids: bool,
    ) -> Result<Self, TraceError> {
        let params = BvhBuildParams {
            pre_split: false,
            ..params
        };
        if scene.triangles.len() > LEAF_START as usize {
            return Err(error(format!(
                "{}: {} triangles, more than the {LEAF_START} the BVH can address",
                scene.name,
                scene.triangles.len()
            )));
        }
        let margin = margin(scene);
        let (grids, gridded) = if use_grids {
            Grids::build(scene, margin)
        } else {
            (Grids::default(), Vec::new())
        };
        let (nodes, ids) = build(scene, margin, &params, |t| {
            !gridded.get(t).copied().unwrap_or(false)
        });
        drop(gridded);
        let triangles: Vec<[[f32; 3]; 3]> = ids
            .iter()
            .map(|&i| scene.triangles[i as usize].map(|v| scene.positions[v as usize]))
            .collect();
        Ok(BvhTracer {
            nodes,
            triangles,
            ids,
            grids,
            rules: HitRules::new(scene),
        })
    }

    /// How many planes' triangles the tracer finds through grids ([`super::grids`]) rather than the tree.
    pub fn planes_in_grids(&self) -> usize {
        self.grids.grids.len()
    }

    /// Offers every leaf whose box the line crosses within `[0, t_max]` to `leaf(first, count)`, which
    /// returns the `t_max` for the rest of the traversal (never more than `line.t_max`). `stack` is
    /// scratch space.
    #[inline(always)]
    fn traverse(
        &self,
        line: &Line,
        ray: &BoxRay,
        stack: &mut Vec<u32>,
        mut leaf: impl FnMut(usize, usize) -> f32,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut t_max = Vec4::splat(line.t_max);
        stack.clear();
        stack.push(0);
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            let mut mask = ray.crossed(&node.bounds[0], t_max);
            if node.wide {
                mask |= ray.crossed(&node.bounds[1], t_max) << 4;
            }
            while mask != 0 {
                let k = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let child = node.children[k % WIDTH];
                if child & LEAF != 0 {
                    let first = (child & LEAF_START) as usize;
                    let count = ((child & !LEAF) >> LEAF_START_BITS) as usize;
                    t_max = Vec4::splat(leaf(first, count));
                } else {
                    stack.push(child);
                }
            }
        }
    }

    /// Calls `visit(t, triangle)` for every hit of one line, in traversal order. `leaves` is scratch.
    ///
    /// The leaves are gathered first and their triangles tested after the traversal: the tests of
    /// different leaves do not depend on each other, so their loads of the triangles (often cache misses)
    /// overlap, where a test in the middle of the traversal waited for its load before the next box.
    #[inline(always)]
    fn line_hits(
        &self,
        line: &Line,
        stack: &mut Vec<u32>,
        leaves: &mut Vec<(u32, u32)>,
        mut visit: impl FnMut(f32, u32),
    ) {
        let ray = BoxRay::new(line);
        let sheared = ShearedRay::new(line.origin, line.dir);
        self.grid_hits(line, &ray, &sheared, line.t_max, &mut visit);
        self.leaf_hits(line, &ray, &sheared, stack, leaves, visit);
    }

    /// Calls `visit(t, triangle)` for every hit of the line in the tree's triangles (those of no grid).
    #[inline(always)]
    fn leaf_hits(
        &self,
        line: &Line,
        ray: &BoxRay,
        sheared: &ShearedRay,
        stack: &mut Vec<u32>,
        leaves: &mut Vec<(u32, u32)>,
        mut visit: impl FnMut(f32, u32),
    ) {
        leaves.clear();
        self.traverse(line, ray, stack, |first, count| {
            leaves.push((first as u32, count as u32));
            line.t_max
        });
        for &(first, count) in leaves.iter() {
            let (first, count) = (first as usize, count as usize);
            for (slot, [a, b, c]) in self.triangles[first..first + count].iter().enumerate() {
                if let Some(t) = sheared.intersect(*a, *b, *c, 0.0, line.t_max) {
                    visit(t, self.ids[first + slot]);
                }
            }
        }
    }

    /// The grids' runs of packets that each line of `chunk` may cross, `(line in chunk, first, end)` in
    /// the order of the lines, into `runs` (emptied first), and the first bytes of each run's packets
    /// and ids read: on a large mesh those are cache misses, and read here, for a chunk of lines in one
    /// tight pass of independent loads, they overlap, where a line's tests would wait for each in turn.
    /// The lines' hits are the same whichever order their runs are tested in (a row is sorted).
    fn chunk_grid_runs(
        &self,
        chunk: &[Line],
        cells: &mut Vec<(u32, u32, [u32; 2])>,
        runs: &mut Vec<(u32, u32, u32)>,
    ) {
        runs.clear();
        cells.clear();
        if self.grids.is_empty() {
            return;
        }
        // The rows of cells first, arithmetic alone; then their packet ranges, loads alone, so that the
        // loads of the chunk's lines are in flight together.
        for (i, line) in chunk.iter().enumerate() {
            let ray = BoxRay::new(line);
            let origin = DVec3::from_array(line.origin.map(f64::from));
            let dir = DVec3::from_array(line.dir.map(f64::from));
            for (four, boxes) in self.grids.boxes.iter().enumerate() {
                let mut mask = ray.crossed(boxes, Vec4::splat(line.t_max));
                while mask != 0 {
                    let k = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let g = 4 * four + k;
                    self.grids.grids[g].candidate_cells(
                        origin,
                        dir,
                        f64::from(line.t_max),
                        |row| {
                            cells.push((i as u32, g as u32, row));
                        },
                    );
                }
            }
        }
        for &(i, g, row) in cells.iter() {
            let (first, end) = self.grids.grids[g as usize].run_of(row);
            if first < end {
                runs.push((i, first as u32, end as u32));
            }
        }
        let warm = runs.iter().fold(0u32, |warm, &(_, first, _)| {
            let first = first as usize;
            warm ^ self.grids.packets[first].first_bits() ^ self.grids.ids[first][0]
        });
        std::hint::black_box(warm);
    }

    /// The nearest hit of one line: the least `t`, ties to the lower triangle index (the first hit of the
    /// canonical list, and what the Embree backend's first-hit query returns).
    fn line_first_hit(&self, line: &Line, stack: &mut Vec<u32>) -> Option<Hit> {
        let sheared = ShearedRay::new(line.origin, line.dir);
        let mut best: Option<Hit> = None;
        let ray = BoxRay::new(line);
        self.grid_hits(line, &ray, &sheared, line.t_max, |t, triangle| {
            if best.is_none_or(|h| t.total_cmp(&h.t).then(triangle.cmp(&h.triangle)).is_lt()) {
                best = Some(Hit { t, triangle });
            }
        });
        let nearest = |first: usize, count: usize| {
            for (slot, [a, b, c]) in self.triangles[first..first + count].iter().enumerate() {
                // Only as far as the nearest hit so far, inclusive: an equal-t tie is still seen.
                let t_max = best.map_or(line.t_max, |h| h.t);
                let Some(t) = sheared.intersect(*a, *b, *c, 0.0, t_max) else {
                    continue;
                };
                let triangle = self.ids[first + slot];
                // The canonical order: `total_cmp` on t (so -0 before +0, as the sorted hit lists have it).
                if best.is_none_or(|h| t.total_cmp(&h.t).then(triangle.cmp(&h.triangle)).is_lt()) {
                    best = Some(Hit { t, triangle });
                }
            }
            // Boxes beyond the nearest hit hold no nearer one (a box reaching back to a hit at `t` is
            // entered at or before `t`, so ties are still offered).
            best.map_or(line.t_max, |h| h.t)
        };
        self.traverse(line, &ray, stack, nearest);
        best
    }

    /// Calls `visit(t, triangle)` for every hit of the line in a grid's triangles: those of the cells
    /// under its crossing of every grid whose box it crosses, four at a time.
    #[inline(always)]
    fn grid_hits(
        &self,
        line: &Line,
        ray: &BoxRay,
        sheared: &ShearedRay,
        t_max: f32,
        mut visit: impl FnMut(f32, u32),
    ) {
        if self.grids.is_empty() {
            return;
        }
        let origin = DVec3::from_array(line.origin.map(f64::from));
        let dir = DVec3::from_array(line.dir.map(f64::from));
        // The cells' runs are gathered before any is tested, so that their loads (often cache misses)
        // overlap rather than wait for each other's tests.
        let mut runs = [(0, 0); 8];
        let mut held = 0;
        for (four, boxes) in self.grids.boxes.iter().enumerate() {
            let mut mask = ray.crossed(boxes, Vec4::splat(line.t_max));
            while mask != 0 {
                let k = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let grid = &self.grids.grids[4 * four + k];
                grid.candidates(origin, dir, f64::from(line.t_max), |first, end| {
                    if held == runs.len() {
                        self.test_packets(sheared, first, end, t_max, &mut visit);
                    } else {
                        runs[held] = (first, end);
                        held += 1;
                    }
                });
            }
        }
        for &(first, end) in &runs[..held] {
            self.test_packets(sheared, first, end, t_max, &mut visit);
        }
    }

    /// Tests packets `first..end` of the grids' triangles.
    #[inline(always)]
    fn test_packets(
        &self,
        sheared: &ShearedRay,
        first: usize,
        end: usize,
        t_max: f32,
        visit: &mut impl FnMut(f32, u32),
    ) {
        for p in first..end {
            let (mut hits, t) = sheared.intersect4(&self.grids.packets[p], 0.0, t_max);
            while hits != 0 {
                let lane = hits.trailing_zeros() as usize;
                hits &= hits - 1;
                visit(t[lane], self.grids.ids[p][lane]);
            }
        }
    }
}

/// Lines whose grid runs are found, and their packets' first bytes read, before any of them is tested
/// ([`BvhTracer::chunk_grid_runs`]).
const RUN_CHUNK: usize = 32;

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

/// Whether a line can be traced: finite numbers, a non-zero direction and `t_max >= 0` (the slab tests
/// assume them). Without short-circuits: branch-free for the common case.
fn traceable(l: &Line) -> bool {
    let finite = l
        .origin
        .iter()
        .chain(&l.dir)
        .fold(l.t_max.is_finite(), |ok, c| ok & c.is_finite());
    finite & (l.t_max >= 0.0) & (l.dir != [0.0; 3])
}

/// The error for line `k`, which is not [`traceable`].
fn bad_line(k: usize, l: &Line) -> TraceError {
    error(format!(
        "line {k} cannot be traced: {l:?} (needs finite values, a direction and t_max >= 0)"
    ))
}

/// Batches whose line indices fit a [`RawHit`].
fn check_batch(lines: &[Line]) -> Result<(), TraceError> {
    if lines.len() > u32::MAX as usize {
        return Err(error(format!(
            "{} lines in one batch; at most 2^32 - 1 fit",
            lines.len()
        )));
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
        check_batch(lines)?;
        out.clear();
        let (mut stack, mut leaves) = (Vec::new(), Vec::new());
        // Each line is checked as it is traced, rather than in a pass of its own: the lines are then
        // read from memory once.
        for (k, line) in lines.iter().enumerate() {
            if !traceable(line) {
                out.clear();
                return Err(bad_line(k, line));
            }
            self.line_hits(line, &mut stack, &mut leaves, |t, triangle| {
                out.push(RawHit {
                    t,
                    triangle,
                    line: k as u32,
                })
            });
        }
        Ok(())
    }

    /// Each line's hits are canonicalised as soon as it is traced, while they are in cache, and written
    /// straight into their row: no raw hits to regroup by line.
    fn all_hits(
        &self,
        lines: &[Line],
        _scratch: &mut Vec<RawHit>,
        out: &mut LineHits,
    ) -> Result<(), TraceError> {
        check_batch(lines)?;
        out.hits.clear();
        out.start.clear();
        out.start.push(0);
        let (mut stack, mut leaves, mut kept) = (Vec::new(), Vec::new(), Vec::new());
        let (mut cells, mut runs) = (Vec::new(), Vec::new());
        for (c, chunk) in lines.chunks(RUN_CHUNK).enumerate() {
            if let Some(i) = chunk.iter().position(|line| !traceable(line)) {
                out.hits.clear();
                out.start.clear();
                let k = c * RUN_CHUNK + i;
                return Err(bad_line(k, &lines[k]));
            }
            self.chunk_grid_runs(chunk, &mut cells, &mut runs);
            let mut next_run = 0;
            for (i, line) in chunk.iter().enumerate() {
                let from = out.hits.len();
                let mut visit = |t, triangle| out.hits.push(Hit { t, triangle });
                let sheared = ShearedRay::new(line.origin, line.dir);
                while let Some(&(_, first, end)) = runs.get(next_run).filter(|r| r.0 == i as u32) {
                    self.test_packets(
                        &sheared,
                        first as usize,
                        end as usize,
                        line.t_max,
                        &mut visit,
                    );
                    next_run += 1;
                }
                self.leaf_hits(
                    line,
                    &BoxRay::new(line),
                    &sheared,
                    &mut stack,
                    &mut leaves,
                    visit,
                );
                let kept_hits = self
                    .rules
                    .canonicalize_row(line, &mut out.hits[from..], &mut kept);
                out.hits.truncate(from + kept_hits);
                out.start.push(out.hits.len() as u32);
            }
        }
        Ok(())
    }

    fn first_hits(&self, lines: &[Line], out: &mut Vec<Option<Hit>>) -> Result<(), TraceError> {
        out.clear();
        let mut stack = Vec::new();
        for (k, line) in lines.iter().enumerate() {
            if !traceable(line) {
                out.clear();
                return Err(bad_line(k, line));
            }
            out.push(self.line_first_hit(line, &mut stack));
        }
        Ok(())
    }
}

impl std::fmt::Debug for BvhTracer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BvhTracer")
            .field("triangles", &self.triangles.len())
            .field("nodes", &self.nodes.len())
            .field("planes_in_grids", &self.grids.grids.len())
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use obvhs::cwbvh::{bvh2_to_cwbvh::bvh2_to_cwbvh, CwBvh};

    /// The tree as obvhs builds it (`build_cwbvh`'s steps: PLOC on a list of the boxes, reinsertion,
    /// `bvh2_to_cwbvh`), copied into our nodes with exact boxes: what [`build`] must reproduce.
    fn obvhs_tree(scene: &Scene, params: &BvhBuildParams) -> (Vec<Node>, Vec<u32>) {
        let m = margin(scene);
        let boxes: Vec<Aabb> = scene
            .triangles
            .iter()
            .map(|t| inflated_box(t.map(|v| scene.positions[v as usize]), m))
            .collect();
        let indices = (0..boxes.len() as u32).collect();
        let mut bvh2 = params.ploc_search_distance.build(
            &boxes,
            indices,
            params.sort_precision,
            params.search_depth_threshold,
        );
        ReinsertionOptimizer::run(&mut bvh2, params.reinsertion_batch_ratio, None);
        let cw = bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false);
        let ordered: Vec<Aabb> = cw
            .primitive_indices
            .iter()
            .map(|&i| boxes[i as usize])
            .collect();
        let mut nodes = Vec::new();
        copy_cwbvh(&cw, 0, &ordered, &mut nodes);
        (nodes, cw.primitive_indices)
    }

    /// Node `index` of `cw` and its subtree, depth first, with the union of the triangles' boxes.
    fn copy_cwbvh(cw: &CwBvh, index: usize, boxes: &[Aabb], nodes: &mut Vec<Node>) -> Aabb {
        let empty = Vec4::splat(f32::INFINITY);
        let at = nodes.len();
        nodes.push(Node {
            bounds: [[[empty, -empty]; 3]; 2],
            children: [0; WIDTH],
            wide: false,
        });
        let source = &cw.nodes[index];
        let mut whole = Aabb::empty();
        let mut used = 0;
        for ch in (0..WIDTH).filter(|&ch| !source.is_child_empty(ch)) {
            let (child, bounds) = if source.is_leaf(ch) {
                let (first, count) = source.child_primitives(ch);
                let bounds = boxes[first as usize..(first + count) as usize]
                    .iter()
                    .fold(Aabb::empty(), |acc, b| acc.union(b));
                (LEAF | count << LEAF_START_BITS | first, bounds)
            } else {
                let child = nodes.len() as u32;
                (
                    child,
                    copy_cwbvh(cw, source.child_node_index(ch) as usize, boxes, nodes),
                )
            };
            let node = &mut nodes[at];
            node.children[used] = child;
            for (axis, [lower, upper]) in node.bounds[used / 4].iter_mut().enumerate() {
                lower[used % 4] = bounds.min[axis];
                upper[used % 4] = bounds.max[axis];
            }
            whole = whole.union(&bounds);
            used += 1;
        }
        nodes[at].wide = used > 4;
        whole
    }

    /// Our build (leaves made from the triangles, our collapse) gives obvhs's tree: the same nodes, the
    /// same children in the same slots, the same boxes to the bit, the same triangle order; on scenes of
    /// 1 to ~10^4 triangles, leaves of 1 to 3 and obvhs's three presets.
    #[test]
    fn the_build_is_obvhs_tree() {
        let mut single = crate::scene::SceneBuilder::new("one triangle");
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]].map(|p| single.vertex(p));
        let material = single.material(crate::scene::Material::default());
        single.polygon(&v, material, "triangle");
        let mut scenes = vec![single.build().unwrap()];
        for spec in [
            "@tetrahedron",
            "@cornell",
            "@cube:30",
            "@cubes512",
            "@fig4:b",
            "@sphere:3",
        ] {
            scenes.push(crate::scenes::load(spec).unwrap());
        }
        let presets = [
            BvhBuildParams::fast_build(),
            BvhBuildParams::medium_build(),
            BvhBuildParams::slow_build(),
        ];
        for scene in &scenes {
            for (preset, leaf) in presets.iter().flat_map(|p| [1, 2, 3].map(|l| (p, l))) {
                let params = BvhBuildParams {
                    pre_split: false,
                    max_prims_per_leaf: leaf,
                    ..*preset
                };
                let (ours, ids) = build(scene, margin(scene), &params, |_| true);
                let (theirs, their_ids) = obvhs_tree(scene, &params);
                assert_eq!(ids, their_ids, "{} leaves {leaf}", scene.name);
                assert_eq!(ours.len(), theirs.len(), "{} leaves {leaf}", scene.name);
                for (a, b) in ours.iter().zip(&theirs) {
                    let bits = |n: &Node| {
                        n.bounds
                            .map(|h| h.map(|s| s.map(|v| v.to_array().map(f32::to_bits))))
                    };
                    assert_eq!(bits(a), bits(b), "{}", scene.name);
                    assert_eq!((a.children, a.wide), (b.children, b.wide), "{}", scene.name);
                }
            }
        }
    }

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
        assert!(traceable(&ok));
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
            assert!(!traceable(&bad), "{bad:?}");
        }
    }
}
