//! The Lambertian lobe: f = ρ/π, the same in every direction pair.

use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

/// The Lambertian BRDF value ρ/π.
#[inline]
pub fn lambert(rho: Vec3) -> Vec3 {
    rho * FRAC_1_PI
}
