//! [`FrameRenderer`]: a scene and a [`FrameState`] in, a frame out. It poses the scene as the
//! frame says (the one place where a scene is posed for a frame), generates the frame's VPLs, hands the tiles on demand to its persistent worker threads ([`TileScheduler`]), each
//! running the [`TilePipeline`], and combines the finished tiles and their luminance
//! statistics in tile order (paper 3.4), so the result is the same at any thread count.
//! [`FrameRenderer::render_cancellable`] stops between tiles when its [`CancelToken`] says so
//! and then returns no image at all.
//!
//! [`FrameRenderer::render_accumulated`] averages frames with fresh VPL sets and sample
//! patterns ([`Progressive`]): the progressive mode of a still scene, converging to the
//! instant-radiosity solution (unclamped with `clamp` 0).

use crate::frame::{FrameState, SettingsError};
use crate::igi::tile_pipeline::{TilePipeline, TileScratch};
use crate::igi::vpl::VplSets;
use crate::image::frame_image::{FrameImage, PixelFormat};
use crate::image::progressive::{Progressive, Shown};
use crate::image::stats::{Phase, PhaseTimes, RayCounts};
use crate::image::tile::TileGrid;
use crate::image::tonemap::{LuminanceStats, ToneMap};
use crate::prepared::PreparedScene;
use crate::schedule::cancel::{CancelToken, Cancelled};
use crate::schedule::scheduler::TileScheduler;
use std::time::{Duration, Instant};

/// A rendered frame and what it cost.
#[derive(Clone, Debug)]
pub struct FrameOutput {
    /// The image, in the frame's [`FrameState::pixels`] format.
    pub image: FrameImage,
    /// Luminance statistics of the image, combined from the tiles in tile order: the input of
    /// the next frame's tone mapping.
    pub stats: LuminanceStats,
    /// Rays traced.
    pub rays: RayCounts,
    /// Time per phase; the tile phases are summed over the worker threads.
    pub times: PhaseTimes,
    /// Wall-clock time of the whole frame.
    pub elapsed: Duration,
    /// VPLs (surface and sky) over all sets.
    pub vpls: usize,
}

/// Why [`FrameRenderer::render_cancellable`] returned no frame.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FrameError {
    /// A setting is out of range.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The frame was cancelled between tiles.
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// Renders frames on a pool of persistent worker threads.
#[derive(Debug)]
pub struct FrameRenderer {
    scheduler: TileScheduler,
}

impl FrameRenderer {
    /// A renderer with `threads` workers (0: one per core).
    pub fn new(threads: usize) -> Self {
        Self { scheduler: TileScheduler::new(threads) }
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.scheduler.threads()
    }

    /// The tile scheduler (for other renderers sharing the threads, such as the path tracer).
    pub fn scheduler(&self) -> &TileScheduler {
        &self.scheduler
    }

    /// Poses `scene` as `frame` says and renders the frame; `progress(done, total)` is called
    /// after each tile.
    pub fn render(
        &self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, SettingsError> {
        self.render_cancellable(scene, frame, &CancelToken::new(), progress).map_err(|e| match e {
            FrameError::Settings(e) => e,
            FrameError::Cancelled(_) => unreachable!("nobody else holds the token"),
        })
    }

    /// [`FrameRenderer::render`], unless `cancel` stops it between two tiles.
    pub fn render_cancellable(
        &self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, FrameError> {
        let start = Instant::now();
        let plan = self.plan(scene, frame)?;
        let pipeline = plan.pipeline();
        let tiles = self.scheduler.run(
            &plan.grid,
            cancel,
            TileScratch::default,
            |scratch, tile| pipeline.render_tile(tile, scratch),
            progress,
        )?;
        let mut stats = LuminanceStats::default();
        let mut rays = RayCounts::default();
        let mut times = plan.times;
        let mut pixels = Vec::with_capacity(tiles.len());
        for t in tiles {
            stats = stats.merge(t.stats);
            rays += t.rays;
            times += t.times;
            pixels.push((t.tile, t.pixels));
        }
        let s = &frame.settings;
        let image = FrameImage::from_tiles(frame.pixels, s.width, s.height, pixels);
        Ok(FrameOutput { image, stats, rays, times, elapsed: start.elapsed(), vpls: plan.vpl_count() })
    }

    /// Makes `frame` ready to render tile by tile: checks its settings, poses `scene` as the
    /// frame says and generates the frame's VPLs on the render threads.
    pub fn plan<'a>(
        &self,
        scene: &'a mut PreparedScene,
        frame: &'a FrameState,
    ) -> Result<FramePlan<'a>, SettingsError> {
        frame.settings.validate()?;
        let start = Instant::now();
        scene.pose(&frame.pose);
        let scene = &*scene;
        let vpls = self.scheduler.install(|| VplSets::generate(scene, frame));
        let mut times = PhaseTimes::default();
        times.add(Phase::VplGeneration, start.elapsed());
        let s = &frame.settings;
        Ok(FramePlan { scene, frame, vpls, grid: TileGrid::new(s.width, s.height, s.tile_size), times })
    }

    /// The average of `frames` frames from `frame` on (frame numbers `frame.frame`,
    /// `frame.frame + 1`, …), each with fresh VPLs and sample patterns, in linear radiance.
    /// `progress(done, total)` counts tiles over all frames. Rays, times and VPLs are the sums
    /// over the frames.
    pub fn render_accumulated(
        &self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        frames: u32,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, SettingsError> {
        let frames = frames.max(1);
        let mut f = frame.clone();
        f.settings.reseed_per_frame |= frames > 1;
        f.pixels = PixelFormat::Linear;
        let per_frame = TileGrid::new(f.settings.width, f.settings.height, f.settings.tile_size).len();
        let total = per_frame.saturating_mul(frames);
        let start = Instant::now();
        let mut mean = Progressive::new(ToneMap::default());
        let (mut rays, mut times, mut vpls) = (RayCounts::default(), PhaseTimes::default(), 0);
        for i in 0..frames {
            f.frame = frame.frame.wrapping_add(i);
            let done_before = per_frame.saturating_mul(i);
            let one = self.render(scene, &f, &|done, _| progress(done_before.saturating_add(done), total))?;
            rays += one.rays;
            times += one.times;
            vpls += one.vpls;
            mean.add(one.image, one.stats);
        }
        let Shown { image, stats } = mean.show();
        Ok(FrameOutput { image, stats, rays, times, elapsed: start.elapsed(), vpls })
    }
}

/// A frame ready to render tile by tile ([`FrameRenderer::plan`]): the posed scene, the
/// frame's VPLs and its tile grid.
#[derive(Debug)]
pub struct FramePlan<'a> {
    scene: &'a PreparedScene,
    frame: &'a FrameState,
    vpls: VplSets,
    /// The frame's tiles.
    pub grid: TileGrid,
    /// Time spent so far (the VPL generation).
    pub times: PhaseTimes,
}

impl FramePlan<'_> {
    /// The pipeline that renders the frame's tiles.
    pub fn pipeline(&self) -> TilePipeline<'_> {
        TilePipeline::new(self.scene, self.frame, &self.vpls)
    }

    /// VPLs (surface and sky) over all sets.
    pub fn vpl_count(&self) -> usize {
        self.vpls.total_vpls()
    }
}
