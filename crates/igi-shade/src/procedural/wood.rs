//! Wood: concentric growth rings around the y axis, t = band(rings · r + k · n(q)) with r the
//! distance from the axis and n improved noise (one octave) bending the rings; the bump height
//! is n, whose gradient comes with the value.

use igi_simd::{F32x8, Vec3x8};

use super::{Sample, band};
use crate::noise::{noise3, noise3_grad};

/// Rings of wood: `rings` per unit radius, bent by noise of strength `k`.
pub(super) fn sample(q: Vec3x8, rings: f32, k: f32, bump: bool) -> Sample {
    let (n, height_gradient) = if bump {
        let (n, g) = noise3_grad(q.into());
        (n, Some(g.into()))
    } else {
        (noise3(q.into()), None)
    };
    let r = q.x.mul_add(q.x, q.z * q.z).sqrt();
    Sample { t: band(n.mul_add(F32x8::splat(k), r * F32x8::splat(rings))), height_gradient }
}
