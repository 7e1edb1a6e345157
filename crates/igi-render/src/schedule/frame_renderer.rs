//! [`FrameRenderer`]: a scene and a [`FrameState`] in, a frame out, on this machine's threads.
//! It poses the scene as the frame says, prepares the frame's estimator ([`FramePlan`]: the
//! VPLs of instant global illumination, or the path tracer), hands the tiles on demand to its
//! persistent worker threads ([`TileScheduler`]; instant global illumination in two passes,
//! every tile lit and then every tile filtered, so no pixel is traced twice for the filter's
//! apron) and combines the finished tiles and their
//! luminance statistics in tile order (paper 3.4), so the result is the same at any thread
//! count. [`FrameRenderer::render_cancellable`] stops between tiles when its [`CancelToken`]
//! says so and then returns no image at all. A render node of a cluster plans a frame the same
//! way and renders the tiles rank 0 hands it ([`FramePlan::tiles`]).

use crate::frame::{Estimator, FrameState, SettingsError};
use crate::igi::tile_pipeline::{LitTile, TilePipeline, TileScratch};
use crate::igi::vpl::VplSets;
use crate::image::frame_image::{FrameImage, TileOutput};
use crate::image::stats::{Phase, PhaseTimes, RayCounts};
use crate::image::tile::{Tile, TileGrid};
use crate::image::tonemap::LuminanceStats;
use crate::path_tracer::PathTracer;
use crate::prepared::PreparedScene;
use crate::schedule::cancel::{CancelToken, Cancelled};
use crate::schedule::pool::{Lent, Pool};
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

/// Why a frame source returned no frame.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FrameError {
    /// A setting is out of range.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The frame was cancelled between tiles.
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
    /// The source could not render it (a cluster lost its nodes); the message says why.
    #[error("{0}")]
    Failed(String),
}

/// The most bytes a frame holds per pixel while it renders, beyond the prepared scene: every
/// tile's lit points until the second pass composes them (ARCHITECTURE.md, "A frame in two
/// passes"; a pixel whose samples see different surfaces has a point per sample), the image
/// and, while frames accumulate, their mean. With [`FRAME_BYTES_PER_THREAD`] it bounds what a
/// frame takes (`tests/frame_memory.rs` holds frames to it), from which `igi render` says what
/// an image will need before it starts.
pub const FRAME_BYTES_PER_PIXEL: u64 = 384;

/// The most bytes a frame holds per render thread whatever its size: the thread's scratch
/// memory for a tile and its apron.
pub const FRAME_BYTES_PER_THREAD: u64 = 32 << 20;

/// Renders frames on a pool of persistent worker threads.
#[derive(Debug)]
pub struct FrameRenderer {
    scheduler: TileScheduler,
    /// The threads' scratch memory and the lit tiles of the last frame, kept for the next.
    scratch: Pool<TileScratch>,
    lit: Pool<LitTile>,
}

impl FrameRenderer {
    /// A renderer with `threads` workers (0: one per core).
    pub fn new(threads: usize) -> Self {
        Self { scheduler: TileScheduler::new(threads), scratch: Pool::default(), lit: Pool::default() }
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.scheduler.threads()
    }

    /// The tile scheduler (for other renderers sharing the threads, such as the path tracer).
    pub fn scheduler(&self) -> &TileScheduler {
        &self.scheduler
    }

    /// Scratch memory for a render thread, given back to the renderer's pool when the guard
    /// drops (a render node's threads render their tiles with it).
    pub fn lend_scratch(&self) -> Lent<'_, TileScratch> {
        self.scratch.lend()
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
            FrameError::Cancelled(_) | FrameError::Failed(_) => {
                unreachable!("nobody else holds the token, and this machine does not fail")
            }
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
        let tiles = match plan.tiles() {
            // Two passes (ARCHITECTURE.md, "A frame in two passes"): every tile's own pixels
            // traced and lit, then every tile filtered from its neighbours' points, so no pixel
            // is traced twice for the filter's apron.
            FrameTiles::Igi(pipeline) => {
                let total = plan.grid.len();
                let lit = self.scheduler.run(
                    &plan.grid,
                    cancel,
                    || self.lend_scratch(),
                    |scratch, tile| {
                        let mut lit = self.lit.take();
                        pipeline.light_tile(tile, scratch, &mut lit);
                        lit
                    },
                    &|done, _| progress(done, 2 * total),
                );
                let composed = lit.as_ref().map_err(|&e| e).and_then(|lit| {
                    self.scheduler.run(
                        &plan.grid,
                        cancel,
                        || self.lend_scratch(),
                        |scratch, tile| pipeline.compose_tile(tile, &plan.grid, lit, scratch),
                        &|done, _| progress(total + done, 2 * total),
                    )
                });
                self.lit.give(lit.into_iter().flatten());
                composed?
            }
            tiles => self.scheduler.run(
                &plan.grid,
                cancel,
                || self.lend_scratch(),
                |scratch, tile| tiles.render(tile, scratch),
                progress,
            )?,
        };
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
    /// frame says and prepares its estimator (instant global illumination generates the
    /// frame's VPLs on the render threads).
    pub fn plan<'a>(
        &self,
        scene: &'a mut PreparedScene,
        frame: &'a FrameState,
    ) -> Result<FramePlan<'a>, SettingsError> {
        frame.settings.validate()?;
        let start = Instant::now();
        scene.pose(&frame.pose);
        let scene = &*scene;
        let estimator = match frame.estimator {
            Estimator::Igi => {
                PlannedEstimator::Igi(self.scheduler.install(|| VplSets::generate(scene, frame)))
            }
            Estimator::PathTracer { spp } => PlannedEstimator::PathTracer(PathTracer::new(scene, frame, spp)),
        };
        let mut times = PhaseTimes::default();
        times.add(Phase::VplGeneration, start.elapsed());
        let s = &frame.settings;
        Ok(FramePlan { scene, frame, estimator, grid: TileGrid::new(s.width, s.height, s.tile_size), times })
    }
}

/// A frame ready to render tile by tile ([`FrameRenderer::plan`]): the posed scene, the
/// frame's estimator and its tile grid.
#[derive(Debug)]
pub struct FramePlan<'a> {
    scene: &'a PreparedScene,
    frame: &'a FrameState,
    estimator: PlannedEstimator<'a>,
    /// The frame's tiles.
    pub grid: TileGrid,
    /// Time spent so far (preparing the estimator: the VPL generation).
    pub times: PhaseTimes,
}

/// A frame's estimator, ready for its tiles.
#[derive(Debug)]
enum PlannedEstimator<'a> {
    /// Instant global illumination with the frame's VPL sets.
    Igi(VplSets),
    /// The reference path tracer.
    PathTracer(PathTracer<'a>),
}

impl FramePlan<'_> {
    /// What renders the frame's tiles.
    pub fn tiles(&self) -> FrameTiles<'_> {
        match &self.estimator {
            PlannedEstimator::Igi(vpls) => FrameTiles::Igi(TilePipeline::new(self.scene, self.frame, vpls)),
            PlannedEstimator::PathTracer(tracer) => FrameTiles::PathTracer(tracer),
        }
    }

    /// VPLs (surface and sky) over all sets (none for the path tracer).
    pub fn vpl_count(&self) -> usize {
        match &self.estimator {
            PlannedEstimator::Igi(vpls) => vpls.total_vpls(),
            PlannedEstimator::PathTracer(_) => 0,
        }
    }
}

/// The tile renderer of a planned frame ([`FramePlan::tiles`]), shared by the render threads.
#[derive(Debug)]
pub enum FrameTiles<'a> {
    /// Instant global illumination's streaming tile pipeline.
    Igi(TilePipeline<'a>),
    /// The path tracer.
    PathTracer(&'a PathTracer<'a>),
}

impl FrameTiles<'_> {
    /// Renders `tile`; `scratch` is the render thread's reusable memory.
    pub fn render(&self, tile: Tile, scratch: &mut TileScratch) -> TileOutput {
        match self {
            Self::Igi(pipeline) => pipeline.render_tile(tile, scratch),
            Self::PathTracer(tracer) => tracer.render_tile(tile),
        }
    }
}
