//! [`FrameSource`]: where frames are rendered, the one interface `igi render`, `igi bench
//! frame` and `igi bench quality`, the viewers and a cluster's rank 0 drive. On this machine it is a [`FrameRenderer`]'s
//! threads; on a cluster (`igi-cluster`) it is rank 0 handing tiles to render nodes, which send
//! back 8-bit pixels (paper section 3.4) unless the frame asks for linear radiance to
//! accumulate. Which estimator computes the frame (instant global illumination or the path
//! tracer) is the frame's own choice ([`FrameState::estimator`]), so every source runs either.
//!
//! Averaging frames (progressive refinement) is [`FrameSource::accumulate`], the one loop that
//! feeds a [`Progressive`] mean from a source.

use crate::frame::FrameState;
use crate::image::frame_image::PixelFormat;
use crate::image::progressive::{Progressive, Shown};
use crate::image::stats::{PhaseTimes, RayCounts};
use crate::image::tile::TileGrid;
use crate::image::tonemap::ToneMap;
use crate::prepared::PreparedScene;
use crate::schedule::cancel::CancelToken;
use crate::schedule::frame_renderer::{FrameError, FrameOutput, FrameRenderer};
use std::time::Instant;

/// Renders frames of a scene.
pub trait FrameSource: Send + std::fmt::Debug {
    /// Renders `frame` unless `cancel` stops it between tiles; `progress(done, total)` counts
    /// the tiles this machine renders. Afterwards `scene` stands in the frame's pose (a remote
    /// source poses its own copies too).
    fn render_frame(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, FrameError>;

    /// Render threads in all (for the per-phase times of the statistics).
    fn threads(&self) -> usize;

    /// True if an 8-bit frame costs markedly less than a linear one (a cluster's nodes send
    /// a quarter of the bytes, paper 3.4), so a viewer asks for linear radiance only for the
    /// frames it averages. Locally the linear image is there anyway.
    fn prefers_srgb8(&self) -> bool {
        false
    }

    /// Renders `frames` frames from `frame` on (frame numbers `frame.number`,
    /// `frame.number + 1`, …; with more than one, each with fresh VPLs and sample patterns)
    /// into `view`, which starts a new mean, and shows it: a linear frame's mean, or an 8-bit
    /// frame as it came. `progress(done, total)` counts tiles over all frames. Rays, times and
    /// VPLs of the output are the sums over the frames.
    fn accumulate(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        frames: u32,
        view: &mut Progressive,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, FrameError> {
        let frames = frames.max(1);
        let mut f = frame.clone();
        f.reseed_per_frame |= frames > 1;
        let per_frame = TileGrid::new(f.settings.width, f.settings.height, f.settings.tile_size).len();
        let total = per_frame.saturating_mul(frames);
        let start = Instant::now();
        let (mut rays, mut times, mut vpls) = (RayCounts::default(), PhaseTimes::default(), 0);
        view.reset();
        for i in 0..frames {
            f.number = frame.number.wrapping_add(i);
            let done_before = per_frame.saturating_mul(i);
            let one = self.render_frame(scene, &f, &CancelToken::new(), &|done, _| {
                progress(done_before.saturating_add(done), total)
            })?;
            rays += one.rays;
            times += one.times;
            vpls += one.vpls;
            view.add(one.image, one.stats);
        }
        let Shown { image, stats } = view.show();
        Ok(FrameOutput { image, stats, rays, times, elapsed: start.elapsed(), vpls })
    }

    /// The average of `frames` frames from `frame` on ([`FrameSource::accumulate`]) in linear
    /// radiance, a mean of its own.
    fn render_accumulated(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        frames: u32,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, FrameError> {
        let linear = FrameState { pixels: PixelFormat::Linear, ..frame.clone() };
        self.accumulate(scene, &linear, frames, &mut Progressive::new(ToneMap::default()), progress)
    }
}

impl FrameSource for FrameRenderer {
    fn render_frame(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, FrameError> {
        self.render_cancellable(scene, frame, cancel, progress)
    }

    fn threads(&self) -> usize {
        FrameRenderer::threads(self)
    }
}
