//! [`FrameSource`]: where a session's frames are rendered. On this machine that is a
//! [`FrameRenderer`]'s threads; on a cluster (`igi-cluster`) it is rank 0 handing tiles to render
//! nodes, which send back 8-bit pixels (paper section 3.4) unless the frame asks for linear
//! radiance to accumulate.

use igi_render::{CancelToken, Cancelled, FrameError, FrameOutput, FrameRenderer, FrameState, PreparedScene};

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

    fn threads(&self) -> usize {
        FrameRenderer::threads(self)
    }
}
