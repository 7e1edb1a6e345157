//! Refitting: recomputing every box of a BVH for moved primitives while keeping its topology,
//! the cheap per-frame update for deforming or animated geometry.
//!
//! Because children are always stored after their parent (an invariant of [`Bvh`]), one sweep
//! from the last node to the first sees both children of a node before the node itself, so no
//! parent links and no recursion are needed: O(nodes + primitives), sequential in memory.

use super::box3a::Box3A;
use crate::aabb::Aabb;
use crate::bvh::Bvh;

impl Bvh {
    /// Recomputes every node's box bottom-up from new primitive bounds, keeping the topology.
    ///
    /// `leaf_order_bounds(i)` is the box of the `i`-th primitive in leaf order, i.e. of input
    /// primitive `prim_order[i]`. Afterwards every box is the exact union of its primitives'
    /// boxes, as after a build. The SAH quality degrades as primitives move away from the
    /// configuration the BVH was built for; rebuild when it matters.
    pub fn refit(&mut self, leaf_order_bounds: impl Fn(u32) -> Aabb) {
        for i in (0..self.nodes.len()).rev() {
            let node = self.nodes[i];
            let bounds = if node.is_leaf() {
                (node.offset..node.offset + node.count)
                    .map(|p| Box3A::from(&leaf_order_bounds(p)))
                    .fold(Box3A::EMPTY, Box3A::union)
            } else {
                let child = |c: u32| Box3A::from(&self.nodes[c as usize].bounds());
                child(node.offset).union(child(node.offset + 1))
            };
            let (min, max) = bounds.node_corners();
            let node = &mut self.nodes[i];
            node.min = min;
            node.max = max;
        }
    }
}
