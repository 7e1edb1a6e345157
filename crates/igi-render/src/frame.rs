//! [`FrameState`]: everything a render node needs to produce any tile of one frame besides the
//! scene itself (ARCHITECTURE.md, "One frame"): camera, settings, where the scene stands
//! ([`ScenePose`]), tone map, the pixels wanted ([`PixelFormat`]) and the seeds. It is small
//! and serialisable, so a cluster node or a viewer thread can receive it, pose its copy of the
//! scene and derive the VPLs and every pixel deterministically.

use crate::image::frame_image::PixelFormat;
use crate::image::tonemap::{DEFAULT_KEY, ToneCurve, ToneMap, ToneMapper};
use crate::prepared::scene_pose::ScenePose;
use crate::sampling::hash_combine;
use igi_scene::Camera;
use serde::{Deserialize, Serialize};

/// The settings of a frame: every option a user sets, the one record the command line parses
/// its flags into, a viewer shows and edits (its JSON, flat), and a cluster sends with each
/// frame (ARCHITECTURE.md, "One record of a frame's settings").
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// VPLs lighting each pixel: the size V of one interleaved VPL set (paper 2.1). Point, spot
    /// and directional lights are in every set and count towards V.
    pub vpls_per_pixel: u32,
    /// Interleave pattern `[n, m]`: pixel (x, y) uses VPL set (x mod n) + n (y mod m), so the
    /// frame has n·m sets (paper 2.1, Keller & Heidrich 2001).
    pub interleave: [u32; 2],
    /// The coarse level of interleaving K (ARCHITECTURE.md, "Two levels of interleaving"): the
    /// n×m block of pixel (x, y) uses group (⌊x/n⌋ mod K) + K (⌊y/m⌋ mod K) of K² groups of
    /// n·m sets, and a second filter level at stride (n, m) merges the groups, so the filter
    /// reaches over nK × mK pixels and n·m·K² sets. 1 is the paper's single level.
    pub coarse_interleave: u32,
    /// Primary rays per pixel; each is lit by its own 1/N of the pixel's VPL set (interleaved
    /// super-sampling, paper 3.3).
    pub aa: u32,
    /// The discontinuity filter (paper 2.1) on; off shows the raw interleaved image. Its
    /// thresholds ([`FrameSettings::discontinuity_filter`]) are kept while it is off, so a
    /// viewer that turns it on again has them back.
    pub filter: bool,
    /// Discontinuity filter: smallest cosine between the normals of pixels averaged together
    /// ([`FilterSettings::min_normal_cos`]).
    pub filter_normal: f32,
    /// Discontinuity filter: largest relative depth difference of pixels averaged together
    /// ([`FilterSettings::max_depth_ratio`]).
    pub filter_depth: f32,
    /// d_min of the VPL contribution `… / max(d², d_min²)` (ARCHITECTURE.md, "Default clamp"); 0 turns
    /// clamping off (unbiased, noisier).
    pub clamp: f32,
    /// Recover the light the clamp removes with short path-traced rays (bias compensation,
    /// Kollig & Keller 2004; see `TilePipeline`): unbiased up to second-order terms, with the
    /// low variance of the clamped estimate, for about one more ray per shading point.
    /// [`FrameSettings::still_image`] turns it on for still images.
    pub compensate_clamp: bool,
    /// Largest number of specular bounces (mirror and glass) followed from the camera.
    pub specular_bounces: u32,
    /// Largest number of surface interactions of a light path, each leaving a VPL: 0 lights
    /// the scene with the VPLs on the lights only (direct light), 1 adds one bounce of
    /// indirect light, and so on up to [`MAX_BOUNCES`](limits::MAX_BOUNCES).
    pub bounces: u32,
    /// Edge length of the square tiles; the image does not depend on it.
    pub tile_size: u32,
    /// Base seed of every random decision (same seed, same image).
    pub seed: u32,
    /// The curve of the automatic tone map of the frames' display images (`--tone-map`); their
    /// exposure comes from the image statistics either way (paper 3.4). Settings written
    /// before it existed read as the default.
    #[serde(default)]
    pub tone_curve: ToneCurve,
}

/// Thresholds of the discontinuity buffer: a neighbour's irradiance is averaged in only if its
/// surface is similar to the centre pixel's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FilterSettings {
    /// Smallest cosine between the two shading normals.
    pub min_normal_cos: f32,
    /// Largest relative difference of the distances along the camera path, |d_a − d_b| / d_a.
    pub max_depth_ratio: f32,
}

impl Default for FilterSettings {
    fn default() -> Self {
        Self { min_normal_cos: 0.9, max_depth_ratio: 0.1 }
    }
}

/// The scale of the default VPL clamp: d_min is this fraction of the scene's bounding-box
/// diagonal (see [`FrameSettings::clamp_for`]).
pub const DEFAULT_CLAMP_FRACTION: f32 = 0.02;

/// The scale of the default clamp of progressive rendering, where the bias compensation
/// restores what the clamp removes: a larger d_min moves more of the near field from the
/// high-variance VPL term to the compensation rays.
pub const COMPENSATED_CLAMP_FRACTION: f32 = 0.05;

impl Default for FrameSettings {
    fn default() -> Self {
        let filter = FilterSettings::default();
        Self {
            width: 640,
            height: 480,
            vpls_per_pixel: 12,
            interleave: [3, 3],
            coarse_interleave: 3,
            aa: 4,
            filter: true,
            filter_normal: filter.min_normal_cos,
            filter_depth: filter.max_depth_ratio,
            clamp: 0.0,
            compensate_clamp: false,
            specular_bounces: 5,
            bounces: limits::MAX_BOUNCES,
            tile_size: 128,
            seed: 0,
            tone_curve: ToneCurve::default(),
        }
    }
}

/// A setting outside its valid range, named by its command-line flag.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("--{field}: {message}")]
pub struct SettingsError {
    /// The flag (without dashes).
    pub field: &'static str,
    /// What is wrong with its value.
    pub message: String,
}

/// Upper bounds that keep a frame's memory and time finite for any input.
pub mod limits {
    /// Largest image side.
    pub const MAX_SIDE: u32 = 16384;
    /// Largest VPL set.
    pub const MAX_VPLS_PER_PIXEL: u32 = 4096;
    /// Largest interleave side.
    pub const MAX_INTERLEAVE: u32 = 16;
    /// Largest coarse interleave K (K² groups of sets).
    pub const MAX_COARSE_INTERLEAVE: u32 = 4;
    /// Largest number of primary rays per pixel.
    pub const MAX_AA: u32 = 64;
    /// Most specular bounces a camera path may follow.
    pub const MAX_SPECULAR_BOUNCES: u32 = 16;
    /// Surface interactions (diffuse, mirror or glass) followed per light path; a path leaves
    /// at most `MAX_BOUNCES + 1` VPLs. The walk is truncated there: with a scene albedo of 0.8
    /// the energy dropped is 0.8³² ≈ 0.08 % of the indirect light, and every interaction keeps
    /// its own Sobol dimensions (see [`crate::igi::vpl`]).
    pub const MAX_BOUNCES: u32 = 32;
    /// Largest tile side.
    pub const MAX_TILE: u32 = 1024;
    /// Largest number of tiles in a frame (each carries its own buffers).
    pub const MAX_TILES: u64 = 1 << 20;
}

impl FrameSettings {
    /// Number of VPL sets, n·m·K².
    pub fn set_count(&self) -> u32 {
        self.interleave[0] * self.interleave[1] * self.coarse_interleave * self.coarse_interleave
    }

    /// Checks every field; the error names the offending flag.
    pub fn validate(&self) -> Result<(), SettingsError> {
        let err = |field, message: String| Err(SettingsError { field, message });
        let side = 1..=limits::MAX_SIDE;
        if !side.contains(&self.width) {
            return err("width", format!("{} is not between 1 and {}", self.width, limits::MAX_SIDE));
        }
        if !side.contains(&self.height) {
            return err("height", format!("{} is not between 1 and {}", self.height, limits::MAX_SIDE));
        }
        if !(1..=limits::MAX_VPLS_PER_PIXEL).contains(&self.vpls_per_pixel) {
            return err(
                "vpls",
                format!("{} is not between 1 and {}", self.vpls_per_pixel, limits::MAX_VPLS_PER_PIXEL),
            );
        }
        if self.interleave.iter().any(|&k| !(1..=limits::MAX_INTERLEAVE).contains(&k)) {
            return err(
                "interleave",
                format!(
                    "{}x{} needs both sides between 1 and {}",
                    self.interleave[0],
                    self.interleave[1],
                    limits::MAX_INTERLEAVE
                ),
            );
        }
        if !(1..=limits::MAX_COARSE_INTERLEAVE).contains(&self.coarse_interleave) {
            return err(
                "coarse-interleave",
                format!("{} is not between 1 and {}", self.coarse_interleave, limits::MAX_COARSE_INTERLEAVE),
            );
        }
        if !(1..=limits::MAX_AA).contains(&self.aa) {
            return err("aa", format!("{} is not between 1 and {}", self.aa, limits::MAX_AA));
        }
        if !(self.clamp >= 0.0 && self.clamp.is_finite()) {
            return err("clamp", format!("{} is not a finite distance ≥ 0", self.clamp));
        }
        if self.specular_bounces > limits::MAX_SPECULAR_BOUNCES {
            return err(
                "specular-bounces",
                format!("{} is more than {}", self.specular_bounces, limits::MAX_SPECULAR_BOUNCES),
            );
        }
        if self.bounces > limits::MAX_BOUNCES {
            return err("bounces", format!("{} is more than {}", self.bounces, limits::MAX_BOUNCES));
        }
        if !(1..=limits::MAX_TILE).contains(&self.tile_size) {
            return err("tile-size", format!("{} is not between 1 and {}", self.tile_size, limits::MAX_TILE));
        }
        let tiles =
            u64::from(self.width.div_ceil(self.tile_size)) * u64::from(self.height.div_ceil(self.tile_size));
        if tiles > limits::MAX_TILES {
            return err(
                "tile-size",
                format!(
                    "{} cuts the image into {tiles} tiles, more than {}",
                    self.tile_size,
                    limits::MAX_TILES
                ),
            );
        }
        if let Some(f) = self.discontinuity_filter() {
            if !(-1.0..=1.0).contains(&f.min_normal_cos) {
                return err("filter-normal", format!("{} is not a cosine in [-1, 1]", f.min_normal_cos));
            }
            if !(f.max_depth_ratio >= 0.0 && f.max_depth_ratio.is_finite()) {
                return err("filter-depth", format!("{} is not a finite ratio ≥ 0", f.max_depth_ratio));
            }
        }
        Ok(())
    }

    /// The automatic tone map these settings choose: the log-average luminance at middle grey
    /// ([`DEFAULT_KEY`]), then [`FrameSettings::tone_curve`].
    pub fn tone_map(&self) -> ToneMap {
        ToneMap::automatic(self.tone_curve, DEFAULT_KEY)
    }

    /// The thresholds of the discontinuity filter, `None` with the filter off.
    pub fn discontinuity_filter(&self) -> Option<FilterSettings> {
        self.filter.then_some(FilterSettings {
            min_normal_cos: self.filter_normal,
            max_depth_ratio: self.filter_depth,
        })
    }

    /// Turns the discontinuity filter on with `filter`'s thresholds, or off with `None` (its
    /// thresholds then stay as they were).
    pub fn set_discontinuity_filter(&mut self, filter: Option<FilterSettings>) {
        self.filter = filter.is_some();
        if let Some(f) = filter {
            (self.filter_normal, self.filter_depth) = (f.min_normal_cos, f.max_depth_ratio);
        }
    }

    /// The defaults for a scene whose bounding box has diagonal `diagonal`: the default
    /// clamp ([`FrameSettings::clamp_for`]) scales with the scene.
    pub fn for_scene(diagonal: f32) -> Self {
        Self { clamp: Self::clamp_for(diagonal), ..Self::default() }
    }

    /// These settings for a still image or a frame of a mean of several (the rule of
    /// ARCHITECTURE.md, "Still images are bias-compensated"): with a clamp, its bias is
    /// compensated, so accumulation converges to the unclamped solution and even one frame
    /// shows the light of creases, contacts and thin slats that the clamp removes. A scene
    /// diagonal given in `default_clamp_of` (the clamp was not the user's choice) replaces the
    /// clamp by the larger default of compensation, which keeps the VPLs' near-field noise
    /// low ([`FrameSettings::compensated_clamp_for`]).
    pub fn still_image(self, default_clamp_of: Option<f32>) -> Self {
        if self.clamp <= 0.0 {
            return self;
        }
        let clamp = default_clamp_of.map_or(self.clamp, Self::compensated_clamp_for);
        Self { compensate_clamp: true, clamp, ..self }
    }

    /// The default d_min for a scene whose bounding box has diagonal `diagonal`:
    /// [`DEFAULT_CLAMP_FRACTION`] of it, so the clamp scales with the scene's units.
    pub fn clamp_for(diagonal: f32) -> f32 {
        if diagonal.is_finite() && diagonal > 0.0 { DEFAULT_CLAMP_FRACTION * diagonal } else { 0.0 }
    }

    /// The default d_min with bias compensation: [`COMPENSATED_CLAMP_FRACTION`] of the diagonal.
    pub fn compensated_clamp_for(diagonal: f32) -> f32 {
        if diagonal.is_finite() && diagonal > 0.0 { COMPENSATED_CLAMP_FRACTION * diagonal } else { 0.0 }
    }
}

/// How a frame's radiance is estimated: the one choice between the estimators a frame source
/// runs (as pbrt's integrators; [`crate::schedule::frame_renderer::FramePlan`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Estimator {
    /// Instant global illumination: VPLs, interleaved sampling and the discontinuity filter
    /// ([`crate::igi`]).
    #[default]
    Igi,
    /// The unbiased reference path tracer ([`crate::path_tracer`]) with `spp` paths per pixel.
    PathTracer {
        /// Paths per pixel, clamped to 1..=[`MAX_SAMPLES`](crate::sampling::MAX_SAMPLES).
        spp: u32,
    },
}

/// One frame, completely: camera, settings, estimator, scene pose, tone map, pixel format,
/// frame index and whether it reseeds. The same value describes a frame to the local
/// renderer and, as a cluster job, to every render node.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameState {
    /// The camera.
    pub camera: Camera,
    /// Render settings.
    pub settings: FrameSettings,
    /// How the radiance is estimated.
    pub estimator: Estimator,
    /// Where the scene stands: clock, moved instances, sky strength and light edits.
    pub pose: ScenePose,
    /// Tone mapping for 8-bit output of this frame, fixed from the previous frame's tile
    /// statistics (paper 3.4) or from a fixed exposure.
    pub tone_map: ToneMapper,
    /// The pixels the frame delivers: the display image only, or linear radiance too.
    pub pixels: PixelFormat,
    /// Frame number (0 for the first frame).
    pub number: u32,
    /// Draw fresh VPLs and sample patterns every frame (for progressive accumulation); off,
    /// a still scene keeps the same VPLs and does not flicker.
    pub reseed_per_frame: bool,
}

/// Where a frame's samples lie in an Owen-scrambled Sobol sequence: the scramble seed and the
/// index of the frame's first sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SequenceSpan {
    /// Scramble seed.
    pub seed: u32,
    /// Index of the frame's first sample.
    pub first: u32,
}

impl FrameState {
    /// Frame 0 of `camera` with `settings`, estimated by instant global illumination: the
    /// scene at time 0 as loaded, the linear tone map, linear radiance delivered, the same
    /// samples every frame.
    pub fn new(camera: Camera, settings: FrameSettings) -> Self {
        Self {
            camera,
            settings,
            estimator: Estimator::Igi,
            pose: ScenePose::default(),
            tone_map: ToneMapper::LINEAR,
            pixels: PixelFormat::Linear,
            number: 0,
            reseed_per_frame: false,
        }
    }

    /// The seed this frame's samples derive from: the base seed, mixed with the frame number if
    /// `reseed_per_frame` is set.
    pub fn sample_seed(&self) -> u32 {
        if self.reseed_per_frame { hash_combine(self.settings.seed, self.number) } else { self.settings.seed }
    }

    /// The part of a sample sequence this frame uses when each frame takes `per_frame`
    /// samples of it. Without `reseed_per_frame` every frame takes the first ones (a still
    /// scene does not flicker). With it, consecutive frames take consecutive blocks of one
    /// sequence, so an average over frames keeps the stratification of the Sobol points
    /// instead of averaging independent sets; the scramble changes only when a sequence of
    /// [`MAX_SAMPLES`](crate::sampling::MAX_SAMPLES) points is used up.
    pub fn sequence(&self, per_frame: u32) -> SequenceSpan {
        if !self.reseed_per_frame {
            return SequenceSpan { seed: self.settings.seed, first: 0 };
        }
        let per_frame = per_frame.clamp(1, crate::sampling::MAX_SAMPLES);
        let frames_per_sequence = crate::sampling::MAX_SAMPLES / per_frame;
        let epoch = self.number / frames_per_sequence;
        SequenceSpan {
            seed: hash_combine(self.settings.seed, epoch),
            first: (self.number % frames_per_sequence) * per_frame,
        }
    }
}
