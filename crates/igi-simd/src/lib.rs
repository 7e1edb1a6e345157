//! Eight-lane SIMD types for the ray-tracing kernels: [`F32x8`], [`I32x8`], the lane mask
//! [`M32x8`] and the structure-of-arrays vector [`Vec3x8`].
//!
//! Two backends implement the same API. On x86_64 built with AVX2 and FMA (the workspace builds
//! for x86-64-v3) the types wrap `__m256`/`__m256i` and every operation is one or two AVX2
//! instructions. Everywhere else, or with the `portable` feature, they are plain arrays and the
//! compiler vectorises what it can. Both backends give bit-identical results for every
//! operation, and each lane equals the scalar `f32` operation (`F32x8::mul_add` equals
//! `f32::mul_add`: one rounding). [`Lanes`] writes a kernel once for `f32` and for [`F32x8`].

#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma",
    not(feature = "portable")
))]
mod avx2;
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma",
    not(feature = "portable")
))]
pub use avx2::{F32x8, I32x8, M32x8};

#[cfg(not(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma",
    not(feature = "portable")
)))]
mod portable;
#[cfg(not(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma",
    not(feature = "portable")
)))]
pub use portable::{F32x8, I32x8, M32x8};

mod lanes;
mod math;
mod vec3x8;
pub use lanes::{LaneMask, Lanes};
pub use vec3x8::Vec3x8;

/// Name of the backend compiled in: `"avx2"` or `"portable"`.
pub const BACKEND: &str = if cfg!(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma",
    not(feature = "portable")
)) {
    "avx2"
} else {
    "portable"
};

#[cfg(test)]
mod tests;
