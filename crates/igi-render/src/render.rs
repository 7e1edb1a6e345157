//! The local tile scheduler: an image is cut into a [`TileGrid`], worker threads take tiles
//! from an atomic counter, and each tile is rendered by a [`TileRenderer`] into its own
//! buffer. Because a tile's pixels depend only on the scene, the settings and the tile, the
//! image is the same bit for bit for any number of threads (DESIGN.md section 4), and the
//! same [`TileRenderer::render_tile`] can serve tiles on demand (a viewer, a cluster node).

use crate::camera::PinholeCamera;
use crate::direct::{DirectLighting, RayCounts};
use crate::film::Film;
use crate::prepared::PreparedScene;
use crate::tile::{Tile, TileGrid};
use crate::tonemap::ToneMap;
use glam::Vec3;
use igi_bvh::{Ray, RayPacket8};
use igi_scene::Camera;
use igi_simd::M32x8;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// Everything about a render besides the scene and the camera.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Area-light samples (shadow rays to emissive triangles) per pixel.
    pub samples: u32,
    /// Frame seed: the sample pattern of every pixel derives from it.
    pub seed: u32,
    /// Worker threads; 0 means one per available core.
    pub threads: usize,
    /// Edge length of the square tiles in pixels.
    pub tile_size: u32,
    /// Fixed exposure in stops for tone-mapped output; `None` for automatic (Reinhard).
    pub exposure: Option<f32>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self { width: 640, height: 480, samples: 4, seed: 0, threads: 0, tile_size: 16, exposure: None }
    }
}

impl RenderSettings {
    /// The number of worker threads these settings ask for (0 resolved to the core count).
    pub fn thread_count(&self) -> usize {
        if self.threads > 0 {
            self.threads
        } else {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        }
    }

    /// The tone map for PNG output: fixed exposure if given, else Reinhard.
    pub fn tone_map(&self) -> ToneMap {
        ToneMap::from_exposure(self.exposure)
    }
}

/// What a render cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Rays traced.
    pub rays: RayCounts,
    /// Wall-clock time of the render.
    pub elapsed: Duration,
    /// Tiles rendered.
    pub tiles: u32,
    /// Worker threads used.
    pub threads: usize,
}

impl RenderStats {
    /// Rays per second over the whole render.
    pub fn rays_per_second(&self) -> f64 {
        self.rays.total() as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }
}

/// Renders tiles of one frame: camera set up for the image size plus the shader.
#[derive(Clone, Debug)]
pub struct TileRenderer<'a> {
    camera: PinholeCamera,
    lighting: DirectLighting<'a>,
}

impl<'a> TileRenderer<'a> {
    /// The renderer of `scene` from `camera` with `settings`.
    pub fn new(scene: &'a PreparedScene, camera: &Camera, settings: &RenderSettings) -> Self {
        Self {
            camera: PinholeCamera::new(camera, settings.width, settings.height),
            lighting: DirectLighting::new(scene, camera, settings.samples, settings.seed),
        }
    }

    /// The camera for the image size.
    pub fn camera(&self) -> &PinholeCamera {
        &self.camera
    }

    /// The shader.
    pub fn lighting(&self) -> &DirectLighting<'a> {
        &self.lighting
    }

    /// Renders `tile` into `out` (resized to the tile's pixel count, row-major within the
    /// tile). Primary rays are traced as 8-ray packets of 4×2 pixel blocks.
    pub fn render_tile(&self, tile: &Tile, out: &mut Vec<Vec3>) -> RayCounts {
        let w = tile.width() as usize;
        out.clear();
        out.resize(tile.pixel_count(), Vec3::ZERO);
        let mut counts = RayCounts::default();
        for by in (tile.y0..tile.y1).step_by(2) {
            for bx in (tile.x0..tile.x1).step_by(4) {
                let mut pixels = [(bx, by); 8];
                let mut rays = [self.camera.ray(bx, by); 8];
                let mut bits = 0u32;
                for lane in 0..8u32 {
                    let (x, y) = (bx + lane % 4, by + lane / 4);
                    if x < tile.x1 && y < tile.y1 {
                        pixels[lane as usize] = (x, y);
                        rays[lane as usize] = self.camera.ray(x, y);
                        bits |= 1 << lane;
                    }
                }
                let packet = RayPacket8::from_rays(&rays);
                let radiance =
                    self.lighting.shade_packet(&packet, M32x8::from_bitmask(bits), &pixels, &mut counts);
                for lane in 0..8 {
                    if bits & (1 << lane) != 0 {
                        let (x, y) = pixels[lane];
                        out[(y - tile.y0) as usize * w + (x - tile.x0) as usize] = radiance[lane];
                    }
                }
            }
        }
        counts
    }

    /// The radiance of pixel `(x, y)` alone (traced as a single ray; equal to its value in a
    /// full render).
    pub fn render_pixel(&self, x: u32, y: u32) -> Vec3 {
        let ray: Ray = self.camera.ray(x, y);
        self.lighting.shade_ray(&ray, (x, y), &mut RayCounts::default())
    }
}

/// What one worker thread hands back: its finished tiles and its ray counts.
type WorkerOutput = (Vec<(Tile, Vec<Vec3>)>, RayCounts);

/// Renders the image of `scene` seen from `camera`.
pub fn render(scene: &PreparedScene, camera: &Camera, settings: &RenderSettings) -> Film {
    render_with_stats(scene, camera, settings, &|_, _| {}).0
}

/// Renders the image and reports the cost. `progress(done, total)` is called from the worker
/// threads after each finished tile.
pub fn render_with_stats(
    scene: &PreparedScene,
    camera: &Camera,
    settings: &RenderSettings,
    progress: &(dyn Fn(u32, u32) + Sync),
) -> (Film, RenderStats) {
    let start = Instant::now();
    let renderer = TileRenderer::new(scene, camera, settings);
    let grid = TileGrid::new(settings.width, settings.height, settings.tile_size);
    let threads = settings.thread_count().clamp(1, grid.len().max(1) as usize);
    let next = AtomicU32::new(0);
    let done = AtomicU32::new(0);

    let worker = || {
        let mut finished: Vec<(Tile, Vec<Vec3>)> = Vec::new();
        let mut counts = RayCounts::default();
        loop {
            let index = next.fetch_add(1, Ordering::Relaxed);
            if index >= grid.len() {
                break;
            }
            let tile = grid.tile(index);
            let mut pixels = Vec::new();
            counts += renderer.render_tile(&tile, &mut pixels);
            finished.push((tile, pixels));
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, grid.len());
        }
        (finished, counts)
    };

    let parts: Vec<WorkerOutput> = if threads == 1 {
        vec![worker()]
    } else {
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..threads).map(|_| s.spawn(worker)).collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
                .collect()
        })
    };

    let mut film = Film::new(settings.width, settings.height);
    let mut rays = RayCounts::default();
    for (tiles, counts) in parts {
        rays += counts;
        for (tile, pixels) in tiles {
            film.write_tile(&tile, &pixels);
        }
    }
    let stats = RenderStats { rays, elapsed: start.elapsed(), tiles: grid.len(), threads };
    (film, stats)
}
