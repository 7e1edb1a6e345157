//! The streaming tile pipeline of instant global illumination (paper 3.1.2; ARCHITECTURE.md,
//! "Data flow"): one tile, breadth first. First:
//!
//! 1. **primary**: the camera rays of all N samples of every pixel of the region, as 8-ray
//!    packets of 4×2 neighbouring pixels (ARCHITECTURE.md, "Camera rays of neighbouring
//!    pixels"), kept per pixel and sample, and the sky behind misses;
//!
//! then for each fine VPL set s, its pixels block by block of the set's sub-grid (paper
//! Figure 2):
//!
//! 2. **shading**: the surface shaders of the hits (paper 3.2: eight consecutive hits of one
//!    material per call; constant materials skip the call), emission
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
//!    glossy radiance G ([`crate::igi::vpl_lighting`]).
//!
//! Specular rays run before the shadow phase (not after it, as in a Whitted tracer) so that
//! every shading point of the set, seen directly or through glass, is lit in one pass over
//! the VPLs while their data is hot. Then the tile is filtered ([`crate::igi::discontinuity`]) and
//! composed: pixel = 1/N Σ_samples (emission and sky seen + Σ_points coverage · throughput ·
//! (ρ_d · D̃ + ρ_s · G̃ + L_l)), where D̃ and G̃ are the filtered VPL terms and L_l the light reflected from
//! point, spot and directional lights, which the filter leaves alone so their shadow edges stay
//! sharp.
//!
//! Every value depends only on the scene, the [`FrameState`] and the pixel, so a tiled image
//! equals an untiled one. A tile renders on its own with the apron it filters
//! ([`TilePipeline::render_tile`], a render node's way), or on one machine in two passes over
//! the frame ([`TilePipeline::light_tile`], then [`TilePipeline::compose_tile`] reading the
//! apron from the neighbours; ARCHITECTURE.md, "A frame in two passes"): the same image.

use crate::camera::PinholeCamera;
use crate::frame::{FilterSettings, FrameState, SequenceSpan};
use crate::igi::discontinuity::{DiscontinuityBuffer, FilterSample, Filtered};
use crate::igi::interleave::Interleave;
use crate::igi::vpl::VplSets;
use crate::igi::vpl_lighting::{GlossyLobe, Receivers, ShadowRoulette};
use crate::image::frame_image::{PixelFormat, TileOutput};
use crate::image::pixel_rect::PixelRect;
use crate::image::stats::{Phase, PhaseTimes, RayCounts};
use crate::image::tile::{Tile, TileGrid};
use crate::image::tonemap::ToneMapper;
use crate::prepared::{PreparedScene, SurfacePoint};
use glam::Vec3;
use igi_bvh::{Hit, Ray};
use std::time::Instant;

mod compensation;
mod primary;
mod shadow;
mod specular;

/// Path code of a camera ray's own hit ([`PathState::path`]: no specular bounce yet).
const CAMERA_PATH: u32 = 1;

/// Path-code bit of the shading points found by the clamp's bias compensation
/// ([`TilePipeline::compensate`]): their light joins the D of their camera path's point, and
/// only the camera paths' own points go through the filter.
const COMPENSATION: u32 = 1 << 31;

/// A point of the bias compensation is lit by every this-many-th VPL of its camera sample's
/// share ([`TilePipeline::vpl_share`]). On the conference room (`scenes/conference.toml`, one
/// compensated frame) 4 instead of 1 takes a frame from 746 to 657 ms and its mean FLIP against
/// the converged image from 0.129 to 0.131.
const COMPENSATION_VPL_STRIDE: u32 = 4;

/// Where a camera path stands: which sample it belongs to and what it carries.
#[derive(Clone, Copy, Debug)]
struct PathState {
    /// Pixel index in the region.
    pixel: u32,
    /// Anti-aliasing sample.
    sample: u32,
    /// Anti-aliasing samples the path stands for: all N of its pixel where they all saw one
    /// surface (the pixel is shaded once, lit by its whole VPL set), else 1 (the sample is
    /// lit by its share of the set; [`crate::igi::interleave`]).
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
    /// lobe, reflected as it is ([`crate::igi::vpl_lighting`]).
    glossy_radiance: [Vec3; 2],
    /// Radiance reflected from point, spot and directional lights: exact, so never filtered
    /// (their shadow edges stay sharp); its diffuse and its glossy part (the glossy lobe's and
    /// the Schlick term's), since only the first is the same from every direction.
    exact: [Vec3; 2],
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
    /// The pixel's index in the region (its samples are in [`TileScratch::camera`]).
    pixel: u32,
    /// See [`ShadingPoint::sample_origins`] (the positions are lifted off the surface once its
    /// side is known).
    sample_origins: Option<u32>,
}

/// The camera rays of a region ([`TilePipeline::trace_camera`]): per pixel (row by row) and
/// anti-aliasing sample, the ray's direction and hit (a miss where it hit nothing). 32 bytes a
/// ray, kept for the region's fine sets.
#[derive(Clone, Debug, Default)]
struct CameraSamples {
    dirs: Vec<Vec3>,
    hits: Vec<Hit>,
    /// Samples per pixel.
    aa: usize,
}

impl CameraSamples {
    /// Room for the `aa` samples of `pixels` pixels, every one to be set before it is read.
    fn reset(&mut self, pixels: usize, aa: usize) {
        self.aa = aa;
        self.dirs.resize(pixels * aa, Vec3::ZERO);
        self.hits.resize(pixels * aa, Hit::miss(f32::INFINITY));
    }

    /// Sets the hit and direction of sample `sample` of pixel `pixel`.
    fn set(&mut self, pixel: usize, sample: usize, hit: Hit, dir: Vec3) {
        let i = pixel * self.aa + sample;
        (self.hits[i], self.dirs[i]) = (hit, dir);
    }

    /// The directions and hits of the samples of region pixel `pixel`.
    fn samples(&self, pixel: u32) -> (&[Vec3], &[Hit]) {
        let at = pixel as usize * self.aa..(pixel as usize + 1) * self.aa;
        (&self.dirs[at.clone()], &self.hits[at])
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
    /// The region's camera rays, traced once for all its fine sets.
    camera: CameraSamples,
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
    /// The region's camera points as the filter reads them, point by point
    /// ([`ComposedPoints`]), their pixels' indices in the region; with their shares only where
    /// a tile is rendered on its own ([`TilePipeline::render_tile`]).
    composed: ComposedPoints,
    /// Where each row of a composed tile's own points starts in `composed`, and its run of
    /// them in the tile's lit points ([`TilePipeline::compose_tile`]).
    own_rows: Vec<(usize, std::ops::Range<usize>)>,
    filtered: Filtered,
    filter: DiscontinuityBuffer,
}

/// What filtering and composing read of shading points, point by point in three arrays: what
/// the filter reads (with D + the compensation's light), the glossy terms G and S, and each
/// point's share of its pixel. Far smaller than the points, and read in order. The copy of a
/// region that [`TilePipeline::compose_tile`] gathers from the lit tiles leaves the shares
/// out: only the tile's own points are composed, with their shares read in their lit tile.
#[derive(Clone, Debug, Default)]
struct ComposedPoints {
    samples: Vec<FilterSample>,
    glossy_radiance: Vec<[Vec3; 2]>,
    shares: Vec<PixelShare>,
}

impl ComposedPoints {
    fn clear(&mut self) {
        self.samples.clear();
        self.glossy_radiance.clear();
        self.shares.clear();
    }

    fn push(&mut self, (sample, glossy_radiance, share): (FilterSample, [Vec3; 2], PixelShare)) {
        self.samples.push(sample);
        self.glossy_radiance.push(glossy_radiance);
        self.shares.push(share);
    }

    /// Appends what the filter reads of the points `range` of `other` (not their shares: a
    /// tile composes only its own points, whose shares stay in their lit tile), their pixel
    /// indices shifted by `shift` (wrapping: a shift into a region before the tile's first
    /// pixel is negative).
    fn extend_filter_input(&mut self, other: &Self, range: std::ops::Range<usize>, shift: u32) {
        self.samples.extend(
            other.samples[range.clone()]
                .iter()
                .map(|s| FilterSample { pixel: s.pixel.wrapping_add(shift), ..*s }),
        );
        self.glossy_radiance.extend_from_slice(&other.glossy_radiance[range]);
    }
}

/// One of the points a tile composes ([`TilePipeline::compose`]).
struct TilePoint<'a> {
    /// Its index in the region's [`ComposedPoints`] (and in the filter's output).
    index: usize,
    /// Its pixel's index in the tile.
    pixel: usize,
    share: &'a PixelShare,
}

/// A shading point's share of its pixel, beside its filtered terms: pixel += coverage ·
/// throughput · (ρ_d · D̃ + exact diffuse + ρ_s · G̃ + S̃ + exact glossy).
#[derive(Clone, Copy, Debug)]
struct PixelShare {
    /// Diffuse reflectance ρ_d and glossy reflectance ρ_s ([`ShadingPoint`]).
    albedo: Vec3,
    glossy: Vec3,
    /// [`ShadingPoint::exact`].
    exact: [Vec3; 2],
    throughput: Vec3,
    /// Samples of the pixel the point stands for.
    coverage: f32,
    /// The point is the camera ray's own hit (what the diffuse layer holds).
    camera_path: bool,
}

/// The camera paths' own points of `points`: the compensation's points only carry light to
/// them ([`TilePipeline::fold_compensation`]) and are neither filtered nor composed.
fn camera_points(points: &[ShadingPoint]) -> impl Iterator<Item = &ShadingPoint> {
    points.iter().filter(|p| p.state.path & COMPENSATION == 0)
}

/// A tile traced and lit but not filtered yet ([`TilePipeline::light_tile`]): what its own
/// filter and its neighbours' read of it.
#[derive(Debug, Default)]
pub struct LitTile {
    tile: Tile,
    /// The camera paths' shading points, lit, with the compensation's light folded in, as
    /// filtering and composing read them, by pixel (stable, so each pixel keeps the order of
    /// its points, which its sum in `compose` follows); their pixels are indices in the tile.
    points: ComposedPoints,
    /// Where each pixel's run of points starts (one more entry than pixels).
    pixel_start: Vec<u32>,
    /// Emission and sky seen, per pixel of the tile and sample.
    emitted: Vec<Vec3>,
    rays: RayCounts,
    times: PhaseTimes,
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
    /// Which shadow rays go by roulette.
    roulette: ShadowRoulette,
    /// The frame's seed of the shadow-ray roulette ([`FrameState::sample_seed`]: another draw
    /// every reseeded frame).
    roulette_seed: u32,
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
            pixel_centres: s.aa == 1 && !frame.reseed_per_frame,
            d_min2: s.clamp * s.clamp,
            roulette: ShadowRoulette::for_scene(scene.bounds().diagonal()),
            roulette_seed: frame.sample_seed(),
            compensate_clamp: s.compensate_clamp,
            filter: s.discontinuity_filter(),
            specular_bounces: s.specular_bounces,
            size: (s.width, s.height),
            tone_map: frame.tone_map,
            pixels: frame.pixels,
            pixel_angle: 2.0 * (0.5 * frame.camera.fov_y_deg.to_radians()).tan() / s.height.max(1) as f32,
        }
    }

    /// Renders `tile` (of an image of the frame's size) on its own: its pixels and the apron
    /// the filter reads around them are traced and lit here. A render node of a cluster renders
    /// its tiles so; on one machine [`TilePipeline::light_tile`] and
    /// [`TilePipeline::compose_tile`] render the same image without tracing any pixel twice.
    pub fn render_tile(&self, tile: Tile, scratch: &mut TileScratch) -> TileOutput {
        let region = self.interleave.region(&tile, self.size.0, self.size.1);
        let (rays, mut times) = self.light_region(&region, scratch);
        let mut clock = Instant::now();
        self.fold_compensation(&mut scratch.points, &mut times, &mut clock);
        scratch.composed.clear();
        for p in camera_points(&scratch.points) {
            scratch.composed.push(self.composed(p, p.state.pixel));
        }
        let (emitted, composed) =
            (std::mem::take(&mut scratch.emitted), std::mem::take(&mut scratch.composed));
        let tile_points =
            composed.samples.iter().zip(&composed.shares).enumerate().filter_map(|(i, (p, share))| {
                let (x, y) = region.pixel(p.pixel);
                tile.rect.contains(x, y).then(|| TilePoint { index: i, pixel: tile.rect.index(x, y), share })
            });
        let radiance = self.compose(&tile, &region, (&region, &emitted), (&composed, tile_points), scratch);
        (scratch.emitted, scratch.composed) = (emitted, composed);
        times.lap(Phase::Filter, &mut clock);
        TileOutput::encode(tile, radiance, self.pixels, &self.tone_map, rays, times)
    }

    /// The first pass of a frame on one machine: traces and lights the pixels of `tile` only,
    /// into `lit` (whose memory it reuses), for [`TilePipeline::compose_tile`] to filter once
    /// its neighbours are lit too (ARCHITECTURE.md, "A frame in two passes").
    pub fn light_tile(&self, tile: Tile, scratch: &mut TileScratch, lit: &mut LitTile) {
        (lit.rays, lit.times) = self.light_region(&tile.rect, scratch);
        lit.tile = tile;
        let mut clock = Instant::now();
        self.fold_compensation(&mut scratch.points, &mut lit.times, &mut clock);
        // The emission moves to the lit tile, and its old buffer becomes the scratch's.
        std::mem::swap(&mut scratch.emitted, &mut lit.emitted);
        // The camera paths' points by pixel (a counting sort, stable): a neighbour's filter
        // takes the rows of its apron as runs. `pixel_start[p + 1]` counts pixel p's points;
        // summed, `pixel_start[p]` is where p's run starts and, as the points are placed (read
        // in order, written where they belong), its end; shifted up one, the runs' ends are
        // their successors' starts.
        let pixel_start = &mut lit.pixel_start;
        let pixels = tile.rect.pixel_count();
        pixel_start.clear();
        pixel_start.resize(pixels + 1, 0);
        let mut count = 0;
        for p in camera_points(&scratch.points) {
            pixel_start[p.state.pixel as usize + 1] += 1;
            count += 1;
        }
        for i in 0..pixels {
            pixel_start[i + 1] += pixel_start[i];
        }
        // (The first point fills the arrays to their length before each is written in place.)
        let Some(first) = camera_points(&scratch.points).next() else {
            lit.points.clear();
            lit.times.lap(Phase::Filter, &mut clock);
            return;
        };
        let (sample, glossy, share) = self.composed(first, first.state.pixel);
        let out = &mut lit.points;
        out.samples.resize(count, sample);
        out.glossy_radiance.resize(count, glossy);
        out.shares.resize(count, share);
        for p in camera_points(&scratch.points) {
            let at = &mut pixel_start[p.state.pixel as usize];
            let i = *at as usize;
            (out.samples[i], out.glossy_radiance[i], out.shares[i]) = self.composed(p, p.state.pixel);
            *at += 1;
        }
        pixel_start.copy_within(0..pixels, 1);
        pixel_start[0] = 0;
        // Arranging the points for the filter is part of filtering.
        lit.times.lap(Phase::Filter, &mut clock);
    }

    /// `p`, at pixel `pixel`, as filtering and composing read it ([`ComposedPoints`]).
    #[inline]
    fn composed(&self, p: &ShadingPoint, pixel: u32) -> (FilterSample, [Vec3; 2], PixelShare) {
        let sample = FilterSample {
            pixel,
            sample: p.state.sample,
            whole_pixel: p.state.coverage == self.interleave.aa,
            path: p.state.path,
            normal: p.ns,
            depth: p.depth,
            material: p.material,
            diffuse_radiance: p.diffuse_radiance + p.compensation,
        };
        let share = PixelShare {
            albedo: p.albedo,
            glossy: p.glossy,
            exact: p.exact,
            throughput: p.state.throughput,
            coverage: p.state.coverage as f32,
            camera_path: p.state.path == CAMERA_PATH,
        };
        (sample, p.glossy_radiance, share)
    }

    /// The second pass of a frame on one machine: filters and composes `tile` from the lit
    /// tiles of the frame, `lit[i]` the tile `i` of `grid`, reading the neighbours' points in
    /// its apron. The image equals [`TilePipeline::render_tile`]'s.
    pub fn compose_tile(
        &self,
        tile: Tile,
        grid: &TileGrid,
        lit: &[LitTile],
        scratch: &mut TileScratch,
    ) -> TileOutput {
        let mut clock = Instant::now();
        let region = self.interleave.region(&tile, self.size.0, self.size.1);
        let mut composed = std::mem::take(&mut scratch.composed);
        composed.clear();
        let mut own_rows = std::mem::take(&mut scratch.own_rows);
        own_rows.clear();
        for neighbour in grid.tiles_overlapping(&region) {
            let lit = &lit[neighbour.index as usize];
            let rect = &lit.tile.rect;
            let (x0, x1) = (region.x0.max(rect.x0), region.x1.min(rect.x1));
            for y in region.y0.max(rect.y0)..region.y1.min(rect.y1) {
                // The row's pixels are consecutive in the tile and in the region.
                let (first, last) = (rect.index(x0, y), rect.index(x1 - 1, y) + 1);
                let shift = (region.index(x0, y) as u32).wrapping_sub(first as u32);
                let run = lit.pixel_start[first] as usize..lit.pixel_start[last] as usize;
                if neighbour.index == tile.index {
                    own_rows.push((composed.samples.len(), run.clone()));
                }
                composed.extend_filter_input(&lit.points, run, shift);
            }
        }
        let own = &lit[tile.index as usize];
        // The own points' pixels are indices in the tile.
        let tile_points = own_rows.iter().flat_map(|(start, run)| {
            run.clone().map(move |j| TilePoint {
                index: start + j - run.start,
                pixel: own.points.samples[j].pixel as usize,
                share: &own.points.shares[j],
            })
        });
        let radiance =
            self.compose(&tile, &region, (&tile.rect, &own.emitted), (&composed, tile_points), scratch);
        (scratch.composed, scratch.own_rows) = (composed, own_rows);
        let mut times = own.times;
        times.lap(Phase::Filter, &mut clock);
        TileOutput::encode(tile, radiance, self.pixels, &self.tone_map, own.rays, times)
    }

    /// Whether the frame compensates the clamp's bias (a clamped still image).
    fn compensates(&self) -> bool {
        self.compensate_clamp && self.d_min2 > 0.0
    }

    /// Steps 1 to 4 for the pixels of `region`: their shading points, lit, in `scratch.points`,
    /// and the emission and sky their samples see in `scratch.emitted`.
    fn light_region(&self, region: &PixelRect, scratch: &mut TileScratch) -> (RayCounts, PhaseTimes) {
        let il = self.interleave;
        scratch.emitted.clear();
        scratch.emitted.resize(region.pixel_count() * il.aa as usize, Vec3::ZERO);
        scratch.points.clear();
        scratch.sample_origins.clear();
        let mut rays = RayCounts::default();
        let mut times = PhaseTimes::default();
        let mut clock = Instant::now();
        self.trace_camera(region, scratch, &mut rays);
        times.lap(Phase::Primary, &mut clock);
        for fine in 0..il.fine_sets() {
            let first = scratch.points.len();
            self.shade_primary(region, fine, scratch);
            times.lap(Phase::Shading, &mut clock);
            self.trace_specular(scratch, &mut rays);
            times.lap(Phase::Specular, &mut clock);
            if self.compensates() {
                self.compensate(region, first, scratch, &mut rays);
                times.lap(Phase::Compensation, &mut clock);
            }
            self.light(region, fine, first, scratch, &mut rays);
            times.lap(Phase::Shadow, &mut clock);
        }
        (rays, times)
    }

    /// The light each compensation point reflects toward its parent joins the D of its camera
    /// path's point, and is filtered with it: one short ray per pixel is as noisy as one VPL
    /// set (more, where it finds a sunlit surface), and left unfiltered it leaves single
    /// bright pixels near creases and contacts. Only a frame that compensates has such points:
    /// the others skip this pass over the points, and count no compensation time in `times`.
    fn fold_compensation(&self, points: &mut [ShadingPoint], times: &mut PhaseTimes, clock: &mut Instant) {
        if !self.compensates() {
            return;
        }
        for i in 0..points.len() {
            let p = &points[i];
            if p.state.path & COMPENSATION != 0 {
                let [g, schlick] = p.glossy_radiance;
                let reflected =
                    p.albedo * p.diffuse_radiance + p.glossy * g + schlick + p.exact[0] + p.exact[1];
                let (root, light) = (p.state.root as usize, p.state.throughput * reflected);
                points[root].compensation += light;
            }
        }
        times.lap(Phase::Compensation, clock);
    }

    /// Filters the diffuse and glossy radiance and composes the tile's pixels, and for a
    /// layered frame their [`DiffuseLayer`](crate::image::frame_image::DiffuseLayer) part: the
    /// diffuse reflection (ρ_d·D and the exact lights' diffuse term) of the camera rays' own
    /// hits. What the filter reads of the region's camera paths' points is in `composed`,
    /// their pixels' indices in `region` (the compensation's light folded in:
    /// [`TilePipeline::fold_compensation`]); `tile_points` are the tile's own points, each
    /// pixel's points in the order they are to be summed; `emitted` is the emission and sky
    /// seen per pixel and sample of a rectangle holding the tile.
    fn compose<'p>(
        &self,
        tile: &Tile,
        region: &PixelRect,
        (emitted_rect, emitted): (&PixelRect, &[Vec3]),
        (composed, tile_points): (&ComposedPoints, impl Iterator<Item = TilePoint<'p>>),
        s: &mut TileScratch,
    ) -> (Vec<Vec3>, Option<Vec<Vec3>>) {
        let TileScratch { filtered, filter, .. } = s;
        // Most tiles have no glossy point; their glossy term stays out of the filter.
        let any_glossy = composed.glossy_radiance.iter().any(|g| *g != [Vec3::ZERO; 2]);
        let glossy_radiance = if any_glossy { &composed.glossy_radiance[..] } else { &[] };
        match &self.filter {
            Some(settings) => {
                let input = (&composed.samples[..], glossy_radiance);
                filter.filter(region, tile, &self.interleave, settings, input, filtered);
            }
            None => {
                filtered.diffuse_radiance.clear();
                filtered.diffuse_radiance.extend(composed.samples.iter().map(|p| p.diffuse_radiance));
                filtered.glossy_radiance.clear();
                filtered.glossy_radiance.extend_from_slice(glossy_radiance);
            }
        }

        let aa = self.interleave.aa as usize;
        let mut pixels = vec![Vec3::ZERO; tile.rect.pixel_count()];
        let mut layer = (self.pixels == PixelFormat::Layered).then(|| vec![Vec3::ZERO; pixels.len()]);
        for TilePoint { index: i, pixel, share: p } in tile_points {
            let d = filtered.diffuse_radiance[i];
            let g = filtered.glossy_radiance.get(i).map_or(Vec3::ZERO, |[g, s]| p.glossy * *g + *s);
            let (coverage, [exact_diffuse, exact_glossy]) = (p.coverage, p.exact);
            let diffuse = p.albedo * d + exact_diffuse;
            pixels[pixel] += coverage * p.throughput * (diffuse + g + exact_glossy);
            // Only the camera ray's own hit: what a mirror or glass shows moves with the view.
            if let (Some(layer), true) = (&mut layer, p.camera_path) {
                layer[pixel] += coverage * diffuse;
            }
        }
        let scale = 1.0 / aa as f32;
        for y in tile.rect.y0..tile.rect.y1 {
            for x in tile.rect.x0..tile.rect.x1 {
                let r = emitted_rect.index(x, y);
                let e: Vec3 = emitted[r * aa..(r + 1) * aa].iter().sum();
                let i = tile.rect.index(x, y);
                pixels[i] = (pixels[i] + e) * scale;
                if let Some(layer) = &mut layer {
                    layer[i] *= scale;
                }
            }
        }
        (pixels, layer)
    }
}
