//! Depth-first traversal of the binary BVH for one ray and for 8-ray packets: the walk of the
//! top level (instances) of [`crate::Accel`], and the box tests that the wide meshes' walks
//! ([`crate::Bvh8`]) share.
//!
//! One walker, [`walk`], written over [`Lanes`] (as the triangle test is), serves both: a single
//! ray is a packet of one lane. It visits the nearer child first (closest-hit queries; any-hit
//! queries use a fixed order, see [`walk`]) and keeps the other on a small stack together with
//! its entry distance, so that a subtree beyond the closest hit found so far is dropped when it
//! is popped (the interval early-out). A packet tests both child boxes against all eight rays at
//! once (one SIMD slab test per box), descends while any active ray hits, orders children by
//! the majority of rays (Wald et al. 2001, Embree's hybrid traversal), and stops as soon as no
//! ray is left active (any-hit queries). For one lane the majority is the ray itself, so the
//! single-ray walk is the classic near-first traversal with no extra work.
//!
//! Box tests follow Ize, "Robust BVH Ray Traversal" (JCGT 2(2), 2013): slab distances are
//! computed as (b - o) · (1/d) and the exit distance is enlarged by 1 + 2γ₃, so a box is never
//! missed by a ray that hits a triangle inside it, which keeps the watertight triangle test
//! watertight through the traversal.

use crate::bvh8::{Bvh8Node, IntervalRay8, PacketBoxes};
use crate::node::Node;
use glam::Vec3;
use igi_simd::{F32x8, LaneMask, Lanes, M32x8, Vec3x8};
use std::mem::MaybeUninit;

/// Entries of the fixed traversal stacks. A walk holds at most one entry per tree level, so the
/// builders keep every tree's depth within it.
pub const TRAVERSAL_STACK_SIZE: usize = 64;

/// 1 + 2γ₃ with γₙ = nε/(1 - nε), ε = 2⁻²⁴ (pbrt, section 3.9).
pub(crate) const EXIT_SCALE: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Reciprocal of a direction component for slab tests. A component smaller than 1e-30 in
/// magnitude makes the ray parallel to its axis, and its reciprocal ±∞: the slab is then the
/// whole line where the origin lies strictly between the box's planes (distances ∓∞), none
/// where it lies outside (both ±∞ of one sign), and 0·∞ = NaN for a plane through the origin.
/// The overlap tests fold each axis's distance into their running interval as the first
/// operand of `max`/`min`, whose result is the second operand when one is NaN, so a NaN
/// plane does not clip the interval: a ray lying in a box's face enters the box, as the
/// watertight triangle test can hit the triangles in that face ("Rays in a box face",
/// ARCHITECTURE.md). A finite stand-in for the reciprocal (±1e30 before) gave that plane the
/// distance 0, and refused such rays with `tnear > 0`.
#[inline(always)]
pub(crate) fn slab_rcp(d: f32) -> f32 {
    if d.abs() < PARALLEL { f32::INFINITY.copysign(d) } else { 1.0 / d }
}

/// Direction components smaller than this in magnitude make a ray parallel to their axis.
const PARALLEL: f32 = 1e-30;

/// Per axis, the index into [`Node::coords`] of the near plane of rays whose direction on that
/// axis is `negative` or not (0..3 = min, 4..7 = max); the far plane's is the index ^ 4.
#[inline(always)]
fn near_coords(negative: [bool; 3]) -> [usize; 3] {
    [0, 1, 2].map(|a| if negative[a] { a + 4 } else { a })
}

/// A single ray prepared for box tests.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxRay1 {
    /// Origin.
    pub(crate) org: [f32; 3],
    /// Reciprocal direction ([`slab_rcp`]).
    pub(crate) inv: [f32; 3],
    /// Start of the ray's interval.
    pub(crate) tnear: f32,
    /// Per axis: index into [`Node::coords`] of the near plane (0..3 = min, 4..7 = max).
    near: [usize; 3],
}

impl BoxRay1 {
    pub(crate) fn new(org: Vec3, dir: Vec3, tnear: f32) -> Self {
        let inv = [slab_rcp(dir.x), slab_rcp(dir.y), slab_rcp(dir.z)];
        Self { org: org.to_array(), inv, tnear, near: near_coords(inv.map(|i| i < 0.0)) }
    }
}

impl BoxTest<f32> for BoxRay1 {
    #[inline(always)]
    fn enter(&self, n: &Node, tfar: f32) -> (bool, f32) {
        let c = n.coords();
        let dist = |i: usize, a: usize| (c[i] - self.org[a]) * self.inv[a];
        // Each axis's distance first, the running interval second: a NaN distance (a plane
        // through the origin of a parallel ray, `slab_rcp`) leaves the interval as it was.
        let (mut tmin, mut tmax) = (self.tnear, tfar);
        for a in 0..3 {
            tmin = dist(self.near[a], a).max(tmin);
            tmax = dist(self.near[a] ^ 4, a).min(tmax);
        }
        let tmax = tmax * EXIT_SCALE;
        (tmin <= tmax, tmin)
    }
}

/// A ray or packet prepared for box tests: [`BoxRay1`] for one ray; for eight, [`OctantBoxes8`]
/// when the active rays' directions share their signs on every axis (nearly always for coherent
/// packets: primary rays of a tile, shadow rays of neighbouring pixels to one VPL), which reads
/// each slab's near and far plane directly, and [`MixedBoxes8`] otherwise, which orders the
/// planes per lane.
pub(crate) trait BoxTest<L: Lanes>: Copy {
    /// Lanes overlapping `n`'s box within `[tnear, tfar]`, and their entry distances.
    fn enter(&self, n: &Node, tfar: L) -> (L::Mask, L);
}

/// Origins, safe reciprocal directions and `tnear` of eight rays.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slabs8 {
    org: [F32x8; 3],
    inv: [F32x8; 3],
    tnear: F32x8,
}

/// Box tests of a packet whose active rays all point into one octant.
#[derive(Clone, Copy, Debug)]
pub(crate) struct OctantBoxes8 {
    s: Slabs8,
    /// Per axis: index into [`Node::coords`] of the near plane (0..3 = min, 4..7 = max).
    near: [usize; 3],
}

/// Box tests of a packet whose rays point into different octants.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MixedBoxes8 {
    s: Slabs8,
    /// Per axis: lanes whose direction is negative (they enter through the max plane).
    neg: [M32x8; 3],
}

/// The box tests of one packet.
#[derive(Clone, Copy, Debug)]
pub(crate) enum BoxRay8 {
    Octant(OctantBoxes8),
    Mixed(MixedBoxes8),
}

impl BoxRay8 {
    pub(crate) fn new(org: &Vec3x8, dir: &Vec3x8, tnear: F32x8, active: M32x8) -> Self {
        // `slab_rcp` lane by lane, in SIMD.
        let parallel = F32x8::splat(PARALLEL);
        let infinity = F32x8::splat(f32::INFINITY);
        let rcp = |d: F32x8| F32x8::select(d.abs().lt(parallel), infinity.xor_sign(d), F32x8::splat(1.0) / d);
        let inv = [rcp(dir.x), rcp(dir.y), rcp(dir.z)];
        let s = Slabs8 { org: (*org).into(), inv, tnear };
        let neg = inv.map(|i| i.lt(F32x8::ZERO));
        let active_bits = active.bitmask();
        let octant = neg.map(|n| {
            let bits = n.bitmask() & active_bits;
            (bits == 0 || bits == active_bits).then_some(bits != 0)
        });
        match octant {
            [Some(x), Some(y), Some(z)] => BoxRay8::Octant(OctantBoxes8 { s, near: near_coords([x, y, z]) }),
            _ => BoxRay8::Mixed(MixedBoxes8 { s, neg }),
        }
    }
}

impl Slabs8 {
    /// The overlap test from per-axis entry and exit distances, each folded into the running
    /// interval as the first operand, so that a NaN distance leaves it as it was (`slab_rcp`).
    #[inline(always)]
    fn overlap(&self, near: [F32x8; 3], far: [F32x8; 3], tfar: F32x8) -> (M32x8, F32x8) {
        let tmin = near[0].max(near[1].max(near[2].max(self.tnear)));
        let tmax = far[0].min(far[1].min(far[2].min(tfar))) * F32x8::splat(EXIT_SCALE);
        (tmin.le(tmax), tmin)
    }

    #[inline(always)]
    fn dist(&self, plane: f32, axis: usize) -> F32x8 {
        (F32x8::splat(plane) - self.org[axis]) * self.inv[axis]
    }
}

impl BoxTest<F32x8> for OctantBoxes8 {
    #[inline(always)]
    fn enter(&self, n: &Node, tfar: F32x8) -> (M32x8, F32x8) {
        let c = n.coords();
        // The far plane of an axis is the other corner's: index ^ 4.
        let near = std::array::from_fn(|a| self.s.dist(c[self.near[a]], a));
        let far = std::array::from_fn(|a| self.s.dist(c[self.near[a] ^ 4], a));
        self.s.overlap(near, far, tfar)
    }
}

impl PacketBoxes for OctantBoxes8 {
    #[inline(always)]
    fn enter_slot(&self, node: &Bvh8Node, i: usize, tfar: F32x8) -> (M32x8, F32x8) {
        let plane = |a: usize, near: bool| {
            if (self.near[a] < 4) == near { node.lower[a][i] } else { node.upper[a][i] }
        };
        let near = std::array::from_fn(|a| self.s.dist(plane(a, true), a));
        let far = std::array::from_fn(|a| self.s.dist(plane(a, false), a));
        self.s.overlap(near, far, tfar)
    }
    #[inline(always)]
    fn interval(&self, active: M32x8) -> Option<IntervalRay8> {
        IntervalRay8::new(&self.s.org, &self.s.inv, self.s.tnear, self.near.map(|n| n < 4), active)
    }
}

impl PacketBoxes for MixedBoxes8 {
    #[inline(always)]
    fn enter_slot(&self, node: &Bvh8Node, i: usize, tfar: F32x8) -> (M32x8, F32x8) {
        self.enter_box(|a| node.lower[a][i], |a| node.upper[a][i], tfar)
    }
    #[inline(always)]
    fn interval(&self, _active: M32x8) -> Option<IntervalRay8> {
        None
    }
}

impl MixedBoxes8 {
    /// The overlap test of the box with lower planes `min` and upper planes `max`: each lane
    /// takes its near and far plane by its own direction's signs.
    #[inline(always)]
    fn enter_box(
        &self,
        min: impl Fn(usize) -> f32,
        max: impl Fn(usize) -> f32,
        tfar: F32x8,
    ) -> (M32x8, F32x8) {
        let lo: [F32x8; 3] = std::array::from_fn(|a| self.s.dist(min(a), a));
        let hi: [F32x8; 3] = std::array::from_fn(|a| self.s.dist(max(a), a));
        let near = std::array::from_fn(|a| F32x8::select(self.neg[a], hi[a], lo[a]));
        let far = std::array::from_fn(|a| F32x8::select(self.neg[a], lo[a], hi[a]));
        self.s.overlap(near, far, tfar)
    }
}

impl BoxTest<F32x8> for MixedBoxes8 {
    #[inline(always)]
    fn enter(&self, n: &Node, tfar: F32x8) -> (M32x8, F32x8) {
        self.enter_box(|a| n.min[a], |a| n.max[a], tfar)
    }
}

/// What a walk needs from its query, for one ray (`L = f32`) or a packet (`L = F32x8`).
pub(crate) trait Query<L: Lanes> {
    /// True if `tfar` shrinks during the walk (closest hit), so that subtrees on the stack may
    /// become too far to visit; any-hit queries skip that bookkeeping.
    const SHRINKS: bool;
    /// Current ends of the rays' intervals.
    fn tfar(&self) -> L;
    /// Rays still looking for an answer (all of them for a query that never retires one before
    /// the walk ends).
    #[inline(always)]
    fn active(&self) -> L::Mask {
        L::Mask::ALL
    }
}

/// Walks `nodes` with one ray or eight, calling `leaf` for every leaf that any active ray
/// reaches. Returns early when no ray is left active.
#[inline(always)]
pub(crate) fn walk<L: Lanes, Q: Query<L>, B: BoxTest<L>>(
    nodes: &[Node],
    ray: &B,
    q: &mut Q,
    mut leaf: impl FnMut(&mut Q, &Node),
) {
    let Some(root) = nodes.first() else { return };
    let (m, _) = ray.enter(root, q.tfar());
    if !(m & q.active()).any() {
        return;
    }
    // Left uninitialised: the walk starts once per ray and again for every instance a ray
    // enters, and zeroing 512 bytes each time was 3.4 % of a shadow ray's time in a field of
    // instanced armadillos (issue 17).
    let mut stack = [MaybeUninit::<(u32, f32)>::uninit(); TRAVERSAL_STACK_SIZE];
    let mut sp = 0;
    let mut node = root;
    loop {
        if node.is_leaf() {
            leaf(q, node);
            if !q.active().any() {
                return;
            }
        } else {
            let (l, r) = (&nodes[node.offset as usize], &nodes[node.offset as usize + 1]);
            let (tfar, active) = (q.tfar(), q.active());
            let (ml, tl) = ray.enter(l, tfar);
            let (mr, tr) = ray.enter(r, tfar);
            let (ml, mr) = (ml & active, mr & active);
            match (ml.any(), mr.any()) {
                (true, true) => {
                    // Closest hit: near-first for the majority of the rays that enter both
                    // children. Any hit: a fixed order. Shadow rays start and end on surfaces
                    // (the shaded point, the VPL) whose own triangles cannot block them, and
                    // near-first (or far-first) order walks into exactly that geometry first;
                    // on the IGI workload the fixed order is 10-20 % faster (`igi bench rays`,
                    // Sponza and conference).
                    let both = ml & mr;
                    let left_first = !Q::SHRINKS || 2 * (tl.le(tr) & both).count() >= both.count();
                    let (near, far, far_m, far_t) =
                        if left_first { (l, node.offset + 1, mr, tr) } else { (r, node.offset, ml, tl) };
                    let entry = if Q::SHRINKS {
                        L::select(far_m, far_t, L::splat(f32::INFINITY)).reduce_min()
                    } else {
                        f32::NEG_INFINITY
                    };
                    stack[sp] = MaybeUninit::new((far, entry));
                    sp += 1;
                    node = near;
                    continue;
                }
                (true, false) => {
                    node = l;
                    continue;
                }
                (false, true) => {
                    node = r;
                    continue;
                }
                (false, false) => {}
            }
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            // SAFETY: entries below the stack pointer were all written by the push above.
            let (n, entry) = unsafe { stack[sp].assume_init() };
            if !Q::SHRINKS
                || entry
                    <= L::select(q.active(), q.tfar(), L::splat(f32::NEG_INFINITY)).reduce_max() * EXIT_SCALE
            {
                node = &nodes[n as usize];
                break;
            }
        }
    }
}
