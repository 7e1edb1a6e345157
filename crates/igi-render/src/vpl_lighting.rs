//! The inner loop of instant radiosity: for each VPL of a set, the shadow rays of all shading
//! points of the set as 8-ray packets (any hit), and the accumulation of the contributions
//! (paper 3.1.2; DESIGN.md section 1), eight points at a time.
//!
//! What is accumulated is the diffuse irradiance divided by π, D = E/π, so that a Lambertian
//! surface of reflectance ρ reflects L = ρ·D. The discontinuity filter smooths D before the
//! albedo multiplies it back in (paper 2.1), which keeps texture detail sharp. Per light:
//!
//! ```text
//! surface VPL (Lambertian emitter of power Φ at y, normal n_y):
//!     D += w · Φ/π² · cosθ_x · cosθ_y / max(|x − y|², d_min²) · V(x, y)
//! point light (intensity I; a spot light only inside its cone):
//!     D += I/π · cosθ_x / |x − p|² · V(x, p)
//! directional light (irradiance E toward −direction):
//!     D += E/π · cosθ_x · V(x, ∞)
//! ```
//!
//! with w the weight of the VPL in this sample (N for a VPL shared among N anti-aliasing
//! samples, paper 3.3) and d_min the clamp that bounds the 1/d² singularity (the bias the
//! paper mentions). Point and directional lights are exact direct light, not samples of it,
//! so they are neither clamped nor weighted.

use crate::stats::RayCounts;
use crate::vpl::Vpl;
use glam::Vec3;
use igi_bvh::{Accel, RayPacket8, offset_ray_origin};
use igi_scene::Light;
use igi_simd::{F32x8, M32x8, Vec3x8};
use std::f32::consts::{FRAC_1_PI, PI};

/// Shadow rays stop this fraction short of their target so the surface a VPL lies on does not
/// block them.
const SHADOW_SHORTEN: f32 = 1.0 - 1e-4;

/// Eight shading points in structure-of-arrays form.
#[derive(Clone, Copy, Debug)]
struct Chunk {
    /// Shadow-ray origins (the points, moved off their surfaces on the lit side).
    origin: [[f32; 8]; 3],
    /// Unit shading normals on the lit side.
    ns: [[f32; 8]; 3],
    /// Unit geometric normals on the lit side.
    ng: [[f32; 8]; 3],
    /// Occupied lanes.
    bits: u32,
}

impl Chunk {
    const EMPTY: Chunk = Chunk { origin: [[0.0; 8]; 3], ns: [[0.0; 8]; 3], ng: [[0.0; 8]; 3], bits: 0 };

    fn set(&mut self, lane: usize, origin: Vec3, ns: Vec3, ng: Vec3) {
        for axis in 0..3 {
            self.origin[axis][lane] = origin[axis];
            self.ns[axis][lane] = ns[axis];
            self.ng[axis][lane] = ng[axis];
        }
        self.bits |= 1 << lane;
    }
}

fn load(a: &[[f32; 8]; 3]) -> Vec3x8 {
    Vec3x8::new(F32x8::from_array(a[0]), F32x8::from_array(a[1]), F32x8::from_array(a[2]))
}

/// The shading points of one interleave group and their accumulated D = E/π, in chunks of
/// eight. Keep one per thread and reuse it: [`Receivers::clear`] keeps the memory.
#[derive(Clone, Debug, Default)]
pub struct Receivers {
    chunks: Vec<Chunk>,
    irradiance: Vec<Vec3x8>,
    len: usize,
}

impl Receivers {
    /// Removes every point.
    pub fn clear(&mut self) {
        self.chunks.clear();
        self.irradiance.clear();
        self.len = 0;
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True if there is no point.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Adds a point with its shadow-ray origin and unit shading and geometric normals, both
    /// turned to the side being lit. Points are lit in the order they were added; neighbours
    /// in that order share packets, so add them in a coherent order.
    pub fn push(&mut self, origin: Vec3, ns: Vec3, ng: Vec3) {
        let lane = self.len % 8;
        if lane == 0 {
            // Unoccupied lanes repeat the first point, so every lane of a packet holds a valid
            // ray (the packet kernels decide the traversal order from all lanes' signs).
            let mut chunk = Chunk::EMPTY;
            for l in 0..8 {
                chunk.set(l, origin, ns, ng);
            }
            chunk.bits = 0;
            self.chunks.push(chunk);
            self.irradiance.push(Vec3x8::splat([0.0; 3]));
        }
        if let Some(chunk) = self.chunks.last_mut() {
            chunk.set(lane, origin, ns, ng);
        }
        self.len += 1;
    }

    /// Sets the accumulated D of every point back to zero (the points stay).
    pub fn reset_irradiance(&mut self) {
        self.irradiance.iter_mut().for_each(|d| *d = Vec3x8::splat([0.0; 3]));
    }

    /// D = E/π accumulated at point `i` (in the order of [`Receivers::push`]).
    pub fn irradiance(&self, i: usize) -> Vec3 {
        Vec3::from(self.irradiance[i / 8].lane(i % 8))
    }

    /// Adds the light of the surface VPLs `vpls`, each weighted by `weight`, with the clamp
    /// `d_min2` = d_min² (0 for none).
    pub fn add_vpls<'v>(
        &mut self,
        accel: &Accel,
        vpls: impl Iterator<Item = &'v Vpl>,
        weight: f32,
        d_min2: f32,
        counts: &mut RayCounts,
    ) {
        let d_min2 = F32x8::splat(d_min2);
        for vpl in vpls {
            // The shadow rays end at the VPL lifted off its surface, so that surface does not
            // count as a blocker.
            let target = offset_ray_origin(vpl.position, vpl.normal);
            let colour = vpl.power * (weight * FRAC_1_PI * FRAC_1_PI);
            let y = Vec3x8::splat(target.to_array());
            let ny = Vec3x8::splat(vpl.normal.to_array());
            for (chunk, acc) in self.chunks.iter().zip(self.irradiance.iter_mut()) {
                let origin = load(&chunk.origin);
                let d = y - origin;
                let dist2 = d.dot(d);
                let dist = dist2.sqrt();
                let wi = d * (F32x8::splat(1.0) / dist);
                let cos_x = load(&chunk.ns).dot(wi);
                let cos_y = -ny.dot(wi);
                let zero = F32x8::ZERO;
                let valid = M32x8::from_bitmask(chunk.bits)
                    & cos_x.gt(zero)
                    & cos_y.gt(zero)
                    & load(&chunk.ng).dot(wi).gt(zero);
                if valid.none() {
                    continue;
                }
                let g = cos_x * cos_y / dist2.max(d_min2);
                let packet =
                    RayPacket8 { origin, dir: wi, tnear: zero, tfar: dist * F32x8::splat(SHADOW_SHORTEN) };
                let lit = unoccluded(accel, &packet, valid, counts);
                accumulate(acc, F32x8::select(lit, g, zero), colour);
            }
        }
    }

    /// Adds the exact direct light of point, spot and directional lights.
    pub fn add_lights(&mut self, accel: &Accel, lights: &[Light], counts: &mut RayCounts) {
        let zero = F32x8::ZERO;
        for light in lights {
            for (chunk, acc) in self.chunks.iter().zip(self.irradiance.iter_mut()) {
                let origin = load(&chunk.origin);
                let active = M32x8::from_bitmask(chunk.bits);
                let (wi, tfar, g, colour, mut valid) = match *light {
                    Light::Point { position, intensity } => {
                        let (wi, dist, dist2) = towards(origin, position);
                        (wi, dist, F32x8::splat(1.0) / dist2, intensity * FRAC_1_PI, active & dist2.gt(zero))
                    }
                    Light::Spot { position, direction, angle_deg, intensity } => {
                        let (wi, dist, dist2) = towards(origin, position);
                        let axis = Vec3x8::splat(direction.normalize_or_zero().to_array());
                        let cos_half = F32x8::splat((0.5 * angle_deg.to_radians()).cos());
                        let inside = (-axis.dot(wi)).ge(cos_half);
                        (
                            wi,
                            dist,
                            F32x8::splat(1.0) / dist2,
                            intensity * FRAC_1_PI,
                            active & inside & dist2.gt(zero),
                        )
                    }
                    Light::Directional { direction, irradiance } => {
                        let dir = -direction.normalize_or_zero();
                        if dir == Vec3::ZERO {
                            continue;
                        }
                        let wi = Vec3x8::splat(dir.to_array());
                        (wi, F32x8::splat(f32::INFINITY), F32x8::splat(1.0), irradiance / PI, active)
                    }
                };
                let cos_x = load(&chunk.ns).dot(wi);
                valid = valid & cos_x.gt(zero) & load(&chunk.ng).dot(wi).gt(zero);
                if valid.none() {
                    continue;
                }
                let packet =
                    RayPacket8 { origin, dir: wi, tnear: zero, tfar: tfar * F32x8::splat(SHADOW_SHORTEN) };
                let lit = unoccluded(accel, &packet, valid, counts);
                accumulate(acc, F32x8::select(lit, cos_x * g, zero), colour);
            }
        }
    }
}

/// Unit directions, distances and squared distances from `origin` to the point `p`.
#[inline(always)]
fn towards(origin: Vec3x8, p: Vec3) -> (Vec3x8, F32x8, F32x8) {
    let d = Vec3x8::splat(p.to_array()) - origin;
    let dist2 = d.dot(d);
    let dist = dist2.sqrt();
    (d * (F32x8::splat(1.0) / dist), dist, dist2)
}

/// `acc += g · colour` per lane.
#[inline(always)]
fn accumulate(acc: &mut Vec3x8, g: F32x8, colour: Vec3) {
    *acc = Vec3x8::new(
        g.mul_add(F32x8::splat(colour.x), acc.x),
        g.mul_add(F32x8::splat(colour.y), acc.y),
        g.mul_add(F32x8::splat(colour.z), acc.z),
    );
}

/// The lanes of `valid` whose shadow ray reaches its end. A packet of one ray goes through the
/// single-ray kernel, which is faster for it.
#[inline(always)]
fn unoccluded(accel: &Accel, packet: &RayPacket8, valid: M32x8, counts: &mut RayCounts) -> M32x8 {
    let bits = valid.bitmask();
    counts.shadow += u64::from(bits.count_ones());
    let blocked = if bits.count_ones() == 1 {
        if accel.occluded(&packet.ray(bits.trailing_zeros() as usize)) { valid } else { M32x8::NONE }
    } else {
        accel.occluded8(packet, valid)
    };
    valid.and_not(blocked)
}
