//! The reference path tracer (`igi render --mode path`): an unbiased estimate of the same
//! light transport the instant-global-illumination renderer approximates, on the same
//! [`PreparedScene`] and BVH, for ground truth in tests and image comparisons.
//!
//! # Physics
//!
//! The surface shaders give the BRDF parameters at every vertex ([`PreparedScene::shade`]) and
//! [`Bsdf`] evaluates and samples their lobes (diffuse, modified Phong, mirror, glass), as in
//! the VPL walk and the IGI pipeline; every surface reflects on both sides; a surface emits
//! the shader's emission only toward its winding normal (area-light sampling uses the
//! material's `emission`, which the built-in shaders pass on unchanged); point, spot and
//! directional lights arrive as [`lights::incident`] says; rays leaving the scene see the sky
//! (black without one); a scene without any light is lit by the headlight
//! [`lights::eye_light`].
//!
//! # Estimator
//!
//! A pixel's value is the mean of `spp` camera paths, the k-th starting through the sub-pixel
//! point (x + u₀, y + u₁) (a box filter over the pixel). Along a path x₀ x₁ … with throughput
//! β_j (1 at the camera, then the product of the BSDF sample weights f·cos/pdf of the bounces
//! so far, divided by the Russian-roulette probabilities), and f_j the non-delta (diffuse plus
//! glossy) BRDF at x_j toward x_{j−1},
//!
//! ```text
//! L ≈ Σ_j β_j · (  w_e L_e(x_j → x_{j−1})                                         (1)
//!                + f_j(ω_y) w_l L_e(y) cosθ_x cosθ_y V(x_j, y) / (|x_j − y|² p_A(y))   (2)
//!                + Σ_l f_j(ω_l) E_l(x_j) cosθ_x V(x_j, l)                          (3)
//!                + f_j(ω) w_s L_sky(ω) cosθ_x V(x_j, ∞) / p_sky(ω) )               (4)
//! ```
//!
//! plus β_k w_e L_sky(ω_k) where the path leaves the scene after vertex k.
//!
//! 1. Emission where the path hits the front of an emitter.
//! 2. Next-event estimation of the area lights: one point y per vertex with a non-delta lobe,
//!    chosen by power and uniformly by area
//!    ([`AreaLights::sample`](crate::prepared::lights::AreaLights::sample), density p_A), one shadow ray.
//! 3. Every point, spot and directional light, one shadow ray each (E_l = I/d² or E).
//! 4. Next-event estimation of the sky: one direction ω drawn by its importance
//!    ([`EnvironmentLight::sample`](crate::prepared::environment_light::EnvironmentLight::sample)), one shadow
//!    ray; the sky seen by a path leaving the scene and this estimate are weighted against
//!    each other by the power heuristic as (1) and (2) are.
//!
//! An emitter seen from a vertex x is found twice, by (2) with the solid-angle density
//! p_l = p_A(y) |x − y|² / cosθ_y and by the BSDF sample of (1) with its density p_b
//! ([`Bsdf::pdf`]), so the two are weighted by the power heuristic (Veach 1997):
//! w_l = p_l² / (p_l² + p_b²) and, after a diffuse or glossy bounce, w_e = p_b² / (p_b² + p_l²).
//! The weights sum to one, so the estimate stays unbiased. On the camera ray and after a
//! mirror or glass bounce, where next-event estimation cannot reach, w_e = 1. Counting
//! emission only there, without weights, would be unbiased too, but with uniform area sampling
//! the shadow-ray estimate (2) of an emitter that comes close to the shading point (an
//! emitting wall meeting a lit one) grows like 1/d² and has unbounded variance; the weights
//! hand that region to the BSDF sample, whose estimate is bounded. In the white-furnace test
//! (emitting walls, 64 spp) the worst pixel is 8 % off with the weights and 700 % without.
//!
//! The path continues in the direction [`Bsdf::sample`] draws from the whole BSDF (the lobe
//! chosen by reflectance; glass reflects with probability F and refracts otherwise), and β is
//! multiplied by the sample's weight. From the [`ROULETTE_START`]-th vertex on, Russian
//! roulette keeps the path with probability q = min(1, max channel of β) and divides β by q,
//! which leaves the estimate unbiased. A path ends for good at [`MAX_VERTICES`] surface hits.
//! With Russian roulette only chains of (nearly) lossless bounces get there, such as two
//! facing perfect mirrors; in a closed room of albedo ρ the cut loses the fraction ρ⁶⁴ of the
//! light (10⁻³ for ρ = 0.9, 10⁻⁶ for 0.8).
//!
//! Paths from a point, spot or directional light through a mirror or glass onto a diffuse
//! surface (caustics of punctual lights) have zero probability in this estimator: the light is
//! a delta, so neither a shadow ray (blocked by the glass) nor a scattered ray can reach it.
//! Caustics of area lights are found through (1).
//!
//! # Normals
//!
//! Normals are turned toward the side the ray arrives from (two-sided reflection). Cosines and
//! lobe directions use the shader's shading normal; the geometric normal decides sides: a
//! light or scattered direction that would cross the geometric surface where it should not
//! (possible where the shading normal is bent) counts nothing, and ray origins are moved off
//! the surface along it ([`offset_ray_origin`]). Glass refracts about the shading normal, as in
//! the VPL walk and the IGI pipeline.
//!
//! # Random numbers
//!
//! Path k of pixel (x, y) reads sample k of an Owen-scrambled Sobol sequence seeded by
//! [`pixel_seed`]`(x, y, frame.sample_seed())`, four dimensions at a time ([`sobol4`]):
//!
//! | dimension set | use |
//! |---|---|
//! | 0 | sub-pixel position (u₀, u₁), –, – |
//! | 3j + 1 | vertex j: light choice, light point (u, v), Russian roulette |
//! | 3j + 2 | vertex j: scattered direction (u, v), lobe choice, – |
//! | 3j + 3 | vertex j: sky direction (u, v), –, – |
//!
//! Sobol sets run out after `sobol_burley::NUM_DIMENSION_SETS_4D` (vertex 31 on); deeper
//! vertices, which carry little light, use hashed uniform numbers instead. Nothing depends on
//! the thread, tile or order of evaluation, so a pixel's value is a function of (scene, frame,
//! pixel) alone, the same bit for bit at any thread count and tile size.

use crate::camera::PinholeCamera;
use crate::frame::FrameState;
use crate::image::frame_image::{PixelFormat, TileOutput};
use crate::image::stats::{PhaseTimes, RayCounts};
use crate::image::tile::Tile;
use crate::image::tonemap::ToneMapper;
use crate::prepared::lights::{self, SHADOW_SHORTEN};
use crate::prepared::{PreparedScene, SurfacePoint};
use crate::sampling::{MAX_SAMPLES, hash_combine, pixel_seed, sobol4};
use glam::{Vec2, Vec3};
use igi_bvh::{Ray, offset_ray_origin};
use igi_scene::Light;
use igi_shade::brdf::Bsdf;

/// Most surface hits of one path (the hard cap; see the module documentation).
pub const MAX_VERTICES: u32 = 64;

/// Number of vertices a path keeps without Russian roulette: the first bounces carry most of
/// the indirect light and are cheap to keep.
pub const ROULETTE_START: u32 = 3;

/// The reference path tracer for one frame.
#[derive(Clone, Debug)]
pub struct PathTracer<'a> {
    scene: &'a PreparedScene,
    camera: PinholeCamera,
    /// The point, spot and directional lights ([`PreparedScene::punctual_lights`]).
    punctual: Vec<Light>,
    spp: u32,
    seed: u32,
    /// The pixels the frame delivers and their tone map.
    pixels: PixelFormat,
    tone_map: ToneMapper,
}

impl<'a> PathTracer<'a> {
    /// The path tracer of `scene` for `frame` (camera, image size `frame.settings.width` ×
    /// `height`, seed) with `spp` paths per pixel, clamped to 1..=[`MAX_SAMPLES`] (the length
    /// of a pixel's Sobol sequence; a caller reports a value outside it as the user's mistake).
    pub fn new(scene: &'a PreparedScene, frame: &FrameState, spp: u32) -> Self {
        Self {
            scene,
            camera: PinholeCamera::new(&frame.camera, frame.settings.width, frame.settings.height),
            punctual: scene.punctual_lights(&frame.camera),
            spp: spp.clamp(1, MAX_SAMPLES),
            seed: frame.sample_seed(),
            pixels: frame.pixels,
            tone_map: frame.tone_map,
        }
    }

    /// Paths per pixel (after clamping).
    pub fn spp(&self) -> u32 {
        self.spp
    }

    /// Radiance of pixel (x, y): the mean of its spp paths. Also counts rays traced into `rays`.
    pub fn pixel(&self, x: u32, y: u32, rays: &mut u64) -> Vec3 {
        let seed = pixel_seed(x, y, self.seed);
        let mut sum = Vec3::ZERO;
        for index in 0..self.spp {
            sum += self.path(x, y, PathSamples { index, seed }, rays);
        }
        sum / self.spp as f32
    }

    /// Renders `tile` in the frame's pixel format, tone-mapped with its tone map.
    pub fn render_tile(&self, tile: Tile) -> TileOutput {
        let mut radiance = Vec::with_capacity(tile.rect.pixel_count());
        let mut rays = 0;
        for y in tile.rect.y0..tile.rect.y1 {
            for x in tile.rect.x0..tile.rect.x1 {
                radiance.push(self.pixel(x, y, &mut rays));
            }
        }
        // The path tracer's rays are camera paths: counted as primary rays.
        let rays = RayCounts { primary: rays, ..RayCounts::default() };
        // No VPLs: temporal reuse carries all of a path-traced frame's radiance.
        TileOutput::encode(tile, (radiance, None), self.pixels, &self.tone_map, rays, PhaseTimes::default())
    }

    /// The radiance one camera path through pixel (x, y) brings back (see the module
    /// documentation for the estimator).
    fn path(&self, x: u32, y: u32, samples: PathSamples, rays: &mut u64) -> Vec3 {
        let scene = self.scene;
        let [dx, dy, _, _] = samples.get(0);
        let mut ray = self.camera.ray_at(x, y, dx, dy);
        let mut beta = Vec3::ONE;
        let mut radiance = Vec3::ZERO;
        // The solid-angle density p_b with which the last diffuse bounce chose `ray`, or `None`
        // on the camera ray and after specular bounces (emission then counts in full).
        let mut bounce_pdf: Option<f32> = None;
        for vertex in 0..MAX_VERTICES {
            *rays += 1;
            let hit = scene.accel().intersect(&ray);
            if !hit.is_hit() {
                // The sky, weighted against its own next-event estimate (4).
                if let Some(sky) = scene.environment() {
                    let weight = bounce_pdf.map_or(1.0, |p_b| power_heuristic(p_b, sky.pdf(ray.dir)));
                    radiance += beta * sky.radiance(ray.dir) * weight;
                }
                break;
            }
            let s = scene.surface(&hit);
            // Every direction here is unit length (camera and sampled directions all are), so
            // `hit.t` is the distance.
            let d = ray.dir;
            let params = scene.shade(&s, 0.0);
            let cos_l = -s.geometric_normal.dot(d);
            if cos_l > 0.0 && params.emission.max_element() > 0.0 {
                let weight = bounce_pdf.map_or(1.0, |p_b| {
                    let pdf_area = scene.area_lights().pdf_area(hit.instance, hit.prim);
                    power_heuristic(p_b, light_pdf(pdf_area, hit.t * hit.t, cos_l))
                });
                radiance += beta * params.emission * weight;
            }
            let [select, light_u, light_v, roulette] = samples.get(3 * vertex + 1);
            let [dir_u, dir_v, lobe, _] = samples.get(3 * vertex + 2);
            let [sky_u, sky_v, _, _] = samples.get(3 * vertex + 3);

            let bsdf = Bsdf::new(params, s.geometric_normal);
            let wo = -d;
            let side = Side::facing(&s, d, params.shading_normal);
            if params.has_non_delta() {
                radiance += beta
                    * (self.area_light(&side, &bsdf, wo, select, Vec2::new(light_u, light_v), rays)
                        + self.punctual_light(&side, &bsdf, wo, rays)
                        + self.sky_light(&side, &bsdf, wo, Vec2::new(sky_u, sky_v), rays));
            }
            let Some(sample) = bsdf.sample(wo, lobe, Vec2::new(dir_u, dir_v)) else { break };
            bounce_pdf = (!sample.lobe.is_delta()).then_some(sample.pdf);
            beta *= sample.weight;
            // A reflection leaves on the arrival side, a refraction on the other.
            let exit = if sample.wi.dot(side.ng) > 0.0 { side.ng } else { -side.ng };
            let next = Ray::new(offset_ray_origin(s.position, exit), sample.wi);
            if vertex + 1 >= ROULETTE_START {
                let keep = beta.max_element().min(1.0);
                if roulette >= keep {
                    break;
                }
                beta /= keep;
            }
            ray = next;
        }
        radiance
    }

    /// Term (2) of the estimator: one area-light sample's MIS-weighted estimate
    /// w_l f(ω_o, ω_i) L_e cosθ_x cosθ_y / (d² p_A) of the light reflected toward `wo`, 0 if
    /// the sample is hidden or faces away.
    fn area_light(&self, side: &Side, bsdf: &Bsdf, wo: Vec3, select: f32, uv: Vec2, rays: &mut u64) -> Vec3 {
        let Some(ls) = self.scene.area_lights().sample(select, uv) else { return Vec3::ZERO };
        let to_light = ls.point - side.position;
        let dist2 = to_light.length_squared();
        if dist2 <= 0.0 {
            return Vec3::ZERO;
        }
        let wi = to_light / dist2.sqrt();
        let cos_x = side.ns.dot(wi);
        let cos_l = -ls.normal.dot(wi);
        if cos_x <= 0.0 || cos_l <= 0.0 || side.ng.dot(wi) <= 0.0 {
            return Vec3::ZERO;
        }
        let f = bsdf.f(wo, wi);
        if f == Vec3::ZERO {
            return Vec3::ZERO;
        }
        let weight = power_heuristic(light_pdf(ls.pdf_area, dist2, cos_l), bsdf.pdf(wo, wi));
        let e = f * ls.emission * (weight * cos_x * cos_l / (dist2 * ls.pdf_area));
        if !(e.is_finite() && e.max_element() > 0.0) {
            return Vec3::ZERO;
        }
        if self.visible(side.origin, ls.point, rays) { e } else { Vec3::ZERO }
    }

    /// Term (4) of the estimator: one sky sample's MIS-weighted estimate
    /// w_s f(ω_o, ω) L_sky(ω) cosθ_x / p_sky(ω) of the light the sky sends toward `wo`, 0 if
    /// the scene blocks it.
    fn sky_light(&self, side: &Side, bsdf: &Bsdf, wo: Vec3, u: Vec2, rays: &mut u64) -> Vec3 {
        let Some(sky) = self.scene.environment().and_then(|e| e.sample(u)) else { return Vec3::ZERO };
        let cos_x = side.ns.dot(sky.dir);
        if cos_x <= 0.0 || side.ng.dot(sky.dir) <= 0.0 {
            return Vec3::ZERO;
        }
        let f = bsdf.f(wo, sky.dir);
        let weight = power_heuristic(sky.pdf, bsdf.pdf(wo, sky.dir));
        let e = f * sky.radiance * (weight * cos_x / sky.pdf);
        if !(e.is_finite() && e.max_element() > 0.0) {
            return Vec3::ZERO;
        }
        *rays += 1;
        if self.scene.accel().occluded(&Ray::new(side.origin, sky.dir)) { Vec3::ZERO } else { e }
    }

    /// Term (3) of the estimator: Σ f(ω_o, ω_l) E_l cosθ_x from the visible point, spot and
    /// directional lights.
    fn punctual_light(&self, side: &Side, bsdf: &Bsdf, wo: Vec3, rays: &mut u64) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for light in &self.punctual {
            let Some(inc) = lights::incident(light, side.position) else { continue };
            let cos_x = side.ns.dot(inc.dir);
            if cos_x <= 0.0 || side.ng.dot(inc.dir) <= 0.0 {
                continue;
            }
            let e = bsdf.f(wo, inc.dir) * inc.irradiance * cos_x;
            if !(e.is_finite() && e.max_element() > 0.0) {
                continue;
            }
            let visible = match inc.position {
                Some(target) => self.visible(side.origin, target, rays),
                None => {
                    *rays += 1;
                    !self.scene.accel().occluded(&Ray::new(side.origin, inc.dir))
                }
            };
            if visible {
                sum += e;
            }
        }
        sum
    }

    /// True if nothing blocks the segment from `origin` to just before `target`.
    fn visible(&self, origin: Vec3, target: Vec3, rays: &mut u64) -> bool {
        let d = target - origin;
        let len = d.length();
        if !(len > 0.0 && len.is_finite()) {
            return false;
        }
        *rays += 1;
        let ray = Ray { origin, dir: d / len, tnear: 0.0, tfar: len * SHADOW_SHORTEN };
        !self.scene.accel().occluded(&ray)
    }
}

/// The power heuristic f² / (f² + g²) for a sample drawn with density `f` where another
/// technique had density `g` (both ≥ 0, at most one infinite); written with ratios so that an
/// overflowing density (a light seen at a grazing angle) still gives 0 or 1, not NaN.
#[inline]
fn power_heuristic(f: f32, g: f32) -> f32 {
    if f <= 0.0 {
        return 0.0;
    }
    if f >= g {
        let r = g / f;
        1.0 / (1.0 + r * r)
    } else {
        let r = f / g;
        r * r / (1.0 + r * r)
    }
}

/// A surface point seen from the side a ray arrived on.
struct Side {
    position: Vec3,
    /// Geometric normal, turned toward the incoming ray.
    ng: Vec3,
    /// Shading normal, on the same side as `ng`.
    ns: Vec3,
    /// Origin for rays leaving on this side.
    origin: Vec3,
}

impl Side {
    /// The side of `s` that the unit direction `d` arrives on, with the shading normal `ns`
    /// (the surface shader's, in the hemisphere of the geometric normal).
    fn facing(s: &SurfacePoint, d: Vec3, ns: Vec3) -> Self {
        let sign = if s.geometric_normal.dot(d) < 0.0 { 1.0 } else { -1.0 };
        let ng = sign * s.geometric_normal;
        Self { position: s.position, ng, ns: sign * ns, origin: offset_ray_origin(s.position, ng) }
    }
}

/// The random numbers of one camera path: sample `index` of its pixel's sequence `seed`.
#[derive(Clone, Copy, Debug)]
struct PathSamples {
    index: u32,
    seed: u32,
}

impl PathSamples {
    /// Dimensions 4·`set` .. 4·`set` + 3 of the path, each in [0, 1): Owen-scrambled Sobol
    /// while sets last, hashed uniform numbers beyond.
    fn get(&self, set: u32) -> [f32; 4] {
        if set < sobol_burley::NUM_DIMENSION_SETS_4D {
            sobol4(self.index, set, self.seed)
        } else {
            let h = hash_combine(hash_combine(self.seed, set), self.index);
            [0, 1, 2, 3].map(|i| unit_float(hash_combine(h, i)))
        }
    }
}

/// The top 24 bits of `x` as a float in [0, 1).
#[inline]
fn unit_float(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The solid-angle density p_l = p_A |x − y|² / cosθ_y with which next-event estimation picks
/// the direction toward an emitter point y of area density `pdf_area`
/// ([`AreaLights::pdf_area`](crate::prepared::lights::AreaLights::pdf_area)) at squared distance `dist2`,
/// seen at cosine `cos_l` from its normal.
fn light_pdf(pdf_area: f32, dist2: f32, cos_l: f32) -> f32 {
    pdf_area * dist2 / cos_l
}
