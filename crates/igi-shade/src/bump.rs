//! Bump mapping (Blinn 1978): a height map displaces the surface along its normal for shading
//! only. With displacement d(u, v) = s · h(u, v) the displaced surface has the tangents
//!
//! ```text
//! ∂p'/∂u ≈ ∂p/∂u + ∂d/∂u · n,     ∂p'/∂v ≈ ∂p/∂v + ∂d/∂v · n
//! ```
//!
//! (dropping the term in ∂n/∂u, small for smooth geometry, as pbrt does), and its normal is
//! their cross product. The derivatives of h are those of the bilinear interpolant at the
//! mipmap level the footprint selects, so the bumps are filtered like the colour.
//!
//! Height maps store h in [0, 1] without a unit, so the height scale s is relative:
//! [`BUMP_HEIGHT`] times the world size of the texture's [0, 1]² tile (the square root of
//! |∂p/∂u × ∂p/∂v|). Bumps then look the same whatever the scene's unit.

use crate::texture::MipMap;
use glam::{Vec2, Vec3};

/// Height of a full-range bump (h from 0 to 1) as a fraction of the world size of the
/// texture's tile.
pub const BUMP_HEIGHT: f32 = 0.004;

/// The shading normal of a surface with unit normal `n` and tangents `dpdu`, `dpdv`, bumped by
/// the height map `heights` (the mean of its RGB) at `uv`, level of detail `lod` (rounded to
/// a level). The height's derivatives are those of the bilinear patch around `uv`, one
/// lookup of four texels. Returns `n` where the tangents are degenerate.
pub fn bump_normal(heights: &MipMap, uv: Vec2, lod: f32, n: Vec3, dpdu: Vec3, dpdv: Vec3) -> Vec3 {
    if !uv.is_finite() {
        return n;
    }
    let (_, d_du, d_dv) = heights.level(lod).bilinear_gradient(uv, heights.wrap());
    let mean = Vec3::splat(1.0 / 3.0);
    let (dh_du, dh_dv) = (d_du.truncate().dot(mean), d_dv.truncate().dot(mean));
    let scale = BUMP_HEIGHT * dpdu.cross(dpdv).length().sqrt();
    let bumped = (dpdu + scale * dh_du * n).cross(dpdv + scale * dh_dv * n);
    let bumped = bumped.normalize_or_zero();
    if bumped == Vec3::ZERO || !bumped.is_finite() {
        return n;
    }
    if bumped.dot(n) < 0.0 { -bumped } else { bumped }
}

#[cfg(test)]
mod tests {
    use super::*;
    use igi_scene::{Texture, Wrap};

    fn ramp(width: u32, slope_per_texel: f32) -> MipMap {
        let texels = (0..width * 4)
            .map(|i| {
                let x = (i % width) as f32;
                [x * slope_per_texel; 4]
            })
            .collect();
        MipMap::new(&Texture { wrap: [Wrap::Clamp; 2], ..Texture::from_linear("ramp", width, 4, texels) })
    }

    #[test]
    fn a_linear_ramp_tilts_the_normal_by_its_slope() {
        // A unit square tile (|dpdu × dpdv| = 1) with h rising 0.01 per texel along u over 64
        // texels: ∂h/∂u = 0.64, displacement slope s·0.64 with s = BUMP_HEIGHT; the normal
        // tilts against +u by atan(slope).
        let m = ramp(64, 0.01);
        let n = bump_normal(&m, Vec2::new(0.4, 0.5), 0.0, Vec3::Z, Vec3::X, Vec3::Y);
        let slope = BUMP_HEIGHT * 0.64;
        let want = Vec3::new(-slope, 0.0, 1.0).normalize();
        assert!((n - want).length() < 1e-5, "{n} vs {want}");
        assert!((n.length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_constant_height_leaves_the_normal_unchanged() {
        let m = ramp(16, 0.0);
        let n = Vec3::new(0.0, 0.6, 0.8);
        let got = bump_normal(&m, Vec2::new(0.3, 0.7), 1.0, n, Vec3::X, Vec3::new(0.0, 0.8, -0.6));
        assert!((got - n).length() < 1e-6, "{got}");
    }
}
