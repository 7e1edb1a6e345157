//! Bricks in mortar, running bond, as a solid texture: q is cut into cells of `size`
//! (length along x, height along y, depth along z); every other row (odd floor(y / height)) is
//! shifted by half a brick in x and in z, so both a wall facing z and one facing x show a bond.
//! Colour 0 is brick, colour 1 mortar. A flat wall facing z (or x) shows clean courses when it
//! lies a quarter cell from the joint planes, z / size.z ≡ ¼ or ¾ (mod 1), so that neither the
//! even nor the shifted odd rows cut it at a depth joint.
//!
//! Height field: in each cell, along each axis, the distance d to the nearest joint plane
//! gives a profile s(clamp((d − mortar/2) / bevel, 0, 1)) with s the smoothstep 3t² − 2t³ and
//! bevel = mortar / 2; h is the product of the three profiles. So h = 1 on the brick faces
//! (flat: the normal is unchanged), h = 0 in the mortar (recessed by `bump`), and between them
//! a C¹ bevel, where the normal is defined and tilts toward the joint. The blend factor is
//! t = 1 − h: the bevel fades from brick colour to mortar colour.

use glam::Vec3;
use igi_simd::{F32x8, I32x8, Vec3x8};

use super::{Sample, saturate};

/// One axis: the profile and its derivative along the axis, for a coordinate `c` (in units of
/// the cell edge `len`) already shifted by the row's bond offset.
fn profile(c: F32x8, len: f32, half_mortar: f32, bevel: f32) -> (F32x8, F32x8) {
    let f = c - c.floor();
    // Distance to the nearer joint plane, in pattern units, and which way it grows.
    let to_far = F32x8::splat(1.0) - f;
    let near_low = f.lt(to_far);
    let d = F32x8::select(near_low, f, to_far) * F32x8::splat(len);
    let dd = F32x8::select(near_low, F32x8::splat(1.0), F32x8::splat(-1.0));
    let t = saturate((d - F32x8::splat(half_mortar)) * F32x8::splat(1.0 / bevel));
    let s = t * t * F32x8::splat(-2.0).mul_add(t, F32x8::splat(3.0));
    // ds/dq = 6t(1 − t) / bevel · dd/dq (zero outside the bevel, where t is clamped).
    let ds = F32x8::splat(6.0 / bevel) * t * (F32x8::splat(1.0) - t) * dd;
    (s, ds)
}

/// Bricks of `size` with joints `mortar` wide (pattern units).
pub(super) fn sample(q: Vec3x8, size: Vec3, mortar: f32, bump: bool) -> Sample {
    let size = size.max(Vec3::splat(1e-6));
    let half_mortar = 0.5 * mortar.max(0.0);
    let bevel = (0.5 * mortar).max(1e-4);
    let row = (q.y * F32x8::splat(1.0 / size.y)).floor();
    // Half a brick on odd rows (two's complement parity works for negative rows too).
    let shift = (row.to_i32() & I32x8::splat(1)).to_f32() * F32x8::splat(0.5);
    let (sx, dx) = profile(q.x.mul_add(F32x8::splat(1.0 / size.x), shift), size.x, half_mortar, bevel);
    let (sy, dy) = profile(q.y * F32x8::splat(1.0 / size.y), size.y, half_mortar, bevel);
    let (sz, dz) = profile(q.z.mul_add(F32x8::splat(1.0 / size.z), shift), size.z, half_mortar, bevel);
    let h = sx * sy * sz;
    let height_gradient = bump.then(|| Vec3x8::new(dx * sy * sz, sx * dy * sz, sx * sy * dz));
    Sample { t: F32x8::splat(1.0) - h, height_gradient }
}
