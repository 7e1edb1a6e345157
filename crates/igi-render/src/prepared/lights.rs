//! Light sources as the renderer samples them: the table of emissive triangles (area lights)
//! with a power-proportional CDF, and the incident light of point, spot and directional lights.
//!
//! Area lights emit on one side only, toward the triangle's winding normal
//! `(p1 - p0) × (p2 - p0)` (taken through the instance transform like any normal), with
//! radiance `emission`, times the emission texture's texel where the material has one
//! (glTF `emissiveTexture`, MTL `map_Ke`). A triangle's power is `π · area · L̄` with L̄ its
//! mean radiance: the texture's integral over the triangle's uv footprint, estimated once by
//! [`footprint_mean`]. Triangles are chosen by that power and points on them uniformly by
//! area; a point carries the texel's radiance there, so Φ = L_e(y)/p_A(y) stays an unbiased
//! estimate wherever the chosen triangle has power (a triangle whose footprint is black is no
//! light at all).
//! The same table starts the light paths of instant radiosity ([`crate::igi::vpl`], paper 2.1) and
//! the path tracer's next-event estimation ([`crate::path_tracer`]).

use crate::image::tonemap::luminance;
use crate::sampling::{Cdf, uniform_triangle};
use glam::{Vec2, Vec3};
use igi_bvh::Aabb;
use igi_scene::{Camera, Light};
use igi_shade::texture::MipMap;
use std::collections::HashMap;
use std::sync::Arc;

/// One emissive triangle in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissiveTriangle {
    /// Instance the triangle belongs to.
    pub instance: u32,
    /// Triangle index in the instance's mesh (stored, BVH leaf order).
    pub prim: u32,
    /// First corner (world space).
    pub p0: Vec3,
    /// Second corner minus the first (world space).
    pub e1: Vec3,
    /// Third corner minus the first (world space).
    pub e2: Vec3,
    /// Unit normal of the emitting side (world space).
    pub normal: Vec3,
    /// Area in world units squared.
    pub area: f32,
    /// Emitted radiance toward the front side: the material's `emission`, which the texture
    /// (if any) multiplies per texel.
    pub emission: Vec3,
    /// The emission texture and where the triangle lies on it.
    pub texture: Option<EmissionMap>,
    /// Mean emitted radiance over the triangle: `emission`, times the texture's
    /// [`footprint_mean`] for a textured one.
    pub mean_emission: Vec3,
}

/// Where an emissive triangle lies on its emission texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmissionMap {
    /// Index of the texture among the scene's textures.
    pub texture: u32,
    /// Texture coordinates of the three corners.
    pub uvs: [Vec2; 3],
}

impl EmissionMap {
    /// The texture coordinates at barycentric weights `b` of the second and third corner.
    #[inline]
    pub fn uv(&self, b: Vec2) -> Vec2 {
        let [t0, t1, t2] = self.uvs;
        t0 + b.x * (t1 - t0) + b.y * (t2 - t0)
    }
}

impl EmissiveTriangle {
    /// The point with barycentric weights `b` of the second and third corner.
    #[inline]
    pub fn point(&self, b: Vec2) -> Vec3 {
        self.p0 + b.x * self.e1 + b.y * self.e2
    }

    /// Emitted power (flux) per channel: π · area · mean radiance.
    pub fn power(&self) -> Vec3 {
        std::f32::consts::PI * self.area * self.mean_emission
    }
}

/// Stratified points per triangle of [`footprint_mean`] (a 4 × 4 grid).
const FOOTPRINT_STRATA: u32 = 4;

/// The mean RGB of `map` over the triangle with corner texture coordinates `uvs`: the mean
/// of 16 stratified points (a 4 × 4 grid of the unit square, carried onto the triangle by the
/// area-preserving [`uniform_triangle`]), each read at the pyramid level whose texels are as
/// large as the triangle's footprint per point, so that the box-filtered levels average the
/// texels between the points too (Williams 1983) and a small texture feature inside the
/// triangle is not missed.
pub fn footprint_mean(map: &MipMap, uvs: [Vec2; 3]) -> Vec3 {
    let (width, height) = map.size();
    let [t0, t1, t2] = uvs;
    let texels = 0.5 * (t1 - t0).perp_dot(t2 - t0).abs() * width as f32 * height as f32;
    let n = FOOTPRINT_STRATA * FOOTPRINT_STRATA;
    let lod = map.lod((texels / n as f32).sqrt());
    let mut sum = Vec3::ZERO;
    for j in 0..FOOTPRINT_STRATA {
        for i in 0..FOOTPRINT_STRATA {
            let cell = (Vec2::new(i as f32, j as f32) + 0.5) / FOOTPRINT_STRATA as f32;
            let b = uniform_triangle(cell);
            sum += map.trilinear(t0 + b.x * (t1 - t0) + b.y * (t2 - t0), lod).truncate();
        }
    }
    sum / n as f32
}

/// The headlight for a scene without lights: a point light at the camera position whose
/// intensity (d² with d the distance from the camera to the centre of the scene's `bounds`, at
/// least 1) gives irradiance about 1 at the scene's centre.
pub fn eye_light(bounds: &Aabb, camera: &Camera) -> Light {
    let b = bounds;
    let d2 = if b.is_empty() { 1.0 } else { (b.centroid() - camera.position).length_squared().max(1.0) };
    Light::Point { position: camera.position, intensity: Vec3::splat(d2) }
}

/// A point chosen on an area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaSample {
    /// The point (world space).
    pub point: Vec3,
    /// Unit normal of the emitting side there.
    pub normal: Vec3,
    /// Emitted radiance toward the front side.
    pub emission: Vec3,
    /// Probability density of having chosen this point, per unit area, over all area lights
    /// (the triangle's selection probability divided by its area).
    pub pdf_area: f32,
    /// Index of the triangle in [`AreaLights::triangles`].
    pub index: usize,
}

/// All emissive triangles of a scene and a distribution to choose among them by power.
#[derive(Clone, Debug, Default)]
pub struct AreaLights {
    triangles: Vec<EmissiveTriangle>,
    cdf: Cdf,
    /// The scene's texture pyramids, indexed by texture ([`EmissionMap::texture`]).
    maps: Vec<Option<Arc<MipMap>>>,
    /// (instance, stored triangle) → index in `triangles`.
    index: HashMap<(u32, u32), u32>,
}

impl AreaLights {
    /// The table of `triangles`, chosen in proportion to their luminous power
    /// (area × luminance of the mean emission); their emission textures are among `maps`.
    /// Triangles of zero area or mean emission are dropped: nothing could be sampled on them.
    pub fn new(triangles: Vec<EmissiveTriangle>, maps: Vec<Option<Arc<MipMap>>>) -> Self {
        let triangles: Vec<EmissiveTriangle> = triangles
            .into_iter()
            .filter(|t| t.area > 0.0 && t.area.is_finite() && luminance(t.mean_emission) > 0.0)
            .collect();
        let cdf = Cdf::new(triangles.iter().map(|t| t.area * luminance(t.mean_emission)));
        let index = triangles.iter().enumerate().map(|(i, t)| ((t.instance, t.prim), i as u32)).collect();
        Self { triangles, cdf, maps, index }
    }

    /// The emissive triangles.
    pub fn triangles(&self) -> &[EmissiveTriangle] {
        &self.triangles
    }

    /// True if the scene has no area light.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Total emitted power per channel.
    pub fn total_power(&self) -> Vec3 {
        self.triangles.iter().map(EmissiveTriangle::power).sum()
    }

    /// A point on the area lights from three numbers in [0, 1): `select` picks the triangle
    /// (by power), `uv` the point on it (uniform by area). `None` if there is no area light.
    pub fn sample(&self, select: f32, uv: Vec2) -> Option<AreaSample> {
        if self.triangles.is_empty() {
            return None;
        }
        let (index, pmf) = self.cdf.sample(select);
        let tri = &self.triangles[index];
        let b = uniform_triangle(uv);
        Some(AreaSample {
            point: tri.point(b),
            normal: tri.normal,
            emission: self.emission_at(tri, b),
            pdf_area: pmf / tri.area,
            index,
        })
    }

    /// The radiance `tri` emits at barycentric weights `b`: its emission times the texel of
    /// its texture there (full resolution, as every lookup without a camera footprint).
    #[inline]
    pub fn emission_at(&self, tri: &EmissiveTriangle, b: Vec2) -> Vec3 {
        match tri.texture.and_then(|t| Some((t, self.maps.get(t.texture as usize)?.as_ref()?))) {
            Some((texture, map)) => tri.emission * map.bilinear(texture.uv(b), 0).truncate(),
            None => tri.emission,
        }
    }

    /// The density per unit area with which [`AreaLights::sample`] picks points of stored
    /// triangle `prim` of `instance`: its selection probability over its area, 0 if it is no
    /// light (the path tracer weighs emitters its BSDF samples hit against it).
    pub fn pdf_area(&self, instance: u32, prim: u32) -> f32 {
        self.index.get(&(instance, prim)).map_or(0.0, |&i| {
            let i = i as usize;
            self.cdf.pmf(i) / self.triangles[i].area
        })
    }
}

/// Light arriving at a point from a punctual or distant light, before visibility.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incident {
    /// Unit direction from the point toward the light.
    pub dir: Vec3,
    /// Distance to the light (infinite for a directional light).
    pub distance: f32,
    /// Position of the light (`None` for a directional light).
    pub position: Option<Vec3>,
    /// Irradiance on a surface facing the light: I / d² for point and spot lights, E for a
    /// directional light. Multiply by cos θ and the BRDF for reflected radiance.
    pub irradiance: Vec3,
}

/// Shadow rays toward a light or a VPL stop this fraction short of it, so that the surface it
/// lies on does not block them.
pub const SHADOW_SHORTEN: f32 = 1.0 - 1e-4;

/// The hard-edged cone of a spot light: full intensity where the angle to the axis is at most
/// half of the light's `angle_deg`, nothing outside (no smooth falloff).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotCone {
    /// Unit axis, the direction the light points in (zero for a zero direction, which lights
    /// nothing).
    pub axis: Vec3,
    /// Cosine of the half angle.
    pub cos_half: f32,
}

impl SpotCone {
    /// The cone of a spot light pointing along `direction` with full opening angle `angle_deg`.
    #[inline]
    pub fn new(direction: Vec3, angle_deg: f32) -> Self {
        Self { axis: direction.normalize_or_zero(), cos_half: (0.5 * angle_deg.to_radians()).cos() }
    }
}

/// The light `light` sends toward the point `x`, ignoring occlusion; `None` if it sends
/// nothing (outside a spot cone, or at the light's own position).
pub fn incident(light: &Light, x: Vec3) -> Option<Incident> {
    match *light {
        Light::Point { position, intensity } => towards_point(x, position, intensity),
        Light::Spot { position, direction, angle_deg, intensity } => {
            let inc = towards_point(x, position, intensity)?;
            let cone = SpotCone::new(direction, angle_deg);
            (cone.axis.dot(-inc.dir) >= cone.cos_half).then_some(inc)
        }
        Light::Directional { direction, irradiance } => {
            let dir = -direction.normalize_or_zero();
            (dir != Vec3::ZERO).then_some(Incident {
                dir,
                distance: f32::INFINITY,
                position: None,
                irradiance,
            })
        }
    }
}

fn towards_point(x: Vec3, position: Vec3, intensity: Vec3) -> Option<Incident> {
    let d = position - x;
    let d2 = d.length_squared();
    if d2 <= 0.0 || !d2.is_finite() {
        return None;
    }
    let distance = d2.sqrt();
    Some(Incident { dir: d / distance, distance, position: Some(position), irradiance: intensity / d2 })
}
