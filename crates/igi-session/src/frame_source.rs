//! [`FrameSource`]: where a session's frames are rendered. On this machine that is a
//! [`FrameRenderer`]'s threads; on a cluster (`igi-cluster`) it is rank 0 handing tiles to render
//! nodes, which send back 8-bit pixels (paper section 3.4) unless the frame asks for linear
//! radiance to accumulate.

use igi_render::image::tonemap::LuminanceStats;
use igi_render::path_tracer::render_path_traced_cancellable;
use igi_render::{
    CancelToken, Cancelled, FrameError, FrameImage, FrameOutput, FrameRenderer, FrameState, PhaseTimes,
    PreparedScene, RayCounts,
};
use std::time::Instant;

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
    /// Renders `frame` unless `cancel` stops it between tiles. Afterwards `scene` stands in
    /// the frame's pose (a remote source poses its own copies too).
    fn render_cancellable(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
    ) -> Result<FrameOutput, SourceError>;

    /// [`FrameSource::render_cancellable`] with nothing that could cancel the frame.
    fn render(&mut self, scene: &mut PreparedScene, frame: &FrameState) -> Result<FrameOutput, SourceError> {
        self.render_cancellable(scene, frame, &CancelToken::new())
    }

    /// Render threads in all (for the per-phase times of the statistics).
    fn threads(&self) -> usize;

    /// One path-traced sample per pixel of `frame`, as linear radiance (the viewers' reference
    /// mode, averaged over frames like IGI frames). A source that cannot says why.
    fn render_path_traced(
        &mut self,
        _scene: &mut PreparedScene,
        _frame: &FrameState,
        _cancel: &CancelToken,
    ) -> Result<FrameOutput, SourceError> {
        Err(SourceError::Failed("the path tracer runs on one machine only, not on a cluster".into()))
    }

    /// True if an 8-bit frame costs markedly less than a linear one (a cluster's nodes send
    /// a quarter of the bytes, paper 3.4), so a session asks for linear radiance only for
    /// the frames it averages. Locally the linear image is there anyway.
    fn prefers_srgb8(&self) -> bool {
        false
    }
}

impl FrameSource for FrameRenderer {
    fn render_cancellable(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
    ) -> Result<FrameOutput, SourceError> {
        FrameRenderer::render_cancellable(self, scene, frame, cancel, &|_, _| {}).map_err(|e| match e {
            FrameError::Settings(e) => SourceError::Failed(e.to_string()),
            FrameError::Cancelled(c) => SourceError::Cancelled(c),
        })
    }

    fn render_path_traced(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
    ) -> Result<FrameOutput, SourceError> {
        let start = Instant::now();
        let (film, rays) =
            render_path_traced_cancellable(scene, frame, 1, self.scheduler(), cancel, &|_, _| {})?;
        let stats = LuminanceStats::of_pixels(film.pixels());
        Ok(FrameOutput {
            image: FrameImage::from_film(film, &frame.tone_map),
            stats,
            // The path tracer's rays are camera paths: counted as primary rays.
            rays: RayCounts { primary: rays, ..RayCounts::default() },
            times: PhaseTimes::default(),
            elapsed: start.elapsed(),
            vpls: 0,
        })
    }

    fn threads(&self) -> usize {
        FrameRenderer::threads(self)
    }
}
