//! [`ViewerSettings`]: what a viewer lets the user change, in one serialisable struct (the
//! browser receives and sends it as JSON): the frame's settings ([`FrameSettings`], the record
//! `igi render` uses too), the tone map, the convergence target and the animation clock.

use igi_render::ToneMap;
use igi_render::frame::{FrameSettings, SettingsError};
use igi_render::image::tonemap::check_exposure;
use serde::{Deserialize, Serialize};

/// Largest animation speed factor.
pub const MAX_SPEED: f32 = 100.0;
/// Largest sky strength.
pub const MAX_SKY: f32 = 100.0;
/// Largest number of frames a still view accumulates (then rendering pauses).
pub const MAX_ACCUMULATION: u32 = 4096;
/// Default of [`ViewerSettings::converge_frames`]: as many frames as `igi render --frames 64`
/// averages for a converged image.
pub const DEFAULT_CONVERGE_FRAMES: u32 = 64;
/// Largest [`ViewerSettings::converge_seconds`]: a day.
pub const MAX_CONVERGE_SECONDS: f32 = 86_400.0;
/// Largest image of a viewer (a 4K UHD frame): a viewer keeps a few images of this size.
pub const MAX_PIXELS: u64 = 3840 * 2160;

/// Serde's default of [`ViewerSettings::temporal`] for a page that does not send it.
fn on() -> bool {
    true
}

/// Render, display and animation settings of a viewer: the frame's settings, the record
/// `igi render` uses too, and beside them what only a viewer has. The browser receives and
/// sends it as one flat JSON object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewerSettings {
    /// The settings of the frames (image size, VPLs, interleaving, filter, clamp, seed, …).
    #[serde(flatten)]
    pub frame: FrameSettings,
    /// Fixed exposure in stops, or `None` for the frame's tone curve
    /// ([`FrameSettings::tone_curve`]) from the previous frame's statistics with
    /// [`ViewerSettings::key`].
    pub exposure: Option<f32>,
    /// The key (the display value of the log-average luminance, middle grey) of the automatic
    /// tone map, used without a fixed exposure.
    pub key: f32,
    /// Render with the path tracer instead of instant radiosity: one path per pixel and
    /// frame, averaged like IGI frames (the progressive reference).
    pub path_tracer: bool,
    /// Average frames while nothing changes (progressive convergence).
    pub accumulate: bool,
    /// While the camera or objects move, blend each frame with the reprojected history of
    /// the earlier ones (temporal reuse); off, every change shows a frame of its own.
    #[serde(default = "on")]
    pub temporal: bool,
    /// A still view is converged, and rendering stops, after this many frames
    /// (1 ..= [`MAX_ACCUMULATION`]).
    pub converge_frames: u32,
    /// ... or once its frames took this many seconds to render (0: no time limit).
    pub converge_seconds: f32,
    /// The animation clock runs.
    pub playing: bool,
    /// Clock speed: scene seconds per wall-clock second.
    pub speed: f32,
    /// Strength of the scene's sky (its environment light): 1 as loaded, 0 off.
    pub sky: f32,
}

impl ViewerSettings {
    /// A viewer's defaults with the frame settings `frame`.
    pub fn new(frame: FrameSettings) -> Self {
        Self {
            frame,
            exposure: None,
            key: igi_render::image::tonemap::DEFAULT_KEY,
            path_tracer: false,
            accumulate: true,
            temporal: true,
            converge_frames: DEFAULT_CONVERGE_FRAMES,
            converge_seconds: 0.0,
            playing: true,
            speed: 1.0,
            sky: 1.0,
        }
    }

    /// The defaults of a viewer for a scene whose bounding box has diagonal `diagonal`: those
    /// of `igi render`, with one primary ray per pixel (an interactive frame first).
    pub fn for_scene(diagonal: f32) -> Self {
        Self::new(FrameSettings { aa: 1, ..FrameSettings::for_scene(diagonal) })
    }

    /// The tone-map operator.
    pub fn tone_map(&self) -> ToneMap {
        match self.exposure {
            Some(stops) => ToneMap::Exposure { stops },
            None => ToneMap::automatic(self.frame.tone_curve, self.key),
        }
    }

    /// Checks every field; the error names it.
    pub fn validate(&self) -> Result<(), SettingsError> {
        self.frame.validate()?;
        let err = |field, message: String| Err(SettingsError { field, message });
        let (width, height) = (self.frame.width, self.frame.height);
        if u64::from(width) * u64::from(height) > MAX_PIXELS {
            return err("width", format!("{width}x{height} is more than {MAX_PIXELS} pixels"));
        }
        if let Some(stops) = self.exposure {
            if let Err(message) = check_exposure(stops) {
                return err("exposure", message);
            }
        }
        if !(self.key.is_finite() && self.key > 0.0 && self.key <= 1.0) {
            return err("key", format!("{} is not in (0, 1]", self.key));
        }
        if !(self.speed.is_finite() && (0.0..=MAX_SPEED).contains(&self.speed)) {
            return err("speed", format!("{} is not between 0 and {MAX_SPEED}", self.speed));
        }
        if !(self.sky.is_finite() && (0.0..=MAX_SKY).contains(&self.sky)) {
            return err("sky", format!("{} is not between 0 and {MAX_SKY}", self.sky));
        }
        if !(1..=MAX_ACCUMULATION).contains(&self.converge_frames) {
            return err(
                "converge-frames",
                format!("{} is not between 1 and {MAX_ACCUMULATION}", self.converge_frames),
            );
        }
        if !(self.converge_seconds.is_finite()
            && (0.0..=MAX_CONVERGE_SECONDS).contains(&self.converge_seconds))
        {
            return err(
                "converge-seconds",
                format!("{} is not between 0 and {MAX_CONVERGE_SECONDS}", self.converge_seconds),
            );
        }
        Ok(())
    }

    /// `error` as the viewers' panels say it: the field by its label there, not by the
    /// command-line flag `SettingsError` names.
    pub fn panel_message(error: &SettingsError) -> String {
        let label = match error.field {
            "width" | "height" => "image size",
            "vpls" => "VPLs per pixel",
            "interleave" => "interleave n × m",
            "coarse-interleave" => "coarse interleave K",
            "aa" => "AA samples",
            "clamp" => "clamp d_min",
            "specular-bounces" => "specular bounces",
            "bounces" => "light bounces",
            "tile-size" => "tile size",
            "filter-normal" => "normal cosine",
            "filter-depth" => "depth ratio",
            "exposure" => "exposure (stops)",
            "key" => "key (middle grey)",
            "speed" => "speed",
            "sky" => "sky strength",
            "converge-frames" => "converged after frames",
            "converge-seconds" => "or after seconds",
            other => other,
        };
        format!("{label}: {}", error.message)
    }
}
