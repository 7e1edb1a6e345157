//! The turbulence pattern: t = clamp(T(q), 0, 1) with T Perlin's turbulence (sum of |noise|
//! over `octaves` octaves); the bump height is T.

use igi_simd::Vec3x8;

use super::{Sample, saturate};
use crate::noise::{turbulence3x8, turbulence3x8_grad};

/// Turbulence blending the colours.
pub(super) fn sample(q: Vec3x8, octaves: u32, bump: bool) -> Sample {
    if bump {
        let (t, g) = turbulence3x8_grad(q, octaves);
        Sample { t: saturate(t), height_gradient: Some(g) }
    } else {
        Sample { t: saturate(turbulence3x8(q, octaves)), height_gradient: None }
    }
}
