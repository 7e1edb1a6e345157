//! Collapsing a binary BVH into a [`Bvh8`] by the SAH (the dynamic programme of Ylitie, Karras
//! & Laine 2017, "Efficient incoherent ray traversal on GPUs through compressed wide BVHs"):
//! for every binary node n and every number of slots i ≤ 8 its subtree may take in a wide
//! parent, the cheapest way to cover it, `C(n, i)`, where a wide node costs [`NODE_COST`] and
//! a triangle test [`TRIANGLE_COST`], each weighted by the surface area of its box (the
//! probability that a ray entering the root enters it; MacDonald & Booth 1990). A subtree of
//! at most [`LEAF_PRIMITIVES`] primitives may become one leaf where testing its triangles in a
//! row costs less than the nodes above them; the wide nodes are filled with the binary nodes
//! the programme picks. Bottom-up over the binary tree, then top-down to emit the nodes.

use super::{Bvh8, Bvh8Node};
use crate::aabb::Aabb;
use crate::bvh::Bvh;
use rayon::prelude::*;

/// Subtrees of at most this many primitives may become one leaf of the wide tree.
pub const LEAF_PRIMITIVES: u32 = 4;

/// The SAH cost of visiting a wide node (the interval cull and the slot tests of a packet,
/// about six box tests), relative to [`TRIANGLE_COST`].
const NODE_COST: f32 = 1.0;

/// The SAH cost of one 8-lane triangle test (about two and a half box tests; ARCHITECTURE.md,
/// "The wide BVH").
const TRIANGLE_COST: f32 = 0.25;

impl Bvh8 {
    /// The wide tree over the primitives of `bvh`, in the same primitive order.
    pub fn collapse(bvh: &Bvh) -> Self {
        let mut nodes = Vec::new();
        if bvh.nodes.is_empty() {
            return Self { nodes, hull: Vec::new() };
        }
        let hull = hull(bvh);
        let plan = Plan::of(bvh);
        if plan.leaf[0] {
            // A tree that is one leaf: a root node with one slot.
            emit_slots(bvh, &plan, &[0], &mut nodes);
            return Self { nodes, hull };
        }
        // The subtrees under the root's slots are emitted in parallel, each into an array of
        // its own, and appended in slot order with their node indices moved by where they
        // start: the same layout as one depth-first pass.
        let slots = plan.slots(bvh, 0);
        let slots = slots.as_slice();
        let subtrees: Vec<Vec<Bvh8Node>> = slots
            .par_iter()
            .map(|&s| {
                let s = s as usize;
                let mut subtree = Vec::with_capacity(plan.range[s].1 as usize / 4 + 1);
                if !plan.leaf[s] {
                    emit(bvh, &plan, s, &mut subtree);
                }
                subtree
            })
            .collect();
        nodes.reserve_exact(1 + subtrees.iter().map(Vec::len).sum::<usize>());
        nodes.push(Bvh8Node::EMPTY);
        for (i, (&s, subtree)) in slots.iter().zip(subtrees).enumerate() {
            let s = s as usize;
            let start = nodes.len() as u32;
            let (child, count) = if plan.leaf[s] { plan.range[s] } else { (start, 0) };
            nodes.extend(subtree.into_iter().map(|mut n| {
                let used = n.used();
                for (child, count) in n.child.iter_mut().zip(n.count).take(used) {
                    if count == 0 {
                        *child += start;
                    }
                }
                n
            }));
            nodes[0].set_bounds(i, bvh.nodes[s].bounds());
            nodes[0].child[i] = child;
            nodes[0].count[i] = count;
        }
        Self { nodes, hull }
    }
}

/// The boxes of [`Bvh8::hull`]: starting from the root, the inner node of largest area is
/// replaced by its two children until there are eight boxes or only leaves.
fn hull(bvh: &Bvh) -> Vec<Aabb> {
    let mut cover = vec![0u32];
    while cover.len() < 8 {
        let largest = (0..cover.len())
            .filter(|&k| !bvh.nodes[cover[k] as usize].is_leaf())
            .map(|k| (k, bvh.nodes[cover[k] as usize].bounds().half_area()))
            .reduce(|a, b| if b.1 > a.1 { b } else { a });
        let Some((k, _)) = largest else { break };
        let first = bvh.nodes[cover[k] as usize].offset;
        cover.splice(k..=k, [first, first + 1]);
    }
    cover.iter().map(|&n| bvh.nodes[n as usize].bounds()).collect()
}

/// The programme's result per binary node: the primitives of its subtree as one range of leaf
/// order (`first`, `count`; a count of 0 where they are not contiguous), whether it becomes
/// one leaf when it takes one slot, and `C(n, i)` for i = 1 ..= 8.
struct Plan {
    range: Vec<(u32, u32)>,
    leaf: Vec<bool>,
    cost: Vec<[f32; 8]>,
}

impl Plan {
    fn of(bvh: &Bvh) -> Self {
        let n = bvh.nodes.len();
        let mut plan = Self { range: vec![(0, 0); n], leaf: vec![false; n], cost: vec![[0.0; 8]; n] };
        // Children come after their parents: one backward sweep sees children first.
        for (i, node) in bvh.nodes.iter().enumerate().rev() {
            // An empty box (a subtree of empty primitives) is entered by no ray.
            let area = node.bounds().half_area();
            let area = if area.is_finite() { area.max(0.0) } else { 0.0 };
            if node.is_leaf() {
                plan.range[i] = (node.offset, node.count);
                plan.leaf[i] = true;
                plan.cost[i] = [area * TRIANGLE_COST * node.count as f32; 8];
                continue;
            }
            let (l, r) = (node.offset as usize, node.offset as usize + 1);
            let (lr, rr) = (plan.range[l], plan.range[r]);
            let joined = lr.1 > 0 && rr.1 > 0 && lr.0 + lr.1 == rr.0;
            plan.range[i] = (lr.0, if joined { lr.1 + rr.1 } else { 0 });
            let distribute: [f32; 8] = std::array::from_fn(|j| plan.split(l, r, j + 1).1);
            let internal = area * NODE_COST + distribute[7];
            let count = plan.range[i].1;
            let as_leaf = if count > 0 && count <= LEAF_PRIMITIVES {
                area * TRIANGLE_COST * count as f32
            } else {
                f32::INFINITY
            };
            plan.leaf[i] = as_leaf <= internal;
            let mut cost = [as_leaf.min(internal); 8];
            for j in 1..8 {
                cost[j] = cost[j - 1].min(distribute[j]);
            }
            plan.cost[i] = cost;
        }
        plan
    }

    /// The cheapest way to give `slots` slots to the children `l` and `r` of a binary node:
    /// the slots of the left one (the fewest of equal costs), and the cost (infinite for fewer
    /// than two slots).
    fn split(&self, l: usize, r: usize, slots: usize) -> (usize, f32) {
        (1..slots)
            .map(|k| (k, self.cost[l][k - 1] + self.cost[r][slots - k - 1]))
            .reduce(|best, c| if c.1 < best.1 { c } else { best })
            .unwrap_or((0, f32::INFINITY))
    }

    /// The binary nodes the slots of the wide node standing for inner node `n` stand for.
    fn slots(&self, bvh: &Bvh, n: usize) -> Slots {
        let mut slots = Slots([0; 8], 0);
        let l = bvh.nodes[n].offset as usize;
        let (k, _) = self.split(l, l + 1, 8);
        self.fill(bvh, l, k, &mut slots);
        self.fill(bvh, l + 1, 8 - k, &mut slots);
        slots
    }

    /// Appends the binary nodes that fill at most `slots` slots for the subtree of `n`, left to
    /// right, as the programme chose.
    fn fill(&self, bvh: &Bvh, n: usize, slots: usize, out: &mut Slots) {
        // Fewer slots where they cost no more (`C(n, i)` never grows with i).
        let mut slots = slots;
        while slots > 1 && self.cost[n][slots - 2] <= self.cost[n][slots - 1] {
            slots -= 1;
        }
        if slots == 1 {
            out.0[out.1] = n as u32;
            out.1 += 1;
            return;
        }
        let l = bvh.nodes[n].offset as usize;
        let (k, _) = self.split(l, l + 1, slots);
        self.fill(bvh, l, k, out);
        self.fill(bvh, l + 1, slots - k, out);
    }
}

/// Appends the wide node that stands for binary inner node `n` (and, depth first, the nodes
/// below it) and returns its index.
fn emit(bvh: &Bvh, plan: &Plan, n: usize, nodes: &mut Vec<Bvh8Node>) -> u32 {
    emit_slots(bvh, plan, plan.slots(bvh, n).as_slice(), nodes)
}

/// The binary nodes a wide node's slots stand for, and how many there are.
struct Slots([u32; 8], usize);

impl Slots {
    fn as_slice(&self) -> &[u32] {
        &self.0[..self.1]
    }
}

/// Appends the wide node whose slots stand for the binary nodes `slots` and returns its index.
fn emit_slots(bvh: &Bvh, plan: &Plan, slots: &[u32], nodes: &mut Vec<Bvh8Node>) -> u32 {
    let index = nodes.len();
    nodes.push(Bvh8Node::EMPTY);
    for (i, &s) in slots.iter().enumerate() {
        let s = s as usize;
        let (child, count) = if plan.leaf[s] { plan.range[s] } else { (emit(bvh, plan, s, nodes), 0) };
        let node = &mut nodes[index];
        node.set_bounds(i, bvh.nodes[s].bounds());
        node.child[i] = child;
        node.count[i] = count;
    }
    index as u32
}
