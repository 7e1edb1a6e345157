//! [`FrameBudget`]: the most one frame may cost, which the server's owner sets (`igi serve
//! --max-frame-mrays`). Anyone who can open the page can change the settings, and a frame's
//! cost grows with their product: 3840x2160 pixels with 64 AA samples and 4096 VPLs per pixel
//! is a frame of hours. Settings over the budget are refused on the connection that sent
//! them, like invalid ones.
//!
//! The cost is counted in rays: each pixel traces one primary ray per AA sample and one
//! shadow ray per VPL of its set (the AA samples share the set, paper 3.3), the two terms
//! that dominate an interactive frame. Mirrors, glass and the filter add a fraction on top.

use igi_session::ViewerSettings;

/// A bound on the rays of one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameBudget {
    /// Millions of rays a frame may trace.
    pub max_mrays: u64,
}

impl FrameBudget {
    /// The default: the panel's whole ranges (4096 VPLs and 64 AA samples per pixel) at the
    /// default 640x480 (1278 M), or 4K UHD with the default settings (108 M); about a minute
    /// of two cores at most.
    pub const DEFAULT: Self = Self { max_mrays: 2000 };

    /// Refuses `settings` whose frame would cost more than the budget.
    pub fn check(&self, settings: &ViewerSettings) -> Result<(), OverBudget> {
        let rays = rays_per_frame(settings);
        if rays > self.max_mrays.saturating_mul(1_000_000) {
            return Err(OverBudget {
                settings: settings.clone(),
                mrays: rays.div_ceil(1_000_000),
                budget: *self,
            });
        }
        Ok(())
    }
}

impl Default for FrameBudget {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The rays of one frame: pixels × (AA samples + VPLs per pixel).
pub fn rays_per_frame(settings: &ViewerSettings) -> u64 {
    let pixels = u64::from(settings.frame.width) * u64::from(settings.frame.height);
    pixels.saturating_mul(u64::from(settings.frame.aa) + u64::from(settings.frame.vpls_per_pixel))
}

/// Settings over the budget, and by how much.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "{}x{} pixels × ({} AA samples + {} VPLs per pixel) is {mrays} million rays per frame, more than \
     this server's {} million (igi serve --max-frame-mrays)",
    settings.frame.width,
    settings.frame.height,
    settings.frame.aa,
    settings.frame.vpls_per_pixel,
    budget.max_mrays
)]
pub struct OverBudget {
    /// The refused settings.
    pub settings: ViewerSettings,
    /// Their cost, millions of rays (rounded up).
    pub mrays: u64,
    /// The budget.
    pub budget: FrameBudget,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_and_the_panels_ranges_fit_the_hostile_frame_does_not() {
        let defaults = ViewerSettings::for_scene(1.0);
        let budget = FrameBudget::DEFAULT;
        assert!(budget.check(&defaults).is_ok());
        let panel_max = ViewerSettings {
            frame: igi_render::FrameSettings { vpls_per_pixel: 4096, aa: 64, ..defaults.clone().frame },
            ..defaults.clone()
        };
        assert!(budget.check(&panel_max).is_ok());
        let uhd = ViewerSettings {
            frame: igi_render::FrameSettings { width: 3840, height: 2160, ..defaults.clone().frame },
            ..defaults.clone()
        };
        assert!(budget.check(&uhd).is_ok());
        let hostile = ViewerSettings {
            frame: igi_render::FrameSettings {
                width: 3840,
                height: 2160,
                aa: 64,
                vpls_per_pixel: 4096,
                ..defaults.frame
            },
            ..defaults
        };
        let refused = budget.check(&hostile).unwrap_err();
        assert_eq!(refused.mrays, 34_505);
        assert!(refused.to_string().contains("--max-frame-mrays"), "{refused}");
        assert!(FrameBudget { max_mrays: 40_000 }.check(&hostile).is_ok());
    }
}
