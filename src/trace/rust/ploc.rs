//! The binary BVH of PLOC, parallel locally-ordered clustering (Meister and Bittner, TVCG 2018): obvhs
//! 0.2's `build_ploc_from_leafs` step for step (its sequential form), so the tree is obvhs's to the bit
//! (a test builds both), with about half its memory.
//!
//! PLOC sorts the leaves along a Morton curve, then, round after round, merges each node with the
//! neighbour (within a search distance) whose union has the least area, when the two agree. obvhs keeps
//! the nodes of a round, those of the next, and the finished tree (every node, written from the end of the
//! list as nodes are merged) all at once, as 48-byte nodes, the tree's list written in full at the
//! start: 170 bytes per triangle before its first merge, the peak of a large scene's memory. Here the
//! nodes of a round are 32 bytes and each round's list is a new one (the last round's freed), and the
//! finished nodes are appended to a list only as they are made, in reverse (then reversed in place):
//! the tree itself, 96 bytes per triangle, is the peak.

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2Node;
use obvhs::ploc::morton::{morton_encode_u128_unorm, morton_encode_u64_unorm};
use obvhs::ploc::SortPrecision;
use rdst::{RadixKey, RadixSort};

/// A node of a round, not yet in the tree: its box, and a leaf's primitive (`prim_count` 1) or an
/// inner node's first child (`prim_count` 0), as in [`Bvh2Node`].
#[derive(Clone, Copy, Debug)]
pub(super) struct Pending {
    min: [f32; 3],
    max: [f32; 3],
    prim_count: u32,
    first_index: u32,
}

impl Pending {
    /// A leaf holding primitive `primitive`, bounded by `aabb`.
    pub(super) fn leaf(aabb: &Aabb, primitive: u32) -> Self {
        Pending::of(aabb, 1, primitive)
    }

    fn of(aabb: &Aabb, prim_count: u32, first_index: u32) -> Self {
        Pending {
            min: aabb.min.to_array(),
            max: aabb.max.to_array(),
            prim_count,
            first_index,
        }
    }

    fn aabb(&self) -> Aabb {
        Aabb::new(Vec3A::from_array(self.min), Vec3A::from_array(self.max))
    }

    fn node(&self) -> Bvh2Node {
        Bvh2Node {
            aabb: self.aabb(),
            prim_count: self.prim_count,
            first_index: self.first_index,
        }
    }
}

/// The tree of `leaves` (bounded by `total`, the union of their boxes taken point by point as obvhs's
/// `build_ploc` does), obvhs's `nodes` list: the root first, each inner node's children side by side.
/// `SEARCH_DISTANCE` (at most 32), `sort_precision` and `search_depth_threshold` are obvhs's.
pub(super) fn build<const SEARCH_DISTANCE: usize>(
    leaves: Vec<Pending>,
    total: Aabb,
    sort_precision: SortPrecision,
    search_depth_threshold: usize,
) -> Vec<Bvh2Node> {
    let prim_count = leaves.len();
    if prim_count == 0 {
        return Vec::new();
    }
    let scale = 1.0 / total.diagonal().as_dvec3();
    let offset = -total.min.as_dvec3() * scale;
    let mut current = match sort_precision {
        SortPrecision::U128 => sorted::<Morton128>(leaves, scale, offset),
        SortPrecision::U64 => sorted::<Morton64>(leaves, scale, offset),
    };

    // obvhs writes the two children of a merge at `insert_index` and `insert_index + 1`, from the end of
    // its list down, and the root at 0; here they go to `placed` in the reverse order, then reversed.
    let nodes_count = 2 * prim_count - 1;
    let mut placed: Vec<Bvh2Node> = Vec::with_capacity(nodes_count);
    let mut insert_index = nodes_count;
    assert!(i8::MAX as usize > SEARCH_DISTANCE);
    let mut merge: Vec<i8> = vec![0; prim_count];
    let mut cache = SearchCache::<SEARCH_DISTANCE>::default();
    let mut depth = 0;
    while current.len() > 1 {
        if SEARCH_DISTANCE == 1 || depth < search_depth_threshold {
            let mut last_cost = f32::MAX;
            for i in 0..current.len() - 1 {
                let cost = current[i].aabb().union(&current[i + 1].aabb()).half_area();
                merge[i] = if last_cost < cost { -1 } else { 1 };
                last_cost = cost;
            }
            merge[current.len() - 1] = -1;
        } else {
            for (index, best) in merge.iter_mut().enumerate().take(current.len()) {
                *best = cache.find_best_node(index, &current);
            }
        }

        let mut next = Vec::with_capacity(current.len());
        for index in 0..current.len() {
            let best_index = (index as i64 + merge[index] as i64) as usize;
            // Merged when the two agree, once (at the second of the two).
            if best_index as i64 + merge[best_index] as i64 != index as i64 {
                next.push(current[index]);
                continue;
            }
            if best_index > index {
                continue;
            }
            let (left, right) = (current[index], current[best_index]);
            insert_index -= 2;
            next.push(Pending::of(
                &left.aabb().union(&right.aabb()),
                0,
                insert_index as u32,
            ));
            placed.push(right.node());
            placed.push(left.node());
        }
        if stalled(current.len(), next.len()) {
            next = merged_in_pairs(next, &mut insert_index, &mut placed);
        }
        current = next;
        depth += 1;
    }
    placed.push(current[0].node());
    debug_assert_eq!(insert_index.saturating_sub(1), 0);
    placed.reverse();
    placed
}

/// Whether a round of PLOC made too little progress: it merges nodes whose best neighbours are each
/// other, and where thousands of boxes are alike (coplanar triangles stacked in a hostile file) the
/// neighbours' costs tie and a round merges a pair or two, so the build took time quadratic in the
/// triangles. Real scenes merge a large share of their nodes every round and never stall.
fn stalled(before: usize, after: usize) -> bool {
    before >= 64 && (before - after) * 64 < before
}

/// The nodes merged two by two in their order (the last alone when odd): a round that always halves
/// the nodes, for a stalled build ([`stalled`]); the tree is poorer there, and the build linearithmic.
fn merged_in_pairs(
    nodes: Vec<Pending>,
    insert_index: &mut usize,
    placed: &mut Vec<Bvh2Node>,
) -> Vec<Pending> {
    let mut next = Vec::with_capacity(nodes.len().div_ceil(2));
    for pair in nodes.chunks(2) {
        match pair {
            [left, right] => {
                *insert_index -= 2;
                next.push(Pending::of(
                    &left.aabb().union(&right.aabb()),
                    0,
                    *insert_index as u32,
                ));
                placed.push(right.node());
                placed.push(left.node());
            }
            [alone] => next.push(*alone),
            _ => unreachable!("chunks of one or two"),
        }
    }
    next
}

/// The leaves in the order of their centres' Morton codes (obvhs's `sort_nodes_m64`/`_m128`: the same
/// codes, the same radix sort).
fn sorted<M: Morton>(leaves: Vec<Pending>, scale: DVec3, offset: DVec3) -> Vec<Pending> {
    let mut codes: Vec<M> = leaves
        .iter()
        .enumerate()
        .map(|(index, leaf)| M::new(index, leaf.aabb().center().as_dvec3() * scale + offset))
        .collect();
    codes.radix_sort_unstable();
    codes.iter().map(|m| leaves[m.index()]).collect()
}

/// A leaf's index and Morton code, sorted by the code.
trait Morton: RadixKey + Copy + Send + Sync {
    fn new(index: usize, unit: DVec3) -> Self;
    fn index(&self) -> usize;
}

#[derive(Clone, Copy)]
struct Morton128 {
    index: usize,
    code: u128,
}

impl RadixKey for Morton128 {
    const LEVELS: usize = 16;

    #[inline(always)]
    fn get_level(&self, level: usize) -> u8 {
        self.code.get_level(level)
    }
}

impl Morton for Morton128 {
    fn new(index: usize, unit: DVec3) -> Self {
        Morton128 {
            index,
            code: morton_encode_u128_unorm(unit),
        }
    }

    fn index(&self) -> usize {
        self.index
    }
}

#[derive(Clone, Copy)]
struct Morton64 {
    index: usize,
    code: u64,
}

impl RadixKey for Morton64 {
    const LEVELS: usize = 8;

    #[inline(always)]
    fn get_level(&self, level: usize) -> u8 {
        self.code.get_level(level)
    }
}

impl Morton for Morton64 {
    fn new(index: usize, unit: DVec3) -> Self {
        Morton64 {
            index,
            code: morton_encode_u64_unorm(unit),
        }
    }

    fn index(&self) -> usize {
        self.index
    }
}

/// obvhs's `SearchCache`: the union areas of a node with its next `SEARCH_DISTANCE` neighbours, which
/// each of those neighbours reads back instead of computing again.
struct SearchCache<const SEARCH_DISTANCE: usize>([[f32; SEARCH_DISTANCE]; SEARCH_DISTANCE]);

impl<const SEARCH_DISTANCE: usize> Default for SearchCache<SEARCH_DISTANCE> {
    fn default() -> Self {
        SearchCache([[0.0; SEARCH_DISTANCE]; SEARCH_DISTANCE])
    }
}

impl<const SEARCH_DISTANCE: usize> SearchCache<SEARCH_DISTANCE> {
    fn back(&self, index: usize, other: usize) -> f32 {
        self.0[other % SEARCH_DISTANCE][index % SEARCH_DISTANCE]
    }

    fn front(&mut self, index: usize, other: usize) -> &mut f32 {
        &mut self.0[index % SEARCH_DISTANCE][other % SEARCH_DISTANCE]
    }

    /// The offset of the neighbour of node `index` whose union with it has the least area.
    fn find_best_node(&mut self, index: usize, nodes: &[Pending]) -> i8 {
        let mut best_node = index;
        let mut best_cost = f32::INFINITY;
        let begin = index - SEARCH_DISTANCE.min(index);
        let end = (index + SEARCH_DISTANCE + 1).min(nodes.len());
        for other in begin..index {
            let area = self.back(index, other);
            if area < best_cost {
                best_node = other;
                best_cost = area;
            }
        }
        let ours = nodes[index].aabb();
        for (other, node) in nodes.iter().enumerate().take(end).skip(index + 1) {
            let cost = ours.union(&node.aabb()).half_area();
            *self.front(index, other) = cost;
            if cost < best_cost {
                best_node = other;
                best_cost = cost;
            }
        }
        (best_node as i64 - index as i64) as i8
    }
}
