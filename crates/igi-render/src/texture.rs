//! Texture lookup: nearest or bilinear filtering of a [`Texture`] with wrap-around (repeat)
//! addressing.
//!
//! Texture coordinates follow the scene model's convention (glTF's; the OBJ and PLY loaders
//! flip v to match): `u` to the right, `v` down, so `(0, 0)` is the top-left corner of the
//! image (texel row 0) and `v = 1` its bottom edge. Every integer translate of `(u, v)` gives
//! the same texel (repeat).

use glam::{Vec2, Vec4};
use igi_scene::Texture;

/// How texels are combined at a lookup point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The texel containing the point.
    Nearest,
    /// Bilinear interpolation of the four texels around the point (texel centres at half
    /// integers).
    #[default]
    Bilinear,
}

/// The texel at integer coordinates, wrapped into the image.
#[inline]
fn texel(tex: &Texture, x: i64, y: i64) -> Vec4 {
    let (w, h) = (i64::from(tex.width), i64::from(tex.height));
    let (x, y) = (x.rem_euclid(w), y.rem_euclid(h));
    Vec4::from_array(tex.texels[(y * w + x) as usize])
}

/// The filtered, linear RGBA value of `tex` at texture coordinates `uv`. A texture without
/// texels (or non-finite coordinates) reads as opaque white, so a broken texture leaves the
/// material's own colour.
pub fn sample(tex: &Texture, uv: Vec2, filter: Filter) -> Vec4 {
    if tex.width == 0 || tex.height == 0 || tex.texels.len() < (tex.width as usize) * (tex.height as usize) {
        return Vec4::ONE;
    }
    if !uv.is_finite() {
        return Vec4::ONE;
    }
    // Continuous texel coordinates, row 0 at the top; reduce to one period first so large
    // coordinates keep their fraction.
    let s = uv.x - uv.x.floor();
    let t = uv.y - uv.y.floor();
    let fx = s * tex.width as f32;
    let fy = t * tex.height as f32;
    match filter {
        Filter::Nearest => texel(tex, fx.floor() as i64, fy.floor() as i64),
        Filter::Bilinear => {
            let (x, y) = (fx - 0.5, fy - 0.5);
            let (x0, y0) = (x.floor(), y.floor());
            let (ax, ay) = (x - x0, y - y0);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let top = texel(tex, x0, y0).lerp(texel(tex, x0 + 1, y0), ax);
            let bottom = texel(tex, x0, y0 + 1).lerp(texel(tex, x0 + 1, y0 + 1), ax);
            top.lerp(bottom, ay)
        }
    }
}
