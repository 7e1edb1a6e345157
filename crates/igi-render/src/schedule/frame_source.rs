//! [`FrameSource`]: where frames are rendered, the one interface `igi render`, `igi bench
//! frame` and `igi bench quality`, the viewers and a cluster's rank 0 drive. On this machine it is a [`FrameRenderer`]'s
//! threads; on a cluster (`igi-cluster`) it is rank 0 handing tiles to render nodes, which send
//! back 8-bit pixels (paper section 3.4) unless the frame asks for linear radiance to
//! accumulate. Which estimator computes the frame (instant global illumination or the path
//! tracer) is the frame's own choice ([`FrameState::estimator`]), so every source runs either.
//!
//! Averaging frames (progressive refinement) is [`FrameSource::accumulate`], the one loop that
//! feeds a [`Progressive`] mean from a source, for a given number of frames or until the
//! stopping rule of [`crate::image::convergence`] says the mean is done.

use crate::frame::FrameState;
use crate::image::convergence::{BlotchEstimate, Stopped, Until};
use crate::image::frame_image::PixelFormat;
use crate::image::progressive::{Progressive, Shown};
use crate::image::stats::{PhaseTimes, RayCounts};
use crate::image::tile::TileGrid;
use crate::image::tonemap::ToneMap;
use crate::prepared::PreparedScene;
use crate::schedule::cancel::CancelToken;
use crate::schedule::frame_renderer::{FrameError, FrameOutput, FrameRenderer};
use std::time::{Duration, Instant};

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

    /// Renders frames from `frame` on (frame numbers `frame.number`, `frame.number + 1`, …;
    /// with more than one, each with fresh VPLs and sample patterns) into `view`, which starts
    /// a new mean, until `until` says the mean is done, and shows it: a linear frame's mean, or
    /// an 8-bit frame as it came. `progress(done, total)` counts tiles: over all frames for a
    /// fixed count, up to the end of the current frame for a converging mean. `on_frame` hears
    /// of each finished frame. Rays, times and VPLs of the output are the sums over the frames.
    fn accumulate(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        until: Until,
        view: &mut Progressive,
        progress: &(dyn Fn(u32, u32) + Sync),
        on_frame: &mut dyn FnMut(&FrameDone),
    ) -> Result<Accumulated, FrameError> {
        let mut f = frame.clone();
        f.reseed_per_frame |= match until {
            Until::Frames(n) => n > 1,
            Until::Converged(_) => true,
        };
        let per_frame = TileGrid::new(f.settings.width, f.settings.height, f.settings.tile_size).len();
        let start = Instant::now();
        let (mut rays, mut times, mut vpls) = (RayCounts::default(), PhaseTimes::default(), 0);
        let mut estimate = BlotchEstimate::new();
        view.reset();
        let mut frames = 0u32;
        let stopped = loop {
            let (rule, planned) = match until {
                Until::Frames(n) if frames >= n.max(1) => break Stopped::Frames,
                Until::Frames(n) => (None, n.max(1)),
                Until::Converged(rule) => (Some(rule), frames + 1),
            };
            f.number = frame.number.wrapping_add(frames);
            let done_before = per_frame.saturating_mul(frames);
            let total = per_frame.saturating_mul(planned);
            let one = self.render_frame(scene, &f, &CancelToken::new(), &|done, _| {
                progress(done_before.saturating_add(done), total)
            })?;
            frames += 1;
            rays += one.rays;
            times += one.times;
            vpls += one.vpls;
            if rule.is_some() {
                if let Some(film) = one.image.film() {
                    estimate.add(film);
                }
            }
            view.add(one.image, one.stats);
            let elapsed = start.elapsed();
            on_frame(&FrameDone { frames, elapsed, estimated_blotch: estimate.blotch() });
            if let Some(rule) = rule {
                if frames >= rule.min_frames && estimate.blotch().is_some_and(|b| b <= rule.target) {
                    break Stopped::Converged;
                }
                // The next frame is expected to take as long as the mean so far.
                if elapsed + elapsed / frames > rule.time_budget {
                    break Stopped::TimeBudget;
                }
            }
        };
        let Shown { image, stats } = view.show();
        Ok(Accumulated {
            output: FrameOutput { image, stats, rays, times, elapsed: start.elapsed(), vpls },
            frames,
            stopped,
            estimated_blotch: estimate.blotch(),
        })
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
        let mut view = Progressive::new(ToneMap::default());
        Ok(self.accumulate(scene, &linear, Until::Frames(frames), &mut view, progress, &mut |_| {})?.output)
    }
}

/// A finished frame of an accumulation.
#[derive(Clone, Copy, Debug)]
pub struct FrameDone {
    /// Frames in the mean so far.
    pub frames: u32,
    /// Time since the first frame started.
    pub elapsed: Duration,
    /// The mean's estimated blotch10 ([`BlotchEstimate`]), for a converging mean of two frames
    /// or more.
    pub estimated_blotch: Option<f64>,
}

/// A mean of frames ([`FrameSource::accumulate`]): the output and how it came about.
#[derive(Debug)]
pub struct Accumulated {
    /// The mean (or the 8-bit frame) and the sums of rays, times and VPLs over its frames.
    pub output: FrameOutput,
    /// Frames averaged.
    pub frames: u32,
    /// Why it stopped there.
    pub stopped: Stopped,
    /// The estimated blotch10 of the mean, for a converging mean of two frames or more.
    pub estimated_blotch: Option<f64>,
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
