//! The smooth dielectric (glass) and the perfect mirror: the two delta lobes, which the camera
//! paths, the VPL walk and the path tracer follow as rays instead of lighting them.
//!
//! Glass refracts about the shading normal, so smooth-shaded glass refracts smoothly; its
//! inside is the side opposite the geometric normal, and it does not absorb.

use glam::Vec3;

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
    /// The interface of glass of index `ior` with normal `n` (outside toward `n`) met by the
    /// unit direction `d`.
    pub fn new(d: Vec3, n: Vec3, ior: f32) -> Self {
        let entering = d.dot(n) < 0.0;
        let (normal, eta) = if entering { (n, 1.0 / ior) } else { (-n, ior) };
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
