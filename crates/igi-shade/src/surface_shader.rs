//! The [`SurfaceShader`] trait: the programmable half of shading (paper 3.2).

use crate::{BrdfParams, BrdfParams8, ShadingHit8};

/// Computes the BRDF parameters of surface hits: textures, procedural patterns, bump and
/// normal maps, anything a user writes in Rust. The renderer calls it over all hits of an
/// interleave group before the VPL loop (streaming), eight hits of one material at a time.
///
/// A shader must be deterministic (the same hit gives the same parameters, on any thread and
/// in any frame at the same time), so that a still scene does not flicker and images do not
/// depend on the thread count. The renderer makes the result energy-conserving
/// ([`crate::BrdfParams::conserving`]) and turns shading normals to the side of the
/// geometric normal, so a shader need not.
///
/// ```
/// use igi_shade::{BrdfParams8, ShadingHit8, SurfaceShader};
/// use igi_simd::{F32x8, Vec3x8};
///
/// /// Red and white stripes along world x, ten per unit.
/// #[derive(Debug)]
/// struct Stripes;
///
/// impl SurfaceShader for Stripes {
///     fn shade(&self, hits: &ShadingHit8, out: &mut BrdfParams8) {
///         let x = hits.position.x * F32x8::splat(5.0);
///         let red = (x - x.floor()).lt(F32x8::splat(0.5));
///         let g = F32x8::select(red, F32x8::splat(0.1), F32x8::splat(0.8));
///         out.diffuse = Vec3x8::new(F32x8::splat(0.8), g, g);
///     }
/// }
/// ```
pub trait SurfaceShader: Send + Sync + std::fmt::Debug {
    /// Writes the parameters of the active lanes of `hits` into `out`, which arrives holding
    /// black, non-emitting surfaces with the interpolated shading normals
    /// ([`BrdfParams8::black`]); what a shader leaves alone stays so.
    fn shade(&self, hits: &ShadingHit8, out: &mut BrdfParams8);

    /// The parameters this shader gives every hit, if they do not depend on the hit (a
    /// constant material), with the shading normal left to the interpolated normal (the value
    /// of `shading_normal` here is ignored). The renderer then skips the 8-wide call for such
    /// materials; it must agree with [`SurfaceShader::shade`].
    fn uniform(&self) -> Option<BrdfParams> {
        None
    }
}
