//! The streaming tile pipeline of instant global illumination (paper 3.1.2; ARCHITECTURE.md,
//! "Data flow"): one tile, breadth first. For each interleave group (VPL set s, sample j):
//!
//! 1. **primary**: the camera rays of the set's pixels in the tile and its apron, as 8-ray
//!    packets of neighbouring set pixels (paper Figure 2);
//! 2. **shading**: the surface shaders of all hits (paper 3.2: eight consecutive hits of one
//!    material per call; constant materials skip the call), the sky behind misses, emission
//!    seen directly, and a shading point for every hit with a diffuse or glossy lobe;
//! 3. **specular**: mirror and glass lobes continue as reflection and refraction rays, traced
//!    as streams of packets bounce by bounce up to `specular_bounces`; their hits are shaded the
//!    same way and become shading points of the same group, weighted by the chain's throughput;
//! 4. **shadow**: for each light, sky VPL and VPL of the group, the shadow packets of all
//!    shading points, and the BRDF shaders accumulating the diffuse radiance D = E/π and the
//!    glossy radiance G ([`crate::vpl_lighting`]).
//!
//! Specular rays run before the shadow phase (not after it, as in a Whitted tracer) so that
//! every shading point of the group, seen directly or through glass, is lit in one pass over
//! the VPLs while their data is hot. Then the tile is filtered ([`crate::discontinuity`]) and
//! composed: pixel = 1/N Σ_samples (emission and sky seen + Σ_points throughput · (ρ_d · D̃ +
//! ρ_s · G̃ + L_l)), where D̃ and G̃ are the filtered VPL terms and L_l the light reflected from
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
use crate::packet::Packet8;
use crate::pixel_rect::PixelRect;
use crate::prepared::{PreparedScene, SurfacePoint};
use crate::sampling::{pixel_seed, sobol4};
use crate::stats::{Phase, PhaseTimes, RayCounts};
use crate::tile::Tile;
use crate::tonemap::{LuminanceStats, ToneMapper};
use crate::vpl::VplSets;
use crate::vpl_lighting::{GlossyLobe, Receivers};
use glam::Vec3;
use igi_bvh::{Hit, Ray, offset_ray_origin};
use igi_shade::BrdfParams;
use igi_shade::brdf::cosine_hemisphere;
use igi_shade::brdf::dielectric::{Interface, glass_exit_side, reflect, refract};
use std::time::Instant;

/// Specular chains carrying less than this (per channel, relative to the camera ray) end: glass
/// splits every ray in two, and without a floor the branches of weak internal reflections
/// would grow as 2^bounces. Two glass reflections (0.04² at normal incidence) still pass.
const MIN_SPECULAR_THROUGHPUT: f32 = 1e-3;

/// Largest number of rays in one bounce of a group's specular stream (a memory bound for
/// pathological scenes; ordinary mirrors and glass stay far below it).
const MAX_SPECULAR_STREAM: usize = 1 << 18;

/// Path-code bit of the shading points found by the clamp's bias compensation
/// ([`TilePipeline::compensate`]); the filter keeps them apart from the camera's own points.
const COMPENSATION: u32 = 1 << 31;

/// Levels of the bias compensation: the points it finds are compensated in turn, since they lie
/// where the clamp removes most (creases, contacts). Each level carries at most ρ·w of the
/// previous one; a fourth would change the Cornell box by far less than its noise.
const COMPENSATION_LEVELS: u32 = 3;

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
    /// Specular chain code: 1 for the camera ray, then one bit per bounce (0 reflection,
    /// 1 refraction) below a leading 1.
    path: u32,
    /// Product of the reflectances along the chain.
    throughput: Vec3,
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
}

/// A hit waiting for its surface shader: the hits of one step are shaded together, grouped
/// by material (paper 3.2: surface shaders run over all hits before the VPL loop).
#[derive(Clone, Copy, Debug)]
struct PendingHit {
    state: PathState,
    dir: Vec3,
    t: f32,
    surface: SurfacePoint,
}

/// A traced primary packet: directions, hits and pixels per lane, occupied lanes.
#[derive(Clone, Copy, Debug)]
struct PrimaryPacket {
    dirs: [Vec3; 8],
    hits: [Hit; 8],
    pixels: [u32; 8],
    bits: u32,
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
        let mut rays = RayCounts::default();
        let mut times = PhaseTimes::default();
        let mut clock = Instant::now();

        for set in 0..il.sets() {
            for sample in 0..aa {
                let first = scratch.points.len();
                self.trace_primary(&region, set, sample, scratch, &mut rays);
                times.lap(Phase::Primary, &mut clock);
                self.shade_primary(sample, scratch);
                times.lap(Phase::Shading, &mut clock);
                self.trace_specular(scratch, &mut rays);
                times.lap(Phase::Specular, &mut clock);
                if self.compensate_clamp && self.d_min2 > 0.0 {
                    self.compensate(&region, sample, first, scratch, &mut rays);
                    times.lap(Phase::Compensation, &mut clock);
                }
                self.light(set, sample, first, scratch, &mut rays);
                times.lap(Phase::Shadow, &mut clock);
            }
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

    /// Step 1: the camera rays of sample `sample` of the pixels of `set`, packet by packet.
    fn trace_primary(
        &self,
        region: &PixelRect,
        set: u32,
        sample: u32,
        s: &mut TileScratch,
        rays: &mut RayCounts,
    ) {
        s.packets.clear();
        let accel = self.scene.accel();
        let mut primary = 0u64;
        self.interleave.packets(region, set, |lanes| {
            primary += lanes.len() as u64;
            let mut packet = Packet8::new();
            let mut pixels = [0u32; 8];
            for (lane, &(x, y)) in lanes.iter().enumerate() {
                let (dx, dy) = self.interleave.sample_offset(
                    x,
                    y,
                    self.sequence.first + sample,
                    self.sequence.seed,
                    self.pixel_centres,
                );
                packet.set(lane, self.camera.ray_at(x, y, dx, dy));
                pixels[lane] = region.index(x, y) as u32;
            }
            let traced = packet.intersect(accel);
            let missed = packet.bits() & !traced.bits;
            if missed != 0 && self.scene.environment().is_some() {
                for lane in (0..8).filter(|lane| missed & (1 << lane) != 0) {
                    s.emitted[(pixels[lane] * self.interleave.aa + sample) as usize] +=
                        self.scene.background(packet.ray(lane).dir);
                }
            }
            s.packets.push(PrimaryPacket {
                dirs: std::array::from_fn(|lane| packet.ray(lane).dir),
                hits: traced.hits,
                pixels,
                bits: traced.bits,
            });
        });
        rays.primary += primary;
    }

    /// Step 2: the surface shaders of every primary hit.
    fn shade_primary(&self, sample: u32, s: &mut TileScratch) {
        let packets = std::mem::take(&mut s.packets);
        for p in &packets {
            for (lane, &pixel) in p.pixels.iter().enumerate() {
                if p.bits & (1 << lane) == 0 {
                    continue;
                }
                let state =
                    PathState { pixel, sample, path: 1, throughput: Vec3::ONE, depth: 0.0, bounces: 0 };
                self.queue_hit(p.dirs[lane], &p.hits[lane], state, s);
            }
        }
        s.packets = packets;
        self.shade_queued(s);
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
                        let sky = r.state.throughput * self.scene.background(r.ray.dir);
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
        let hit = PendingHit { state, dir, t: hit.t, surface: self.scene.surface(hit) };
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
            s.emitted[(state.pixel * self.interleave.aa + state.sample) as usize] +=
                state.throughput * b.emission;
        }
        let depth = state.depth + hit.t;
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
    /// shading point of the group with throughput ρ_x · w(d) (its emission counts directly),
    /// lit by the same VPLs, and is compensated in turn, up to [`COMPENSATION_LEVELS`]. What
    /// remains biased is the clamp below the last level and the light of specular surfaces at
    /// y, which it drops. The rays are short, and few hit anything away from creases and
    /// contacts.
    fn compensate(
        &self,
        region: &PixelRect,
        sample: u32,
        first: usize,
        s: &mut TileScratch,
        rays: &mut RayCounts,
    ) {
        let d_min = self.d_min2.sqrt();
        let accel = self.scene.accel();
        let index = self.sequence.first + sample;
        // Level 0 starts from the group's own points; each level compensates the points the
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
                    let state = PathState {
                        path: p.state.path | COMPENSATION,
                        throughput: p.state.throughput * p.albedo * w,
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

    /// Step 4: the lights and the VPLs of the group (set `set`, sample `sample`) on the
    /// shading points from index `first` on.
    fn light(&self, set: u32, sample: u32, first: usize, s: &mut TileScratch, rays: &mut RayCounts) {
        let points = &mut s.points[first..];
        if points.is_empty() {
            return;
        }
        let receivers = &mut s.receivers;
        receivers.clear();
        for p in points.iter() {
            receivers.push(p.origin, p.ns, p.ng, p.lobe);
        }
        let accel = self.scene.accel();
        if !self.vpls.lights().is_empty() {
            receivers.add_lights(accel, self.vpls.lights().iter(), 1.0, rays);
            for (i, p) in points.iter_mut().enumerate() {
                let (d, g, schlick) = receivers.radiance(i);
                p.exact = p.albedo * d + p.glossy * g + schlick;
            }
            receivers.reset_radiance();
        }
        receivers.regularise();
        let aa = self.interleave.aa as usize;
        let sky = self.vpls.sky(set).iter().skip(sample as usize).step_by(aa);
        receivers.add_lights(accel, sky, aa as f32, rays);
        let vpls = self.vpls.set(set).iter().skip(sample as usize).step_by(aa);
        receivers.add_vpls(accel, vpls, aa as f32, self.d_min2, rays);
        for (i, p) in points.iter_mut().enumerate() {
            let (d, g, schlick) = receivers.radiance(i);
            (p.diffuse_radiance, p.glossy_radiance) = (d, [g, schlick]);
        }
    }

    /// Filters the diffuse and glossy radiance and composes the tile's pixels.
    fn compose(&self, tile: &Tile, region: &PixelRect, s: &mut TileScratch) -> Vec<Vec3> {
        let TileScratch { points, emitted, filter_samples, glossy_radiance, filtered, filter, .. } = s;
        // Most tiles have no glossy point; their glossy term stays out of the filter.
        glossy_radiance.clear();
        if points.iter().any(|p| p.glossy_radiance != [Vec3::ZERO; 2]) {
            glossy_radiance.extend(points.iter().map(|p| p.glossy_radiance));
        }
        match &self.filter {
            Some(settings) => {
                filter_samples.clear();
                filter_samples.extend(points.iter().map(|p| FilterSample {
                    pixel: p.state.pixel,
                    sample: p.state.sample,
                    path: p.state.path,
                    normal: p.ns,
                    depth: p.depth,
                    material: p.material,
                    diffuse_radiance: p.diffuse_radiance,
                }));
                let input = (&filter_samples[..], &glossy_radiance[..]);
                filter.filter(region, tile, &self.interleave, settings, input, filtered);
                // The compensation's points lie wherever its rays landed, not on a pixel grid:
                // averaging their D over neighbours would weight it by the wrong distances.
                for (i, p) in points.iter().enumerate() {
                    if p.state.path & COMPENSATION != 0 {
                        filtered.diffuse_radiance[i] = p.diffuse_radiance;
                        if let Some(g) = filtered.glossy_radiance.get_mut(i) {
                            *g = p.glossy_radiance;
                        }
                    }
                }
            }
            None => {
                filtered.diffuse_radiance.clear();
                filtered.diffuse_radiance.extend(points.iter().map(|p| p.diffuse_radiance));
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
        for (i, (p, d)) in points.iter().zip(&filtered.diffuse_radiance).enumerate() {
            if let Some(pixel) = tile_index(p.state.pixel) {
                let g = filtered.glossy_radiance.get(i).map_or(Vec3::ZERO, |[g, s]| p.glossy * *g + *s);
                pixels[pixel] += p.state.throughput * (p.albedo * *d + g + p.exact);
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
