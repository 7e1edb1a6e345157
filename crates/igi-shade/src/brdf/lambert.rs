//! The Lambertian lobe: f = ρ/π, the same for every pair of directions, sampled with density
//! cos θ / π so that its estimator weight is simply ρ.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};

/// The Lambertian BRDF value ρ/π.
#[inline]
pub fn lambert(rho: Vec3) -> Vec3 {
    rho * FRAC_1_PI
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

/// The density of [`cosine_hemisphere`] at a direction whose cosine to the normal is `cos`.
#[inline]
pub fn cosine_hemisphere_pdf(cos: f32) -> f32 {
    cos.max(0.0) * FRAC_1_PI
}
