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
use crate::bvh::{BinaryTree, Bvh};
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
        Self::collapse_tree(bvh)
    }

    /// [`Bvh8::collapse`] of any binary tree in [`Bvh`]'s depth-first layout, such as a build
    /// not yet compacted.
    pub(crate) fn collapse_tree(tree: &impl BinaryTree) -> Self {
        let mut nodes = Vec::new();
        if tree.slots() == 0 {
            return Self { nodes, hull: Vec::new() };
        }
        let hull = hull(tree);
        let plan = Plan::of(tree);
        if plan.leaf(0) {
            // A tree that is one leaf: a root node with one slot.
            emit_slots(tree, &plan, &[0], &mut nodes);
            return Self { nodes, hull };
        }
        // The subtrees under the root's slots are emitted in parallel, each into an array of
        // its own, and appended in slot order with their node indices moved by where they
        // start: the same layout as one depth-first pass.
        let slots = plan.slots(tree, 0);
        let slots = slots.as_slice();
        let subtrees: Vec<Vec<Bvh8Node>> = slots
            .par_iter()
            .map(|&s| {
                let s = s as usize;
                let mut subtree = Vec::with_capacity(plan.range(s).1 as usize / 4 + 1);
                if !plan.leaf(s) {
                    emit(tree, &plan, s, &mut subtree);
                }
                subtree
            })
            .collect();
        nodes.reserve_exact(1 + subtrees.iter().map(Vec::len).sum::<usize>());
        nodes.push(Bvh8Node::EMPTY);
        for (i, (&s, subtree)) in slots.iter().zip(subtrees).enumerate() {
            let s = s as usize;
            let start = nodes.len() as u32;
            let (child, count) = if plan.leaf(s) { plan.range(s) } else { (start, 0) };
            nodes.extend(subtree.into_iter().map(|mut n| {
                let used = n.used();
                for (child, count) in n.child.iter_mut().zip(n.count).take(used) {
                    if count == 0 {
                        *child += start;
                    }
                }
                n
            }));
            nodes[0].set_bounds(i, tree.node(s).bounds());
            nodes[0].child[i] = child;
            nodes[0].count[i] = count;
        }
        Self { nodes, hull }
    }
}

/// The boxes of [`Bvh8::hull`]: starting from the root, the inner node of largest area is
/// replaced by its two children until there are eight boxes or only leaves.
fn hull(tree: &impl BinaryTree) -> Vec<Aabb> {
    let mut cover = vec![0u32];
    while cover.len() < 8 {
        let largest = (0..cover.len())
            .filter(|&k| !tree.node(cover[k] as usize).is_leaf())
            .map(|k| (k, tree.node(cover[k] as usize).bounds().half_area()))
            .reduce(|a, b| if b.1 > a.1 { b } else { a });
        let Some((k, _)) = largest else { break };
        let first = tree.node(cover[k] as usize).offset;
        cover.splice(k..=k, [first, first + 1]);
    }
    cover.iter().map(|&n| tree.node(n as usize).bounds()).collect()
}

/// The programme's decisions for one binary node, all the top-down pass needs (the costs live
/// only while the bottom-up pass climbs past the node: on a 10-million-triangle mesh, storing
/// them made this pass as slow as writing a gigabyte).
#[derive(Clone, Copy, Debug, Default)]
struct Choice {
    /// Its subtree's primitives as one range of leaf order (`first`, `count`; a count of 0
    /// where they are not contiguous).
    range: (u32, u32),
    /// Whether it becomes one leaf when it takes one slot.
    leaf: bool,
    /// Per slot budget i = 1 ..= 8 its subtree may take: 0 where it takes one slot, else the
    /// slots of its left child (low four bits) and of its right child (high four bits); fewer
    /// than i where more cost no less (`C(n, i)` never grows with i).
    fill: [u8; 8],
    /// Where it is a wide node of its own: the slots of its left child (the right one takes
    /// the rest of the eight).
    wide: u8,
}

/// Subtrees of at least this many nodes below their root plan their two children as parallel
/// tasks.
const PARALLEL_NODES_MIN: usize = 1 << 13;

/// The programme's [`Choice`] per binary node, indexed like the binary tree's nodes.
struct Plan(Vec<Choice>);

impl Plan {
    fn of(tree: &impl BinaryTree) -> Self {
        let mut choices = vec![Choice::default(); tree.slots()];
        let (root, below) = choices.split_first_mut().expect("a tree with nodes");
        // The root's descendants are every node after it (the depth-first layout of [`Bvh`]).
        *root = plan_subtree(tree, 0, below).0;
        Self(choices)
    }

    /// [`Choice::range`] of binary node `n`.
    fn range(&self, n: usize) -> (u32, u32) {
        self.0[n].range
    }

    /// [`Choice::leaf`] of binary node `n`.
    fn leaf(&self, n: usize) -> bool {
        self.0[n].leaf
    }

    /// The binary nodes the slots of the wide node standing for inner node `n` stand for.
    fn slots(&self, tree: &impl BinaryTree, n: usize) -> Slots {
        let mut slots = Slots([0; 8], 0);
        let l = tree.node(n).offset as usize;
        let k = usize::from(self.0[n].wide);
        self.fill(tree, l, k, &mut slots);
        self.fill(tree, l + 1, 8 - k, &mut slots);
        slots
    }

    /// Appends the binary nodes that fill at most `slots` slots for the subtree of `n`, left to
    /// right, as the programme chose.
    fn fill(&self, tree: &impl BinaryTree, n: usize, slots: usize, out: &mut Slots) {
        let split = self.0[n].fill[slots - 1];
        if split == 0 {
            out.0[out.1] = n as u32;
            out.1 += 1;
            return;
        }
        let l = tree.node(n).offset as usize;
        self.fill(tree, l, usize::from(split & 15), out);
        self.fill(tree, l + 1, usize::from(split >> 4), out);
    }
}

/// The choice for binary node `n` and its costs `C(n, i)` for i = 1 ..= 8, after planning its
/// descendants, whose choices `below` holds in the depth-first layout of [`Bvh`]: the child
/// pair, the left child's descendants, then the right child's. Large subtrees are planned as
/// two parallel tasks.
fn plan_subtree(tree: &impl BinaryTree, n: usize, below: &mut [Choice]) -> (Choice, [f32; 8]) {
    let node = &tree.node(n);
    // An empty box (a subtree of empty primitives) is entered by no ray.
    let area = node.bounds().half_area();
    let area = if area.is_finite() { area.max(0.0) } else { 0.0 };
    if node.is_leaf() {
        let choice = Choice { range: (node.offset, node.count), leaf: true, ..Choice::default() };
        return (choice, [area * TRIANGLE_COST * node.count as f32; 8]);
    }
    let parallel = below.len() >= PARALLEL_NODES_MIN;
    let (pair, descendants) = below.split_at_mut(2);
    let (l, r) = (node.offset as usize, node.offset as usize + 1);
    // The left child's descendants end where the right child's child pair starts.
    let right = &tree.node(r);
    let left_len = if right.is_leaf() { descendants.len() } else { right.offset as usize - l - 2 };
    let (left_below, right_below) = descendants.split_at_mut(left_len);
    let ((lp, lc), (rp, rc)) = if parallel {
        rayon::join(|| plan_subtree(tree, l, left_below), || plan_subtree(tree, r, right_below))
    } else {
        (plan_subtree(tree, l, left_below), plan_subtree(tree, r, right_below))
    };
    (pair[0], pair[1]) = (lp, rp);
    let (lr, rr) = (lp.range, rp.range);
    let joined = lr.1 > 0 && rr.1 > 0 && lr.0 + lr.1 == rr.0;
    let range = (lr.0, if joined { lr.1 + rr.1 } else { 0 });
    let distribute: [(usize, f32); 8] = std::array::from_fn(|j| split(&lc, &rc, j + 1));
    let internal = area * NODE_COST + distribute[7].1;
    let as_leaf = if range.1 > 0 && range.1 <= LEAF_PRIMITIVES {
        area * TRIANGLE_COST * range.1 as f32
    } else {
        f32::INFINITY
    };
    let mut cost = [as_leaf.min(internal); 8];
    for j in 1..8 {
        cost[j] = cost[j - 1].min(distribute[j].1);
    }
    let fill = std::array::from_fn(|j| {
        // Fewer slots where they cost no more.
        let mut slots = j + 1;
        while slots > 1 && cost[slots - 2] <= cost[slots - 1] {
            slots -= 1;
        }
        let k = distribute[slots - 1].0;
        if slots == 1 { 0 } else { (k | (slots - k) << 4) as u8 }
    });
    (Choice { range, leaf: as_leaf <= internal, fill, wide: distribute[7].0 as u8 }, cost)
}

/// The cheapest way to give `slots` slots to the two children of a binary node, whose costs
/// `C(child, i)` are `left` and `right`: the slots of the left one (the fewest of equal costs),
/// and the cost (infinite for fewer than two slots).
fn split(left: &[f32; 8], right: &[f32; 8], slots: usize) -> (usize, f32) {
    (1..slots)
        .map(|k| (k, left[k - 1] + right[slots - k - 1]))
        .reduce(|best, c| if c.1 < best.1 { c } else { best })
        .unwrap_or((0, f32::INFINITY))
}

/// Appends the wide node that stands for binary inner node `n` (and, depth first, the nodes
/// below it) and returns its index.
fn emit(tree: &impl BinaryTree, plan: &Plan, n: usize, nodes: &mut Vec<Bvh8Node>) -> u32 {
    emit_slots(tree, plan, plan.slots(tree, n).as_slice(), nodes)
}

/// The binary nodes a wide node's slots stand for, and how many there are.
struct Slots([u32; 8], usize);

impl Slots {
    fn as_slice(&self) -> &[u32] {
        &self.0[..self.1]
    }
}

/// Appends the wide node whose slots stand for the binary nodes `slots` and returns its index.
fn emit_slots(tree: &impl BinaryTree, plan: &Plan, slots: &[u32], nodes: &mut Vec<Bvh8Node>) -> u32 {
    let index = nodes.len();
    nodes.push(Bvh8Node::EMPTY);
    for (i, &s) in slots.iter().enumerate() {
        let s = s as usize;
        let (child, count) = if plan.leaf(s) { plan.range(s) } else { (emit(tree, plan, s, nodes), 0) };
        let node = &mut nodes[index];
        node.set_bounds(i, tree.node(s).bounds());
        node.child[i] = child;
        node.count[i] = count;
    }
    index as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build::{BuildParams, build_binned_sah_tree_by};
    use crate::bvh::sah_cost;
    use glam::Vec3;
    use rand_core::{RngCore, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// A mesh's tree is collapsed as the builder left it (ARCHITECTURE.md, "A wide BVH"): the
    /// unused slots between the parallel tasks' subtrees must change neither the wide tree nor
    /// the SAH cost reported for the binary one.
    #[test]
    fn the_uncompacted_build_collapses_as_the_compacted_one() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
        let mut unit = || (rng.next_u32() >> 8) as f32 / (1 << 24) as f32;
        let boxes: Vec<Aabb> = (0..50_000)
            .map(|_| {
                let centre = Vec3::new(unit(), unit(), unit()) * 100.0;
                let size = Vec3::new(unit(), unit(), unit()) * 2.0;
                Aabb { min: centre - size, max: centre + size }
            })
            .collect();
        let params = BuildParams::default();
        let (tree, prim_order) = build_binned_sah_tree_by(boxes.len(), |i| boxes[i], &params).unwrap();
        let (wide, sah) = (Bvh8::collapse_tree(&tree), sah_cost(&tree, &params));
        let slots = tree.slots();
        let bvh = Bvh { nodes: tree.into_compact(), prim_order };
        assert!(
            slots > bvh.nodes.len(),
            "the build leaves unused slots ({slots} for {} nodes)",
            bvh.nodes.len()
        );
        assert!(wide == Bvh8::collapse(&bvh), "the wide trees differ");
        assert_eq!(sah, bvh.sah_cost(&params));
    }
}
