//! Eight rays through a [`Bvh8`](super::Bvh8) together. A packet whose rays share their
//! direction signs first culls a node's slots with its interval ray ([`IntervalRay8`]: one
//! 8-lane test for the eight child boxes); each slot left is tested against all eight rays at
//! once (the binary walk's packet box test). Closest-hit queries push the children entered
//! with the nearest entry among their rays, sorted so the nearest pops first, and drop a popped
//! child when every active ray's closest hit lies before it; any-hit queries take the slots in
//! the binary tree's left-to-right order. This is the packet kernel of Embree's hybrid
//! traversal over its wide trees (Benthin et al. 2012).

use super::{Bvh8Node, Entry, IntervalRay8, insert_sorted};
use crate::traverse::{BoxTest, EXIT_SCALE, Query, TRAVERSAL_STACK_SIZE};
use igi_simd::{F32x8, M32x8};
use std::mem::MaybeUninit;

/// The box tests of a packet over wide nodes: the ray-by-ray test of one slot, and the
/// packet's interval ray where its rays share their direction signs.
pub(crate) trait PacketBoxes: BoxTest<F32x8> {
    /// Lanes overlapping the box of slot `i` of `node` within `[tnear, tfar]`, and their entry
    /// distances.
    fn enter_slot(&self, node: &Bvh8Node, i: usize, tfar: F32x8) -> (M32x8, F32x8);
    /// The interval ray of the `active` lanes, if they share their direction signs.
    fn interval(&self, active: M32x8) -> Option<IntervalRay8>;
}

/// The slots of `node` that a ray of the packet may enter: those the interval ray does not
/// cull, else every used slot.
#[inline(always)]
fn candidates(node: &Bvh8Node, interval: &Option<IntervalRay8>, reach: f32) -> u32 {
    match interval {
        Some(iv) => iv.cull(node, reach) & node.used_bits(),
        None => node.used_bits(),
    }
}

/// The farthest interval end of the active rays.
#[inline(always)]
fn reach<Q: Query<F32x8>>(q: &Q) -> f32 {
    F32x8::select(q.active(), q.tfar(), F32x8::splat(f32::NEG_INFINITY)).reduce_max()
}

/// Walks `nodes` with a packet prepared as `ray`, calling `leaf(q, first, count)` for every
/// leaf an active ray reaches, until no ray is left active.
#[inline(always)]
pub(crate) fn walk8_packet<Q: Query<F32x8>, B: PacketBoxes>(
    nodes: &[Bvh8Node],
    ray: &B,
    q: &mut Q,
    mut leaf: impl FnMut(&mut Q, u32, u32),
) {
    if nodes.is_empty() {
        return;
    }
    let interval = ray.interval(q.active());
    if !Q::SHRINKS {
        return walk_any(nodes, ray, &interval, q, leaf);
    }
    let mut stack = [MaybeUninit::<Entry>::uninit(); 7 * TRAVERSAL_STACK_SIZE + 1];
    let mut sp = 0;
    let mut next = Entry { child: 0, count: 0, t: f32::NEG_INFINITY };
    loop {
        if next.count > 0 {
            leaf(q, next.child, next.count);
        } else {
            let node = &nodes[next.child as usize];
            let (tfar, active) = (q.tfar(), q.active());
            let base = sp;
            // The nearest child entered is descended into at once; the others wait on the
            // stack, sorted so that the nearer pop first.
            let mut nearest: Option<Entry> = None;
            let mut bits = candidates(node, &interval, reach(q));
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let (m, t) = ray.enter_slot(node, i, tfar);
                let m: M32x8 = m & active;
                if !m.any() {
                    continue;
                }
                let t = F32x8::select(m, t, F32x8::splat(f32::INFINITY)).reduce_min();
                let mut e = Entry { child: node.child[i], count: node.count[i], t };
                if let Some(n) = nearest {
                    if e.t < n.t {
                        (nearest, e) = (Some(e), n);
                    }
                    insert_sorted(&mut stack, base, sp, e);
                    sp += 1;
                } else {
                    nearest = Some(e);
                }
            }
            if let Some(n) = nearest {
                next = n;
                continue;
            }
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            // SAFETY: entries below the stack pointer were all written above.
            let e = unsafe { stack[sp].assume_init() };
            if e.t <= reach(q) * EXIT_SCALE {
                next = e;
                break;
            }
        }
    }
}

/// The any-hit walk: the candidate slots of a node are tested one at a time, left to right,
/// with the rays still active, and the first one entered is descended into at once (the
/// node's candidates left wait on the stack); the binary tree's fixed-order walk with the
/// binary levels inside a wide node flattened.
#[inline(always)]
fn walk_any<Q: Query<F32x8>, B: PacketBoxes>(
    nodes: &[Bvh8Node],
    ray: &B,
    interval: &Option<IntervalRay8>,
    q: &mut Q,
    mut leaf: impl FnMut(&mut Q, u32, u32),
) {
    let mut stack = [MaybeUninit::<(u32, u32)>::uninit(); TRAVERSAL_STACK_SIZE];
    let mut sp = 0;
    let mut at = 0u32;
    let mut bits = candidates(&nodes[0], interval, reach(q));
    loop {
        let node = &nodes[at as usize];
        let (tfar, active) = (q.tfar(), q.active());
        let mut entered = None;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let (m, _) = ray.enter_slot(node, i, tfar);
            if (m & active).any() {
                entered = Some(i);
                break;
            }
        }
        match entered {
            Some(i) if node.count[i] > 0 => {
                leaf(q, node.child[i], node.count[i]);
                if !q.active().any() {
                    return;
                }
                // Go on with the node's next candidate.
            }
            Some(i) => {
                if bits != 0 {
                    stack[sp] = MaybeUninit::new((at, bits));
                    sp += 1;
                }
                at = node.child[i];
                bits = candidates(&nodes[at as usize], interval, reach(q));
            }
            None => {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                // SAFETY: entries below the stack pointer were all written above.
                (at, bits) = unsafe { stack[sp].assume_init() };
            }
        }
    }
}
