//! The [`SurfaceShader`] trait: the programmable half of shading (paper 3.2).

use crate::{BrdfParams8, ShadingHit8};

/// Computes the BRDF parameters of surface hits: textures, procedural patterns, bump and
/// normal maps, anything a user writes in Rust. The renderer calls it over all hits of an
/// interleave group before the VPL loop (streaming), eight hits of one material at a time.
///
/// A shader must be deterministic (the same hit gives the same parameters, on any thread and
/// in any frame at the same time), so that a still scene does not flicker and images do not
/// depend on the thread count. The renderer makes the result energy-conserving
/// ([`crate::BrdfParams::conserving`]) and turns shading normals to the side of the
/// geometric normal, so a shader need not.
pub trait SurfaceShader: Send + Sync + std::fmt::Debug {
    /// Writes the parameters of the active lanes of `hits` into `out`, which arrives holding
    /// black, non-emitting surfaces with the interpolated shading normals
    /// ([`BrdfParams8::black`]); what a shader leaves alone stays so.
    fn shade(&self, hits: &ShadingHit8, out: &mut BrdfParams8);
}
