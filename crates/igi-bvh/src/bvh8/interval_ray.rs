//! A packet of rays that share their direction signs as one interval ray: per axis the range
//! of the active rays' origins and reciprocal directions. Interval arithmetic (Wald, Boulos &
//! Shirley 2007, "Ray tracing deformable scenes using dynamic bounding volume hierarchies")
//! gives bounds on every ray's slab distances, so one 8-lane test over a wide node's eight
//! child boxes finds the slots that no ray of the packet can enter; only the others are tested
//! ray by ray. Over a binary tree such a test culls one of two boxes and did not pay
//! (ARCHITECTURE.md); over eight boxes at once it is one test instead of eight.
//!
//! The bounds are conservative for the computed distances, not only the exact ones: a ray's
//! box test computes `fl(fl(p - o) · inv)`, and rounding is monotone, so with
//! `o ∈ [o_min, o_max]` and `inv ∈ [inv_min, inv_max]` of one sign the products of the range
//! ends, rounded the same way, bound it from both sides. A slot culled here is one that the
//! ray-by-ray test would not enter, and the walk answers exactly as without the culling.

use super::Bvh8Node;
use crate::traverse::EXIT_SCALE;
use igi_simd::{F32x8, M32x8};

/// One packet's interval ray, for culling the slots of [`Bvh8Node`]s.
#[derive(Clone, Copy, Debug)]
pub(crate) struct IntervalRay8 {
    /// Per axis, the origin end that bounds the distance to the near plane from below.
    org_near: [F32x8; 3],
    /// Per axis, the origin end that bounds the distance to the far plane from above.
    org_far: [F32x8; 3],
    /// Per axis, the smallest and largest reciprocal direction.
    inv_min: [F32x8; 3],
    inv_max: [F32x8; 3],
    /// The smallest `tnear`.
    tnear: F32x8,
    /// Per axis, whether the near plane is the lower one (a positive direction).
    lower_is_near: [bool; 3],
}

impl IntervalRay8 {
    /// The interval ray of the `active` lanes of rays with origins `org`, reciprocal
    /// directions `inv` (one sign per axis among the active lanes, given by `lower_is_near`)
    /// and starts `tnear`; none if a lane is parallel to an axis (an infinite reciprocal,
    /// `slab_rcp`), whose plane distances interval arithmetic cannot bound.
    pub(crate) fn new(
        org: &[F32x8; 3],
        inv: &[F32x8; 3],
        tnear: F32x8,
        lower_is_near: [bool; 3],
        active: M32x8,
    ) -> Option<Self> {
        let min = |v: F32x8| F32x8::splat(F32x8::select(active, v, F32x8::splat(f32::INFINITY)).reduce_min());
        let max =
            |v: F32x8| F32x8::splat(F32x8::select(active, v, F32x8::splat(f32::NEG_INFINITY)).reduce_max());
        let (org_min, org_max) = (org.map(min), org.map(max));
        // The distance (p - o)·inv grows with p - o for a positive inv and shrinks for a
        // negative one: its lower bound takes the origin end that makes p - o smallest
        // (positive inv) or largest (negative inv), its upper bound the other end.
        let pick = |a: usize, positive: bool| if positive { org_max[a] } else { org_min[a] };
        let (inv_min, inv_max) = (inv.map(min), inv.map(max));
        if inv_min.iter().chain(&inv_max).any(|i| !i.lane(0).is_finite()) {
            return None;
        }
        Some(Self {
            org_near: std::array::from_fn(|a| pick(a, lower_is_near[a])),
            org_far: std::array::from_fn(|a| pick(a, !lower_is_near[a])),
            inv_min,
            inv_max,
            tnear: min(tnear),
            lower_is_near,
        })
    }

    /// The slots of `node` (bit `i` for slot `i`) that a ray of the packet may enter within
    /// its interval, when no ray's interval reaches beyond `tfar`.
    #[inline(always)]
    pub(crate) fn cull(&self, node: &Bvh8Node, tfar: f32) -> u32 {
        let mut tmin = self.tnear;
        let mut tmax = F32x8::splat(tfar);
        for a in 0..3 {
            let (near, far) = if self.lower_is_near[a] {
                (&node.lower[a], &node.upper[a])
            } else {
                (&node.upper[a], &node.lower[a])
            };
            let dn = F32x8::from_array(*near) - self.org_near[a];
            tmin = tmin.max((dn * self.inv_min[a]).min(dn * self.inv_max[a]));
            let df = F32x8::from_array(*far) - self.org_far[a];
            tmax = tmax.min((df * self.inv_min[a]).max(df * self.inv_max[a]));
        }
        tmin.le(tmax * F32x8::splat(EXIT_SCALE)).bitmask()
    }
}
