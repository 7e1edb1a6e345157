//! How a surface scatters light, as every estimator of this crate reads a material: the VPL
//! random walk, the IGI tile pipeline and the reference path tracer use these functions, so
//! they agree on the physics they estimate.
//!
//! - [`MaterialKind::Plastic`]: Lambertian with reflectance ρ = diffuse × texture. Its Phong
//!   lobe (`specular`, `exponent`) is not evaluated yet (the BRDF shaders of the shading issue
//!   add it); both estimators ignore it alike.
//! - [`MaterialKind::Mirror`]: perfect specular reflection with reflectance `specular` (white
//!   if the material gives none).
//! - [`MaterialKind::Glass`]: a smooth dielectric of index `ior` (1.5 if unset): Fresnel
//!   reflection and refraction about the shading normal (so smooth-shaded glass refracts
//!   smoothly), no absorption; the inside is the side opposite the normal.
//!
//! Every surface reflects on both sides; a triangle emits only toward its winding normal.

use glam::{Vec2, Vec3};
use igi_scene::{Material, MaterialKind};
use std::f32::consts::PI;

/// The scattering of a material at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scattering {
    /// Lambertian reflection, BRDF ρ/π.
    Diffuse {
        /// Reflectance ρ per channel.
        albedo: Vec3,
    },
    /// Perfect mirror.
    Mirror {
        /// Reflectance per channel.
        reflectance: Vec3,
    },
    /// Smooth dielectric.
    Glass {
        /// Index of refraction of the inside (the side opposite the winding normal).
        ior: f32,
    },
}

impl Scattering {
    /// The scattering of `material` where its diffuse reflectance (diffuse × texture) is
    /// `albedo`.
    pub fn of(material: &Material, albedo: Vec3) -> Self {
        match material.kind {
            MaterialKind::Plastic => Self::Diffuse { albedo },
            MaterialKind::Mirror => Self::Mirror {
                reflectance: if material.specular.max_element() > 0.0 {
                    material.specular
                } else {
                    Vec3::ONE
                },
            },
            MaterialKind::Glass => Self::Glass {
                ior: if material.ior > 0.0 && material.ior != 1.0 { material.ior } else { 1.5 },
            },
        }
    }

    /// True for mirror and glass, which the camera path follows instead of shading.
    pub fn is_specular(&self) -> bool {
        !matches!(self, Self::Diffuse { .. })
    }
}

/// Fresnel reflectance of a smooth dielectric for unpolarised light, with `cos_i` the cosine
/// of the incident angle (positive) and `eta` = n_incident / n_transmitted. Returns 1 under
/// total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_s = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_p = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_s * r_s + r_p * r_p)
}

/// The mirror direction of `d` (pointing at the surface) about the unit normal `n`.
#[inline]
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

/// The refracted direction of the unit direction `d` (pointing at the surface) through the
/// unit normal `n` facing against `d`, with `eta` = n_incident / n_transmitted; `None` under
/// total internal reflection.
#[inline]
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((eta * d + (eta * cos_i - cos_t) * n).normalize())
}

/// A dielectric interface as seen by a ray: which way its normal faces and the ratio of
/// indices across it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interface {
    /// Unit normal on the ray's side.
    pub normal: Vec3,
    /// n_incident / n_transmitted.
    pub eta: f32,
    /// Fresnel reflectance for this ray.
    pub reflectance: f32,
}

impl Interface {
    /// The interface of glass of index `ior` with geometric normal `ng` (outside toward the
    /// winding normal) met by the unit direction `d`.
    pub fn new(d: Vec3, ng: Vec3, ior: f32) -> Self {
        let entering = d.dot(ng) < 0.0;
        let (normal, eta) = if entering { (ng, 1.0 / ior) } else { (-ng, ior) };
        Self { normal, eta, reflectance: fresnel_dielectric(-d.dot(normal), eta) }
    }
}

/// The side of the geometric surface (unit normal `ng`) a ray continuing a glass interaction
/// must leave from: a reflection (`reflected`) stays on the side the incoming direction `d_in`
/// arrived from, a refraction crosses. Glass refracts about the shading normal, so where it
/// is bent the continuation `d_out` can point to the wrong side; then `None` (the path ends).
pub fn glass_exit_side(d_in: Vec3, d_out: Vec3, ng: Vec3, reflected: bool) -> Option<Vec3> {
    let arriving = if d_in.dot(ng) < 0.0 { ng } else { -ng };
    let side = if reflected { arriving } else { -arriving };
    (d_out.dot(side) > 0.0).then_some(side)
}

/// A unit vector on the hemisphere around the unit normal `n`, distributed with density
/// cos θ / π (Malley's method), from a point of the unit square.
pub fn cosine_hemisphere(n: Vec3, u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let (t, b) = n.any_orthonormal_pair();
    let z = (1.0 - u.x).max(0.0).sqrt();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * z).normalize()
}

/// A unit vector uniformly distributed on the sphere (density 1 / 4π).
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A unit vector uniformly distributed in the cone of directions within angle acos(`cos_max`)
/// of the unit axis `axis` (density 1 / (2π (1 − cos_max))).
pub fn uniform_cone(axis: Vec3, cos_max: f32, u: Vec2) -> Vec3 {
    let z = 1.0 - u.x * (1.0 - cos_max);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let (t, b) = axis.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + axis * z).normalize()
}

/// A point uniformly distributed on the unit disc (concentric mapping, Shirley & Chiu 1997).
pub fn concentric_disc(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, PI / 4.0 * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_at_normal_incidence_and_total_reflection() {
        // ((n1 - n2) / (n1 + n2))² = 0.04 for glass of index 1.5.
        assert!((fresnel_dielectric(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert_eq!(fresnel_dielectric(0.1, 1.5), 1.0);
        assert!((fresnel_dielectric(0.0, 1.0 / 1.5) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn refraction_obeys_snell() {
        let n = Vec3::Y;
        let d = Vec3::new(0.6, -0.8, 0.0);
        let t = refract(d, n, 1.0 / 1.5).unwrap();
        let sin_i = d.x;
        let sin_t = t.x;
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-6);
        assert!(t.y < 0.0);
        assert!(refract(Vec3::new(0.9, -(1.0f32 - 0.81).sqrt(), 0.0), n, 1.5).is_none());
    }

    #[test]
    fn interface_flips_for_rays_leaving_the_glass() {
        let inside = Interface::new(Vec3::Y, Vec3::Y, 1.5);
        assert_eq!(inside.normal, -Vec3::Y);
        assert_eq!(inside.eta, 1.5);
        let outside = Interface::new(-Vec3::Y, Vec3::Y, 1.5);
        assert_eq!(outside.normal, Vec3::Y);
        assert!((outside.eta - 1.0 / 1.5).abs() < 1e-7);
    }

    #[test]
    fn cosine_hemisphere_has_mean_cosine_two_thirds() {
        // E[cos θ] under the density cos θ / π is 2/3.
        let n = Vec3::new(1.0, 2.0, -0.5).normalize();
        let k = 64;
        let mut sum = 0.0;
        for i in 0..k {
            for j in 0..k {
                let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                let d = cosine_hemisphere(n, u);
                assert!((d.length() - 1.0).abs() < 1e-5 && d.dot(n) >= 0.0);
                sum += d.dot(n);
            }
        }
        assert!((sum / (k * k) as f32 - 2.0 / 3.0).abs() < 1e-3);
    }

    #[test]
    fn sphere_cone_and_disc_samples_stay_in_their_domains() {
        let axis = Vec3::new(0.0, -1.0, 1.0).normalize();
        for i in 0..32 {
            for j in 0..32 {
                let u = Vec2::new(i as f32 / 32.0, j as f32 / 32.0);
                assert!((uniform_sphere(u).length() - 1.0).abs() < 1e-5);
                assert!(uniform_cone(axis, 0.9, u).dot(axis) >= 0.9 - 1e-5);
                assert!(concentric_disc(u).length() <= 1.0 + 1e-6);
            }
        }
    }
}
