//! The 8-wide BVH ("BVH8", as Embree names its AVX2 tree) that every mesh is walked through:
//! each node holds the boxes of up to eight children side by side, so one ray tests all of them
//! with one 8-lane slab test and visits the ones it enters near-first, and a packet culls them
//! with one interval test before testing the rest ray by ray (ARCHITECTURE.md, "The wide BVH").
//!
//! It is not built from the primitives but collapsed from the binned-SAH binary [`Bvh`](crate::Bvh)
//! ([`Bvh8::collapse`](crate::Bvh8::collapse), by the SAH's dynamic programme over the binary
//! nodes): its leaves are the binary tree's leaves or subtrees of a few primitives, in the
//! same primitive order, and its boxes the binary tree's.

use crate::aabb::Aabb;

mod collapse;
mod intersector1;
mod intersector8;
mod interval_ray;
mod node;

pub(crate) use intersector1::{Boxes8, walk8};
pub(crate) use intersector8::{PacketBoxes, walk8_packet};
pub(crate) use interval_ray::IntervalRay8;
pub use node::Bvh8Node;

use std::mem::MaybeUninit;

/// A child on a wide walk's stack: the node (`count` 0) or leaf, and where its box is entered
/// (by a packet: the nearest entry of its rays that enter it).
#[derive(Clone, Copy)]
struct Entry {
    child: u32,
    count: u32,
    t: f32,
}

/// Writes `entry` at `sp` into the run `stack[base..sp]` of a node's children, kept sorted
/// farthest lowest so that the nearest pops first. The entries in `base..sp` must have been
/// written.
#[inline(always)]
fn insert_sorted(stack: &mut [MaybeUninit<Entry>], base: usize, sp: usize, entry: Entry) {
    let mut j = sp;
    // SAFETY: the caller wrote the entries in `base..sp`.
    while j > base && unsafe { stack[j - 1].assume_init().t } < entry.t {
        stack[j] = stack[j - 1];
        j -= 1;
    }
    stack[j] = MaybeUninit::new(entry);
}

/// A BVH of nodes with up to eight children, over the leaves of a binary [`Bvh`](crate::Bvh).
///
/// Invariants, relied on by the traversal kernels:
/// - No primitives, no nodes; otherwise node 0 is the root (even over a single leaf).
/// - A child slot is a leaf (`count > 0`: primitives `first .. first + count` in leaf order),
///   an inner node (`count == 0`, `child` a node index greater than its parent's), or unused
///   (an empty box, which no ray enters).
/// - Each child box is the box of the binary node it stands for.
/// - The depth is at most the binary tree's, so `(8 - 1) · TRAVERSAL_STACK_SIZE + 1` stack
///   entries always suffice.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh8 {
    /// The nodes, root first.
    pub nodes: Vec<Bvh8Node>,
    /// Boxes of up to eight subtrees of the binary tree that together hold every primitive,
    /// the largest opened first: an instance's world bounds are the union of their placed
    /// boxes (the root's slots are chosen for rays by the SAH and can be larger).
    pub hull: Vec<Aabb>,
}

impl Bvh8 {
    /// Heap memory held by the nodes, in bytes.
    pub fn bytes(&self) -> usize {
        self.nodes.capacity() * size_of::<Bvh8Node>() + self.hull.capacity() * size_of::<Aabb>()
    }

    /// Number of used child slots over all nodes (a measure of how full the nodes are).
    pub fn used_slots(&self) -> usize {
        self.nodes.iter().map(Bvh8Node::used).sum()
    }
}
