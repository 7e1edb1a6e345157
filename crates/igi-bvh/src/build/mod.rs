//! BVH construction: the binned SAH builder used in production ([`build_binned_sah`]), a
//! full-sweep SAH builder as a quality reference ([`build_sweep_sah`]), and refitting for
//! moving geometry ([`Bvh::refit`](crate::bvh::Bvh::refit)).
//!
//! Both builders are greedy top-down minimisers of the surface area heuristic (SAH) of
//! Goldsmith & Salmon 1987 and MacDonald & Booth 1990: a ray that hits node N hits a child C
//! with probability A(C) / A(N) (A = surface area), so splitting N into L and R costs
//! `C_trav + C_isect (A(L) N(L) + A(R) N(R)) / A(N)` against `C_isect N(N)` for a leaf, where
//! N(·) counts primitives. They produce the same layout (see [`Bvh`](crate::bvh::Bvh)) with the
//! same leaf rules, so their SAH costs compare directly: on the conference room, Sponza,
//! Sibenik, Lost Empire and random triangle soups the binned builder stays within 1.2 % of the
//! full sweep (`cargo run --release -p igi-bvh --example build_report`).
//!
//! Both bound the tree's depth by the size of the traversal stacks,
//! [`TRAVERSAL_STACK_SIZE`](crate::traverse::TRAVERSAL_STACK_SIZE), whatever the input: where a split could lead deeper, they split at the median instead.

mod binned_sah;
mod bins;
mod box3a;
mod node_region;
mod partition;
mod prim_box;
mod refit;
mod small_subtree;
mod sweep_sah;

pub(crate) use binned_sah::build_binned_sah_tree_by;
pub use binned_sah::{build_binned_sah, build_binned_sah_by};
pub use sweep_sah::build_sweep_sah;

/// Parameters shared by the builders.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildParams {
    /// Largest number of primitives in a leaf, 1 ..= [`BuildParams::MAX_LEAF_SIZE`]. Nodes with
    /// more primitives are always split, even where the SAH prefers a leaf.
    pub max_leaf_size: u32,
    /// SAH cost `C_trav` of visiting an inner node (testing the ray against its two children).
    pub traversal_cost: f32,
    /// SAH cost `C_isect` of one ray-primitive test, relative to `traversal_cost`.
    pub intersection_cost: f32,
    /// Number of centroid bins per axis of the binned builder, 2 ..= [`BuildParams::MAX_BINS`].
    pub bins: u32,
}

impl BuildParams {
    /// Upper limit of [`BuildParams::max_leaf_size`], so that a leaf's count fits in 4 bits.
    pub const MAX_LEAF_SIZE: u32 = 15;
    /// Upper limit of [`BuildParams::bins`].
    pub const MAX_BINS: u32 = 32;

    /// Panics with a message naming the field if a parameter is out of range.
    fn assert_valid(&self) {
        assert!(
            (1..=Self::MAX_LEAF_SIZE).contains(&self.max_leaf_size),
            "BuildParams::max_leaf_size must be in 1..={}, got {}",
            Self::MAX_LEAF_SIZE,
            self.max_leaf_size
        );
        assert!(
            (2..=Self::MAX_BINS).contains(&self.bins),
            "BuildParams::bins must be in 2..={}, got {}",
            Self::MAX_BINS,
            self.bins
        );
        assert!(
            self.traversal_cost.is_finite() && self.traversal_cost >= 0.0,
            "BuildParams::traversal_cost must be finite and non-negative, got {}",
            self.traversal_cost
        );
        assert!(
            self.intersection_cost.is_finite() && self.intersection_cost > 0.0,
            "BuildParams::intersection_cost must be finite and positive, got {}",
            self.intersection_cost
        );
    }

    /// True if making a node of `count` primitives and half area `area` a leaf costs no more
    /// than splitting it with `A(L) N(L) + A(R) N(R) = area_count_sum` (the SAH comparison of
    /// the module doc, multiplied through by `A(N)` so that flat nodes need no division).
    #[inline]
    fn leaf_is_cheaper(&self, count: usize, area: f32, area_count_sum: f32) -> bool {
        let leaf = self.intersection_cost * count as f32 * area;
        let split = self.traversal_cost * area + self.intersection_cost * area_count_sum;
        leaf <= split
    }
}

/// The checks both builders start with (their `# Panics`): the number of primitives, or `None`
/// for an empty input, whose BVH is empty.
fn prim_count(n: usize, params: &BuildParams) -> Option<usize> {
    params.assert_valid();
    assert!(n < 1 << 31, "a BVH holds fewer than 2^31 primitives, got {n}");
    (n > 0).then_some(n)
}

/// The number of tree levels below a node of `n` primitives if it is halved until every part
/// fits in a leaf of `max_leaf_size`: `⌈log₂ ⌈n / max_leaf_size⌉⌉`. The builders keep
/// `depth + levels_to_split(n) <= TRAVERSAL_STACK_SIZE` for every node, which bounds the tree's
/// depth by the size of the traversal stacks
/// ([`TRAVERSAL_STACK_SIZE`](crate::traverse::TRAVERSAL_STACK_SIZE)).
fn levels_to_split(n: usize, max_leaf_size: usize) -> usize {
    let leaves = n.div_ceil(max_leaf_size);
    (usize::BITS - leaves.saturating_sub(1).leading_zeros()) as usize
}

impl Default for BuildParams {
    /// Leaves of up to 8 primitives, equal traversal and intersection costs, 16 bins, chosen with
    /// `build_report --params` on the conference room: the SAH cost is 35.75 with leaves of up to
    /// 2, 34.86 with 4, 34.62 with 8 and 34.61 with 15; 32 bins gain 0.1 % for 11 % more build
    /// time, 8 bins lose 15 %; `intersection_cost` 1.5 grows the BVH from 34 to 37 bytes per
    /// triangle.
    fn default() -> Self {
        Self { max_leaf_size: 8, traversal_cost: 1.0, intersection_cost: 1.0, bins: 16 }
    }
}
