//! `igi bench quality`: how far what `igi render` writes by default (frames until its stopping
//! rule), one frame (bias-compensated, and as a viewer shows it while the view moves), and the
//! mean of N frames are from the converged image, and how much an animation flickers (issue 16
//! measures every change to image quality with it). `--orbit` measures a moving camera instead
//! ([`super::camera_path`]), `--lag` a change of the light ([`super::light_lag`]).
//!
//! Every image is compared as a user sees it: its linear radiance tone-mapped with its own
//! statistics (`--tone-map`, as `igi render` writes a PNG) and encoded as 8-bit sRGB. The figures
//! are the mean LDR-FLIP (Andersson et al. 2020, NVIDIA's implementation through the `nv-flip`
//! crate, 67 pixels per degree), blotch10 on the linear images ([`Blotch`]) and the RMSE of the
//! display values in [0, 1], the figures of `../shared/tools/compare` (its `ldr` mode on the
//! same PNGs for FLIP and RMSE). The reference is the path
//! tracer at `--reference-spp` samples per pixel, or with `--reference-frames N` the mean of N
//! IGI frames (converging to the same solution; the path tracer is slow to find light that
//! comes through a doorway), kept as an EXR file so that later runs reuse it.
//!
//! Flicker (`--flicker F`, for animated scenes): F consecutive frames of the animation at
//! 25 fps from a still camera, each one frame with the VPL seeds a viewer keeps while playing,
//! against the same frames each accumulated over `--accumulate` frames (the same samples for
//! every animation frame, so their own noise changes little from one to the next). With L the luminance
//! of a pixel's radiance, ΔL its change from one frame to the next, and L_ref, ΔL_ref those of
//! the accumulated frames, flicker = mean over frame pairs and pixels of |ΔL − ΔL_ref|, divided
//! by the mean of L_ref: 0 when one frame changes exactly as the converged image does.

use super::camera_path::{self, Orbit, OrbitReport};
use super::frame::ANIMATION_FPS;
use super::light_lag;
use crate::frame_args::FrameArgs;
use crate::progress::LateProgress;
use anyhow::{Context, Result, bail};
use clap::Args;
use igi_render::image::blotch::Blotch;
use igi_render::image::output::{to_srgb8, write_exr};
use igi_render::image::tonemap::luminance;
use igi_render::schedule::frame_renderer::FrameRenderer;
use igi_render::{
    Estimator, Film, FrameSource, FrameState, PixelFormat, PreparedScene, Progressive, ScenePose,
    StoppingRule, ToneMap, ToneMapper, Until,
};
use serde::Serialize;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Arguments of `igi bench quality`.
#[derive(Debug, Args)]
pub struct QualityBenchArgs {
    /// Built-in scene name or scene file.
    pub scene: String,
    /// Frames averaged for the accumulated image (and for each reference frame of `--flicker`).
    #[arg(long, default_value_t = 16)]
    pub accumulate: u32,
    /// Samples per pixel of the path-traced reference.
    #[arg(long, default_value_t = 256)]
    pub reference_spp: u32,
    /// Make the reference the mean of this many IGI frames (as `igi render --frames N`, on
    /// samples the measured frames do not use) instead of path-tracing it: for scenes whose
    /// light the path tracer finds slowly (light through a doorway).
    #[arg(long, conflicts_with = "reference_spp")]
    pub reference_frames: Option<u32>,
    /// The reference as an EXR file: read if it exists, else rendered and written there.
    /// Default: a file in the system's temporary folder named after the scene, camera, image
    /// size and how the reference is made.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Also measure flicker over this many frames of the scene's animation (0: off).
    #[arg(long, default_value_t = 0)]
    pub flicker: u32,
    /// The time budget of the default image (as `igi render --time-budget`).
    #[arg(long, default_value_t = 10.0)]
    pub time_budget: f64,
    /// Instead of the still image, measure this many frames of an orbit about the view's
    /// target as a viewer shows them, with temporal reuse and without (0: off).
    #[arg(long, default_value_t = 0)]
    pub orbit: u32,
    /// Degrees the orbit turns per frame.
    #[arg(long, default_value_t = 4.0, allow_hyphen_values = true)]
    pub orbit_degrees: f32,
    /// Orbit the point this far ahead of the camera instead of its target (scene units; a
    /// far target takes the orbit out of a room).
    #[arg(long)]
    pub orbit_distance: Option<f32>,
    /// The first orbit frame measured (1-based).
    #[arg(long, default_value_t = 9)]
    pub orbit_from: u32,
    /// Instead of the still image, measure the lag of a change of the light: the frames a
    /// viewer takes to show the change the scene's animation makes between `--time` and this
    /// many seconds later.
    #[arg(long)]
    pub lag: Option<f32>,
    /// Frames averaged for the converged image of each view `--orbit` measures and of the
    /// two poses of `--lag`.
    #[arg(long, default_value_t = 64)]
    pub view_reference_frames: u32,
    /// Write the results as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Frame options.
    #[command(flatten)]
    pub frame: FrameArgs,
}

/// Error figures of one image against the reference.
#[derive(Debug, Serialize)]
pub struct Figures {
    /// Mean LDR-FLIP of the display images.
    pub flip: f64,
    /// RMSE of the display values in [0, 1].
    pub rmse: f64,
    /// The share of pixels whose 9×9 window is more than 10 % off in luminance (blotch10,
    /// [`Blotch`]).
    pub blotch10: f64,
    /// Frames in the image.
    pub frames: u32,
    /// Wall time to render the image.
    pub seconds: f64,
}

impl Figures {
    /// The figures of `film`, rendered in `seconds` from `frames` frames, against `reference`
    /// (`reference_display` its display image).
    /// `tone_map` makes the display image of `film`, as it made `reference_display`.
    pub fn of(
        (reference, reference_display): (&Film, &[u8]),
        film: &Film,
        tone_map: ToneMap,
        frames: u32,
        seconds: f64,
    ) -> Self {
        let test = display(film, tone_map);
        Self {
            flip: mean_flip(reference_display, &test, film.width(), film.height()),
            rmse: rmse(reference_display, &test),
            blotch10: Blotch::between(reference, film).over_10,
            frames,
            seconds,
        }
    }
}

/// The results, as printed and written.
#[derive(Debug, Serialize)]
struct Report {
    scene: String,
    width: u32,
    height: u32,
    aa: u32,
    vpls_per_pixel: u32,
    interleave: [u32; 2],
    coarse_interleave: u32,
    filter: bool,
    reference: PathBuf,
    /// How the reference was made, e.g. "path tracer, 256 spp" (unknown for a file given
    /// with `--reference` that already existed).
    reference_method: String,
    /// Time to render the reference (0 when it was read from its file).
    reference_seconds: f64,
    /// What `igi render` writes by default: compensated frames until the stopping rule.
    default: Figures,
    /// One frame as `igi render --frames 1` writes it (bias-compensated).
    one_frame: Figures,
    /// One frame as a viewer shows it while the view moves (no compensation, the smaller
    /// clamp).
    moving_frame: Figures,
    accumulated_frames: u32,
    accumulated: Figures,
    /// The flicker figure, if measured.
    flicker: Option<f64>,
    flicker_frames: u32,
}

/// Runs `igi bench quality`.
pub fn run(args: &QualityBenchArgs) -> Result<()> {
    if !(1..=100_000).contains(&args.accumulate) {
        bail!("--accumulate must be between 1 and 100000");
    }
    if !(1..=igi_render::sampling::MAX_SAMPLES).contains(&args.reference_spp) {
        bail!("--reference-spp must be between 1 and {}", igi_render::sampling::MAX_SAMPLES);
    }
    let method = match args.reference_frames {
        Some(frames) if !(2..=1_000_000).contains(&frames) => {
            bail!("--reference-frames must be between 2 and 1000000")
        }
        Some(frames) => Method::Accumulated { frames },
        None => Method::PathTracer { spp: args.reference_spp },
    };
    if args.flicker == 1 || args.flicker > 10_000 {
        bail!("--flicker must be 0 (off) or between 2 and 10000 frames");
    }
    if !(args.time_budget.is_finite() && args.time_budget > 0.0 && args.time_budget <= 1e7) {
        bail!("--time-budget must be a number of seconds above 0 (and at most 10000000)");
    }
    super::json_report::check_json(args.json.as_deref())?;
    if let Some(seconds) = args.lag {
        let report = light_lag::measure(&args.frame, &args.scene, seconds, args.view_reference_frames)?;
        outln!(
            "{}: a change of the light over {seconds} s of the animation, {} pixels changed",
            args.scene,
            report.changed_pixels
        );
        let shares: Vec<String> = report.shares.iter().map(|s| format!("{:.0} %", 100.0 * s)).collect();
        outln!("  share of the change shown, frame 1 on: {}", shares.join(", "));
        match report.lag_frames {
            Some(k) => outln!("  lag: 90 % of the change in frame {k}"),
            None => outln!("  lag: 90 % of the change not reached in {} frames", report.shares.len()),
        }
        if let Some(path) = &args.json {
            super::json_report::write_json(path, &report)?;
        }
        return Ok(());
    }
    if args.orbit > 0 {
        let orbit = Orbit {
            frames: args.orbit,
            degrees: args.orbit_degrees,
            from: args.orbit_from,
            reference_frames: args.view_reference_frames,
            distance: args.orbit_distance,
        };
        let report = camera_path::measure(&args.frame, &args.scene, orbit)?;
        print_orbit(&args.scene, &report);
        if let Some(path) = &args.json {
            super::json_report::write_json(path, &report)?;
        }
        return Ok(());
    }
    let scene = igi_scene::load_named(&args.scene).context("cannot load scene")?;
    let digest = scene.digest();
    let mut prepared = args.frame.prepare(scene);
    let frame = args.frame.frame_state(&prepared)?;
    let mut renderer = FrameRenderer::new(args.frame.threads);

    let reference_path =
        args.reference.clone().unwrap_or_else(|| default_reference_path(args, digest, &frame, method));
    let (reference, reference_seconds) =
        reference(args, &mut prepared, &frame, method, &reference_path, &mut renderer)?;
    let reference_display = display(&reference, frame.settings.tone_map());

    let mut still = frame.clone();
    args.frame.still_image(&mut still, &prepared);
    let mut measure = |frame: &FrameState, until: Until| {
        figures((&reference, &reference_display), &mut renderer, &mut prepared, frame, until)
    };
    let rule = StoppingRule::still_image(Duration::from_secs_f64(args.time_budget));
    let default = measure(&still, Until::Converged(rule))?;
    let one_frame = measure(&still, Until::Frames(1))?;
    let moving_frame = measure(&frame, Until::Frames(1))?;
    let accumulated = measure(&still, Until::Frames(args.accumulate))?;
    let accumulating = still;
    let flicker = if args.flicker > 1 {
        Some(flicker(
            &mut renderer,
            &mut prepared,
            &frame,
            &accumulating,
            args.accumulate,
            args.flicker,
            args.frame.time,
        )?)
    } else {
        None
    };

    let s = &frame.settings;
    let report = Report {
        scene: args.scene.clone(),
        width: s.width,
        height: s.height,
        aa: s.aa,
        vpls_per_pixel: s.vpls_per_pixel,
        interleave: s.interleave,
        coarse_interleave: s.coarse_interleave,
        filter: s.filter,
        reference: reference_path,
        // A file named with --reference may have been made any way; the default file's name
        // records its method.
        reference_method: match (&args.reference, reference_seconds) {
            (Some(_), 0.0) => "the file given with --reference (how it was made is not recorded)".into(),
            _ => method.to_string(),
        },
        reference_seconds,
        default,
        one_frame,
        moving_frame,
        accumulated_frames: args.accumulate,
        accumulated,
        flicker,
        flicker_frames: args.flicker,
    };
    print(&report);
    if let Some(path) = &args.json {
        super::json_report::write_json(path, &report)?;
    }
    Ok(())
}

/// How the reference image is made.
#[derive(Clone, Copy, Debug)]
enum Method {
    /// The path tracer with this many samples per pixel.
    PathTracer { spp: u32 },
    /// The mean of this many IGI frames, set up as `igi render --frames N` sets them up.
    Accumulated { frames: u32 },
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::PathTracer { spp } => write!(f, "path tracer, {spp} spp"),
            Self::Accumulated { frames } => write!(f, "IGI, the mean of {frames} frames"),
        }
    }
}

/// The frame number the accumulated reference starts at: its samples lie far from those of
/// the measured frames (which start at 0), so its noise is not theirs.
const REFERENCE_FIRST_FRAME: u32 = 1 << 24;

/// Where the reference of this scene, camera, image size and method is kept by default.
fn default_reference_path(
    args: &QualityBenchArgs,
    digest: u64,
    frame: &FrameState,
    method: Method,
) -> PathBuf {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    // Everything the reference image depends on (the IGI settings too, for an IGI mean).
    format!("{digest} {:?} {:?} {method:?} {}", frame.camera, frame.pose, args.frame.no_default_light)
        .hash(&mut h);
    if let Method::Accumulated { .. } = method {
        format!("{:?}", frame.settings).hash(&mut h);
    }
    let tag = match method {
        Method::PathTracer { spp } => format!("{spp}spp"),
        Method::Accumulated { frames } => format!("igi{frames}f"),
    };
    let stem = Path::new(&args.scene).file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy());
    std::env::temp_dir().join("igi-quality").join(format!(
        "{stem}-{}x{}-{tag}-{:016x}.exr",
        frame.settings.width,
        frame.settings.height,
        h.finish()
    ))
}

/// The reference image: read from `path`, or rendered by `method` and written there. Returns
/// it and the time spent rendering it.
fn reference(
    args: &QualityBenchArgs,
    scene: &mut PreparedScene,
    frame: &FrameState,
    method: Method,
    path: &Path,
    renderer: &mut FrameRenderer,
) -> Result<(Film, f64)> {
    let (width, height) = (frame.settings.width, frame.settings.height);
    if path.exists() {
        let image =
            image::open(path).with_context(|| format!("cannot read the reference {}", path.display()))?;
        if (image.width(), image.height()) != (width, height) {
            bail!(
                "the reference {} is {}x{}, the frame {width}x{height}",
                path.display(),
                image.width(),
                image.height()
            );
        }
        let pixels: Vec<glam::Vec3> =
            image.to_rgb32f().pixels().map(|p| glam::Vec3::from_array(p.0)).collect();
        // Radiance is finite and not negative; a reference that is not would make every
        // figure against it meaningless (an all-NaN file measured FLIP 0.887).
        if let Some(i) = pixels.iter().position(|p| !(p.is_finite() && p.min_element() >= 0.0)) {
            let (x, y) = (i as u32 % width, i as u32 / width);
            bail!(
                "the reference {} is not radiance: pixel ({x}, {y}) is {} (values must be finite and not negative)",
                path.display(),
                pixels[i]
            );
        }
        if pixels.iter().all(|p| *p == glam::Vec3::ZERO) {
            bail!("the reference {} is black: every figure against it would be meaningless", path.display());
        }
        return Ok((Film::from_pixels(width, height, pixels), 0.0));
    }
    tracing::info!("rendering the reference ({method}) into {}", path.display());
    let start = Instant::now();
    let bar = LateProgress::new();
    let progress = |done, total| bar.tile_done(done, total);
    let film = match method {
        Method::PathTracer { spp } => {
            let traced = FrameState { estimator: Estimator::PathTracer { spp }, ..frame.clone() };
            let out = renderer.render_accumulated(scene, &traced, 1, &progress)?;
            out.image.into_film().context("a path-traced frame without its film")?
        }
        Method::Accumulated { frames } => {
            let mut mean = frame.clone();
            args.frame.still_image(&mut mean, scene);
            mean.number = REFERENCE_FIRST_FRAME;
            let out = renderer.render_accumulated(scene, &mean, frames, &progress)?;
            out.image.into_film().context("an accumulated frame without its film")?
        }
    };
    bar.finish();
    let seconds = start.elapsed().as_secs_f64();
    if let Some(folder) = path.parent() {
        std::fs::create_dir_all(folder).with_context(|| format!("cannot create {}", folder.display()))?;
    }
    write_exr(&film, path).with_context(|| format!("cannot write the reference {}", path.display()))?;
    Ok((film, seconds))
}

/// The 8-bit sRGB display image of `film`, tone-mapped by `tone_map` with its own statistics,
/// as `igi render` writes a PNG.
pub fn display(film: &Film, tone_map: ToneMap) -> Vec<u8> {
    to_srgb8(film, &ToneMapper::for_film(tone_map, film))
}

/// Renders the mean of `frame`'s frames until `until` (in linear radiance) and measures it
/// against the reference (its film and display image).
fn figures(
    (reference, reference_display): (&Film, &[u8]),
    renderer: &mut FrameRenderer,
    scene: &mut PreparedScene,
    frame: &FrameState,
    until: Until,
) -> Result<Figures> {
    let start = Instant::now();
    let bar = LateProgress::new();
    let linear = FrameState { pixels: PixelFormat::Linear, ..frame.clone() };
    let mut view = Progressive::new(frame.settings.tone_map());
    let mean = renderer.accumulate(
        scene,
        &linear,
        until,
        &mut view,
        &|done, total| bar.tile_done(done, total),
        &mut |_| {},
    )?;
    bar.finish();
    let seconds = start.elapsed().as_secs_f64();
    let film = mean.output.image.into_film().context("an accumulated frame without its film")?;
    Ok(Figures::of((reference, reference_display), &film, frame.settings.tone_map(), mean.frames, seconds))
}

/// Mean LDR-FLIP of two 8-bit sRGB images of the same size (67 pixels per degree: a 0.7 m wide
/// monitor of 3840 pixels seen from 0.7 m, FLIP's default).
pub fn mean_flip(reference: &[u8], test: &[u8], width: u32, height: u32) -> f64 {
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, reference);
    let test = nv_flip::FlipImageRgb8::with_data(width, height, test);
    let errors = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let values = errors.to_vec();
    values.iter().map(|&e| f64::from(e)).sum::<f64>() / values.len().max(1) as f64
}

/// RMSE of two 8-bit images' values in [0, 1] over all pixels and channels.
fn rmse(reference: &[u8], test: &[u8]) -> f64 {
    let sum: f64 = reference
        .iter()
        .zip(test)
        .map(|(&r, &t)| {
            let d = (f64::from(t) - f64::from(r)) / 255.0;
            d * d
        })
        .sum();
    (sum / reference.len().max(1) as f64).sqrt()
}

/// The flicker figure (module documentation) over `count` frames of the animation from
/// `start` s: one frame each with `frame`'s settings, against `accumulate` frames each with
/// `accumulating`'s.
fn flicker(
    renderer: &mut FrameRenderer,
    scene: &mut PreparedScene,
    frame: &FrameState,
    accumulating: &FrameState,
    accumulate: u32,
    count: u32,
    start: f32,
) -> Result<f64> {
    let mut luminances = |f: &FrameState, frames: u32| -> Result<Vec<Vec<f32>>> {
        (0..count)
            .map(|k| {
                let mut f = f.clone();
                f.pose = ScenePose::at(start + k as f32 / ANIMATION_FPS);
                // One frame each: frame k as a playing viewer numbers it. Accumulated: every
                // animation frame averages the same frames of the sequence, so their residual
                // noise is alike and cancels in ΔL_ref instead of counting as flicker.
                f.number = if frames == 1 { k } else { 0 };
                let out = renderer.render_accumulated(scene, &f, frames, &|_, _| {})?;
                let film = out.image.into_film().context("an accumulated frame without its film")?;
                Ok(film.pixels().iter().map(|&p| luminance(p)).collect())
            })
            .collect()
    };
    let one = luminances(frame, 1)?;
    let converged = luminances(accumulating, accumulate)?;
    Ok(flicker_of(&one, &converged))
}

/// mean over consecutive pairs and pixels of |ΔL − ΔL_ref|, over the mean of L_ref (module
/// documentation); frames are luminance images of one size.
pub fn flicker_of(frames: &[Vec<f32>], reference: &[Vec<f32>]) -> f64 {
    let mut change = 0.0f64;
    let mut pairs = 0usize;
    for (f, r) in frames.windows(2).zip(reference.windows(2)) {
        for (((&a0, &a1), &r0), &r1) in f[0].iter().zip(&f[1]).zip(&r[0]).zip(&r[1]) {
            change += (f64::from(a1 - a0) - f64::from(r1 - r0)).abs();
            pairs += 1;
        }
    }
    let (sum, n) = reference.iter().flatten().fold((0.0f64, 0usize), |(s, n), &l| (s + f64::from(l), n + 1));
    let mean = sum / n.max(1) as f64;
    if pairs == 0 || mean <= 0.0 { 0.0 } else { change / pairs as f64 / mean }
}

fn print_orbit(scene: &str, r: &OrbitReport) {
    outln!(
        "{scene}: orbit of {}° per frame, frames {}-{} against the converged image of each view",
        r.degrees,
        r.measured[0],
        r.measured[1]
    );
    for (name, f) in [("temporal reuse", &r.temporal), ("single frames", &r.single)] {
        outln!(
            "  {name:<15} mean FLIP {:.4}  blotch10 {:.4}  {:.1} ms a frame  history kept {:.0} % (least {:.0} %)",
            f.flip,
            f.blotch10,
            f.frame_ms,
            100.0 * f.history_kept,
            100.0 * f.history_kept_least
        );
    }
    if r.temporal.history_kept_least < 0.5 {
        outln!(
            "  a measured frame kept {:.0} % of its history: the eye went through something or turned to a new view, \
             which no history helps; another --orbit-distance measures the reuse itself",
            100.0 * r.temporal.history_kept_least
        );
    }
}

fn print(r: &Report) {
    outln!(
        "{}: {}x{}, aa {}, {} VPLs per pixel in {}, filter {}",
        r.scene,
        r.width,
        r.height,
        r.aa,
        r.vpls_per_pixel,
        crate::frame_args::sets_label(r.interleave, r.coarse_interleave),
        if r.filter { "on" } else { "off" }
    );
    let made = if r.reference_seconds > 0.0 {
        format!("rendered in {:.1} s", r.reference_seconds)
    } else {
        "read".to_string()
    };
    outln!("  reference: {}, {made}: {}", r.reference_method, r.reference.display());
    let line = |name: String, f: &Figures| {
        outln!(
            "  {name:<18} mean FLIP {:.4}  blotch10 {:.4}  RMSE {:.4}  {:.3} s",
            f.flip,
            f.blotch10,
            f.rmse,
            f.seconds
        );
    };
    line(format!("default ({} frames)", r.default.frames), &r.default);
    line("one frame".into(), &r.one_frame);
    line("moving frame".into(), &r.moving_frame);
    line(format!("{} frames", r.accumulated_frames), &r.accumulated);
    if let Some(flicker) = r.flicker {
        outln!(
            "  flicker      {flicker:.4} over {} frames at {ANIMATION_FPS} fps (one frame each against {} accumulated)",
            r.flicker_frames,
            r.accumulated_frames
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flicker_is_zero_when_frames_change_as_the_reference_does_and_grows_with_noise() {
        let reference = vec![vec![1.0, 2.0], vec![1.5, 2.5], vec![2.0, 3.0]];
        // The same changes on a constant offset: no flicker.
        let offset: Vec<Vec<f32>> = reference.iter().map(|f| f.iter().map(|l| l + 0.3).collect()).collect();
        assert_eq!(flicker_of(&offset, &reference), 0.0);
        // Frame 1 is 0.5 too bright in both pixels: each pair changes 0.5 off, mean L_ref = 2.
        let noisy = vec![vec![1.0, 2.0], vec![2.0, 3.0], vec![2.0, 3.0]];
        assert!((flicker_of(&noisy, &reference) - 0.25).abs() < 1e-12);
    }

    #[test]
    fn mean_flip_agrees_with_nvidias_python_flip_evaluator() {
        // A 48x32 pattern and a copy with a structured error in red and green; the value is
        // flip-evaluator 1.x's `evaluate(ref / 255, test / 255, "LDR", inputsRGB=True,
        // parameters={"ppd": 67})` mean on the same bytes (as ../shared/tools/compare's ldr
        // mode computes it).
        let (w, h) = (48u32, 32u32);
        let (mut reference, mut test) = (Vec::new(), Vec::new());
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                let (r, g, b) = ((x * 5 + y * 3) % 256, (x * x + y) % 256, (x * y * 7) % 256);
                let t = (x * 13 + y * 29) % 31 - 15;
                reference.extend([r as u8, g as u8, b as u8]);
                test.extend([(r + t).clamp(0, 255) as u8, (g - t).clamp(0, 255) as u8, b as u8]);
            }
        }
        let flip = mean_flip(&reference, &test, w, h);
        assert!((flip - 0.071_443_349_123_001_1).abs() < 1e-5, "{flip}");
        assert_eq!(mean_flip(&reference, &reference, w, h), 0.0);
    }

    #[test]
    fn rmse_of_display_values() {
        assert_eq!(rmse(&[0, 0, 0], &[0, 0, 0]), 0.0);
        assert!((rmse(&[0, 0], &[255, 0]) - 0.5f64.sqrt()).abs() < 1e-12);
    }
}
