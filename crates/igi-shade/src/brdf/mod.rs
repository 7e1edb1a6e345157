//! The BRDF shaders (paper 3.2): a small fixed set of lobes, evaluated eight shading points at
//! a time inside the VPL loop and sampled one direction at a time by the VPL random walk and
//! the path tracer. Directions are unit vectors pointing away from the surface unless a
//! function says otherwise.
//!
//! - [`lambert`](mod@lambert): ρ/π, sampled by the cosine.
//! - [`phong`]: the energy-conserving modified Phong lobe (MTL, scene files).
//! - [`ggx`]: the GGX microfacet lobe of glTF metallic-roughness materials, with Smith
//!   masking, Schlick Fresnel and its Fresnel-weighted diffuse lobe.
//! - [`dielectric`]: the perfect mirror and the smooth dielectric with Fresnel.
//! - [`bsdf`]: their weighted sum at one point, evaluated and sampled.

pub mod bsdf;
pub mod dielectric;
pub mod ggx;
pub mod lambert;
pub mod phong;

pub use bsdf::{Bsdf, BsdfSample, Lobe};
pub use lambert::{cosine_hemisphere, lambert};
