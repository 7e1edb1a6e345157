//! Marble (Perlin 1985's classic, as in Figure 3 of the paper): veins running across x, bent by
//! turbulence, t = band(x + k · T(q)) with T the turbulence of `octaves` octaves and band the
//! smooth periodic profile of [`super::band`] in place of Perlin's sine. The bump height is
//! T itself, so the gradient comes with the turbulence at no extra hashing.

use igi_simd::Vec3x8;

use super::{Sample, band};
use crate::noise::{turbulence3, turbulence3_grad};

/// Veins of marble; `k` is the turbulence strength.
pub(super) fn sample(q: Vec3x8, octaves: u32, k: f32, bump: bool) -> Sample {
    let (turb, height_gradient) = if bump {
        let (t, g) = turbulence3_grad(q.into(), octaves);
        (t, Some(g.into()))
    } else {
        (turbulence3(q.into(), octaves), None)
    };
    Sample { t: band(turb.mul_add(igi_simd::F32x8::splat(k), q.x)), height_gradient }
}
