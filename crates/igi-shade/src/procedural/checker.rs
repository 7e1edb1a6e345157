//! The checker pattern: unit cubes of q alternate between colour 0 (even floor(x) + floor(y) +
//! floor(z)) and colour 1 (odd). It is flat, so it has no bump.

use igi_simd::{I32x8, Vec3x8};

use super::Sample;

/// Blend factor 0 or 1 by the parity of the cube q lies in.
pub(super) fn sample(q: Vec3x8) -> Sample {
    let sum = q.x.floor().to_i32() + q.y.floor().to_i32() + q.z.floor().to_i32();
    // Two's complement: the low bit is the parity of negative sums as well.
    Sample { t: (sum & I32x8::splat(1)).to_f32(), height_gradient: None }
}
