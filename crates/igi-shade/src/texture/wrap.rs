//! Wrap modes: where an integer texel coordinate outside the image reads from.

use igi_scene::Wrap;

/// The texel index in [0, `size`) that texel coordinate `i` reads under `wrap` (`size` > 0).
#[inline]
pub fn wrap_texel(i: i64, size: i64, wrap: Wrap) -> i64 {
    match wrap {
        Wrap::Repeat => i.rem_euclid(size),
        Wrap::Clamp => i.clamp(0, size - 1),
        Wrap::MirroredRepeat => {
            let period = i.rem_euclid(2 * size);
            if period < size { period } else { 2 * size - 1 - period }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_mode_maps_outside_coordinates_into_the_image() {
        // A 4-texel row: texel coordinates -5..9.
        let repeat: Vec<i64> = (-5..9).map(|i| wrap_texel(i, 4, Wrap::Repeat)).collect();
        assert_eq!(repeat, [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]);
        let clamp: Vec<i64> = (-5..9).map(|i| wrap_texel(i, 4, Wrap::Clamp)).collect();
        assert_eq!(clamp, [0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3]);
        let mirror: Vec<i64> = (-5..9).map(|i| wrap_texel(i, 4, Wrap::MirroredRepeat)).collect();
        assert_eq!(mirror, [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]);
    }
}
