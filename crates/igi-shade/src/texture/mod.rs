//! Image textures as the surface shaders read them: a [`MipMap`] pyramid built once per image,
//! [`Wrap`] modes per axis, and bilinear and trilinear lookups.
//!
//! Texture coordinates follow the scene model (glTF's convention; the OBJ and PLY loaders flip
//! v to match): u to the right, v down, (0, 0) the top-left corner of the image, texel centres
//! at half-integer texel coordinates.

mod mipmap;
mod wrap;

pub use mipmap::{Level, MipMap};
pub use wrap::wrap_texel;
