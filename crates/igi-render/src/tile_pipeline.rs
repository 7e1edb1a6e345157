//! The streaming tile pipeline of instant global illumination (paper 3.1.2; ARCHITECTURE.md,
//! "Data flow"): one tile, breadth first. For each VPL set s:
//!
//! 1. **primary**: the camera rays of all N samples of the set's pixels in the tile and its
//!    apron, as 8-ray packets of neighbouring set pixels (paper Figure 2);
//! 2. **shading**: the surface shaders of the hits (paper 3.2: eight consecutive hits of one
//!    material per call; constant materials skip the call), the sky behind misses, emission
//!    seen directly, and a shading point for every hit with a diffuse or glossy lobe. A pixel
//!    whose samples all see one surface is shaded once, as one point that stands for all N
//!    samples ([`PathState::coverage`]; ARCHITECTURE.md, "Anti-aliasing costs primary rays");
//!    the other pixels are shaded per sample;
//! 3. **specular**: mirror and glass lobes continue as reflection and refraction rays, traced
//!    as streams of packets bounce by bounce up to `specular_bounces`; their hits are shaded the
//!    same way and become shading points of the same set, weighted by the chain's throughput;
//! 4. **shadow**: for each light, sky VPL and VPL of the set, the shadow packets of its
//!    shading points (a whole pixel's point by every VPL, sample j's own point by VPLs j,
//!    j + N, …), and the BRDF shaders accumulating the diffuse radiance D = E/π and the
//!    glossy radiance G ([`crate::vpl_lighting`]).
//!
//! Specular rays run before the shadow phase (not after it, as in a Whitted tracer) so that
//! every shading point of the set, seen directly or through glass, is lit in one pass over
//! the VPLs while their data is hot. Then the tile is filtered ([`crate::discontinuity`]) and
//! composed: pixel = 1/N Σ_samples (emission and sky seen + Σ_points coverage · throughput ·
//! (ρ_d · D̃ + ρ_s · G̃ + L_l)), where D̃ and G̃ are the filtered VPL terms and L_l the light reflected from
//! point, spot and directional lights, which the filter leaves alone so their shadow edges stay
//! sharp.
//!
//! Every value depends only on the scene, the [`FrameState`] and the pixel, and the apron
//! pixels are computed exactly as in their own tile, so a tiled image equals an untiled one.

use crate::camera::PinholeCamera;
use crate::discontinuity::{DiscontinuityBuffer, FilterSample, Filtered};
use crate::frame::{FilterSettings, FrameState, SequenceSpan};
use crate::frame_image::{PixelFormat, Pixels};
use crate::interleave::Interleave;
use crate::packet::{Packet8, unpack_hits};
use crate::pixel_rect::PixelRect;
use crate::prepared::{PreparedScene, SurfacePoint};
use crate::sampling::{hash_combine, pixel_seed, sobol4};
use crate::stats::{Phase, PhaseTimes, RayCounts};
use crate::tile::Tile;
use crate::tonemap::{LuminanceStats, ToneMapper};
use crate::vpl::VplSets;
use crate::vpl_lighting::{GlossyLobe, Receivers};
use glam::Vec3;
use igi_bvh::{Hit, Ray, RayPacket8, offset_ray_origin};
use igi_shade::BrdfParams;
use igi_shade::brdf::cosine_hemisphere;
use igi_shade::brdf::dielectric::{Interface, glass_exit_side, reflect, refract};
use igi_simd::{F32x8, M32x8, Vec3x8};
use std::time::Instant;

/// Specular chains carrying less than this (per channel, relative to the camera ray) end: glass
/// splits every ray in two, and without a floor the branches of weak internal reflections
/// would grow as 2^bounces. Two glass reflections (0.04² at normal incidence) still pass.
const MIN_SPECULAR_THROUGHPUT: f32 = 1e-3;

/// Largest number of rays in one bounce of a set's specular stream (a memory bound for
/// pathological scenes; ordinary mirrors and glass stay far below it).
const MAX_SPECULAR_STREAM: usize = 1 << 18;

/// Path-code bit of the shading points found by the clamp's bias compensation
/// ([`TilePipeline::compensate`]): their light joins the D of their camera path's point, and
/// only the camera paths' own points go through the filter.
const COMPENSATION: u32 = 1 << 31;

/// Levels of the bias compensation: the points it finds are compensated in turn, since they lie
/// where the clamp removes most (creases, contacts). Each level carries at most ρ·w of the
/// previous one; a fourth would change the Cornell box by far less than its noise.
const COMPENSATION_LEVELS: u32 = 3;

/// A point of the bias compensation is lit by every this-many-th VPL of its camera sample's
/// share ([`TilePipeline::vpl_share`]). On the conference room (`scenes/conference.toml`, one
/// compensated frame) 4 instead of 1 takes a frame from 746 to 657 ms and its mean FLIP against
/// the converged image from 0.129 to 0.131.
const COMPENSATION_VPL_STRIDE: u32 = 4;

/// A finished tile: its pixels and what it cost.
#[derive(Clone, Debug)]
pub struct TileOutput {
    /// The tile.
    pub tile: Tile,
    /// Its pixels in the frame's [`FrameState::pixels`] format: linear radiance, or tone-mapped
    /// with the frame's [`FrameState::tone_map`] and sRGB-encoded, what a display shows (and
    /// what a render node sends while the view moves, paper 3.4).
    pub pixels: Pixels,
    /// Luminance statistics of the pixels (for the next frame's tone mapping, paper 3.4).
    pub stats: LuminanceStats,
    /// Rays traced.
    pub rays: RayCounts,
    /// Time per phase.
    pub times: PhaseTimes,
}

/// Where a camera path stands: which sample it belongs to and what it carries.
#[derive(Clone, Copy, Debug)]
struct PathState {
    /// Pixel index in the region.
    pixel: u32,
    /// Anti-aliasing sample.
    sample: u32,
    /// Anti-aliasing samples the path stands for: all N of its pixel where they all saw one
    /// surface (the pixel is shaded once, lit by its whole VPL set), else 1 (the sample is
    /// lit by its share of the set; [`crate::interleave`]).
    coverage: u32,
    /// Specular chain code: 1 for the camera ray, then one bit per bounce (0 reflection,
    /// 1 refraction) below a leading 1.
    path: u32,
    /// Product of the reflectances along the chain; for a point of the bias compensation, the
    /// weight of its light in the D of the camera path's point it compensates (`root`).
    throughput: Vec3,
    /// For a point of the bias compensation: the index of the camera path's point whose D its
    /// light joins ([`TilePipeline::compensate`]); unused otherwise.
    root: u32,
    /// Distance travelled before this ray.
    depth: f32,
    /// Specular bounces so far.
    bounces: u32,
}

/// A point with a diffuse or glossy lobe seen by a camera path.
#[derive(Clone, Copy, Debug)]
struct ShadingPoint {
    state: PathState,
    origin: Vec3,
    ns: Vec3,
    ng: Vec3,
    /// Distance from the camera along the path (the filter's depth).
    depth: f32,
    material: u32,
    /// Diffuse reflectance ρ_d.
    albedo: Vec3,
    /// Glossy reflectance ρ_s (F₀ for GGX) and the glossy lobe toward the camera.
    glossy: Vec3,
    lobe: Option<GlossyLobe>,
    /// Diffuse radiance D = E/π from the VPLs (filtered): what a white Lambertian surface
    /// here reflects, so that ρ_d·D is the diffuse term.
    diffuse_radiance: Vec3,
    /// Glossy radiance G = Σ E · lobe from the VPLs (filtered): what the glossy lobe reflects
    /// per unit ρ_s, so that ρ_s·G is the glossy term; and the Schlick radiance S of a GGX
    /// lobe, reflected as it is ([`crate::vpl_lighting`]).
    glossy_radiance: [Vec3; 2],
    /// Radiance reflected from point, spot and directional lights: exact, so never filtered
    /// (their shadow edges stay sharp).
    exact: Vec3,
    /// The light the bias compensation found for this camera path's point, as a share of D:
    /// it is filtered with D ([`TilePipeline::compensate`]).
    compensation: Vec3,
    /// Where a camera ray's point stands for its whole pixel in a scene with exact lights:
    /// the first of the N shadow-ray origins at the positions its samples hit, in
    /// [`TileScratch::sample_origins`], from which the exact lights are seen, so their
    /// shadow edges stay anti-aliased.
    sample_origins: Option<u32>,
}

/// A hit waiting for its surface shader: the hits of one step are shaded together, grouped
/// by material (paper 3.2: surface shaders run over all hits before the VPL loop).
#[derive(Clone, Copy, Debug)]
struct PendingHit {
    state: PathState,
    dir: Vec3,
    t: f32,
    surface: SurfacePoint,
    /// For a camera ray's hit that stands for its whole pixel: where the pixel's samples are.
    whole_pixel: Option<WholePixel>,
}

/// The samples of a pixel shaded once ([`PathState::coverage`]).
#[derive(Clone, Copy, Debug)]
struct WholePixel {
    /// Index of the pixel's first packet in [`TileScratch::packets`] (one per sample).
    packets: u32,
    /// The pixel's lane in them.
    lane: u32,
    /// See [`ShadingPoint::sample_origins`] (the positions are lifted off the surface once its
    /// side is known).
    sample_origins: Option<u32>,
}

/// A traced primary packet of one anti-aliasing sample: directions, hits and pixels per lane,
/// occupied lanes.
#[derive(Clone, Copy, Debug)]
struct PrimaryPacket {
    dirs: [Vec3; 8],
    /// The pixels' sequence seeds ([`pixel_seed`]).
    seeds: [u32; 8],
    hits: [Hit; 8],
    pixels: [u32; 8],
    bits: u32,
}

impl PrimaryPacket {
    /// The hit of `lane`, if its ray hit something.
    fn hit(&self, lane: usize) -> Option<&Hit> {
        (self.bits & (1 << lane) != 0).then(|| &self.hits[lane])
    }
}

/// A ray of the specular stream.
#[derive(Clone, Copy, Debug)]
struct SpecularRay {
    state: PathState,
    ray: Ray,
}

/// Per-thread scratch memory of the pipeline, reused from tile to tile.
#[derive(Debug, Default)]
pub struct TileScratch {
    emitted: Vec<Vec3>,
    points: Vec<ShadingPoint>,
    packets: Vec<PrimaryPacket>,
    pending: Vec<PendingHit>,
    stream: Vec<SpecularRay>,
    next_stream: Vec<SpecularRay>,
    receivers: Receivers,
    /// Shadow-ray origins of the samples of whole pixels ([`ShadingPoint::sample_origins`]).
    sample_origins: Vec<Vec3>,
    /// Whole pixels that turned out to have a mirror or glass lobe: shaded again per sample.
    split: Vec<WholePixel>,
    /// A fine set's shading points (set and lighting group, index) in the order they are lit.
    order: Vec<(u64, u32)>,
    /// The camera paths' own points (not the compensation's), which the filter sees.
    camera_points: Vec<u32>,
    filter_samples: Vec<FilterSample>,
    glossy_radiance: Vec<[Vec3; 2]>,
    filtered: Filtered,
    filter: DiscontinuityBuffer,
}

/// Renders tiles of one frame: the scene, the frame's VPLs and settings.
#[derive(Debug)]
pub struct TilePipeline<'a> {
    scene: &'a PreparedScene,
    vpls: &'a VplSets,
    interleave: Interleave,
    camera: PinholeCamera,
    sequence: SequenceSpan,
    /// One ray through each pixel centre (one sample per pixel, no reseeding).
    pixel_centres: bool,
    d_min2: f32,
    compensate_clamp: bool,
    filter: Option<FilterSettings>,
    specular_bounces: u32,
    size: (u32, u32),
    tone_map: ToneMapper,
    pixels: PixelFormat,
    /// Angle subtended by a pixel at the image centre: a ray cone's spread per unit distance,
    /// which sizes the texture footprint of a hit.
    pixel_angle: f32,
}

impl<'a> TilePipeline<'a> {
    /// The pipeline for `frame` of `scene` lit by `vpls` (generated for the same frame).
    pub fn new(scene: &'a PreparedScene, frame: &FrameState, vpls: &'a VplSets) -> Self {
        let s = &frame.settings;
        Self {
            scene,
            vpls,
            interleave: Interleave::of(s),
            camera: PinholeCamera::new(&frame.camera, s.width, s.height),
            sequence: frame.sequence(s.aa),
            pixel_centres: s.aa == 1 && !s.reseed_per_frame,
            d_min2: s.clamp * s.clamp,
            compensate_clamp: s.compensate_clamp,
            filter: s.filter,
            specular_bounces: s.specular_bounces,
            size: (s.width, s.height),
            tone_map: frame.tone_map,
            pixels: frame.pixels,
            pixel_angle: 2.0 * (0.5 * frame.camera.fov_y_deg.to_radians()).tan() / s.height.max(1) as f32,
        }
    }

    /// Renders `tile` (of an image of the frame's size).
    pub fn render_tile(&self, tile: Tile, scratch: &mut TileScratch) -> TileOutput {
        let il = self.interleave;
        let region = il.region(&tile, self.size.0, self.size.1);
        let aa = il.aa;
        scratch.emitted.clear();
        scratch.emitted.resize(region.pixel_count() * aa as usize, Vec3::ZERO);
        scratch.points.clear();
        scratch.sample_origins.clear();
        let mut rays = RayCounts::default();
        let mut times = PhaseTimes::default();
        let mut clock = Instant::now();

        for fine in 0..il.fine_sets() {
            let first = scratch.points.len();
            self.trace_primary(&region, fine, scratch, &mut rays);
            times.lap(Phase::Primary, &mut clock);
            self.shade_primary(scratch);
            times.lap(Phase::Shading, &mut clock);
            self.trace_specular(scratch, &mut rays);
            times.lap(Phase::Specular, &mut clock);
            if self.compensate_clamp && self.d_min2 > 0.0 {
                self.compensate(&region, first, scratch, &mut rays);
                times.lap(Phase::Compensation, &mut clock);
            }
            self.light(&region, fine, first, scratch, &mut rays);
            times.lap(Phase::Shadow, &mut clock);
        }

        let pixels = self.compose(&tile, &region, scratch);
        times.lap(Phase::Filter, &mut clock);
        let stats = LuminanceStats::of_pixels(&pixels);
        // Encoded here, while the tile is in cache, for either format.
        let mut srgb8 = vec![0u8; 3 * pixels.len()];
        self.tone_map.encode_pixels(&pixels, &mut srgb8);
        let pixels = match self.pixels {
            PixelFormat::Linear => Pixels::Linear { radiance: pixels, srgb8 },
            PixelFormat::Srgb8 => Pixels::Srgb8(srgb8),
        };
        times.lap(Phase::ToneMap, &mut clock);
        TileOutput { tile, pixels, stats, rays, times }
    }

    /// Step 1: the camera rays of every anti-aliasing sample of the pixels of fine set `fine`,
    /// packet by packet: the N packets of one group of pixels follow each other in `s.packets`.
    fn trace_primary(&self, region: &PixelRect, fine: u32, s: &mut TileScratch, rays: &mut RayCounts) {
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
            let occupied = (1u32 << lanes.len()) - 1;
            for sample in 0..aa {
                let offsets: [(f32, f32); 8] = std::array::from_fn(|i| {
                    self.interleave.sample_offset(self.sequence.first + sample, seeds[i], self.pixel_centres)
                });
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
    fn shade_primary(&self, s: &mut TileScratch) {
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
                    path: 1,
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
    fn shading_sample(&self, pixel_seed: u32) -> usize {
        let aa = self.interleave.aa;
        if aa == 1 {
            return 0;
        }
        (hash_combine(pixel_seed, self.sequence.first) % aa) as usize
    }

    /// Queues the hit of `lane` of each sample's packet in `samples` on its own.
    fn shade_samples(&self, samples: &[PrimaryPacket], lane: usize, s: &mut TileScratch) {
        for (sample, p) in samples.iter().enumerate() {
            if p.bits & (1 << lane) != 0 {
                let state = PathState {
                    pixel: p.pixels[lane],
                    sample: sample as u32,
                    coverage: 1,
                    path: 1,
                    throughput: Vec3::ONE,
                    root: 0,
                    depth: 0.0,
                    bounces: 0,
                };
                self.queue_hit(p.dirs[lane], &p.hits[lane], state, s);
            }
        }
    }

    /// Step 3: the specular stream, bounce by bounce: the rays queued by the previous step
    /// are traced as packets and shaded, which queues the next bounce.
    fn trace_specular(&self, s: &mut TileScratch, rays: &mut RayCounts) {
        let accel = self.scene.accel();
        loop {
            std::mem::swap(&mut s.stream, &mut s.next_stream);
            if s.stream.is_empty() {
                return;
            }
            let stream = std::mem::take(&mut s.stream);
            for chunk in stream.chunks(8) {
                let mut packet = Packet8::new();
                for (lane, r) in chunk.iter().enumerate() {
                    packet.set(lane, r.ray);
                }
                rays.specular += u64::from(packet.len());
                let traced = packet.intersect(accel);
                for (r, hit) in chunk.iter().zip(&traced.hits) {
                    if hit.is_hit() {
                        self.queue_hit(r.ray.dir, hit, r.state, s);
                    } else {
                        let sky =
                            r.state.coverage as f32 * r.state.throughput * self.scene.background(r.ray.dir);
                        s.emitted[(r.state.pixel * self.interleave.aa + r.state.sample) as usize] += sky;
                    }
                }
            }
            s.stream = stream;
            s.stream.clear();
            self.shade_queued(s);
        }
    }

    /// Queues `hit` of a ray in unit direction `dir` for [`TilePipeline::shade_queued`], or,
    /// where its material's parameters are the same at every hit (a constant material),
    /// scatters it at once.
    fn queue_hit(&self, dir: Vec3, hit: &Hit, state: PathState, s: &mut TileScratch) {
        let hit = PendingHit { state, dir, t: hit.t, surface: self.scene.surface(hit), whole_pixel: None };
        self.queue(hit, s);
    }

    /// Queues a hit whose surface is known (see [`TilePipeline::queue_hit`]).
    fn queue(&self, hit: PendingHit, s: &mut TileScratch) {
        match self.scene.uniform_shading(&hit.surface) {
            Some(params) => self.scatter(&hit, &params, s),
            None => s.pending.push(hit),
        }
    }

    /// Runs the surface shaders over the queued hits, up to eight consecutive hits of one
    /// material at a time, and turns each hit into what its BRDF asks for
    /// ([`TilePipeline::scatter`]). Hits stay in the order they were queued: neighbouring
    /// pixels, whose runs of one material are long, and which the shadow packets want
    /// together.
    fn shade_queued(&self, s: &mut TileScratch) {
        let pending = std::mem::take(&mut s.pending);
        let mut out = [BrdfParams::black(Vec3::Z); 8];
        let mut start = 0;
        while start < pending.len() {
            let material = pending[start].surface.material;
            let run = pending[start..].iter().take(8).take_while(|p| p.surface.material == material).count();
            let batch = &pending[start..start + run];
            let point = |lane: usize| {
                let p = &batch[lane];
                (&p.surface, (p.state.depth + p.t) * self.pixel_angle)
            };
            self.scene.shade8(material, run, point, &mut out);
            for (p, b) in batch.iter().zip(&out) {
                self.scatter(p, b, s);
            }
            start += run;
        }
        s.pending = pending;
        s.pending.clear();
    }

    /// What a shaded hit becomes: emission seen, a shading point for its diffuse and glossy
    /// lobes, and the reflection and refraction rays of its mirror and glass lobes (into the
    /// next stream).
    fn scatter(&self, hit: &PendingHit, b: &BrdfParams, s: &mut TileScratch) {
        let (sp, dir, state) = (&hit.surface, hit.dir, hit.state);
        let front = sp.geometric_normal.dot(dir) < 0.0;
        let (ng, ns) = if front {
            (sp.geometric_normal, b.shading_normal)
        } else {
            (-sp.geometric_normal, -b.shading_normal)
        };
        if front && b.emission.max_element() > 0.0 {
            if state.path & COMPENSATION != 0 {
                s.points[state.root as usize].compensation += state.throughput * b.emission;
            } else {
                s.emitted[(state.pixel * self.interleave.aa + state.sample) as usize] +=
                    state.coverage as f32 * state.throughput * b.emission;
            }
        }
        let depth = state.depth + hit.t;
        if let Some(w) = hit.whole_pixel.filter(|_| b.mirror.max_element() > 0.0 || b.glass > 0.0) {
            s.split.push(w);
            return;
        }
        let sample_origins = hit.whole_pixel.and_then(|w| w.sample_origins);
        if let Some(at) = sample_origins {
            let at = at as usize;
            for o in &mut s.sample_origins[at..at + self.interleave.aa as usize] {
                *o = offset_ray_origin(*o, ng);
            }
        }
        if b.has_non_delta() {
            s.points.push(ShadingPoint {
                state,
                origin: offset_ray_origin(sp.position, ng),
                ns,
                ng,
                depth,
                material: sp.material,
                albedo: b.diffuse,
                glossy: b.glossy,
                lobe: GlossyLobe::new(b, ns, -dir),
                diffuse_radiance: Vec3::ZERO,
                glossy_radiance: [Vec3::ZERO; 2],
                exact: Vec3::ZERO,
                compensation: Vec3::ZERO,
                sample_origins,
            });
        }
        if state.bounces >= self.specular_bounces {
            return;
        }
        if b.mirror.max_element() > 0.0 {
            // About the shading normal; a reflection that an interpolated normal sends
            // below the surface ends the path (as in the VPL walk and the path tracer).
            let dir = reflect(dir, ns);
            if dir.dot(ng) > 0.0 {
                self.continue_path(state, 0, b.mirror, depth, offset_ray_origin(sp.position, ng), dir, s);
            }
        }
        if b.glass > 0.0 {
            // About the shading normal; a continuation that a bent normal sends to the
            // wrong side of the geometric surface ends (as in the walk and path tracer).
            let interface = Interface::new(dir, b.shading_normal, b.ior);
            let n = interface.normal;
            let f = interface.reflectance;
            let ng = sp.geometric_normal;
            let reflected = reflect(dir, n);
            if let Some(side) = glass_exit_side(dir, reflected, ng, true) {
                let origin = offset_ray_origin(sp.position, side);
                self.continue_path(state, 0, Vec3::splat(b.glass * f), depth, origin, reflected, s);
            }
            let refracted =
                refract(dir, n, interface.eta).and_then(|t| Some((t, glass_exit_side(dir, t, ng, false)?)));
            if let Some((t, side)) = refracted {
                let origin = offset_ray_origin(sp.position, side);
                self.continue_path(state, 1, Vec3::splat(b.glass * (1.0 - f)), depth, origin, t, s);
            }
        }
    }

    /// Queues the continuation of a camera path through a specular bounce.
    #[allow(clippy::too_many_arguments)]
    fn continue_path(
        &self,
        state: PathState,
        branch: u32,
        weight: Vec3,
        depth: f32,
        origin: Vec3,
        dir: Vec3,
        s: &mut TileScratch,
    ) {
        let throughput = state.throughput * weight;
        if throughput.max_element() < MIN_SPECULAR_THROUGHPUT
            || !dir.is_finite()
            || s.next_stream.len() >= MAX_SPECULAR_STREAM
        {
            return;
        }
        s.next_stream.push(SpecularRay {
            state: PathState {
                path: state.path << 1 | branch,
                throughput,
                depth,
                bounces: state.bounces + 1,
                ..state
            },
            ray: Ray::new(origin, dir),
        });
    }

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
    fn compensate(&self, region: &PixelRect, first: usize, s: &mut TileScratch, rays: &mut RayCounts) {
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

    /// Step 4: the lights and the VPLs on the shading points of fine set `fine` from index
    /// `first` on, each point lit by the set of its pixel's coarse group
    /// ([`Interleave::set`]), with its share of the set's VPLs ([`TilePipeline::vpl_share`]):
    /// each pixel uses each VPL of its set once. The exact lights light every point with
    /// weight 1.
    fn light(&self, region: &PixelRect, fine: u32, first: usize, s: &mut TileScratch, rays: &mut RayCounts) {
        let TileScratch { points, receivers, order, sample_origins, .. } = s;
        // The lighting group of a point: its set, then the share of the set's VPLs that
        // lights it ([`TilePipeline::vpl_share`]).
        let group = |p: &ShadingPoint| {
            let (x, y) = region.pixel(p.state.pixel);
            let (skip, step) = self.vpl_share(&p.state, x, y);
            u64::from(self.interleave.set(fine, x, y)) << 32 | u64::from(step) << 16 | u64::from(skip)
        };
        order.clear();
        order.extend((first..points.len()).map(|i| (group(&points[i]), i as u32)));
        // Stable: each group keeps the pixel order its shadow packets want.
        order.sort_by_key(|&(g, _)| g);
        let accel = self.scene.accel();
        for run in order.chunk_by(|a, b| a.0 == b.0) {
            let set = (run[0].0 >> 32) as u32;
            let (skip, step) = ((run[0].0 & 0xffff) as usize, (run[0].0 >> 16 & 0xffff) as usize);
            let weight = step as f32;
            if !self.vpls.lights().is_empty() {
                self.light_exactly(points, run, sample_origins, receivers, rays);
            }
            receivers.clear();
            for &(_, i) in run {
                let p = &points[i as usize];
                receivers.push(p.origin, p.ns, p.ng, p.lobe);
            }
            receivers.regularise();
            let sky = self.vpls.sky(set).iter().skip(skip).step_by(step);
            receivers.add_lights(accel, sky, weight, rays);
            let vpls = self.vpls.set(set).iter().skip(skip).step_by(step);
            receivers.add_vpls(accel, vpls, weight, self.d_min2, rays);
            for (k, &(_, i)) in run.iter().enumerate() {
                let p = &mut points[i as usize];
                let (d, g, schlick) = receivers.radiance(k);
                (p.diffuse_radiance, p.glossy_radiance) = (d, [g, schlick]);
            }
        }
    }

    /// The share of its set's VPLs that lights a point of pixel (x, y): the VPLs `skip`,
    /// `skip + step`, `skip + 2·step`, … each weighted by `step`. A point that stands for its
    /// whole pixel takes all of them, a point of sample j of an edge pixel every N-th from j
    /// (paper 3.3). A point of the bias compensation takes every
    /// [`COMPENSATION_VPL_STRIDE`]-th of its camera sample's share, starting at an offset
    /// drawn per pixel and frame: its light is one short ray's estimate that the filter
    /// averages over the neighbours anyway, and lighting it with every VPL would cost as
    /// many shadow rays as the camera's own point.
    fn vpl_share(&self, state: &PathState, x: u32, y: u32) -> (u32, u32) {
        let aa = self.interleave.aa;
        let (skip, step) = if state.coverage == aa { (0, 1) } else { (state.sample, aa) };
        if state.path & COMPENSATION == 0 {
            return (skip, step);
        }
        let offset = hash_combine(pixel_seed(x, y, self.sequence.seed), !self.sequence.first)
            % COMPENSATION_VPL_STRIDE;
        (skip + step * offset, step * COMPENSATION_VPL_STRIDE)
    }

    /// The light of the exact lights (point, spot, directional) reflected at the points
    /// `run` of `points`; a whole pixel's point is lit from each of its samples' positions
    /// ([`ShadingPoint::sample_origins`]) and takes their mean, so a hard shadow's edge across
    /// the pixel stays anti-aliased.
    fn light_exactly(
        &self,
        points: &mut [ShadingPoint],
        run: &[(u64, u32)],
        sample_origins: &[Vec3],
        receivers: &mut Receivers,
        rays: &mut RayCounts,
    ) {
        let aa = self.interleave.aa as usize;
        let origins = |p: &ShadingPoint| match p.sample_origins {
            Some(at) => at as usize..at as usize + aa,
            None => 0..1,
        };
        let origin = |p: &ShadingPoint, k: usize| match p.sample_origins {
            Some(_) => sample_origins[k],
            None => p.origin,
        };
        receivers.clear();
        for &(_, i) in run {
            let p = &points[i as usize];
            for k in origins(p) {
                receivers.push(origin(p, k), p.ns, p.ng, p.lobe);
            }
        }
        receivers.add_lights(self.scene.accel(), self.vpls.lights().iter(), 1.0, rays);
        let mut k = 0;
        for &(_, i) in run {
            let p = &mut points[i as usize];
            let n = origins(p).len();
            let mut sum = Vec3::ZERO;
            for _ in 0..n {
                let (d, g, schlick) = receivers.radiance(k);
                sum += p.albedo * d + p.glossy * g + schlick;
                k += 1;
            }
            p.exact = sum / n as f32;
        }
    }

    /// Filters the diffuse and glossy radiance and composes the tile's pixels.
    fn compose(&self, tile: &Tile, region: &PixelRect, s: &mut TileScratch) -> Vec<Vec3> {
        let TileScratch {
            points,
            emitted,
            camera_points,
            filter_samples,
            glossy_radiance,
            filtered,
            filter,
            ..
        } = s;
        // The light each compensation point reflects toward its parent joins the D of its camera
        // path's point, and is filtered with it: one short ray per pixel is as noisy as one VPL
        // set (more, where it finds a sunlit surface), and left unfiltered it leaves single
        // bright pixels near creases and contacts.
        for i in 0..points.len() {
            let p = points[i];
            if p.state.path & COMPENSATION != 0 {
                let [g, schlick] = p.glossy_radiance;
                let reflected = p.albedo * p.diffuse_radiance + p.glossy * g + schlick + p.exact;
                points[p.state.root as usize].compensation += p.state.throughput * reflected;
            }
        }
        // The compensation points' light is in their roots' D now: only the camera paths' own
        // points are filtered and composed.
        camera_points.clear();
        camera_points
            .extend((0..points.len() as u32).filter(|&i| points[i as usize].state.path & COMPENSATION == 0));
        let camera = || camera_points.iter().map(|&i| &points[i as usize]);
        // Most tiles have no glossy point; their glossy term stays out of the filter.
        glossy_radiance.clear();
        if camera().any(|p| p.glossy_radiance != [Vec3::ZERO; 2]) {
            glossy_radiance.extend(camera().map(|p| p.glossy_radiance));
        }
        match &self.filter {
            Some(settings) => {
                filter_samples.clear();
                filter_samples.extend(camera().map(|p| FilterSample {
                    pixel: p.state.pixel,
                    sample: p.state.sample,
                    whole_pixel: p.state.coverage == self.interleave.aa,
                    path: p.state.path,
                    normal: p.ns,
                    depth: p.depth,
                    material: p.material,
                    diffuse_radiance: p.diffuse_radiance + p.compensation,
                }));
                let input = (&filter_samples[..], &glossy_radiance[..]);
                filter.filter(region, tile, &self.interleave, settings, input, filtered);
            }
            None => {
                filtered.diffuse_radiance.clear();
                filtered.diffuse_radiance.extend(camera().map(|p| p.diffuse_radiance + p.compensation));
                filtered.glossy_radiance.clear();
                filtered.glossy_radiance.extend_from_slice(glossy_radiance);
            }
        }

        let aa = self.interleave.aa as usize;
        let mut pixels = vec![Vec3::ZERO; tile.rect.pixel_count()];
        let tile_index = |pixel: u32| {
            let (x, y) = region.pixel(pixel);
            tile.rect.contains(x, y).then(|| tile.rect.index(x, y))
        };
        for (i, (p, d)) in camera().zip(&filtered.diffuse_radiance).enumerate() {
            if let Some(pixel) = tile_index(p.state.pixel) {
                let g = filtered.glossy_radiance.get(i).map_or(Vec3::ZERO, |[g, s]| p.glossy * *g + *s);
                pixels[pixel] += p.state.coverage as f32 * p.state.throughput * (p.albedo * *d + g + p.exact);
            }
        }
        let scale = 1.0 / aa as f32;
        for y in tile.rect.y0..tile.rect.y1 {
            for x in tile.rect.x0..tile.rect.x1 {
                let r = region.index(x, y);
                let e: Vec3 = emitted[r * aa..(r + 1) * aa].iter().sum();
                let i = tile.rect.index(x, y);
                pixels[i] = (pixels[i] + e) * scale;
            }
        }
        pixels
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
