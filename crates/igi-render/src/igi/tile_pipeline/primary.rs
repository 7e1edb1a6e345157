//! Steps 1 and 2 of the tile pipeline ([`super`]): the camera rays of a region as 8-ray
//! packets of neighbouring pixels, and the shading of their hits set by set, once per pixel
//! whose samples see one surface (paper 3.3).

use super::{CAMERA_PATH, CameraSamples, PathState, PendingHit, TilePipeline, TileScratch, WholePixel};
use crate::igi::packet::unpack_hits;
use crate::image::pixel_rect::PixelRect;
use crate::image::stats::RayCounts;
use crate::prepared::SurfacePoint;
use crate::sampling::{Sobol2, hash_combine, pixel_seed};
use glam::Vec3;
use igi_bvh::RayPacket8;
use igi_simd::{F32x8, M32x8, Vec3x8};

/// Width and height in pixels of a camera packet's block.
const BLOCK: (u32, u32) = (4, 2);

impl TilePipeline<'_> {
    /// Step 1: the camera rays of every anti-aliasing sample of every pixel of `region`, as
    /// 8-ray packets of blocks of 4×2 neighbouring pixels, their directions and hits kept per
    /// pixel and sample ([`CameraSamples`]) for the fine sets' shading; the sky seen where they
    /// miss. The pixels of one fine set lie n apart, so packets of one set's pixels (paper
    /// Figure 2) would spread n times as wide and m times as tall, and cost more to traverse
    /// (ARCHITECTURE.md, "Camera rays of neighbouring pixels"). The blocks lie on the image's
    /// grid, and every pixel of a block inside the image is traced (those outside the region
    /// too, their hits dropped), so a ray's packet and its active lanes do not depend on the
    /// tile or on the apron: its hit is the same whoever renders it, even between nearly
    /// coincident surfaces (ARCHITECTURE.md, "Known: closest hits between nearly coincident
    /// surfaces depend on the traversal order"). `s.emitted` must be zero for the region.
    pub(super) fn trace_camera(&self, region: &PixelRect, s: &mut TileScratch, rays: &mut RayCounts) {
        let accel = self.scene.accel();
        let aa = self.interleave.aa;
        s.camera.reset(region.pixel_count(), aa as usize);
        let origin = Vec3x8::splat(self.camera.origin.to_array());
        let sky = self.scene.environment().is_some();
        let (bw, bh) = BLOCK;
        for y0 in (region.y0 - region.y0 % bh..region.y1).step_by(bh as usize) {
            for x0 in (region.x0 - region.x0 % bw..region.x1).step_by(bw as usize) {
                let at = |i: u32| (x0 + i % bw, y0 + i / bw);
                let in_image = |i: u32| at(i).0 < self.size.0 && at(i).1 < self.size.1;
                let traced_lanes = (0..8).filter(|&i| in_image(i)).fold(0u32, |bits, i| bits | 1 << i);
                // Lanes outside the image repeat the first pixel, so every lane holds a finite
                // ray; they take no part.
                let lane = |i: usize| if in_image(i as u32) { at(i as u32) } else { (x0, y0) };
                let (x, y): ([u32; 8], [u32; 8]) =
                    (std::array::from_fn(|i| lane(i).0), std::array::from_fn(|i| lane(i).1));
                let sequences =
                    std::array::from_fn(|i| Sobol2::new(pixel_seed(x[i], y[i], self.sequence.seed)));
                // The lanes whose pixels lie in the region, with their pixels' indices there.
                let (mut kept, mut kept_count) = ([(0, 0); 8], 0);
                for i in (0..8).filter(|&i| traced_lanes & (1 << i) != 0 && region.contains(x[i], y[i])) {
                    kept[kept_count] = (i, region.index(x[i], y[i]));
                    kept_count += 1;
                }
                for sample in 0..aa {
                    let index = self.sequence.first + sample;
                    let offsets = self.interleave.sample_offsets(index, &sequences, self.pixel_centres);
                    let dir = self.camera.directions_at8(x, y, offsets.map(|o| o.0), offsets.map(|o| o.1));
                    let packet =
                        RayPacket8 { origin, dir, tnear: F32x8::ZERO, tfar: F32x8::splat(f32::INFINITY) };
                    // Lanes that miss come back as misses.
                    let hits = unpack_hits(&accel.intersect8(&packet, M32x8::from_bitmask(traced_lanes)));
                    for &(lane, pixel) in &kept[..kept_count] {
                        let d = Vec3::from(dir.lane(lane));
                        s.camera.set(pixel, sample as usize, hits[lane], d);
                        if sky && !hits[lane].is_hit() {
                            s.emitted[pixel * aa as usize + sample as usize] += self.scene.background(d);
                        }
                    }
                }
                rays.primary += u64::from(traced_lanes.count_ones() * aa);
            }
        }
    }

    /// Step 2: the surface shaders of the camera rays' hits at fine set `fine`'s pixels: once
    /// per pixel whose samples all hit one surface ([`same_surface`]), else once per sample
    /// that hit something. The pixels go block by block of the set's sub-grid (paper Figure 2),
    /// the order their shading points are lit in, which keeps neighbours in one shadow packet
    /// ([`Receivers::push`](crate::igi::vpl_lighting::Receivers::push)).
    pub(super) fn shade_primary(&self, region: &PixelRect, fine: u32, s: &mut TileScratch) {
        let camera = std::mem::take(&mut s.camera);
        let aa = self.interleave.aa as usize;
        self.interleave.set_blocks(region, fine, |lanes| {
            for &(x, y) in lanes {
                let pixel = region.index(x, y) as u32;
                let (dirs, hits) = camera.samples(pixel);
                let shading_sample = self.shading_sample(pixel_seed(x, y, self.sequence.seed));
                let first = &hits[shading_sample];
                if !first.is_hit() {
                    self.shade_samples(&camera, pixel, s);
                    continue;
                }
                let surface = self.scene.surface(first);
                // Hits of one triangle lie on one surface; others are looked at closer.
                let whole_pixel = hits.iter().all(|h| {
                    h.is_hit()
                        && ((h.instance, h.prim) == (first.instance, first.prim)
                            || same_surface(&surface, first.t, &self.scene.surface(h)))
                });
                if !whole_pixel {
                    self.shade_samples(&camera, pixel, s);
                    continue;
                }
                let state = PathState {
                    pixel,
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
                    s.sample_origins.extend(hits.iter().map(|h| accel.hit_position(h)));
                    at
                });
                let whole_pixel = Some(WholePixel { pixel, sample_origins });
                let (dir, t) = (dirs[shading_sample], first.t);
                self.queue(PendingHit { state, dir, t, surface, whole_pixel }, s);
            }
        });
        self.shade_queued(s);
        // Mirrors and glass show what lies behind them, which the samples must resolve as
        // they resolve the pixel's own edges: such pixels are shaded again, sample by sample.
        let split = std::mem::take(&mut s.split);
        for w in &split {
            self.shade_samples(&camera, w.pixel, s);
        }
        s.split = split;
        s.split.clear();
        self.shade_queued(s);
        s.camera = camera;
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

    /// Queues the hit of each sample of region pixel `pixel` on its own.
    pub(super) fn shade_samples(&self, camera: &CameraSamples, pixel: u32, s: &mut TileScratch) {
        let (dirs, hits) = camera.samples(pixel);
        for (sample, (hit, &dir)) in hits.iter().zip(dirs).enumerate() {
            if hit.is_hit() {
                let state = PathState {
                    pixel,
                    sample: sample as u32,
                    coverage: 1,
                    path: CAMERA_PATH,
                    throughput: Vec3::ONE,
                    root: 0,
                    depth: 0.0,
                    bounces: 0,
                };
                self.queue_hit(dir, hit, state, s);
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
