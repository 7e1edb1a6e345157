//! [`FrameSource`]: where a session's frames are rendered. On this machine that is a
//! [`FrameRenderer`]'s threads; on a cluster (`igi-cluster`) it is rank 0 handing tiles to render
//! nodes, which send back 8-bit pixels (paper section 3.4) unless the session asks for linear
//! radiance to accumulate.

use glam::Affine3A;
use igi_render::stats::{PhaseTimes, RayCounts};
use igi_render::tonemap::LuminanceStats;
use igi_render::{CancelToken, Cancelled, Film, FrameError, FrameRenderer, FrameState, PreparedScene};

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

/// Why a source returned no frame.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// The source could not render it; the message says why.
    #[error("{0}")]
    Failed(String),
    /// The frame was cancelled between tiles (it is not wanted any more).
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// Renders frames of a session's scene.
pub trait FrameSource: Send + std::fmt::Debug {
    /// Renders `frame` of `scene` posed at `pose`, unless `cancel` stops it between tiles;
    /// the session has already posed `scene` itself. With `linear` the result carries the
    /// linear film.
    fn render_cancellable(
        &mut self,
        scene: &PreparedScene,
        pose: &ScenePose,
        frame: &FrameState,
        linear: bool,
        cancel: &CancelToken,
    ) -> Result<SourceFrame, SourceError>;

    /// [`FrameSource::render_cancellable`] with nothing that could cancel the frame.
    fn render(
        &mut self,
        scene: &PreparedScene,
        pose: &ScenePose,
        frame: &FrameState,
        linear: bool,
    ) -> Result<SourceFrame, SourceError> {
        self.render_cancellable(scene, pose, frame, linear, &CancelToken::new())
    }

    /// Render threads in all (for the per-phase times of the statistics).
    fn threads(&self) -> usize;
}

impl FrameSource for FrameRenderer {
    fn render_cancellable(
        &mut self,
        scene: &PreparedScene,
        _pose: &ScenePose,
        frame: &FrameState,
        _linear: bool,
        cancel: &CancelToken,
    ) -> Result<SourceFrame, SourceError> {
        let out =
            FrameRenderer::render_cancellable(self, scene, frame, cancel, &|_, _| {}).map_err(
                |e| match e {
                    FrameError::Settings(e) => SourceError::Failed(e.to_string()),
                    FrameError::Cancelled(c) => SourceError::Cancelled(c),
                },
            )?;
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
