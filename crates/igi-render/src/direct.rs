//! Direct lighting with shadow rays: the shading of the first real image (issue #2), and the
//! "light-surface samples" part of the later instant-radiosity frame.
//!
//! For each primary hit x with viewer-facing normal n and Lambert BRDF ρ/π (ρ = diffuse ×
//! texture), the radiance toward the camera is
//!
//! ```text
//! L = L_e(x, front side only)
//!   + 1/N Σ_k ρ/π · L_e(y_k) · cosθ_x · cosθ_y / (|x - y_k|² · p_A(y_k)) · V(x, y_k)   (area lights)
//!   + Σ_lights ρ/π · E_l(x) · cosθ_x · V(x, l)                                      (point, spot, sun)
//! ```
//!
//! with y_k chosen on the emissive triangles by power and uniformly by area (p_A =
//! P(triangle) / area), one-sided emission toward the winding normal, E_l = I/d² for point and
//! spot lights and E for directional lights, and V one shadow ray each. The N area samples of
//! a pixel are points of an Owen-scrambled Sobol sequence seeded by (pixel, seed), so they are
//! stratified and the same on every run and thread count.
//!
//! Surfaces are two-sided for reflection: normals are turned toward the viewer before
//! shading. A scene without any light source is lit by a headlight: a point light at the
//! camera ([`eye_light`]).
//!
//! Primary rays go through the packet kernel in 8-ray packets (a 4×2 pixel block), and each
//! light sample of the eight pixels forms one 8-ray shadow packet.

use crate::lights::{self, AreaLights, eye_light};
use crate::prepared::PreparedScene;
use crate::sampling::{pixel_seed, sobol4};
use glam::{Vec2, Vec3};
use igi_bvh::{Ray, RayPacket8, offset_ray_origin};
use igi_scene::{Camera, Light};
use igi_simd::{F32x8, M32x8, Vec3x8};
use std::f32::consts::FRAC_1_PI;

/// Shadow rays stop this fraction short of the light so the light's own surface does not
/// block them.
const SHADOW_SHORTEN: f32 = 1.0 - 1e-4;

/// Rays traced, for throughput figures.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Camera rays.
    pub primary: u64,
    /// Shadow (any-hit) rays.
    pub shadow: u64,
}

impl RayCounts {
    /// All rays.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: Self) {
        self.primary += o.primary;
        self.shadow += o.shadow;
    }
}

/// A primary hit ready for light evaluation.
#[derive(Clone, Copy, Debug)]
struct ShadePoint {
    /// Hit position.
    position: Vec3,
    /// Shadow-ray origin: the position moved off the surface on the viewer's side.
    origin: Vec3,
    /// Geometric normal, turned toward the viewer.
    ng: Vec3,
    /// Shading normal, turned toward the viewer.
    ns: Vec3,
    /// Lambert BRDF ρ/π.
    brdf: Vec3,
    /// Sample sequence seed of the pixel.
    seed: u32,
}

/// The shadow rays of one light sample for the lanes of a primary packet, in
/// structure-of-arrays form, with the radiance each carries if unblocked.
struct ShadowPacket {
    origin: [[f32; 8]; 3],
    dir: [[f32; 8]; 3],
    tfar: [f32; 8],
    radiance: [Vec3; 8],
    /// Lanes holding a ray.
    bits: u32,
}

impl ShadowPacket {
    fn new() -> Self {
        Self { origin: [[0.0; 8]; 3], dir: [[0.0; 8]; 3], tfar: [0.0; 8], radiance: [Vec3::ZERO; 8], bits: 0 }
    }

    /// Sets lane `lane` to the ray `origin + t dir`, `t` in `[0, tfar]`, carrying `radiance`.
    #[inline(always)]
    fn set(&mut self, lane: usize, origin: Vec3, dir: Vec3, tfar: f32, radiance: Vec3) {
        for axis in 0..3 {
            self.origin[axis][lane] = origin[axis];
            self.dir[axis][lane] = dir[axis];
        }
        self.tfar[lane] = tfar;
        self.radiance[lane] = radiance;
        self.bits |= 1 << lane;
    }

    /// The rays as a packet; empty lanes repeat an occupied one so every lane holds a valid
    /// ray. Call only with at least one lane set.
    fn packet(&mut self) -> RayPacket8 {
        let first = self.bits.trailing_zeros() as usize;
        for lane in 0..8 {
            if self.bits & (1 << lane) == 0 {
                for axis in 0..3 {
                    self.origin[axis][lane] = self.origin[axis][first];
                    self.dir[axis][lane] = self.dir[axis][first];
                }
                self.tfar[lane] = self.tfar[first];
            }
        }
        let v = |a: &[[f32; 8]; 3]| {
            Vec3x8::new(F32x8::from_array(a[0]), F32x8::from_array(a[1]), F32x8::from_array(a[2]))
        };
        RayPacket8 {
            origin: v(&self.origin),
            dir: v(&self.dir),
            tnear: F32x8::ZERO,
            tfar: F32x8::from_array(self.tfar),
        }
    }
}

/// Direct-lighting shader for one frame: the scene, its lights and the sampling settings.
#[derive(Clone, Debug)]
pub struct DirectLighting<'a> {
    scene: &'a PreparedScene,
    punctual: Vec<Light>,
    samples: u32,
    seed: u32,
}

impl<'a> DirectLighting<'a> {
    /// The shader for `scene` seen from `camera`, with `samples` area-light samples per pixel
    /// (at most [`crate::sampling::MAX_SAMPLES`]) and frame seed `seed`.
    pub fn new(scene: &'a PreparedScene, camera: &Camera, samples: u32, seed: u32) -> Self {
        let punctual =
            if scene.has_lights() { scene.lights().to_vec() } else { vec![eye_light(scene, camera)] };
        Self { scene, punctual, samples: samples.min(crate::sampling::MAX_SAMPLES), seed }
    }

    /// The point, spot and directional lights evaluated (the scene's, or the headlight).
    pub fn punctual_lights(&self) -> &[Light] {
        &self.punctual
    }

    /// Area-light samples per pixel.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Radiance arriving at the camera along each active lane of `rays` (unit directions),
    /// where lane `i` belongs to pixel `pixels[i]`. Inactive lanes return zero.
    pub fn shade_packet(
        &self,
        rays: &RayPacket8,
        active: M32x8,
        pixels: &[(u32, u32); 8],
        counts: &mut RayCounts,
    ) -> [Vec3; 8] {
        let scene = self.scene;
        let mut radiance = [Vec3::ZERO; 8];
        if active.none() {
            return radiance;
        }
        counts.primary += u64::from(active.bitmask().count_ones());
        let hits = scene.accel().intersect8(rays, active);
        let hit_mask = hits.hit_mask() & active;

        let mut points: [Option<ShadePoint>; 8] = [None; 8];
        for lane in 0..8 {
            if !hit_mask.lane(lane) {
                continue;
            }
            let s = scene.surface(&hits.hit(lane));
            let wo = -Vec3::from(rays.dir.lane(lane));
            let front = s.geometric_normal.dot(wo) > 0.0;
            let (ng, ns) = if front {
                (s.geometric_normal, s.shading_normal)
            } else {
                (-s.geometric_normal, -s.shading_normal)
            };
            let material = &scene.materials()[s.material as usize];
            if front && material.is_emissive() {
                radiance[lane] += material.emission;
            }
            let brdf = scene.albedo(s.material, s.uv) * FRAC_1_PI;
            if brdf.max_element() <= 0.0 {
                continue;
            }
            let (x, y) = pixels[lane];
            points[lane] = Some(ShadePoint {
                position: s.position,
                origin: offset_ray_origin(s.position, ng),
                ng,
                ns,
                brdf,
                seed: pixel_seed(x, y, self.seed),
            });
        }
        if points.iter().all(Option::is_none) {
            return radiance;
        }

        let area = self.scene.area_lights();
        if !area.is_empty() && self.samples > 0 {
            let weight = 1.0 / self.samples as f32;
            for k in 0..self.samples {
                let mut shadows = ShadowPacket::new();
                for (lane, p) in points.iter().enumerate() {
                    if let Some(p) = p {
                        area_sample(area, p, k, weight, lane, &mut shadows);
                    }
                }
                self.trace_shadows(&mut shadows, &mut radiance, counts);
            }
        }
        for light in &self.punctual {
            let mut shadows = ShadowPacket::new();
            for (lane, p) in points.iter().enumerate() {
                if let Some(p) = p {
                    punctual_sample(light, p, lane, &mut shadows);
                }
            }
            self.trace_shadows(&mut shadows, &mut radiance, counts);
        }
        radiance
    }

    /// Radiance along one primary ray (unit direction) of pixel `pixel`; the same computation
    /// as one lane of [`DirectLighting::shade_packet`].
    pub fn shade_ray(&self, ray: &Ray, pixel: (u32, u32), counts: &mut RayCounts) -> Vec3 {
        let packet = RayPacket8::from_rays(&[*ray; 8]);
        let active = M32x8::from_bitmask(1);
        self.shade_packet(&packet, active, &[pixel; 8], counts)[0]
    }

    /// Traces the shadow rays of a packet (one kernel call) and adds what the unblocked ones
    /// carry.
    fn trace_shadows(&self, shadows: &mut ShadowPacket, radiance: &mut [Vec3; 8], counts: &mut RayCounts) {
        let bits = shadows.bits;
        if bits == 0 {
            return;
        }
        counts.shadow += u64::from(bits.count_ones());
        let active = M32x8::from_bitmask(bits);
        let packet = shadows.packet();
        let blocked = if bits.count_ones() == 1 {
            let lane = bits.trailing_zeros() as usize;
            if self.scene.accel().occluded(&packet.ray(lane)) { active } else { M32x8::NONE }
        } else {
            self.scene.accel().occluded8(&packet, active)
        };
        let lit = active.and_not(blocked).bitmask();
        for (lane, r) in radiance.iter_mut().enumerate() {
            if lit & (1 << lane) != 0 {
                *r += shadows.radiance[lane];
            }
        }
    }
}

/// Sets `lane` of `shadows` to the ray from `origin` to `target` (a finite point), stopping
/// just short of it, carrying `radiance`.
#[inline(always)]
fn shadow_ray_to(shadows: &mut ShadowPacket, lane: usize, origin: Vec3, target: Vec3, radiance: Vec3) {
    let d = target - origin;
    let len = d.length();
    if len > 0.0 && len.is_finite() {
        shadows.set(lane, origin, d / len, len * SHADOW_SHORTEN, radiance);
    }
}

/// Area-light sample `k` of a pixel, weighted by `weight` (1/N), into `lane` of `shadows`
/// (left empty if it contributes nothing before visibility).
#[inline(always)]
fn area_sample(
    area: &AreaLights,
    p: &ShadePoint,
    k: u32,
    weight: f32,
    lane: usize,
    shadows: &mut ShadowPacket,
) {
    let [sel, u, v, _] = sobol4(k, 0, p.seed);
    let Some(ls) = area.sample(sel, Vec2::new(u, v)) else { return };
    let d = ls.point - p.position;
    let dist2 = d.length_squared();
    if dist2 <= 0.0 {
        return;
    }
    let wi = d / dist2.sqrt();
    let cos_x = p.ns.dot(wi);
    let cos_l = -ls.normal.dot(wi);
    if cos_x <= 0.0 || cos_l <= 0.0 || p.ng.dot(wi) <= 0.0 {
        return;
    }
    let radiance = p.brdf * ls.emission * (cos_x * cos_l * weight / (dist2 * ls.pdf_area));
    if radiance.is_finite() && radiance.max_element() > 0.0 {
        shadow_ray_to(shadows, lane, p.origin, ls.point, radiance);
    }
}

/// The shadow sample of a point, spot or directional light into `lane` of `shadows`.
#[inline(always)]
fn punctual_sample(light: &Light, p: &ShadePoint, lane: usize, shadows: &mut ShadowPacket) {
    let Some(inc) = lights::incident(light, p.position) else { return };
    let cos_x = p.ns.dot(inc.dir);
    if cos_x <= 0.0 || p.ng.dot(inc.dir) <= 0.0 {
        return;
    }
    let radiance = p.brdf * inc.irradiance * cos_x;
    if !radiance.is_finite() || radiance.max_element() <= 0.0 {
        return;
    }
    match inc.position {
        Some(target) => shadow_ray_to(shadows, lane, p.origin, target, radiance),
        None => shadows.set(lane, p.origin, inc.dir, f32::INFINITY, radiance),
    }
}
