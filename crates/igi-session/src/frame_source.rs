//! [`FrameSource`]: where a session's frames are rendered. On this machine that is a
//! [`FrameRenderer`]'s threads; on a cluster (`igi-cluster`) it is rank 0 handing tiles to render
//! nodes, which send back 8-bit pixels (paper section 3.4) unless the session asks for linear
//! radiance to accumulate.

use glam::Affine3A;
use igi_render::stats::{PhaseTimes, RayCounts};
use igi_render::tonemap::LuminanceStats;
use igi_render::{Film, FrameRenderer, FrameState, PreparedScene};

/// Where the scene stands for a frame: the clock and the instances a user moved (their world
/// transforms), as [`PreparedScene::place`] takes them. A remote renderer poses its own copy
/// of the scene from it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScenePose {
    /// Scene clock, seconds.
    pub time: f32,
    /// Moved instances and their extra world transforms.
    pub moved: Vec<(u32, Affine3A)>,
}

/// A rendered frame as a source returns it.
#[derive(Clone, Debug)]
pub struct SourceFrame {
    /// Linear radiance, if it was asked for (a local renderer always has it).
    pub film: Option<Film>,
    /// The display image, tone-mapped with the frame's [`FrameState::tone_map`]: 8-bit sRGB,
    /// 3 bytes per pixel, rows top to bottom.
    pub srgb8: Vec<u8>,
    /// Luminance statistics combined in tile order.
    pub stats: LuminanceStats,
    /// Rays traced.
    pub rays: RayCounts,
    /// Time per phase, summed over the render threads.
    pub times: PhaseTimes,
    /// VPLs of the frame.
    pub vpls: usize,
}

/// Why a source could not render a frame.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct SourceError(pub String);

/// Renders frames of a session's scene.
pub trait FrameSource: Send + std::fmt::Debug {
    /// Renders `frame` of `scene` posed at `pose`; the session has already posed `scene`
    /// itself. With `linear` the result carries the linear film.
    fn render(
        &mut self,
        scene: &PreparedScene,
        pose: &ScenePose,
        frame: &FrameState,
        linear: bool,
    ) -> Result<SourceFrame, SourceError>;

    /// Render threads in all (for the per-phase times of the statistics).
    fn threads(&self) -> usize;
}

impl FrameSource for FrameRenderer {
    fn render(
        &mut self,
        scene: &PreparedScene,
        _pose: &ScenePose,
        frame: &FrameState,
        _linear: bool,
    ) -> Result<SourceFrame, SourceError> {
        let out =
            FrameRenderer::render(self, scene, frame, &|_, _| {}).map_err(|e| SourceError(e.to_string()))?;
        Ok(SourceFrame {
            film: Some(out.film),
            srgb8: out.srgb8,
            stats: out.stats,
            rays: out.rays,
            times: out.times,
            vpls: out.vpls,
        })
    }

    fn threads(&self) -> usize {
        FrameRenderer::threads(self)
    }
}
