//! The collapse of a binary BVH into nodes of up to 8 children and leaves of up to 3 triangles: the
//! dynamic programme of Ylitie, Karras and Laine (HPG 2017, sec. 3.1) with the cost model and child
//! order of obvhs 0.2's `bvh2_to_cwbvh`, whose decisions it reproduces exactly (a test builds both).
//!
//! obvhs keeps, for each of the 2n - 1 binary nodes and each of the 7 ways it can spend its child slots,
//! a cost and a decision in 8 bytes: 112 bytes per triangle, the peak of a large scene's memory, beside
//! the compressed 8-wide nodes it writes and we do not use. A node's costs are needed only while its
//! parent's are computed, so here they are returned up the recursion, and each decision is kept in one
//! byte ([`Decision`]): 14 bytes per triangle.

use glam::Vec3A;
use obvhs::bvh2::{Bvh2, Bvh2Node};

/// Child slots of an 8-wide node, and the ways (`0..7`, for 1 to 7 slots) a binary node can fill them.
const WIDTH: usize = 8;
const WAYS: usize = 7;

/// The cost of a triangle relative to a box test (obvhs's `PRIM_COST`).
const PRIM_COST: f32 = 0.3;

/// What a binary node becomes when given `i + 1` child slots: a leaf of the 8-wide tree, an 8-wide node
/// of its own, or its slots distributed between its two children (`left` and `right`: the ways of each
/// child). Packed in a byte: the kind in bits 0-1, `left` in 2-4, `right` in 5-7.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Decision(u8);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Leaf = 0,
    Internal = 1,
    Distribute = 2,
}

impl Decision {
    fn new(kind: Kind, left: usize, right: usize) -> Self {
        debug_assert!(left < WAYS && right < WAYS);
        Decision(kind as u8 | (left as u8) << 2 | (right as u8) << 5)
    }

    fn kind(self) -> Kind {
        match self.0 & 3 {
            0 => Kind::Leaf,
            1 => Kind::Internal,
            _ => Kind::Distribute,
        }
    }

    fn left(self) -> usize {
        (self.0 >> 2 & 7) as usize
    }

    fn right(self) -> usize {
        (self.0 >> 5) as usize
    }
}

/// The decisions of every binary node of a BVH, ready to be read as an 8-wide tree.
pub(super) struct Collapse<'a> {
    bvh2: &'a Bvh2,
    decisions: Vec<[Decision; WAYS]>,
}

impl<'a> Collapse<'a> {
    /// The decisions for `bvh2` (built with one primitive per leaf, as obvhs's PLOC does) and leaves of
    /// at most `max_leaf` primitives (1 to 3).
    pub(super) fn new(bvh2: &'a Bvh2, max_leaf: u32) -> Self {
        let mut c = Collapse {
            bvh2,
            decisions: vec![[Decision::default(); WAYS]; bvh2.nodes.len()],
        };
        if !bvh2.nodes.is_empty() {
            c.decide(0, max_leaf.clamp(1, 3));
        }
        c
    }

    /// Fills in the decisions of node `index` and its subtree; returns the cost of each way and the
    /// node's primitives (the same operations as obvhs's `calculate_cost_impl`).
    fn decide(&mut self, index: usize, max_leaf: u32) -> ([f32; WAYS], u32) {
        let node = &self.bvh2.nodes[index];
        let half_area = node.aabb.half_area();
        if node.is_leaf() {
            assert_eq!(
                node.prim_count, 1,
                "the collapse needs leaves of one primitive"
            );
            self.decisions[index] = [Decision::new(Kind::Leaf, 0, 0); WAYS];
            return ([half_area * 1.0 * PRIM_COST; WAYS], 1);
        }
        let first = node.first_index as usize;
        let (left, left_prims) = self.decide(first, max_leaf);
        let (right, right_prims) = self.decide(first + 1, max_leaf);
        let prims = left_prims + right_prims;
        let mut cost = [0.0; WAYS];
        let mut decided = [Decision::default(); WAYS];

        // One slot: a leaf, or a node of its own whose slots the children share.
        let cost_leaf = if prims <= max_leaf {
            prims as f32 * half_area * PRIM_COST
        } else {
            f32::INFINITY
        };
        let (mut best, mut split) = (f32::INFINITY, None);
        for k in 0..WAYS {
            let c = left[k] + right[WAYS - 1 - k];
            if c < best {
                (best, split) = (c, Some(k));
            }
        }
        // Costs are finite (boxes of a scene in the unit sphere), so a split is always found.
        let k = split.unwrap_or(0);
        let cost_internal = best + half_area;
        let (kind, c) = if cost_leaf < cost_internal {
            (Kind::Leaf, cost_leaf)
        } else {
            (Kind::Internal, cost_internal)
        };
        (cost[0], decided[0]) = (c, Decision::new(kind, k, WAYS - 1 - k));

        // i + 1 slots: as with i, or distributed between the children.
        for i in 1..WAYS {
            let (mut best, mut split) = (cost[i - 1], None);
            for k in 0..i {
                let c = left[k] + right[i - k - 1];
                if c < best {
                    (best, split) = (c, Some(k));
                }
            }
            (cost[i], decided[i]) = match split {
                Some(k) => (best, Decision::new(Kind::Distribute, k, i - k - 1)),
                None => (cost[i - 1], decided[i - 1]),
            };
        }
        self.decisions[index] = decided;
        (cost, prims)
    }

    /// Whether binary node `index`, as a child of an 8-wide node, is a leaf of the 8-wide tree (else an
    /// 8-wide node).
    pub(super) fn is_leaf(&self, index: u32) -> bool {
        self.decisions[index as usize][0].kind() == Kind::Leaf
    }

    /// The children of the 8-wide node made from binary node `index`, in obvhs's slots (`None`: empty).
    pub(super) fn children(&self, index: u32) -> [Option<u32>; WIDTH] {
        let mut children = [None; WIDTH];
        let mut count = 0;
        self.gather(index as usize, 0, &mut children, &mut count);
        order_children(self.bvh2, index as usize, children, count)
    }

    /// obvhs's `get_children`: the binary nodes that fill the slots of node `index` given `way + 1`.
    fn gather(&self, index: usize, way: usize, out: &mut [Option<u32>; WIDTH], count: &mut usize) {
        let node = &self.bvh2.nodes[index];
        if node.is_leaf() {
            out[*count] = Some(index as u32);
            *count += 1;
            return;
        }
        let d = self.decisions[index][way];
        let first = node.first_index as usize;
        for (child, way) in [(first, d.left()), (first + 1, d.right())] {
            if self.decisions[child][way].kind() == Kind::Distribute {
                self.gather(child, way, out, count);
            } else {
                out[*count] = Some(child as u32);
                *count += 1;
            }
        }
    }

    /// Calls `leaf` for the binary leaves under node `index`, left to right (a leaf of the 8-wide tree:
    /// its primitives in obvhs's order).
    pub(super) fn leaves(&self, index: u32, leaf: &mut impl FnMut(&Bvh2Node)) {
        let node = &self.bvh2.nodes[index as usize];
        if node.is_leaf() {
            leaf(node);
        } else {
            self.leaves(node.first_index, leaf);
            self.leaves(node.first_index + 1, leaf);
        }
    }

    /// The number of 8-wide nodes of the tree (its root is binary node 0).
    pub(super) fn node_count(&self) -> usize {
        if self.bvh2.nodes.is_empty() {
            return 0;
        }
        let mut count = 0;
        let mut stack = vec![0u32];
        while let Some(index) = stack.pop() {
            count += 1;
            let mut children = [None; WIDTH];
            let mut n = 0;
            self.gather(index as usize, 0, &mut children, &mut n);
            stack.extend(children.iter().flatten().filter(|&&c| !self.is_leaf(c)));
        }
        count
    }
}

/// obvhs's `order_children`: each child takes the slot of the octant direction its centre lies
/// furthest along (greedily, the largest dot product first), which spreads them as the CWBVH's
/// ray-ordered traversal wants. Our traversal does not order, but the same slots give the same tree.
fn order_children(
    bvh2: &Bvh2,
    index: usize,
    children: [Option<u32>; WIDTH],
    count: usize,
) -> [Option<u32>; WIDTH] {
    let p = bvh2.nodes[index].aabb.center();
    let direction = |s: usize| {
        let sign = |bit: usize| if s & bit != 0 { -1.0 } else { 1.0 };
        Vec3A::new(sign(0b100), sign(0b010), sign(0b001))
    };
    let mut cost = [[f32::MAX; WIDTH]; WIDTH];
    for (s, d) in (0..WIDTH).map(|s| (s, direction(s))) {
        for c in 0..count {
            let child = children[c].expect("gathered") as usize;
            cost[c][s] = d.dot(bvh2.nodes[child].aabb.center() - p);
        }
    }
    let mut slot_of = [None; WIDTH];
    let mut filled = [false; WIDTH];
    loop {
        let mut best = (f32::MAX, None);
        for c in (0..count).filter(|&c| slot_of[c].is_none()) {
            for s in (0..WIDTH).filter(|&s| !filled[s]) {
                if cost[c][s] < best.0 {
                    best = (cost[c][s], Some((c, s)));
                }
            }
        }
        let Some((c, s)) = best.1 else { break };
        filled[s] = true;
        slot_of[c] = Some(s);
    }
    let mut ordered = [None; WIDTH];
    for c in 0..count {
        ordered[slot_of[c].expect("a slot for every child")] = children[c];
    }
    ordered
}
