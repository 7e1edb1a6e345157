//! Self-intersection avoidance for secondary rays: the origin is moved off the surface along
//! the geometric normal by a few units in the last place of its coordinates, as in Wächter and
//! Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing Gems, ch. 6).
//! The offset scales with the magnitude of the position, not with the scene, so it works for a
//! 2 m Cornell box and a 2 km conference room alike.

use glam::Vec3;

/// Positions closer to the origin than this get a fixed float offset instead of an integer one.
const ORIGIN: f32 = 1.0 / 32.0;
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
const INT_SCALE: f32 = 256.0;

/// `p` moved off its surface to the side `n` points to (`n` is the geometric normal, any
/// length, oriented toward the side the new ray leaves from).
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    let n = n.normalize_or_zero();
    let step = |p: f32, n: f32| {
        let of_i = (INT_SCALE * n) as i32;
        let bits = p.to_bits() as i32;
        let moved = if p < 0.0 { bits.wrapping_sub(of_i) } else { bits.wrapping_add(of_i) };
        let p_i = f32::from_bits(moved as u32);
        if p.abs() < ORIGIN { p + FLOAT_SCALE * n } else { p_i }
    };
    Vec3::new(step(p.x, n.x), step(p.y, n.y), step(p.z, n.z))
}
