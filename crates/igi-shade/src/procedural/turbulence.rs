//! The turbulence pattern: t = clamp(T(q), 0, 1) with T Perlin's turbulence (sum of |noise|
//! over `octaves` octaves); the bump height is T.

use igi_simd::Vec3x8;

use super::{Sample, saturate};
use crate::noise::{turbulence3, turbulence3_grad};

/// Turbulence blending the colours.
pub(super) fn sample(q: Vec3x8, octaves: u32, bump: bool) -> Sample {
    if bump {
        let (t, g) = turbulence3_grad(q.into(), octaves);
        Sample { t: saturate(t), height_gradient: Some(g.into()) }
    } else {
        Sample { t: saturate(turbulence3(q.into(), octaves)), height_gradient: None }
    }
}
