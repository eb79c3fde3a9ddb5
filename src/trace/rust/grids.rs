//! Flat walls meshed into many triangles: each large plane's triangles in a 2D grid on the plane.
//!
//! # Why
//!
//! A radiosity or thermal mesh is mostly walls, each plane cut into hundreds to millions of coplanar
//! patches. A BVH reaches the triangle a line crosses in such a wall through a descent of box tests,
//! each a likely cache miss; on a plane, the cell of a uniform grid under the line's crossing point
//! holds it, found with a few f64 operations. The tracer keeps a grid for each of the (at most
//! [`MAX_GRIDS`]) planes holding at least [`MIN_TRIANGLES`] triangles whose cells fit them (a few
//! cells a triangle, a few triangles a cell: `Grid::fits`; a plane refused leaves its place to the
//! next), when together they hold most of the scene; every other triangle stays in the BVH.
//!
//! # Exactness
//!
//! The grids only *propose* triangles; the watertight test decides each, as for the BVH's candidates, so
//! the hits are the same as long as every triangle the test accepts is proposed. A line the test finds
//! crossing triangle `T` passes within f32 rounding (`delta`, far below the margin the tracer grows every box by,
//! `m`) of a point `Q` of `T`: at some point `P` of the segment, `|P - Q| <= delta`. The plane's slab
//! (half-width: its vertices' largest distance from the fitted plane, plus `m`) therefore holds `P`, so
//! `P` lies on the part of the segment inside the slab; the box of that part's projection, grown by `m`
//! on every side, holds `Q`'s projection with `m - delta` to spare. A triangle is entered in every cell
//! its projected box, shrunk by `m / 4` on every side, overlaps, and a query visits every cell its box
//! overlaps; the cell of a point is one monotone f64 function of its coordinates in both, so the cell of
//! `Q` clamped into the shrunk box (within `m / 4` of `Q`) is entered and visited. Shrinking keeps a
//! triangle of a regular mesh in one cell (its box would otherwise touch the next cells on its edges);
//! a query near a cell's side visits both cells, and a triangle in both is tested twice (exact repeats
//! of a hit are one hit: [`crate::trace::HitRules`]).

use std::hash::{Hash, Hasher};

use glam::{DVec3, Vec4};

use super::watertight::Triangles4;
use crate::scene::Scene;

/// Planes with fewer triangles stay in the BVH.
pub const MIN_TRIANGLES: usize = 64;

/// At most this many grids: every line tests every grid's box (four at a time).
pub const MAX_GRIDS: usize = 16;

/// The grids are used only when they hold at least this share of the scene's triangles: a line pays
/// for their boxes and for the BVH of the rest.
const MIN_SHARE: f64 = 0.75;

/// A plane whose triangles would fill more cells than this each, on average, stays in the tree.
const MAX_CELLS_PER_TRIANGLE: usize = 4;

/// So does one whose cells would hold more triangles than this each, on average (a graded mesh's small
/// patches crowd into few cells): a line crossing the plane tests a cell's worth.
const MAX_TRIANGLES_PER_CELL: usize = 8;

/// Planes are told apart by their unit normals and offsets rounded to this (tracing units); triangles
/// whose planes round alike, or to neighbouring values ([`joined_runs`]), and lie within the BVH margin
/// of one fitted plane share a grid.
const PLANE_QUANTUM: f64 = 1e-4;

/// The grids of a scene's large planes, and the boxes every line tests first.
#[derive(Clone, Debug, Default)]
pub struct Grids {
    /// The grids' boxes (the union of their triangles' boxes grown by the margin), four to an entry,
    /// in the layout of the BVH's node halves: `boxes[g][axis][side]`, lane `k` for grid `4 g + k`.
    /// Unused lanes hold the empty box.
    pub boxes: Vec<[[Vec4; 2]; 3]>,
    /// The grids.
    pub grids: Vec<Grid>,
    /// Every cell's triangles, four to a packet, cell after cell (a triangle in several cells repeats).
    pub packets: Vec<Triangles4>,
    /// The scene's index of each packet's triangles (lanes beyond a cell's last triangle: unused).
    pub ids: Vec<[u32; 4]>,
}

/// One plane's grid: cells in rows along the plane's second axis, each holding a run of triangles.
#[derive(Clone, Debug)]
pub struct Grid {
    /// The fitted plane: `normal . x = offset`, `normal` unit.
    normal: DVec3,
    offset: f64,
    /// Half the slab's thickness: the vertices' largest distance from the plane plus the margin.
    half_width: f64,
    /// The two coordinate axes the plane is projected on (the normal's largest component's axis dropped).
    axes: [usize; 2],
    /// The grid's corner and the inverse of its cells' sides, along `axes`.
    corner: [f64; 2],
    inv_cell: [f64; 2],
    /// Cells along `axes`.
    cells: [usize; 2],
    /// Cell `c`'s triangles are in packets `packets[c][0]..packets[c][1]` of [`Grids::packets`]. Cells
    /// of a row with few triangles share packets (a packet may hold the next cells' triangles too, which
    /// the test rejects unless the line crosses them), so the first and end packets grow along a row.
    packets: Vec<[u32; 2]>,
    /// How far a query's box grows (the margin).
    margin: f64,
}

impl Grids {
    /// The grids of `scene`'s large planes (none if they hold too little of it), and which triangles
    /// they hold (the BVH takes the others). `margin` is the tracer's (every box grows by it).
    pub fn build(scene: &Scene, margin: f32) -> (Grids, Vec<bool>) {
        let margin = f64::from(margin);
        let planes = large_planes(scene, margin);
        let enough = |held: usize| held as f64 >= MIN_SHARE * scene.triangles.len() as f64;
        let mut grids = Grids::default();
        let mut gridded = vec![false; scene.triangles.len()];
        if planes.is_empty() || !enough(planes.iter().map(Plane::len).sum()) {
            return (grids, gridded);
        }
        // A plane refused (its cells would not fit its triangles: `Grid::fits`) leaves its place to
        // the next; one joined from neighbouring plane keys is tried in its parts, largest first, before
        // the next plane (patches turned differently in one plane may fit no grid together, and fit
        // apart).
        let mut kept: Vec<Vec<u32>> = Vec::with_capacity(MAX_GRIDS);
        let try_grid = |members: Vec<u32>, grids: &mut Grids, kept: &mut Vec<Vec<u32>>| {
            if kept.len() == MAX_GRIDS {
                return false;
            }
            let Some(grid) = Grid::new(scene, &members, margin, grids) else {
                return false;
            };
            grids.grids.push(grid);
            kept.push(members);
            true
        };
        for plane in planes {
            if kept.len() == MAX_GRIDS {
                break;
            }
            if try_grid(plane.whole(), &mut grids, &mut kept) || plane.parts.len() < 2 {
                continue;
            }
            for part in plane.parts.into_iter().filter(|p| p.len() >= MIN_TRIANGLES) {
                try_grid(part, &mut grids, &mut kept);
            }
        }
        if kept.is_empty() || !enough(kept.iter().map(Vec::len).sum()) {
            return (Grids::default(), gridded);
        }
        for &t in kept.iter().flatten() {
            gridded[t as usize] = true;
        }
        grids.boxes = grid_boxes(scene, &kept, margin as f32);
        (grids, gridded)
    }

    /// Whether the scene has no grids.
    pub fn is_empty(&self) -> bool {
        self.grids.is_empty()
    }

    /// Appends triangles (scene indices), four to a packet.
    fn push_triangles(&mut self, scene: &Scene, cell: &[u32]) {
        for four in cell.chunks(4) {
            let corners: Vec<[[f32; 3]; 3]> = four
                .iter()
                .map(|&t| scene.triangles[t as usize].map(|v| scene.positions[v as usize]))
                .collect();
            self.packets.push(Triangles4::new(&corners));
            let mut ids = [u32::MAX; 4];
            ids[..four.len()].copy_from_slice(four);
            self.ids.push(ids);
        }
    }
}

impl Grid {
    /// The grid of the triangles `members` (indices into `scene.triangles`); appends their packets,
    /// cell after cell, to `into`'s. None (and nothing appended) when its cells do not
    /// [fit](Grid::fits) them.
    fn new(scene: &Scene, members: &[u32], margin: f64, into: &mut Grids) -> Option<Grid> {
        let corners = |t: u32| scene.triangles[t as usize].map(|v| point(scene, v));
        let fit = fit_plane(scene, members);
        let axes = projection_axes(fit.0);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut sides: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
        for &t in members {
            let c = corners(t);
            for (k, &a) in axes.iter().enumerate() {
                let (l, h) = span(c.map(|p| p[a]));
                lo[k] = lo[k].min(l);
                hi[k] = hi[k].max(h);
                sides[k].push(h - l);
            }
        }
        let cells = cell_counts(&mut sides, lo, hi, members.len());
        let mut grid = Grid::empty(fit, axes, (lo, hi), cells, margin);
        let ranges = grid.cells_of(scene, members);
        if !grid.fits(&ranges) {
            return None;
        }
        let cells = grid.cells;
        let n_cells = cells[0] * cells[1];
        let mut count = vec![0u32; n_cells + 1];
        for r in &ranges {
            for j in r[1][0]..=r[1][1] {
                for i in r[0][0]..=r[0][1] {
                    count[j * cells[0] + i + 1] += 1;
                }
            }
        }
        for c in 0..n_cells {
            count[c + 1] += count[c];
        }
        let mut order = vec![0; count[n_cells] as usize];
        let mut next = count[..n_cells].to_vec();
        for (r, &t) in ranges.iter().zip(members) {
            for j in r[1][0]..=r[1][1] {
                for i in r[0][0]..=r[0][1] {
                    let slot = &mut next[j * cells[0] + i];
                    order[*slot as usize] = t;
                    *slot += 1;
                }
            }
        }
        grid.packets.reserve(n_cells);
        for row in 0..cells[1] {
            let mut packet: Vec<u32> = Vec::with_capacity(4);
            for c in row * cells[0]..(row + 1) * cells[0] {
                let cell = &order[count[c] as usize..count[c + 1] as usize];
                if packet.len() + cell.len() > 4 && !packet.is_empty() {
                    into.push_triangles(scene, &packet);
                    packet.clear();
                }
                let first = into.packets.len() as u32;
                if cell.len() > 4 {
                    into.push_triangles(scene, cell);
                    grid.packets.push([first, into.packets.len() as u32]);
                } else {
                    packet.extend_from_slice(cell);
                    grid.packets
                        .push([first, first + u32::from(!packet.is_empty())]);
                }
            }
            if !packet.is_empty() {
                into.push_triangles(scene, &packet);
            }
        }
        Some(grid)
    }

    /// A grid with no triangles yet: `cells` cells over the box `lo..hi` of a plane `fit` (normal,
    /// offset, spread: [`fit_plane`]) projected on `axes`.
    fn empty(
        (normal, offset, spread): (DVec3, f64, f64),
        axes: [usize; 2],
        (lo, hi): ([f64; 2], [f64; 2]),
        cells: [usize; 2],
        margin: f64,
    ) -> Grid {
        let inv_cell = [0, 1].map(|k| {
            let side = (hi[k] - lo[k]) / cells[k] as f64;
            if side > 0.0 {
                1.0 / side
            } else {
                0.0
            }
        });
        Grid {
            normal,
            offset,
            half_width: spread + margin,
            axes,
            corner: lo,
            inv_cell,
            cells,
            packets: Vec::new(),
            margin,
        }
    }

    /// The first and last cell along each axis of each of `members`: those its projected box, shrunk by
    /// a quarter margin on every side, overlaps.
    fn cells_of(&self, scene: &Scene, members: &[u32]) -> Vec<[[usize; 2]; 2]> {
        let shrink = self.margin / 4.0;
        members
            .iter()
            .map(|&t| {
                let c = scene.triangles[t as usize].map(|v| point(scene, v));
                [0, 1].map(|k| {
                    let (l, h) = span(c.map(|p| p[self.axes[k]]));
                    let (l, h) = if h - l > 2.0 * shrink {
                        (l + shrink, h - shrink)
                    } else {
                        let mid = 0.5 * (l + h);
                        (mid, mid)
                    };
                    [self.cell(k, l), self.cell(k, h)]
                })
            })
            .collect()
    }

    /// Whether triangles entered in the cells `ranges` stay within [`MAX_CELLS_PER_TRIANGLE`] cells each
    /// and [`MAX_TRIANGLES_PER_CELL`] triangles a cell, on average. Long thin triangles would each fill
    /// many cells (a hostile file's could fill them all, for every triangle); coarse cells hold many.
    fn fits(&self, ranges: &[[[usize; 2]; 2]]) -> bool {
        let entries: usize = ranges
            .iter()
            .map(|r| (r[0][1] - r[0][0] + 1) * (r[1][1] - r[1][0] + 1))
            .sum();
        entries <= MAX_CELLS_PER_TRIANGLE * ranges.len()
            && entries <= MAX_TRIANGLES_PER_CELL * self.cells[0] * self.cells[1]
    }

    /// The cell along projected axis `k` of coordinate `x`, clamped to the grid: monotone in `x`.
    /// (Clamped first, the conversion's truncation is the floor; `floor` itself is a library call
    /// without SSE 4.1.)
    #[inline(always)]
    fn cell(&self, k: usize, x: f64) -> usize {
        let c = (x - self.corner[k]) * self.inv_cell[k];
        c.clamp(0.0, (self.cells[k] - 1) as f64) as usize
    }

    /// Calls `visit(first, end)` for the runs of packets (indices into [`Grids::packets`]) of every cell that may hold a triangle the line `origin + t dir`, `t` in `[0, t_max]`, crosses:
    /// one run per row of cells the query covers.
    #[inline(always)]
    pub fn candidates(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        mut visit: impl FnMut(usize, usize),
    ) {
        self.candidate_cells(origin, dir, t_max, |cells| {
            let (first, end) = self.run_of(cells);
            if first < end {
                visit(first, end);
            }
        });
    }

    /// The run of packets `(first, end)` of a row's cells `[from, to]` ([`Grid::candidate_cells`]);
    /// empty when the cells hold no triangle.
    #[inline(always)]
    pub fn run_of(&self, [from, to]: [u32; 2]) -> (usize, usize) {
        (
            self.packets[from as usize][0] as usize,
            self.packets[to as usize][1] as usize,
        )
    }

    /// [`Grid::candidates`] before the cells' packets are read: calls `visit([from, to])` with the
    /// first and last cell (row-major indices) of every row of cells the query covers. The arithmetic
    /// of a chunk of lines can so be done before any of their cells is read
    /// (`BvhTracer::chunk_grid_runs`).
    #[inline(always)]
    pub fn candidate_cells(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        mut visit: impl FnMut([u32; 2]),
    ) {
        let along = self.normal.dot(dir);
        let height = self.normal.dot(origin) - self.offset;
        let (mut t0, mut t1) = (0.0f64, t_max);
        if along != 0.0 {
            // One division: its rounding (a few 1e-16 of t) is far inside the slab's margin.
            let inv = 1.0 / along;
            let a = (-self.half_width - height) * inv;
            let b = (self.half_width - height) * inv;
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        } else if height.abs() > self.half_width {
            return;
        }
        if t0 > t1 {
            return;
        }
        let (p0, p1) = (origin + dir * t0, origin + dir * t1);
        let mut range = [[0usize; 2]; 2];
        for (k, cells) in range.iter_mut().enumerate() {
            let a = self.axes[k];
            let lo = p0[a].min(p1[a]) - self.margin;
            let hi = p0[a].max(p1[a]) + self.margin;
            let side = self.cells[k] as f64;
            if (hi - self.corner[k]) * self.inv_cell[k] < 0.0
                || (lo - self.corner[k]) * self.inv_cell[k] >= side
            {
                return;
            }
            *cells = [self.cell(k, lo), self.cell(k, hi)];
        }
        let row = self.cells[0];
        for j in range[1][0]..=range[1][1] {
            visit([
                (j * row + range[0][0]) as u32,
                (j * row + range[0][1]) as u32,
            ]);
        }
    }
}

fn point(scene: &Scene, v: u32) -> DVec3 {
    DVec3::from_array(scene.positions[v as usize].map(f64::from))
}

fn span(x: [f64; 3]) -> (f64, f64) {
    (x[0].min(x[1]).min(x[2]), x[0].max(x[1]).max(x[2]))
}

/// The triangles of one plane, as the runs of triangles whose rounded planes were joined into it
/// ([`joined_runs`]), each in the scene's triangle order.
struct Plane {
    parts: Vec<Vec<u32>>,
}

impl Plane {
    fn len(&self) -> usize {
        self.parts.iter().map(Vec::len).sum()
    }

    /// All its triangles, in the scene's order.
    fn whole(&self) -> Vec<u32> {
        let mut m = self.parts.concat();
        m.sort_unstable();
        m
    }
}

/// The planes holding at least [`MIN_TRIANGLES`] triangles lying within `margin` of one fitted plane,
/// largest first.
fn large_planes(scene: &Scene, margin: f64) -> Vec<Plane> {
    if scene.triangles.len() < MIN_TRIANGLES {
        return Vec::new();
    }
    // Each triangle's rounded plane, hashed: 16 bytes a triangle while the planes are sorted out (a map
    // of lists would weigh several times that on a large curved mesh, where every plane is new). Two
    // planes whose hashes collide fail the flatness test below and stay in the tree.
    let mut keyed: Vec<(u64, u32)> = (0..scene.triangles.len() as u32)
        .filter_map(|t| plane_key(scene, t).map(|key| (hash_key(key), t)))
        .collect();
    keyed.sort_unstable();
    let flat = |p: &Plane| fit_plane(scene, &p.whole()).2 <= margin;
    let mut planes: Vec<Plane> = Vec::new();
    for group in joined_runs(scene, &keyed) {
        let part = |r: &Run| {
            keyed[r.clone()]
                .iter()
                .map(|&(_, t)| t)
                .collect::<Vec<u32>>()
        };
        let mut parts: Vec<Vec<u32>> = group.iter().map(part).collect();
        // Largest first, ties by first triangle: not in the hashes' order.
        parts.sort_by_key(|p| (std::cmp::Reverse(p.len()), p[0]));
        let whole = Plane { parts };
        if flat(&whole) {
            planes.push(whole);
        } else {
            // Neighbouring keys that are not one plane: each run on its own, as if never joined.
            planes.extend(
                whole
                    .parts
                    .into_iter()
                    .map(|p| Plane { parts: vec![p] })
                    .filter(|p| p.len() >= MIN_TRIANGLES && flat(p)),
            );
        }
    }
    // Largest first; ties by first triangle, so that the choice does not depend on the map's order.
    planes.sort_by_key(|p| {
        (
            std::cmp::Reverse(p.len()),
            p.parts.iter().map(|q| q[0]).min(),
        )
    });
    planes
}

/// A run of triangles with one plane key: a range of indices into the sorted `(hash, triangle)` list.
type Run = std::ops::Range<usize>;

/// Runs whose plane keys are neighbours (one quantum apart in some of their four numbers) joined, when
/// one of them holds a quarter of [`MIN_TRIANGLES`] or more: the triangles of one plane whose numbers
/// lie near a rounding boundary round to either side of it (small triangles of a wall turned off the
/// axes, whose normals carry the rounding of their f32 vertices, split a wall two to four ways). The
/// groups holding at least [`MIN_TRIANGLES`]; the flatness test decides whether a group is one plane.
fn joined_runs(scene: &Scene, keyed: &[(u64, u32)]) -> Vec<Vec<Run>> {
    let run_at = |start: usize| {
        let h = keyed[start].0;
        start..start + keyed[start..].partition_point(|x| x.0 == h)
    };
    let mut seeds: Vec<Run> = Vec::new();
    let mut start = 0;
    while start < keyed.len() {
        let run = run_at(start);
        start = run.end;
        if run.len() >= MIN_TRIANGLES / 4 {
            seeds.push(run);
        }
    }
    // Union-find over the runs met, each known by its start.
    let mut parent: std::collections::BTreeMap<usize, usize> =
        seeds.iter().map(|r| (r.start, r.start)).collect();
    fn root(parent: &mut std::collections::BTreeMap<usize, usize>, mut x: usize) -> usize {
        while parent[&x] != x {
            let up = parent[&parent[&x]];
            parent.insert(x, up);
            x = up;
        }
        x
    }
    for seed in &seeds {
        let Some(key) = plane_key(scene, keyed[seed.start].1) else {
            continue;
        };
        for near in neighbour_keys(key) {
            let h = hash_key(near);
            let at = keyed.partition_point(|x| x.0 < h);
            // The run found must have this very key, not one whose hash collides with it.
            if at == keyed.len() || keyed[at].0 != h || plane_key(scene, keyed[at].1) != Some(near)
            {
                continue;
            }
            parent.entry(at).or_insert(at);
            let (a, b) = (root(&mut parent, seed.start), root(&mut parent, at));
            parent.insert(a.max(b), a.min(b));
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<Run>> = Default::default();
    let starts: Vec<usize> = parent.keys().copied().collect();
    for s in starts {
        let r = root(&mut parent, s);
        groups.entry(r).or_default().push(run_at(s));
    }
    groups
        .into_values()
        .filter(|g| g.iter().map(|r| r.len()).sum::<usize>() >= MIN_TRIANGLES)
        .collect()
}

/// A triangle's plane rounded to [`PLANE_QUANTUM`]: its unit normal (largest component positive) and
/// offset; None for a degenerate (or NaN) normal, which belongs to no plane.
fn plane_key(scene: &Scene, t: u32) -> Option<[i64; 4]> {
    let [a, b, c] = scene.triangles[t as usize].map(|v| point(scene, v));
    let n = (b - a).cross(c - a);
    let length = n.length();
    if length.is_nan() || length <= 0.0 {
        return None;
    }
    let n = canonical_sign(n / length);
    Some([n.x, n.y, n.z, n.dot(a)].map(|x| (x / PLANE_QUANTUM).round() as i64))
}

fn hash_key(key: [i64; 4]) -> u64 {
    let mut hasher = std::hash::DefaultHasher::new();
    key.hash(&mut hasher);
    hasher.finish()
}

/// The 80 keys one quantum away from `key` in one to four of its numbers.
fn neighbour_keys(key: [i64; 4]) -> impl Iterator<Item = [i64; 4]> {
    (0..81)
        .filter(|&k| k != 40)
        .map(move |k: i64| [0, 1, 2, 3].map(|i| key[i] + (k / 3i64.pow(i as u32)) % 3 - 1))
}

/// The normal with its largest component positive (a plane's two faces share a grid).
fn canonical_sign(n: DVec3) -> DVec3 {
    let a = n.abs();
    let largest = if a.x >= a.y && a.x >= a.z {
        n.x
    } else if a.y >= a.z {
        n.y
    } else {
        n.z
    };
    if largest < 0.0 {
        -n
    } else {
        n
    }
}

/// The plane of `members`: the unit normal of their area-weighted normals' sum, the offset halfway
/// between the extreme vertices, and the vertices' largest distance from it.
fn fit_plane(scene: &Scene, members: &[u32]) -> (DVec3, f64, f64) {
    let mut sum = DVec3::ZERO;
    for &t in members {
        let [a, b, c] = scene.triangles[t as usize].map(|v| point(scene, v));
        sum += canonical_sign((b - a).cross(c - a));
    }
    let normal = sum.normalize_or_zero();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &t in members {
        for v in scene.triangles[t as usize] {
            let h = normal.dot(point(scene, v));
            lo = lo.min(h);
            hi = hi.max(h);
        }
    }
    let offset = 0.5 * (lo + hi);
    (normal, offset, 0.5 * (hi - lo))
}

/// The two axes a plane of normal `n` is projected on: the other two than its largest component's.
fn projection_axes(n: DVec3) -> [usize; 2] {
    let a = n.abs();
    if a.x >= a.y && a.x >= a.z {
        [1, 2]
    } else if a.y >= a.z {
        [2, 0]
    } else {
        [0, 1]
    }
}

/// Cells along each axis: the extent over the triangles' median side along it (a regular mesh gets one
/// cell per patch, aligned with it), at most twice as many cells as triangles in all (an axis cut down
/// to one cell leaves the other the whole allowance, not more).
fn cell_counts(
    sides: &mut [Vec<f64>; 2],
    lo: [f64; 2],
    hi: [f64; 2],
    triangles: usize,
) -> [usize; 2] {
    let mut n = [0, 1].map(|k| {
        let s = &mut sides[k];
        s.sort_by(f64::total_cmp);
        let median = s[s.len() / 2];
        let extent = hi[k] - lo[k];
        if median > 0.0 && extent > 0.0 {
            (extent / median).round().clamp(1.0, 65536.0)
        } else {
            1.0
        }
    });
    let most = 2.0 * triangles as f64;
    if n[0] * n[1] > most {
        let scale = (most / (n[0] * n[1])).sqrt();
        n = n.map(|c| (c * scale).floor().max(1.0).min(most));
    }
    n.map(|c| c as usize)
}

/// The grids' boxes, four to an entry: each the union of its triangles' boxes grown by `margin`, in f32
/// (as the BVH's leaves are bounded).
fn grid_boxes(scene: &Scene, planes: &[Vec<u32>], margin: f32) -> Vec<[[Vec4; 2]; 3]> {
    let empty = Vec4::splat(f32::INFINITY);
    let mut boxes = vec![[[empty, -empty]; 3]; planes.len().div_ceil(4)];
    for (g, members) in planes.iter().enumerate() {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for &t in members {
            for v in scene.triangles[t as usize] {
                let p = scene.positions[v as usize];
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a] - margin);
                    hi[a] = hi[a].max(p[a] + margin);
                }
            }
        }
        for (axis, [lower, upper]) in boxes[g / 4].iter_mut().enumerate() {
            lower[g % 4] = lo[axis];
            upper[g % 4] = hi[axis];
        }
    }
    boxes
}

#[cfg(test)]
mod tests {
    use super::*;

    /// About the tracer's margin on these scenes (1/65536 of their extent).
    const MARGIN: f32 = 2e-5;

    /// A wall meshed into n x n squares gets an n x n grid with each triangle in one cell, and a scene
    /// whose planes hold few triangles gets none.
    #[test]
    fn meshed_walls_get_one_cell_per_patch() {
        for (spec, n) in [("@cube:10", 10), ("@cube:30", 30)] {
            let scene = crate::scenes::load(spec).unwrap();
            let (grids, gridded) = Grids::build(&scene, MARGIN);
            assert_eq!(grids.grids.len(), 6, "{spec}");
            assert!(gridded.iter().all(|&g| g), "{spec}");
            for grid in &grids.grids {
                assert_eq!(grid.cells, [n, n], "{spec}");
            }
            let lanes: usize = grids
                .ids
                .iter()
                .map(|ids| ids.iter().filter(|&&t| t != u32::MAX).count())
                .sum();
            assert_eq!(
                lanes,
                scene.triangles.len(),
                "{spec}: each triangle in one cell"
            );
            assert_eq!(
                grids.packets.len(),
                scene.triangles.len() / 4,
                "{spec}: packets full"
            );
        }
        for spec in ["@cube:4", "@sphere:3", "@cubes512", "@tetrahedron"] {
            let scene = crate::scenes::load(spec).unwrap();
            let (grids, gridded) = Grids::build(&scene, MARGIN);
            assert!(grids.is_empty() && !gridded.contains(&true), "{spec}");
        }
    }

    /// A plane of small squares (which set the cells' size) crossed by long slivers along its diagonal
    /// (each would fill a whole diagonal band of cells, as a hostile file's triangles could fill them
    /// all): the plane stays in the tree, and the scene gets no grid.
    #[test]
    fn long_slivers_keep_their_plane_in_the_tree() {
        let mut b = crate::scene::SceneBuilder::new("slivers");
        let material = b.material(crate::scene::Material::default());
        for i in 0..10 {
            for j in 0..10 {
                let (x, y) = (i as f64, j as f64);
                let v = [[x, y], [x + 1.0, y], [x + 1.0, y + 1.0], [x, y + 1.0]]
                    .map(|[x, y]| b.vertex([x, y, 0.0]));
                b.polygon(&v, material, "squares");
            }
        }
        for k in 0..100 {
            let o = k as f64 * 1e-3;
            let v = [[o, 0.0], [10.0, 10.0 - o], [10.0, 10.0]].map(|[x, y]| b.vertex([x, y, 0.0]));
            b.polygon(&v, material, "slivers");
        }
        let scene = b.build().unwrap();
        assert_eq!(
            large_planes(&scene, f64::from(MARGIN)).len(),
            1,
            "one large plane"
        );
        let (grids, gridded) = Grids::build(&scene, MARGIN);
        assert!(grids.is_empty() && !gridded.contains(&true));
    }

    /// At most twice as many cells as triangles, also when one axis is cut down to a single cell (a
    /// long strip: 65,536 cells along it by its patches' median side, one across).
    #[test]
    fn cells_stay_within_twice_the_triangles() {
        for (along, across) in [(65536.0, 1e-3), (1e9, 1.0), (100.0, 100.0), (3.0, 1e6)] {
            let mut sides = [vec![1.0; 64], vec![1.0; 64]];
            let n = cell_counts(&mut sides, [0.0, 0.0], [along, across], 64);
            assert!(n[0] >= 1 && n[1] >= 1, "{along} x {across}: {n:?}");
            assert!(n[0] * n[1] <= 128, "{along} x {across}: {n:?}");
        }
        let mut regular = [vec![1.0; 200], vec![1.0; 200]];
        assert_eq!(
            cell_counts(&mut regular, [0.0; 2], [10.0; 2], 200),
            [10, 10]
        );
    }

    /// A refused plane leaves its place among the [`MAX_GRIDS`] to the next largest: the largest plane
    /// (slivers among squares) stays in the tree, and the 16 smaller walls all get grids.
    #[test]
    fn a_refused_plane_leaves_its_place_to_the_next() {
        let mut b = crate::scene::SceneBuilder::new("walls and slivers");
        let material = b.material(crate::scene::Material::default());
        let square = |b: &mut crate::scene::SceneBuilder, x: f64, y: f64, z: f64, group: &str| {
            let v = [[x, y], [x + 1.0, y], [x + 1.0, y + 1.0], [x, y + 1.0]]
                .map(|[x, y]| b.vertex([x, y, z]));
            b.polygon(&v, material, group);
        };
        for (i, j) in (0..10).flat_map(|i| (0..10).map(move |j| (i, j))) {
            square(&mut b, i as f64, j as f64, 0.0, "floor");
        }
        for k in 1..=100 {
            let o = k as f64 * 1e-3;
            let v = [[o, 0.0], [10.0, 10.0 - o], [10.0, 10.0]].map(|[x, y]| b.vertex([x, y, 0.0]));
            b.polygon(&v, material, "slivers");
        }
        let walls = MAX_GRIDS;
        for z in 1..=walls {
            for (i, j) in (0..8).flat_map(|i| (0..8).map(move |j| (i, j))) {
                square(&mut b, i as f64, j as f64, z as f64, "wall");
            }
        }
        let scene = b.build().unwrap();
        let planes = large_planes(&scene, f64::from(MARGIN));
        assert_eq!(planes.len(), walls + 1);
        assert_eq!(planes[0].len(), 300, "the sliver plane is the largest");
        let (grids, gridded) = Grids::build(&scene, MARGIN);
        assert_eq!(grids.grids.len(), walls, "every wall gets a grid");
        assert!(planes[0].whole().iter().all(|&t| !gridded[t as usize]));
        assert_eq!(gridded.iter().filter(|&&g| g).count(), walls * 128);
    }
}
