//! One ray through a [`Bvh8`](super::Bvh8): all eight child boxes of a node in one 8-lane slab
//! test, the children entered pushed on a stack with their entry distances (sorted, nearest
//! on top, for closest-hit queries; in slot order for any-hit queries, as the binary walk's
//! fixed order), and a popped entry dropped when it lies beyond the closest hit found since
//! (the interval early-out). This is the single-ray kernel Embree runs on its wide trees for
//! incoherent rays; a node visit costs one test for eight boxes instead of one per box.
//!
//! The box test is the binary walk's (Ize 2013, robust: `(b - o) · (1/d)`, the exit distance
//! enlarged by 1 + 2γ₃), with each slab's near plane chosen by the sign of the direction, so
//! that the inverted box of an unused slot is never entered.

use super::{Bvh8Node, Entry, insert_sorted};
use crate::traverse::{BoxRay1, EXIT_SCALE, Query, TRAVERSAL_STACK_SIZE};
use igi_simd::{F32x8, LaneMask, M32x8};
use std::mem::MaybeUninit;

/// Entries of the stack of a wide walk: a node pushes at most seven children beside the one
/// it descends into, once per level.
const STACK_SIZE: usize = 7 * TRAVERSAL_STACK_SIZE + 1;

/// One ray prepared for testing eight boxes at once: origin, safe reciprocal direction and
/// `tnear` in every lane, and per axis whether the near plane is the lower one.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Boxes8 {
    org: [F32x8; 3],
    inv: [F32x8; 3],
    tnear: F32x8,
    lower_is_near: [bool; 3],
}

impl Boxes8 {
    /// The ray `ray` as the binary walk prepared it, in every lane.
    #[inline(always)]
    pub(crate) fn of(ray: &BoxRay1) -> Self {
        Self {
            org: ray.org.map(F32x8::splat),
            inv: ray.inv.map(F32x8::splat),
            tnear: F32x8::splat(ray.tnear),
            lower_is_near: ray.inv.map(|i| i >= 0.0),
        }
    }

    /// The children of `n` the ray overlaps within `[tnear, tfar]`, and their entry distances.
    #[inline(always)]
    fn enter(&self, n: &Bvh8Node, tfar: f32) -> (M32x8, F32x8) {
        let dist = |axis: usize, near: bool| {
            let plane = if near == self.lower_is_near[axis] { &n.lower[axis] } else { &n.upper[axis] };
            (F32x8::from_array(*plane) - self.org[axis]) * self.inv[axis]
        };
        // Each axis's distances first, so that a NaN one leaves the interval as it was
        // (`slab_rcp`).
        let tmin = dist(0, true).max(dist(1, true).max(dist(2, true).max(self.tnear)));
        let tmax = dist(0, false).min(dist(1, false).min(dist(2, false).min(F32x8::splat(tfar))))
            * F32x8::splat(EXIT_SCALE);
        (tmin.le(tmax), tmin)
    }
}

/// Walks `nodes` with one ray, calling `leaf(q, first, count)` for every leaf the ray
/// reaches, until the query has its answer.
#[inline(always)]
pub(crate) fn walk8<Q: Query<f32>>(
    nodes: &[Bvh8Node],
    ray: &Boxes8,
    q: &mut Q,
    mut leaf: impl FnMut(&mut Q, u32, u32),
) {
    if nodes.is_empty() {
        return;
    }
    // Left uninitialised, as the binary walk's stack (ARCHITECTURE.md, "Instances").
    let mut stack = [MaybeUninit::<Entry>::uninit(); STACK_SIZE];
    let mut sp = 0;
    let mut node = &nodes[0];
    loop {
        let (mask, tmin) = ray.enter(node, q.tfar());
        let mut bits = mask.bitmask() & node.used_bits();
        if bits != 0 {
            let t = tmin.to_array();
            let base = sp;
            while bits != 0 {
                // Any hit: last slot first, so that the slots pop in the binary tree's
                // left-to-right order (its fixed order, ARCHITECTURE.md).
                let i = if Q::SHRINKS { bits.trailing_zeros() } else { 31 - bits.leading_zeros() } as usize;
                bits &= !(1 << i);
                let entry = Entry { child: node.child[i], count: node.count[i], t: t[i] };
                if Q::SHRINKS {
                    insert_sorted(&mut stack, base, sp, entry);
                } else {
                    stack[sp] = MaybeUninit::new(entry);
                }
                sp += 1;
            }
        }
        // The next node: pop until an inner node, handling leaves on the way.
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            // SAFETY: entries below the stack pointer were all written above.
            let e = unsafe { stack[sp].assume_init() };
            if Q::SHRINKS && e.t > q.tfar() * EXIT_SCALE {
                continue;
            }
            if e.count > 0 {
                leaf(q, e.child, e.count);
                if !q.active().any() {
                    return;
                }
            } else {
                node = &nodes[e.child as usize];
                break;
            }
        }
    }
}
