//! [`Resolution`]: how many pixels the window renders for the area beside the panel. The image
//! always fills that area; the resolution trades sharpness for frame rate (issue 18).

use std::fmt;

/// The render size relative to the image area of the window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Resolution {
    /// The largest scale at most 1 whose image has at most [`AUTO_PIXELS`] pixels, so that a
    /// large window stays interactive.
    #[default]
    Auto,
    /// One image pixel per window pixel.
    Full,
    /// Half the window's pixels along each axis.
    Half,
    /// A quarter along each axis.
    Quarter,
}

/// The pixel bound of [`Resolution::Auto`]: twice the paper's 640x480.
pub const AUTO_PIXELS: f32 = 640.0 * 480.0 * 2.0;

/// The smallest render size along an axis.
const MIN_SIDE: f32 = 16.0;

impl Resolution {
    /// Every choice, in the order the panel lists them.
    pub const ALL: [Self; 4] = [Self::Auto, Self::Full, Self::Half, Self::Quarter];

    /// The image size to render for an image area of `area` pixels.
    pub fn render_size(self, area: [f32; 2]) -> [u32; 2] {
        let [w, h] = area.map(|a| a.max(MIN_SIDE));
        let scale = match self {
            Self::Auto => (AUTO_PIXELS / (w * h)).sqrt().min(1.0),
            Self::Full => 1.0,
            Self::Half => 0.5,
            Self::Quarter => 0.25,
        };
        [w, h].map(|a| (a * scale).round().max(MIN_SIDE) as u32)
    }
}

impl fmt::Display for Resolution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Auto => "auto",
            Self::Full => "full",
            Self::Half => "1/2",
            Self::Quarter => "1/4",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_follow_the_area() {
        assert_eq!(Resolution::Full.render_size([920.0, 760.0]), [920, 760]);
        assert_eq!(Resolution::Half.render_size([920.0, 760.0]), [460, 380]);
        assert_eq!(Resolution::Quarter.render_size([920.0, 760.0]), [230, 190]);
        // Auto: full up to the bound, then the largest scale within it, same aspect.
        assert_eq!(Resolution::Auto.render_size([640.0, 480.0]), [640, 480]);
        let [w, h] = Resolution::Auto.render_size([1640.0, 1080.0]);
        assert!((w * h) as f32 <= AUTO_PIXELS * 1.01 && (w * h) as f32 >= AUTO_PIXELS * 0.98, "{w}x{h}");
        assert!((w as f32 / h as f32 - 1640.0 / 1080.0).abs() < 0.01);
        assert_eq!(Resolution::Full.render_size([0.0, -3.0]), [16, 16]);
    }
}
