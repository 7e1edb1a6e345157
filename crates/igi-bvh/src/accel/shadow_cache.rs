//! The shadow cache (Haines & Greenberg 1986, "The Light Buffer: A Shadow-Testing
//! Accelerator"): shadow rays toward one light from neighbouring points are mostly blocked by
//! the same triangle, so the triangle that blocked the last packet is tested first, and a
//! packet whose rays it blocks all skips the BVH walk.
//!
//! The answer is the walk's: a lane is blocked iff a triangle within its interval is hit, and
//! the cached triangle is tested with the same watertight test (and cut-out filter) as in the
//! walk. Only a triangle of an instance placed without a transform is cached (a moved
//! instance would need the rays in its object space first).

use super::{Accel, Any, Cut, Local8, Query, TriangleQuery};
use crate::ray::RayPacket8;
use crate::triangle::{Shear8, TriangleHit, intersect};
use igi_simd::{F32x8, M32x8};

/// The triangle that last blocked a shadow ray toward one light, as (instance, triangle).
/// Keep one per light while its shadow packets are traced, in a coherent order.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadowCache {
    blocker: Option<(u32, u32)>,
}

/// The any-hit query that remembers the last triangle that blocked a lane.
struct Blocking {
    any: Any<F32x8>,
    blocker: Option<(u32, u32)>,
}

impl Query<F32x8> for Blocking {
    const SHRINKS: bool = false;
    #[inline(always)]
    fn tfar(&self) -> F32x8 {
        self.any.tfar
    }
    #[inline(always)]
    fn active(&self) -> M32x8 {
        self.any.active
    }
}

impl TriangleQuery<F32x8> for Blocking {
    #[inline(always)]
    fn take(&mut self, h: TriangleHit<F32x8>, inst: u32, prim: u32) -> bool {
        let hit = self.any.active & h.mask;
        if hit.any() {
            self.blocker = Some((inst, prim));
            self.any.active = self.any.active.and_not(hit);
        }
        self.any.active.any()
    }
}

impl Accel {
    /// [`Accel::occluded8`] with the shadow cache `cache` of the light the rays go to: the
    /// cached triangle first, the walk for the lanes it does not block; the cache then holds
    /// the last triangle found blocking.
    pub fn occluded8_cached(&self, rays: &RayPacket8, active: M32x8, cache: &mut ShadowCache) -> M32x8 {
        let world = Local8::new(rays.origin, rays.dir, rays.tnear, active);
        let blocked = match cache.blocker {
            Some((inst, prim)) if self.placements[inst as usize].identity => {
                let mesh = self.placements[inst as usize].mesh;
                let [a, b, c] = self.meshes[mesh as usize].triangle(prim);
                let (org, tnear) = (world.start.org, world.start.tnear);
                let h = match &world.shear {
                    Shear8::Uniform(s) => intersect(org, s, a, b, c, tnear, rays.tfar),
                    Shear8::Mixed(s) => intersect(org, s, a, b, c, tnear, rays.tfar),
                };
                let h = match self.may_cut(mesh) {
                    Some(cut) => cut.keep(prim, h),
                    None => h,
                };
                h.mask & active
            }
            _ => M32x8::NONE,
        };
        let rest = active.and_not(blocked);
        if rest.none() {
            return blocked;
        }
        let mut q = Blocking { any: Any { tfar: rays.tfar, active: rest }, blocker: None };
        self.trace8_from(&world, rays, &mut q);
        if q.blocker.is_some() {
            cache.blocker = q.blocker;
        }
        blocked | rest.and_not(q.any.active)
    }
}
