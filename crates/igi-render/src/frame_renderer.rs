//! [`FrameRenderer`]: a scene and a [`FrameState`] in, a frame out. It generates the frame's
//! VPLs, hands the tiles on demand to its persistent worker threads ([`TileScheduler`]), each
//! running the [`TilePipeline`], and combines the finished tiles and their luminance
//! statistics in tile order (paper 3.4), so the result is the same at any thread count.
//! [`FrameRenderer::render_cancellable`] stops between tiles when its [`CancelToken`] says so
//! and then returns no image at all.
//!
//! [`FrameRenderer::render_accumulated`] averages frames with fresh VPL sets and sample
//! patterns: the progressive mode of a still scene, converging to the instant-radiosity
//! solution (unclamped with `clamp` 0).

use crate::cancel::{CancelToken, Cancelled};
use crate::film::Film;
use crate::frame::{FrameState, SettingsError};
use crate::prepared::PreparedScene;
use crate::scheduler::TileScheduler;
use crate::stats::{Phase, PhaseTimes, RayCounts};
use crate::tile::TileGrid;
use crate::tile_pipeline::{TilePipeline, TileScratch};
use crate::tonemap::LuminanceStats;
use crate::vpl::VplSets;
use glam::Vec3;
use std::time::{Duration, Instant};

/// A rendered frame and what it cost.
#[derive(Clone, Debug)]
pub struct FrameOutput {
    /// Linear radiance.
    pub film: Film,
    /// The display image: 8-bit sRGB, 3 bytes per pixel, row-major, tone-mapped with the
    /// frame's [`FrameState::tone_map`].
    pub srgb8: Vec<u8>,
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
    /// Frames averaged into the image.
    pub frames: u32,
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

    /// Renders one frame; `progress(done, total)` is called after each tile.
    pub fn render(
        &self,
        scene: &PreparedScene,
        frame: &FrameState,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, SettingsError> {
        self.render_cancellable(scene, frame, &CancelToken::new(), progress).map_err(|e| match e {
            FrameError::Settings(e) => e,
            FrameError::Cancelled(_) => unreachable!("nobody else holds the token"),
        })
    }

    /// Renders one frame unless `cancel` stops it between two tiles; `progress(done, total)`
    /// is called after each tile.
    pub fn render_cancellable(
        &self,
        scene: &PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, FrameError> {
        frame.settings.validate()?;
        let start = Instant::now();
        let mut times = PhaseTimes::default();
        let vpls = self.scheduler.install(|| VplSets::generate(scene, frame));
        times.add(Phase::VplGeneration, start.elapsed());

        let s = &frame.settings;
        let grid = TileGrid::new(s.width, s.height, s.tile_size);
        let pipeline = TilePipeline::new(scene, frame, &vpls);
        let tiles = self.scheduler.run(
            &grid,
            cancel,
            TileScratch::default,
            |scratch, tile| pipeline.render_tile(tile, scratch),
            progress,
        )?;

        let mut film = Film::new(s.width, s.height);
        let mut srgb8 = vec![0u8; 3 * s.width as usize * s.height as usize];
        let mut stats = LuminanceStats::default();
        let mut rays = RayCounts::default();
        for t in &tiles {
            film.write_tile(&t.tile, &t.pixels);
            let row = 3 * t.tile.width() as usize;
            for (r, src) in t.srgb8.chunks_exact(row).enumerate() {
                let start = 3 * ((t.tile.y0 as usize + r) * s.width as usize + t.tile.x0 as usize);
                srgb8[start..start + row].copy_from_slice(src);
            }
            stats = stats.merge(t.stats);
            rays += t.rays;
            times += t.times;
        }
        let vpl_count = vpls.total_vpls();
        Ok(FrameOutput {
            film,
            srgb8,
            stats,
            rays,
            times,
            elapsed: start.elapsed(),
            vpls: vpl_count,
            frames: 1,
        })
    }

    /// The average of `frames` frames from `frame` on (frame numbers `frame.frame`,
    /// `frame.frame + 1`, …), each with fresh VPLs and sample patterns. `progress(done,
    /// total)` counts tiles over all frames.
    pub fn render_accumulated(
        &self,
        scene: &PreparedScene,
        frame: &FrameState,
        frames: u32,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, SettingsError> {
        let frames = frames.max(1);
        let mut f = *frame;
        f.settings.reseed_per_frame |= frames > 1;
        let grid = TileGrid::new(f.settings.width, f.settings.height, f.settings.tile_size);
        let per_frame = grid.len();
        let total = per_frame.saturating_mul(frames);
        let start = Instant::now();
        let mut render_frame = |i: u32| {
            f.frame = frame.frame.wrapping_add(i);
            let done_before = per_frame.saturating_mul(i);
            self.render(scene, &f, &|done, _| progress(done_before.saturating_add(done), total))
        };
        let mut out = render_frame(0)?;
        let mut sum: Vec<Vec3> = out.film.pixels().to_vec();
        for i in 1..frames {
            let one = render_frame(i)?;
            sum.iter_mut().zip(one.film.pixels()).for_each(|(a, b)| *a += *b);
            out.rays += one.rays;
            out.times += one.times;
            out.vpls += one.vpls;
        }
        let scale = 1.0 / frames as f32;
        let film = Film::from_pixels(
            f.settings.width,
            f.settings.height,
            sum.into_iter().map(|p| p * scale).collect(),
        );
        out.stats = LuminanceStats::of_pixels(film.pixels());
        out.srgb8 = crate::output::to_srgb8(&film, &frame.tone_map);
        out.film = film;
        out.frames = frames;
        out.elapsed = start.elapsed();
        Ok(out)
    }
}
