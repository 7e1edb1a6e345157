//! Steps 1 and 2 of the tile pipeline ([`super`]): the camera rays of a VPL set's pixels as
//! 8-ray packets (paper Figure 2), and the shading of their hits, once per pixel whose samples
//! see one surface (paper 3.3).

use super::{CAMERA_PATH, PathState, PendingHit, PrimaryPacket, TilePipeline, TileScratch, WholePixel};
use crate::igi::packet::unpack_hits;
use crate::image::pixel_rect::PixelRect;
use crate::image::stats::RayCounts;
use crate::prepared::SurfacePoint;
use crate::sampling::{Sobol2, hash_combine, pixel_seed};
use glam::Vec3;
use igi_bvh::RayPacket8;
use igi_simd::{F32x8, M32x8, Vec3x8};

impl TilePipeline<'_> {
    /// Step 1: the camera rays of every anti-aliasing sample of the pixels of fine set `fine`,
    /// packet by packet: the N packets of one group of pixels follow each other in `s.packets`.
    pub(super) fn trace_primary(
        &self,
        region: &PixelRect,
        fine: u32,
        s: &mut TileScratch,
        rays: &mut RayCounts,
    ) {
        s.packets.clear();
        let accel = self.scene.accel();
        let aa = self.interleave.aa;
        let mut primary = 0u64;
        let origin = Vec3x8::splat(self.camera.origin.to_array());
        self.interleave.packets(region, fine, |lanes| {
            primary += (lanes.len() as u64) * u64::from(aa);
            // Unoccupied lanes repeat the first pixel, so every lane holds a valid ray (the
            // packet kernel decides the traversal order from all lanes' signs).
            let lane = |i: usize| lanes[if i < lanes.len() { i } else { 0 }];
            let (x, y) = (std::array::from_fn(|i| lane(i).0), std::array::from_fn(|i| lane(i).1));
            let pixels = std::array::from_fn(|i| region.index(lane(i).0, lane(i).1) as u32);
            let seeds: [u32; 8] = std::array::from_fn(|i| pixel_seed(x[i], y[i], self.sequence.seed));
            let sequences = seeds.map(Sobol2::new);
            let occupied = (1u32 << lanes.len()) - 1;
            for sample in 0..aa {
                let index = self.sequence.first + sample;
                let offsets = self.interleave.sample_offsets(index, &sequences, self.pixel_centres);
                let dir = self.camera.directions_at8(x, y, offsets.map(|o| o.0), offsets.map(|o| o.1));
                let packet =
                    RayPacket8 { origin, dir, tnear: F32x8::ZERO, tfar: F32x8::splat(f32::INFINITY) };
                let traced = accel.intersect8(&packet, M32x8::from_bitmask(occupied));
                let bits = occupied & traced.hit_mask().bitmask();
                let dirs: [Vec3; 8] = std::array::from_fn(|i| Vec3::from(dir.lane(i)));
                let missed = occupied & !bits;
                if missed != 0 && self.scene.environment().is_some() {
                    for lane in (0..8).filter(|lane| missed & (1 << lane) != 0) {
                        s.emitted[(pixels[lane] * aa + sample) as usize] += self.scene.background(dirs[lane]);
                    }
                }
                s.packets.push(PrimaryPacket { dirs, seeds, hits: unpack_hits(&traced), pixels, bits });
            }
        });
        rays.primary += primary;
    }

    /// Step 2: the surface shaders of the primary hits: once per pixel whose samples all hit
    /// one surface ([`same_surface`]), else once per sample that hit something.
    pub(super) fn shade_primary(&self, s: &mut TileScratch) {
        let packets = std::mem::take(&mut s.packets);
        let aa = self.interleave.aa as usize;
        for (k, samples) in packets.chunks(aa).enumerate() {
            for lane in 0..8 {
                let shading_sample = self.shading_sample(samples[0].seeds[lane]);
                let p = &samples[shading_sample];
                let Some(first) = p.hit(lane) else {
                    self.shade_samples(samples, lane, s);
                    continue;
                };
                let surface = self.scene.surface(first);
                // Hits of one triangle lie on one surface; others are looked at closer.
                let whole_pixel = samples.iter().all(|q| {
                    q.hit(lane).is_some_and(|h| {
                        (h.instance, h.prim) == (first.instance, first.prim)
                            || same_surface(&surface, first.t, &self.scene.surface(h))
                    })
                });
                if !whole_pixel {
                    self.shade_samples(samples, lane, s);
                    continue;
                }
                let state = PathState {
                    pixel: p.pixels[lane],
                    sample: shading_sample as u32,
                    coverage: aa as u32,
                    path: CAMERA_PATH,
                    throughput: Vec3::ONE,
                    root: 0,
                    depth: 0.0,
                    bounces: 0,
                };
                let sample_origins = (aa > 1 && !self.vpls.lights().is_empty()).then(|| {
                    let at = s.sample_origins.len() as u32;
                    let accel = self.scene.accel();
                    s.sample_origins
                        .extend(samples.iter().map(|p| p.hits[lane]).map(|h| accel.hit_position(&h)));
                    at
                });
                let packets = (k * aa) as u32;
                let whole_pixel = Some(WholePixel { packets, lane: lane as u32, sample_origins });
                self.queue(PendingHit { state, dir: p.dirs[lane], t: first.t, surface, whole_pixel }, s);
            }
        }
        self.shade_queued(s);
        // Mirrors and glass show what lies behind them, which the samples must resolve as
        // they resolve the pixel's own edges: such pixels are shaded again, sample by sample.
        let split = std::mem::take(&mut s.split);
        for w in &split {
            let at = w.packets as usize;
            self.shade_samples(&packets[at..at + aa], w.lane as usize, s);
        }
        s.split = split;
        s.split.clear();
        self.shade_queued(s);
        s.packets = packets;
    }

    /// The sample that stands for the pixel of sequence seed `pixel_seed` if all its samples
    /// see one surface: one of them chosen at random per pixel and frame. Each sample is a
    /// uniformly random point in the pixel, but a fixed choice j would take the points f·N + j
    /// of the pixel's sequence in frames f = 0, 1, …, and a (0,2)-sequence puts every N-th
    /// point into one stripe of the pixel: accumulated frames would integrate that stripe.
    pub(super) fn shading_sample(&self, pixel_seed: u32) -> usize {
        let aa = self.interleave.aa;
        if aa == 1 {
            return 0;
        }
        (hash_combine(pixel_seed, self.sequence.first) % aa) as usize
    }

    /// Queues the hit of `lane` of each sample's packet in `samples` on its own.
    pub(super) fn shade_samples(&self, samples: &[PrimaryPacket], lane: usize, s: &mut TileScratch) {
        for (sample, p) in samples.iter().enumerate() {
            if p.bits & (1 << lane) != 0 {
                let state = PathState {
                    pixel: p.pixels[lane],
                    sample: sample as u32,
                    coverage: 1,
                    path: CAMERA_PATH,
                    throughput: Vec3::ONE,
                    root: 0,
                    depth: 0.0,
                    bounces: 0,
                };
                self.queue_hit(p.dirs[lane], &p.hits[lane], state, s);
            }
        }
    }
}

/// Largest angle between the geometric normals of samples that count as one surface: the
/// cosine. A pixel across a crease sharper than about 11° keeps its samples apart.
const SAME_SURFACE_MIN_COS: f32 = 0.98;

/// Largest distance of a sample's hit from the plane of another's, relative to the distance
/// from the camera, for the two to count as one surface (a step in depth keeps them apart).
const SAME_SURFACE_PLANE_DISTANCE: f32 = 0.01;

/// Whether the camera-ray hit `b` lies on the surface of `a` (reached at distance `t`): same
/// material, geometric normals within [`SAME_SURFACE_MIN_COS`] and `b` on the plane of `a`
/// within [`SAME_SURFACE_PLANE_DISTANCE`]. Samples of a pixel that all lie on one surface are
/// shaded and lit once (anti-aliasing at the cost of primary rays, paper 3.3).
fn same_surface(a: &SurfacePoint, t: f32, b: &SurfacePoint) -> bool {
    a.material == b.material
        && a.geometric_normal.dot(b.geometric_normal) >= SAME_SURFACE_MIN_COS
        && a.geometric_normal.dot(b.position - a.position).abs() <= SAME_SURFACE_PLANE_DISTANCE * t
}
