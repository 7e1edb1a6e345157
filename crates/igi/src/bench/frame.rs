//! `igi bench frame`: frames per second of the whole instant-global-illumination pipeline
//! (VPL generation, primary rays, shading, specular rays, bias compensation, shadow rays,
//! filter, tone mapping to 8-bit), with the time per phase, Mrays/s, rays per pixel and the energy the VPL clamp
//! removes.

use crate::frame_args::FrameArgs;
use anyhow::{Context, Result, bail};
use clap::Args;
use igi_render::image::tonemap::luminance;
use igi_render::schedule::frame_renderer::FrameRenderer;
use igi_render::{CancelToken, FrameSource};
use igi_render::{FrameState, Phase, PreparedScene, Progressive};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Scene-clock frames per second of `--animate` (also `igi bench cluster`'s).
pub const ANIMATION_FPS: f32 = 25.0;

/// Arguments of `igi bench frame`.
#[derive(Debug, Args)]
pub struct FrameBenchArgs {
    /// The scene and the frames timed.
    #[command(flatten)]
    pub timed: super::TimedFrames,
    /// Fresh VPLs every frame (as in progressive accumulation); otherwise the VPLs stay.
    #[arg(long)]
    pub reseed: bool,
    /// Play the scene's animation: frame i shows time `--time` + i/25 s, and each frame's
    /// time includes moving the instances and lights and rebuilding the top-level BVH.
    #[arg(long)]
    pub animate: bool,
    /// Write the results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Frame options.
    #[command(flatten)]
    pub frame: FrameArgs,
}

/// The results, as printed and written.
#[derive(Debug, Serialize)]
struct Report {
    scene: String,
    width: u32,
    height: u32,
    threads: usize,
    vpls_per_pixel: u32,
    interleave: [u32; 2],
    coarse_interleave: u32,
    aa: u32,
    filter: bool,
    clamp: f32,
    frames: u32,
    /// True if the animation played.
    animate: bool,
    /// Mean time per frame spent posing the scene (instances, lights, top-level BVH).
    animate_ms: f64,
    /// Frames per second: timed frames over their total wall time.
    fps: f64,
    /// Mean wall time per frame.
    frame_ms: f64,
    /// Fastest frame.
    min_frame_ms: f64,
    /// Per phase: thread time per frame divided by the thread count (the phase's share of the
    /// wall time when the load is even).
    phases_ms: BTreeMap<&'static str, f64>,
    mrays_per_s: f64,
    rays_per_pixel: f64,
    /// Camera rays per pixel (the tiles' aprons included).
    primary_rays_per_pixel: f64,
    /// Shadow rays per pixel (the tiles' aprons included).
    shadow_rays_per_pixel: f64,
    primary_rays: u64,
    shadow_rays: u64,
    specular_rays: u64,
    /// Surface VPLs per frame over all sets.
    vpls_per_frame: usize,
    /// Fraction of the image's luminance removed by the clamp (frame 0 against the same frame
    /// unclamped).
    clamp_energy_loss: f64,
}

/// Runs `igi bench frame`.
pub fn run(args: &FrameBenchArgs) -> Result<()> {
    if !(1..=100_000).contains(&args.timed.frames) {
        bail!("--frames must be between 1 and 100000");
    }
    super::json_report::check_json(args.json.as_deref())?;
    let scene = igi_scene::load_named(&args.timed.scene).context("cannot load scene")?;
    let mut prepared = args.frame.prepare(scene);
    let mut frame = args.frame.frame_state(&prepared)?;
    frame.reseed_per_frame = args.reseed;
    let mut renderer = FrameRenderer::new(args.frame.threads);
    let threads = renderer.threads();

    let loss = clamp_energy_loss(&mut renderer, &mut prepared, &frame)?;

    // As a viewer in motion does: each frame is tone-mapped with the parameters from the
    // previous frame's statistics, and none is averaged.
    let mut view = Progressive::new(frame.settings.tone_map());
    let posing = std::cell::Cell::new(Duration::ZERO);
    let mut step = |f: &mut FrameState, index: u32| -> Result<igi_render::FrameOutput> {
        if args.animate {
            f.pose.time = args.frame.time + index as f32 / ANIMATION_FPS;
        }
        // Posed here (the render then finds the scene in place) to time it on its own.
        let start = Instant::now();
        prepared.pose(&f.pose);
        let posed = start.elapsed();
        posing.set(posing.get() + posed);
        f.number = index;
        f.tone_map = view.tone_mapper();
        let mut out = renderer.render_frame(&mut prepared, f, &CancelToken::new(), &|_, _| {})?;
        out.elapsed += posed;
        view.reset();
        view.add(out.image, out.stats);
        out.image = view.show().image;
        Ok(out)
    };
    for i in 0..args.timed.warmup {
        step(&mut frame, i)?;
    }
    let warmup_posing = posing.get();
    let mut total = Duration::ZERO;
    let mut fastest = Duration::MAX;
    let mut rays = igi_render::RayCounts::default();
    let mut times = igi_render::PhaseTimes::default();
    let mut vpls = 0;
    for i in 0..args.timed.frames {
        let out = step(&mut frame, args.timed.warmup + i)?;
        total += out.elapsed;
        fastest = fastest.min(out.elapsed);
        rays += out.rays;
        times += out.times;
        vpls += out.vpls;
    }

    let posing = posing.get() - warmup_posing;
    let s = &frame.settings;
    let n = f64::from(args.timed.frames);
    let per_frame_ms = |d: Duration| d.as_secs_f64() * 1e3 / n / threads as f64;
    let phases_ms = Phase::ALL
        .iter()
        .map(|&p| {
            // VPL generation runs on one thread before the tiles: report its wall time.
            let scale = if p == Phase::VplGeneration { threads as f64 } else { 1.0 };
            (p.name(), per_frame_ms(times.get(p)) * scale)
        })
        .collect();
    let pixels = n * f64::from(s.width) * f64::from(s.height);
    let report = Report {
        scene: args.timed.scene.clone(),
        width: s.width,
        height: s.height,
        threads,
        vpls_per_pixel: s.vpls_per_pixel,
        interleave: s.interleave,
        coarse_interleave: s.coarse_interleave,
        aa: s.aa,
        filter: s.filter,
        clamp: s.clamp,
        frames: args.timed.frames,
        animate: args.animate,
        animate_ms: posing.as_secs_f64() * 1e3 / n,
        fps: n / total.as_secs_f64().max(1e-12),
        frame_ms: total.as_secs_f64() * 1e3 / n,
        min_frame_ms: fastest.as_secs_f64() * 1e3,
        phases_ms,
        mrays_per_s: rays.total() as f64 * 1e-6 / total.as_secs_f64().max(1e-12),
        rays_per_pixel: rays.total() as f64 / pixels,
        primary_rays_per_pixel: rays.primary as f64 / pixels,
        shadow_rays_per_pixel: rays.shadow as f64 / pixels,
        primary_rays: rays.primary,
        shadow_rays: rays.shadow,
        specular_rays: rays.specular,
        vpls_per_frame: vpls / args.timed.frames as usize,
        clamp_energy_loss: loss,
    };
    print_report(&report);
    if let Some(path) = &args.json {
        super::json_report::write_json(path, &report)?;
    }
    Ok(())
}

/// 1 − (luminance of frame 0) / (luminance of frame 0 without clamping): the same VPLs and
/// rays, so the difference is exactly what the clamp removes.
fn clamp_energy_loss(
    renderer: &mut dyn FrameSource,
    scene: &mut PreparedScene,
    frame: &FrameState,
) -> Result<f64> {
    if frame.settings.clamp == 0.0 {
        return Ok(0.0);
    }
    let mut total = |f: &FrameState| -> Result<f64> {
        let out = renderer.render_frame(scene, f, &CancelToken::new(), &|_, _| {})?;
        let film = out.image.film().context("a linear frame without its film")?;
        Ok(film.pixels().iter().map(|&p| f64::from(luminance(p))).sum())
    };
    let clamped = total(frame)?;
    let mut unclamped_frame = frame.clone();
    unclamped_frame.settings.clamp = 0.0;
    let unclamped = total(&unclamped_frame)?;
    Ok(if unclamped > 0.0 { 1.0 - clamped / unclamped } else { 0.0 })
}

fn print_report(r: &Report) {
    outln!(
        "{}: {}x{}, {} VPLs/pixel in {} ({} VPLs/frame), aa {}, filter {}, clamp {:.3}, {} thread(s)",
        r.scene,
        r.width,
        r.height,
        r.vpls_per_pixel,
        crate::frame_args::sets_label(r.interleave, r.coarse_interleave),
        r.vpls_per_frame,
        r.aa,
        if r.filter { "on" } else { "off" },
        r.clamp,
        r.threads
    );
    outln!(
        "  {:.2} fps ({:.2} ms/frame, fastest {:.2} ms), {:.1} Mrays/s, {:.1} rays/pixel ({:.1} primary, {:.1} shadow)",
        r.fps,
        r.frame_ms,
        r.min_frame_ms,
        r.mrays_per_s,
        r.rays_per_pixel,
        r.primary_rays_per_pixel,
        r.shadow_rays_per_pixel,
    );
    let phases: Vec<String> =
        Phase::ALL.iter().map(|p| format!("{} {:.2}", p.name(), r.phases_ms[p.name()])).collect();
    outln!("  ms per phase: {}", phases.join(", "));
    if r.animate {
        outln!("  animation: {:.3} ms per frame posing the scene and rebuilding the top level", r.animate_ms);
    }
    outln!("  clamp removes {:.2} % of the image's luminance", 100.0 * r.clamp_energy_loss);
}
