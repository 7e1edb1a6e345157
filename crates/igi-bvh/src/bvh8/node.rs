//! The BVH8 node: eight child boxes in structure-of-arrays form (one 8-lane register per box
//! plane), and what each child is.

use crate::aabb::Aabb;
use igi_simd::I32x8;

/// One node of a [`Bvh8`](super::Bvh8): the boxes of up to eight children, plane by plane, so
/// that `lower[axis]` and `upper[axis]` each load as one 8-lane register; 256 bytes, four
/// cache lines.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct Bvh8Node {
    /// Per axis, the lower box planes of the eight children (+∞ in an unused slot).
    pub lower: [[f32; 8]; 3],
    /// Per axis, the upper box planes of the eight children (−∞ in an unused slot).
    pub upper: [[f32; 8]; 3],
    /// Per child: the index of an inner child's node, or a leaf's first primitive in leaf
    /// order; [`Bvh8Node::UNUSED`] in an unused slot. Used slots come first.
    pub child: [u32; 8],
    /// Per child: the number of primitives of a leaf; 0 for an inner child or an unused slot.
    pub count: [u32; 8],
}

impl Bvh8Node {
    /// A node with every slot unused: inverted boxes, which no ray enters (the near plane of
    /// an empty slab lies at +∞, its far plane at −∞, whatever the ray's direction).
    pub const EMPTY: Self = Self {
        lower: [[f32::INFINITY; 8]; 3],
        upper: [[f32::NEG_INFINITY; 8]; 3],
        child: [Self::UNUSED; 8],
        count: [0; 8],
    };

    /// The `child` of an unused slot.
    pub const UNUSED: u32 = u32::MAX;

    /// Sets slot `i` to `bounds`.
    pub(crate) fn set_bounds(&mut self, i: usize, bounds: Aabb) {
        for axis in 0..3 {
            self.lower[axis][i] = bounds.min[axis];
            self.upper[axis][i] = bounds.max[axis];
        }
    }

    /// The box of slot `i`.
    pub fn bounds(&self, i: usize) -> Aabb {
        Aabb {
            min: [self.lower[0][i], self.lower[1][i], self.lower[2][i]].into(),
            max: [self.upper[0][i], self.upper[1][i], self.upper[2][i]].into(),
        }
    }

    /// Number of used slots (a leaf or an inner child).
    pub fn used(&self) -> usize {
        self.child.iter().take_while(|&&c| c != Self::UNUSED).count()
    }

    /// The used slots as bits (bit `i` for slot `i`). The walks enter only these: a ray with
    /// a NaN distance to every plane (a NaN origin or direction) folds none of them into its
    /// interval (`slab_rcp`) and would otherwise enter the unused slots too.
    #[inline(always)]
    pub(crate) fn used_bits(&self) -> u32 {
        let unused = I32x8::from_array(self.child.map(|c| c as i32)).eq(I32x8::splat(Self::UNUSED as i32));
        !unused.bitmask() & 0xff
    }
}

const _: () = assert!(std::mem::size_of::<Bvh8Node>() == 256);
