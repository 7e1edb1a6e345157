//! Programmable shading (paper 3.2, Figure 3): the shading model is split in two so the
//! expensive part stays fast.
//!
//! - **Surface shaders** ([`SurfaceShader`]) turn a hit (position, normals, texture
//!   coordinates, tangents, object, time) into [`BrdfParams`]: albedo, glossy colour and
//!   exponent, mirror and glass weights, index of refraction, shading normal and emission.
//!   They are arbitrary code (textures, procedural noise, bump mapping) and run once per hit,
//!   eight hits at a time, over all hits of an interleave group before the VPL loop.
//! - **BRDF shaders** ([`brdf`]) are a small fixed set (Lambert, modified Phong, the glTF
//!   GGX lobe, perfect mirror, smooth dielectric) that read those parameters inside the VPL loop, eight shading
//!   points per packet, and that sample directions for the VPL random walk and the path
//!   tracer.

pub mod brdf;
pub mod bump;
mod hit;
mod material_shader;
pub mod noise;
mod params;
pub mod procedural;
mod shader_table;
mod surface_shader;
pub mod texture;

pub use hit::ShadingHit8;
pub use material_shader::MaterialShader;
pub use params::{BrdfParams, BrdfParams8, GlossyModel, MIN_ALPHA};
pub use procedural::ProceduralShader;
pub use shader_table::ShaderTable;
pub use surface_shader::SurfaceShader;

/// The README's Rust examples (a surface shader of one's own), compiled as doctests so that
/// they keep working.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
struct ReadmeExamples;
