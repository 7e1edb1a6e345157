//! The clamp's bias compensation in the tile pipeline ([`super`]; Kollig & Keller 2004):
//! short path-traced rays recover the near-field light the VPL clamp removes.

use super::{COMPENSATION, PathState, TilePipeline, TileScratch};
use crate::igi::packet::Packet8;
use crate::image::pixel_rect::PixelRect;
use crate::image::stats::RayCounts;
use crate::sampling::{pixel_seed, sobol4};
use glam::Vec3;
use igi_bvh::Ray;
use igi_shade::brdf::cosine_hemisphere;

impl TilePipeline<'_> {
    /// Step 3b, with a clamp and `compensate_clamp`: the bias compensation of Kollig & Keller (2004). The clamp
    /// replaces 1/d² by 1/max(d², d_min²); the light it removes at x,
    ///
    /// ```text
    /// R(x) = ρ_x/π ∫ L(y → x) cosθ_x · w(|x − y|) dω,   w(d) = max(0, 1 − d²/d_min²),
    /// ```
    ///
    /// comes only from surfaces closer than d_min. One cosine-distributed ray per shading point,
    /// at most d_min long, estimates it as ρ_x · w(d) · L(y → x): the point y it hits becomes a
    /// shading point of the set, lit by the same VPLs, and is compensated in turn, up to
    /// [`COMPENSATION_LEVELS`]. w(d) · L(y → x) (and what the further levels find, weighted
    /// down the chain) joins D at x, the camera path's point ([`PathState::root`]), which ρ_x
    /// multiplies when the pixel is composed: so the filter averages the one-ray estimate over
    /// the neighbours as it does the VPLs' light. What remains biased is the clamp below the
    /// last level and the light of specular surfaces at y, which it drops. The rays are short,
    /// and few hit anything away from creases and contacts.
    pub(super) fn compensate(
        &self,
        region: &PixelRect,
        first: usize,
        s: &mut TileScratch,
        rays: &mut RayCounts,
    ) {
        let d_min = self.d_min2.sqrt();
        let accel = self.scene.accel();
        // Level 0 starts from the set's own points; each level compensates the points the
        // previous one found (their near field is clamped too).
        let (mut lo, mut hi) = (first, s.points.len());
        for level in 0..COMPENSATION_LEVELS {
            let mut start = lo;
            while start < hi {
                let chunk_end = (start + 8).min(hi);
                let mut packet = Packet8::new();
                let mut parents = [usize::MAX; 8];
                for (lane, i) in (start..chunk_end).enumerate() {
                    let p = &s.points[i];
                    let (x, y) = region.pixel(p.state.pixel);
                    let index = self.sequence.first + p.state.sample;
                    let [_, _, u, v] = sobol4(index, 1 + level, pixel_seed(x, y, self.sequence.seed));
                    let dir = cosine_hemisphere(p.ns, glam::Vec2::new(u, v));
                    if dir.dot(p.ng) <= 0.0 {
                        continue;
                    }
                    packet.set(lane, Ray { origin: p.origin, dir, tnear: 0.0, tfar: d_min });
                    parents[lane] = i;
                }
                start = chunk_end;
                rays.compensation += u64::from(packet.len());
                let traced = packet.intersect(accel);
                for (lane, hit) in traced.hits.iter().enumerate() {
                    if traced.bits & (1 << lane) == 0 {
                        continue;
                    }
                    let p = s.points[parents[lane]];
                    let w = 1.0 - hit.t * hit.t / self.d_min2;
                    if w <= 0.0 {
                        continue;
                    }
                    // Weights relative to the camera path's point, whose throughput and ρ_x
                    // multiply its D when the pixel is composed.
                    let (root, throughput) = if p.state.path & COMPENSATION == 0 {
                        (parents[lane] as u32, Vec3::splat(w))
                    } else {
                        (p.state.root, p.state.throughput * p.albedo * w)
                    };
                    let state = PathState {
                        path: p.state.path | COMPENSATION,
                        throughput,
                        root,
                        depth: p.depth,
                        // No specular continuation from y.
                        bounces: self.specular_bounces,
                        ..p.state
                    };
                    self.queue_hit(packet.ray(lane).dir, hit, state, s);
                }
            }
            self.shade_queued(s);
            (lo, hi) = (hi, s.points.len());
            if lo == hi {
                break;
            }
        }
    }
}

/// Levels of the bias compensation: the points it finds are compensated in turn, since they lie
/// where the clamp removes most (creases, contacts). Each level carries at most ρ·w of the
/// previous one; a fourth would change the Cornell box by far less than its noise.
const COMPENSATION_LEVELS: u32 = 3;
