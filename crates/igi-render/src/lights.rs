//! Light sources as the renderer samples them: the table of emissive triangles (area lights)
//! with a power-proportional CDF, and the incident light of point, spot and directional lights.
//!
//! Area lights emit on one side only, toward the triangle's winding normal
//! `(p1 - p0) × (p2 - p0)` (taken through the instance transform like any normal), with
//! constant radiance `emission`. A triangle's power is then `π · area · emission`.
//! The same table starts the light paths of instant radiosity ([`crate::vpl`], paper 2.1) and
//! the path tracer's next-event estimation ([`crate::path_tracer`]).

use crate::sampling::{Cdf, uniform_triangle};
use glam::{Vec2, Vec3};
use igi_bvh::Aabb;
use igi_scene::{Camera, Light};

/// Relative luminance of linear RGB (Rec. 709 primaries).
#[inline]
pub fn luminance(rgb: Vec3) -> f32 {
    0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z
}

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
    /// Emitted radiance toward the front side.
    pub emission: Vec3,
}

impl EmissiveTriangle {
    /// The point with barycentric weights `b` of the second and third corner.
    #[inline]
    pub fn point(&self, b: Vec2) -> Vec3 {
        self.p0 + b.x * self.e1 + b.y * self.e2
    }

    /// Emitted power (flux) per channel: π · area · emission.
    pub fn power(&self) -> Vec3 {
        std::f32::consts::PI * self.area * self.emission
    }
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
}

impl AreaLights {
    /// The table of `triangles`, chosen in proportion to their luminous power
    /// (area × luminance of the emission). Triangles of zero area or emission are dropped.
    pub fn new(triangles: Vec<EmissiveTriangle>) -> Self {
        let triangles: Vec<EmissiveTriangle> = triangles
            .into_iter()
            .filter(|t| t.area > 0.0 && t.area.is_finite() && luminance(t.emission) > 0.0)
            .collect();
        let cdf = Cdf::new(triangles.iter().map(|t| t.area * luminance(t.emission)));
        Self { triangles, cdf }
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
        Some(AreaSample {
            point: tri.point(uniform_triangle(uv)),
            normal: tri.normal,
            emission: tri.emission,
            pdf_area: pmf / tri.area,
            index,
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
