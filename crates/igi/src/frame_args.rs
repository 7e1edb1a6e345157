//! The frame options shared by `igi render`, the viewers (`igi view`, `igi serve`) and the
//! benchmarks (`igi bench frame`, `quality`, `cluster`): image size, VPLs, interleaving,
//! anti-aliasing, filter, clamp, seed, threads, tile size, the scene clock and the camera,
//! parsed once into a [`FrameState`] ([`FrameArgs::frame_state`]) that every consumer reads.

use crate::camera_args::CameraArgs;
use anyhow::Result;
use clap::{Args, ValueEnum};
use igi_render::ScenePose;
use igi_render::frame::{FilterSettings, FrameSettings, FrameState};
use igi_render::image::tonemap::ToneCurve;
use igi_render::{PreparedScene, add_default_light};
use igi_scene::Scene;

/// Largest `--threads`.
const MAX_THREADS: usize = 1024;

/// Primary rays per pixel of offline renders and benchmarks.
pub const DEFAULT_AA: u32 = 4;

/// Options describing a frame.
#[derive(Debug, Args)]
pub struct FrameArgs {
    /// Image width in pixels.
    #[arg(long, default_value_t = 640, help_heading = "Output")]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 480, help_heading = "Output")]
    pub height: u32,
    /// How radiance becomes display values in 8-bit images: the log-average luminance is
    /// exposed at middle grey, then this curve compresses the range into the display's.
    #[arg(long, value_enum, default_value_t = ToneMapArg::Filmic, help_heading = "Output")]
    pub tone_map: ToneMapArg,
    /// VPLs per pixel: the size of one interleaved VPL set (point, spot and directional
    /// lights count towards it).
    #[arg(long, default_value_t = 12, help_heading = "Instant radiosity")]
    pub vpls: u32,
    /// Interleave pattern NxM: the frame has N·M VPL sets, one per pixel of every NxM block.
    #[arg(long, default_value = "3x3", value_parser = parse_nxm, help_heading = "Instant radiosity")]
    pub interleave: [u32; 2],
    /// Coarse interleave K: a second level of interleaving K times coarser, merged by a second
    /// filter level over K×K blocks of NxM pixels, so each pixel's light is averaged from
    /// N·M·K² VPL sets instead of N·M at the same VPLs per pixel (less of the blotchy
    /// low-frequency noise of one frame, ARCHITECTURE.md "Two levels of interleaving"). 1 turns
    /// it off.
    #[arg(long, default_value_t = FrameSettings::default().coarse_interleave, help_heading = "Filter")]
    pub coarse_interleave: u32,
    /// Primary rays per pixel (interleaved super-sampling: a pixel whose rays all see one
    /// surface is shaded once, with all its VPLs; across an edge each ray is lit by its share
    /// of them). Default 4 for one frame and `--frames N`; 1 for `igi render`'s converging
    /// mean (its frames' jittered rays anti-alias it) and in the interactive viewers (`view`,
    /// `serve`).
    #[arg(long, help_heading = "Sampling")]
    pub aa: Option<u32>,
    /// Show the raw interleaved image: no discontinuity filter.
    #[arg(long, help_heading = "Filter")]
    pub no_filter: bool,
    /// Filter: smallest cosine between the normals of pixels averaged together.
    #[arg(
        long,
        default_value_t = FilterSettings::default().min_normal_cos,
        allow_hyphen_values = true,
        help_heading = "Filter"
    )]
    pub filter_normal: f32,
    /// Filter: largest relative depth difference of pixels averaged together.
    #[arg(long, default_value_t = FilterSettings::default().max_depth_ratio, help_heading = "Filter")]
    pub filter_depth: f32,
    /// d_min of the VPL contribution 1/max(d², d_min²) in scene units; 0 turns clamping off.
    /// Default: 2 % of the scene's bounding-box diagonal for the viewers' and benchmarks' frames,
    /// 5 % for `igi render`'s bias-compensated still images.
    #[arg(long, allow_hyphen_values = true, help_heading = "Instant radiosity")]
    pub clamp: Option<f32>,
    /// Recover the light the clamp removes with short path-traced rays (bias compensation):
    /// nearly unbiased at the clamp's low noise, for about one ray more per pixel. Always on
    /// for `igi render`.
    #[arg(long, help_heading = "Instant radiosity")]
    pub compensate: bool,
    /// Largest number of mirror and glass bounces followed from the camera.
    // `--specular-depth` is the flag's former name, kept so existing command lines work.
    #[arg(long, alias = "specular-depth", default_value_t = 5, help_heading = "Instant radiosity")]
    pub specular_bounces: u32,
    /// Largest number of bounces of a light path (each leaves a VPL): 0 is direct light only,
    /// 1 adds one bounce of indirect light.
    #[arg(long, default_value_t = igi_render::frame::limits::MAX_BOUNCES, help_heading = "Instant radiosity")]
    pub bounces: u32,
    /// Seed of the VPLs and sample patterns (same seed, same image).
    #[arg(long, default_value_t = 0, help_heading = "Sampling")]
    pub seed: u32,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0, help_heading = "Performance")]
    pub threads: usize,
    /// Tile edge length in pixels (the image does not depend on it).
    #[arg(long, default_value_t = FrameSettings::default().tile_size, help_heading = "Performance")]
    pub tile_size: u32,
    /// Scene clock in seconds: animated instances and lights take their pose at this time.
    #[arg(long, default_value_t = 0.0, help_heading = "Animation")]
    pub time: f32,
    /// Do not add a light to a scene whose own lights show nothing of the view (by default a
    /// sun and a daylight sky where the camera stands in the open, else lamps under the
    /// ceiling of the space it looks into).
    #[arg(long, help_heading = "Instant radiosity")]
    pub no_default_light: bool,
    /// Camera overrides.
    #[command(flatten, next_help_heading = "Camera")]
    pub camera: crate::camera_args::CameraArgs,
}

/// `scene` prepared for rendering, with the default light it needs if `default_light` (one
/// warning says what was added), judged from the camera `camera` asks for (none: the one the
/// scene starts with).
pub fn prepare_scene(scene: Scene, default_light: bool, camera: Option<&CameraArgs>) -> PreparedScene {
    let mut prepared = PreparedScene::new(scene);
    // A camera the options cannot make is refused by `FrameArgs::frame_state`, naming the flag.
    let view = camera.and_then(|c| c.requested(&prepared));
    if let Some(warning) = add_default_light(&mut prepared, default_light, view.as_ref()) {
        tracing::warn!("{warning}");
    }
    prepared
}

/// The values of `--tone-map`: the tone curves ([`ToneCurve`]) as the help describes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ToneMapArg {
    /// The ACES filmic curve (Narkowicz's fit) on the luminance: middle grey a little lighter,
    /// a white wall lit well near white, highlights rolling off to white with their hue kept.
    Filmic,
    /// Reinhard's operator (2002): softer, mid-tones darker (a white wall lit as the average
    /// shows mid-grey), the brightest 0.5 % of the image white.
    Reinhard,
}

impl From<ToneMapArg> for ToneCurve {
    fn from(arg: ToneMapArg) -> Self {
        match arg {
            ToneMapArg::Filmic => Self::Filmic,
            ToneMapArg::Reinhard => Self::Reinhard,
        }
    }
}

/// Parses `NxM` (an interleave pattern, a window size) into `[N, M]`.
pub fn parse_nxm(s: &str) -> Result<[u32; 2], String> {
    let bad = || format!("{s:?} is not NxM with two whole numbers, e.g. 3x3");
    let (n, m) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let n = n.trim().parse::<u32>().map_err(|_| bad())?;
    let m = m.trim().parse::<u32>().map_err(|_| bad())?;
    Ok([n, m])
}

/// How a summary names the VPL sets: "3x3 sets", or "3x3 sets in 3x3 groups" with a coarse
/// level.
pub fn sets_label([n, m]: [u32; 2], coarse: u32) -> String {
    match coarse {
        1 => format!("{n}x{m} sets"),
        k => format!("{n}x{m} sets in {k}x{k} groups"),
    }
}

impl FrameArgs {
    /// `scene` prepared for rendering, with the default light it needs unless
    /// `--no-default-light` (one warning says what was added), judged from the camera the
    /// options ask for.
    pub fn prepare(&self, scene: Scene) -> PreparedScene {
        prepare_scene(scene, !self.no_default_light, Some(&self.camera))
    }

    /// The first frame of `scene` with these options, checked (errors name the flag).
    pub fn frame_state(&self, scene: &PreparedScene) -> Result<FrameState> {
        if self.threads > MAX_THREADS {
            anyhow::bail!("--threads: {} is more than {MAX_THREADS}", self.threads);
        }
        if !(self.time.is_finite() && self.time >= 0.0) {
            anyhow::bail!("--time: {} is not a finite number of seconds ≥ 0", self.time);
        }
        let camera = self.camera.resolve(scene)?;
        let defaults = FrameSettings::for_scene(scene.bounds().diagonal());
        let settings = FrameSettings {
            width: self.width,
            height: self.height,
            vpls_per_pixel: self.vpls,
            interleave: self.interleave,
            coarse_interleave: self.coarse_interleave,
            aa: self.aa.unwrap_or(DEFAULT_AA),
            filter: !self.no_filter,
            filter_normal: self.filter_normal,
            filter_depth: self.filter_depth,
            clamp: self.clamp.unwrap_or(defaults.clamp),
            compensate_clamp: self.compensate,
            specular_bounces: self.specular_bounces,
            bounces: self.bounces,
            tile_size: self.tile_size,
            seed: self.seed,
            tone_curve: self.tone_map.into(),
        };
        settings.validate()?;
        Ok(FrameState { pose: ScenePose::at(self.time), ..FrameState::new(camera, settings) })
    }

    /// `frame` set up to be a still image or a frame of one (a mean of several), by the rule of
    /// [`FrameSettings::still_image`]: the clamp's bias compensated and, unless `--clamp`
    /// was given, the larger clamp of compensation.
    pub fn still_image(&self, frame: &mut FrameState, scene: &PreparedScene) {
        let default_clamp_of = self.clamp.is_none().then(|| scene.bounds().diagonal());
        frame.settings = frame.settings.still_image(default_clamp_of);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frame settings written before `tone_curve` existed (a viewer page's JSON) still read, with
    /// the default curve; the flag's default is that default.
    #[test]
    fn settings_without_a_tone_curve_read_as_the_default() {
        let mut json = serde_json::to_value(FrameSettings::default()).unwrap();
        json.as_object_mut().unwrap().remove("tone_curve").expect("the field is serialised");
        let settings: FrameSettings = serde_json::from_value(json).unwrap();
        assert_eq!(settings.tone_curve, ToneCurve::default());
        assert_eq!(ToneCurve::from(ToneMapArg::Filmic), ToneCurve::default());
    }

    #[test]
    fn interleave_patterns() {
        assert_eq!(parse_nxm("3x3"), Ok([3, 3]));
        assert_eq!(parse_nxm("4X2"), Ok([4, 2]));
        assert!(parse_nxm("3").is_err());
        assert!(parse_nxm("ax3").is_err());
        assert!(parse_nxm("-1x3").is_err());
    }
}
