//! `igi render`: load a scene, render it with instant global illumination (or the reference
//! path tracer) and write a PNG or EXR file, then print one summary line.

use crate::cluster::{ClusterArgs, Rank};
use crate::frame_args::FrameArgs;
use crate::progress::{LateProgress, Stages};
use anyhow::{Result, bail};
use clap::{Args, ValueEnum};
use igi_render::image::output::{ImageFormat, check_writable, write_png_rgb8};
use igi_render::image::tonemap::check_exposure;
use igi_render::sampling::MAX_SAMPLES;
use igi_render::{
    Estimator, Film, FrameImage, FrameRenderer, FrameSource, FrameState, PixelFormat, PreparedScene,
    Progressive, Stopped, StoppingRule, ToneMap, ToneMapper, Until, write_exr, write_image,
};
use std::path::Path;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// How the image is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    /// Instant global illumination: VPLs, interleaved sampling, discontinuity filter.
    Igi,
    /// The unbiased reference path tracer (slow; for ground truth).
    Path,
}

/// Arguments of `igi render`.
#[derive(Debug, Args)]
#[command(after_help = crate::cli::scenes_help())]
pub struct RenderArgs {
    /// Built-in scene (listed below) or scene file (.obj, .ply, .gltf, .glb, .toml).
    pub scene: String,
    /// Output image: .png (tone-mapped sRGB) or .exr (linear radiance).
    #[arg(short, long, help_heading = "Output")]
    pub output: PathBuf,
    /// Rendering method.
    #[arg(long, value_enum, default_value_t = Mode::Igi, help_heading = "Sampling")]
    pub mode: Mode,
    /// IGI: average exactly this many frames, each with fresh VPLs; 1 is the fast single
    /// frame. Default: average frames until the image is clean (the estimated share of
    /// 9×9-pixel windows more than 10 % off, from the frames' own variance, reaches 0.5 %) or
    /// the time budget runs out.
    #[arg(long, help_heading = "Sampling")]
    pub frames: Option<u32>,
    /// IGI: seconds a converging image may take at most (without `--frames`); the first frame
    /// always runs.
    #[arg(long, default_value_t = 10.0, help_heading = "Sampling")]
    pub time_budget: f64,
    /// IGI: render one frame as a viewer shows it while the view moves: without the bias
    /// compensation, with the viewers' clamp (2 % of the scene's diagonal unless `--clamp`).
    #[arg(long, help_heading = "Sampling")]
    pub moving_frame: bool,
    /// Path tracer: samples per pixel.
    #[arg(long, default_value_t = 64, help_heading = "Sampling")]
    pub spp: u32,
    /// Fixed exposure in stops for PNG output, linear with a clip at 1, instead of the tone
    /// map (default: automatic, the log-average luminance at middle grey, then `--tone-map`).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "tone_map", help_heading = "Output")]
    pub exposure: Option<f32>,
    /// IGI: render this many frames of the scene's animation, `--fps` apart from `--time` on,
    /// into OUTPUT-0000.png, OUTPUT-0001.png, … Each PNG after the first is tone-mapped with
    /// the previous frame's statistics, as the viewers do (paper 3.4).
    #[arg(long, default_value_t = 1, help_heading = "Animation")]
    pub sequence: u32,
    /// Frames per second of scene time for `--sequence`.
    #[arg(long, default_value_t = 24.0, help_heading = "Animation")]
    pub fps: f32,
    /// Frame options.
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Cluster options.
    #[command(flatten, next_help_heading = "Cluster")]
    pub cluster: ClusterArgs,
}

/// Runs `igi render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    if let Some(stops) = args.exposure {
        check_exposure(stops).map_err(|e| anyhow::anyhow!("--exposure: {e}"))?;
    }
    if !(1..=MAX_SAMPLES).contains(&args.spp) {
        bail!("--spp must be between 1 and {MAX_SAMPLES}");
    }
    if args.frames.is_some_and(|f| !(1..=1_000_000).contains(&f)) {
        bail!("--frames must be between 1 and 1000000");
    }
    if !(args.time_budget.is_finite() && args.time_budget > 0.0 && args.time_budget <= 1e7) {
        bail!("--time-budget must be a number of seconds above 0 (and at most 10000000)");
    }
    if args.moving_frame && args.frames.is_some_and(|f| f > 1) {
        bail!("--moving-frame renders one frame as a viewer shows it while moving; leave out --frames");
    }
    if !(1..=1_000_000).contains(&args.sequence) {
        bail!("--sequence must be between 1 and 1000000");
    }
    if !(args.fps.is_finite() && args.fps > 0.0) {
        bail!("--fps must be a positive number");
    }
    ImageFormat::from_path(&args.output)?;
    // A render can take hours: a folder that takes no files fails now, not at the end. On a
    // cluster only rank 0 writes, so there the check waits until this process knows its rank.
    if !args.cluster.cluster {
        check_writable(&args.output)?;
    }
    crate::render_memory::check(args.frame.width, args.frame.height, args.frame.threads)?;

    // Nothing on a terminal before the render's bar; lines in a log while a large scene loads
    // (not on a cluster, whose render nodes spend the whole job in `cluster::start`).
    let stages = (!args.cluster.cluster).then(|| Stages::lines_only(format!("loading {}", args.scene)));
    let t_load = Instant::now();
    let (scene, source): (_, Option<Box<dyn FrameSource>>) = if args.cluster.cluster {
        match crate::cluster::start(&args.cluster, &args.scene, &args.frame)? {
            Rank::Root(root) => {
                check_writable(&args.output)?;
                (root.scene, Some(crate::cluster::source(root.master, args.frame.threads)))
            }
            Rank::NodeDone => return Ok(()),
        }
    } else {
        (crate::scene_load::load_scene(&args.scene)?, None)
    };
    let load = t_load.elapsed();

    let stages = Stages::preparing(stages, &args.scene, Stages::lines_only);
    let t_prepare = Instant::now();
    let mut prepared = args.frame.prepare(scene);
    let prepare = t_prepare.elapsed();
    drop(stages);
    // The summary's "prepare" is this whole step; the log's BVH time is one part of it.
    tracing::info!(
        "{}: prepared in {:.3} s: the BVH, the shading tables, the lights and the default light's choice",
        args.scene,
        prepare.as_secs_f64()
    );

    let mut frame = args.frame.frame_state(&prepared)?;
    if !args.moving_frame {
        args.frame.still_image(&mut frame, &prepared);
    }
    frame.estimator = match args.mode {
        Mode::Igi => Estimator::Igi,
        Mode::Path => Estimator::PathTracer { spp: args.spp },
    };
    let until = until(args);
    if let (Until::Converged(_), None) = (until, args.frame.aa) {
        // A converging mean anti-aliases itself: each frame's one ray per pixel is jittered
        // anew, so frames of one ray a pixel give it more frames (and VPL sets) in its budget
        // (ARCHITECTURE.md, "Convergence by the blotch figure").
        frame.settings.aa = 1;
    }

    let mut source = source.unwrap_or_else(|| Box::new(FrameRenderer::new(args.frame.threads)));
    let bar = LateProgress::with_rule(match until {
        Until::Converged(rule) => Some(rule),
        Until::Frames(_) => None,
    });
    let start = Instant::now();
    let totals = render_frames(args, until, source.as_mut(), &mut prepared, &frame, &bar)?;
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish();

    let s = &frame.settings;
    let what = if args.cluster.cluster || args.sequence > 1 {
        format!(
            "{} image(s), each the mean of {}, in {:.3} s ({:.2} fps, {:.1} Mrays/s; ",
            args.sequence,
            match until {
                Until::Frames(n) => format!("{n} frame(s)"),
                Until::Converged(_) =>
                    format!("{:.1} frames on average", totals.frames as f64 / f64::from(args.sequence)),
            },
            elapsed,
            f64::from(args.sequence) / elapsed.max(1e-9),
            totals.rays as f64 * 1e-6 / elapsed.max(1e-9),
        )
    } else {
        let summary = match args.mode {
            Mode::Igi => igi_summary(&totals, s, elapsed),
            Mode::Path => format!(
                "path tracer, {} spp: {:.2} M rays, {:.1} Mrays/s",
                args.spp,
                totals.rays as f64 * 1e-6,
                totals.rays as f64 * 1e-6 / elapsed.max(1e-9)
            ),
        };
        format!("{summary} in {elapsed:.3} s (")
    };
    outln!(
        "{}: {}x{}, {} triangles, {} thread(s){}: {what}load {:.3} s, prepare {:.3} s) -> {}",
        args.scene,
        s.width,
        s.height,
        prepared.triangle_count(),
        source.threads(),
        if args.cluster.cluster { " on the cluster" } else { "" },
        load.as_secs_f64(),
        prepare.as_secs_f64(),
        args.output.display()
    );
    if args.mode == Mode::Igi && args.sequence == 1 {
        outln!("{}", how_it_ended(args, until, &totals, elapsed));
    }
    Ok(())
}

/// When `igi render`'s images are done: after `--frames` frames, one for `--moving-frame` and
/// the path tracer (its `--spp` are its samples), else by the stopping rule of a still image
/// within `--time-budget`.
fn until(args: &RenderArgs) -> Until {
    match (args.frames, args.moving_frame || args.mode == Mode::Path) {
        (Some(frames), _) => Until::Frames(frames),
        (None, true) => Until::Frames(1),
        (None, false) => {
            Until::Converged(StoppingRule::still_image(Duration::from_secs_f64(args.time_budget)))
        }
    }
}

/// The line after the summary that says what the image is and why it stopped where it did.
fn how_it_ended(args: &RenderArgs, until: Until, totals: &Totals, elapsed: f64) -> String {
    let estimate = totals.estimated_blotch.map_or(String::new(), |b| format!(", estimated blotch10 {b:.3}"));
    match (until, totals.stopped) {
        (Until::Frames(1), _) if args.moving_frame => {
            "one frame as a viewer shows it while the view moves".into()
        }
        (Until::Frames(1), _) => format!(
            "one frame with fresh VPLs and the clamp's bias compensated; without `--frames` igi render \
             averages frames until the image is clean (about {:.1} s here at most: `--time-budget`)",
            args.time_budget.min(64.0 * elapsed)
        ),
        (Until::Frames(n), _) => format!("the mean of {n} compensated frames{estimate}"),
        (Until::Converged(rule), Some(Stopped::Converged)) => format!(
            "the mean of {} compensated frames: stopped as clean{estimate} (done at {:.3})",
            totals.frames, rule.target
        ),
        (Until::Converged(rule), _) => format!(
            "the mean of {} compensated frames: stopped at the time budget of {:.1} s{estimate} (clean at {:.3}; \
             a larger `--time-budget` averages more)",
            totals.frames,
            rule.time_budget.as_secs_f64(),
            rule.target
        ),
    }
}

/// What a render traced, over all its frames.
#[derive(Clone, Copy, Debug, Default)]
struct Totals {
    /// Rays.
    rays: u64,
    /// VPLs (surface and sky) of all frames.
    vpls: usize,
    /// Frames rendered.
    frames: u32,
    /// Why the last image's mean stopped.
    stopped: Option<Stopped>,
    /// The last image's estimated blotch10.
    estimated_blotch: Option<f64>,
}

/// Renders `--sequence` images (each a mean of frames until `until`) of `first`'s estimator
/// through `source` and writes them; `progress` follows the tiles and frames of each image.
/// The first
/// image, every accumulated one and EXR output come back as linear radiance (a PNG is then
/// tone-mapped from the image's own statistics); later PNG images of a sequence come back as
/// 8-bit pixels tone-mapped with the previous image's statistics, which is what a cluster
/// sends (paper 3.4). This machine and a cluster therefore write the same bytes.
fn render_frames(
    args: &RenderArgs,
    until: Until,
    source: &mut dyn FrameSource,
    scene: &mut PreparedScene,
    first: &FrameState,
    progress: &LateProgress,
) -> Result<Totals> {
    let tone_map = ToneMap::chosen(first.settings.tone_curve, args.exposure);
    let exr = ImageFormat::from_path(&args.output)? == ImageFormat::Exr;
    let (width, height) = (first.settings.width, first.settings.height);
    // Files are written on their own thread, so frame k + 1 renders (on the cluster: the nodes
    // start it) while frame k is encoded.
    std::thread::scope(|s| -> Result<Totals> {
        let (to_writer, images) = std::sync::mpsc::sync_channel::<(std::path::PathBuf, Image)>(2);
        let writer = s.spawn(move || -> Result<()> {
            for (path, image) in images {
                match image {
                    Image::Srgb8(bytes) => write_png_rgb8(&bytes, width, height, &path),
                    Image::Exr(film) => write_exr(&film, &path),
                    Image::Png(film, mapper) => write_image(&film, &path, &mapper),
                }?;
            }
            Ok(())
        });
        let mut view = Progressive::new(tone_map);
        let mut totals = Totals::default();
        for k in 0..args.sequence {
            let path = sequence_path(&args.output, k, args.sequence);
            let mut frame = first.clone();
            frame.pose.time = first.pose.time + k as f32 / args.fps;
            frame.tone_map = view.tone_mapper();
            let linear = exr || until != Until::Frames(1) || k == 0;
            frame.pixels = if linear { PixelFormat::Linear } else { PixelFormat::Srgb8 };
            let until = if linear { until } else { Until::Frames(1) };
            progress.image(k, args.sequence);
            let mean = source.accumulate(
                scene,
                &frame,
                until,
                &mut view,
                &|done, total| progress.tile_done(done, total),
                &mut |f| progress.frame_done(f),
            )?;
            let out = mean.output;
            totals.rays += out.rays.total();
            totals.vpls += out.vpls;
            totals.frames += mean.frames;
            totals.stopped = Some(mean.stopped);
            totals.estimated_blotch = mean.estimated_blotch;
            let image = match out.image {
                FrameImage::Srgb8 { bytes, .. } => Image::Srgb8(bytes),
                FrameImage::Linear { film, .. } if exr => Image::Exr(film),
                FrameImage::Linear { film, .. } => Image::Png(film, ToneMapper::new(tone_map, &out.stats)),
            };
            if to_writer.send((path, image)).is_err() {
                break;
            }
        }
        drop(to_writer);
        writer.join().map_err(|_| anyhow::anyhow!("the image writer panicked"))??;
        Ok(totals)
    })
}

/// A finished frame on its way to its file.
enum Image {
    /// 8-bit pixels as rendered (tone-mapped with the previous frame's statistics).
    Srgb8(Vec<u8>),
    /// Linear radiance for an EXR file.
    Exr(Film),
    /// Linear radiance and the tone map from its own statistics, for a PNG file.
    Png(Film, ToneMapper),
}

/// `out.png` for a single frame, `out-0007.png` for frame 7 of a sequence.
fn sequence_path(output: &Path, k: u32, frames: u32) -> std::path::PathBuf {
    if frames == 1 {
        return output.to_path_buf();
    }
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let ext = output.extension().map(|e| e.to_string_lossy().into_owned()).unwrap_or_default();
    output.with_file_name(format!("{stem}-{k:04}.{ext}"))
}

/// The summary of an IGI render in `seconds`: VPLs, rays.
fn igi_summary(totals: &Totals, s: &igi_render::frame::FrameSettings, seconds: f64) -> String {
    let frames = totals.frames;
    let pixels = f64::from(s.width) * f64::from(s.height) * f64::from(frames);
    format!(
        "igi, {} frame(s), {} VPLs/frame in {}, aa {}, filter {}, clamp {:.3}: {:.2} M rays ({:.1} per pixel), {:.1} Mrays/s",
        frames,
        totals.vpls / frames.max(1) as usize,
        crate::frame_args::sets_label(s.interleave, s.coarse_interleave),
        s.aa,
        if s.filter { "on" } else { "off" },
        s.clamp,
        totals.rays as f64 * 1e-6,
        totals.rays as f64 / pixels.max(1.0),
        totals.rays as f64 * 1e-6 / seconds.max(1e-9)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// `igi render`'s arguments alone.
    #[derive(Debug, Parser)]
    struct Line {
        #[command(flatten)]
        args: RenderArgs,
    }

    /// The arguments of a whole command line: `igi`, `render`, then the arguments.
    fn args(line: &[&str]) -> RenderArgs {
        let line = std::iter::once(line[0]).chain(line[2..].iter().copied());
        Line::try_parse_from(line).expect("valid command line").args
    }

    #[test]
    fn specular_depth_stays_a_hidden_name_of_specular_bounces() {
        // Command lines written before the flag was renamed keep working.
        let bounces =
            |flag| args(&["igi", "render", "cornell-box", "-o", "x.png", flag, "3"]).frame.specular_bounces;
        assert_eq!((bounces("--specular-bounces"), bounces("--specular-depth")), (3, 3));
        let mut cli = <crate::cli::Cli as clap::CommandFactory>::command();
        let help = cli.find_subcommand_mut("render").expect("render command").render_long_help().to_string();
        assert!(help.contains("--specular-bounces") && !help.contains("--specular-depth"), "{help}");
    }

    #[test]
    fn missing_scene_names_the_file() {
        let a = args(&["igi", "render", "/no/such/dir/scene.obj", "-o", "/tmp/never.png"]);
        let err = format!("{:#}", run(&a).unwrap_err());
        assert!(err.contains("/no/such/dir/scene.obj"), "{err}");
    }

    #[test]
    fn bad_output_extension_fails_before_rendering() {
        let a = args(&["igi", "render", "cornell-box", "-o", "out.jpg"]);
        assert!(format!("{:#}", run(&a).unwrap_err()).contains("out.jpg"));
    }

    #[test]
    fn a_missing_output_folder_fails_before_the_scene_is_loaded() {
        // The scene does not exist either: the folder's error proves the check came first.
        let a = args(&["igi", "render", "/no/such/scene.obj", "-o", "/nonexistent-igi/x.png"]);
        let err = format!("{:#}", run(&a).unwrap_err());
        assert!(err.contains("cannot create files in the folder /nonexistent-igi"), "{err}");
        let folder = std::env::temp_dir().join(format!("igi-cmd-render-folder-{}.png", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let a = args(&["igi", "render", "/no/such/scene.obj", "-o", folder.to_str().unwrap()]);
        let err = format!("{:#}", run(&a).unwrap_err());
        assert!(err.contains("is a folder"), "{err}");
        std::fs::remove_dir(&folder).unwrap();
    }

    #[test]
    fn renders_the_cornell_box() {
        let out = std::env::temp_dir().join(format!("igi-cmd-render-{}.png", std::process::id()));
        let a = args(&[
            "igi",
            "render",
            "cornell-box",
            "-o",
            out.to_str().unwrap(),
            "--width",
            "64",
            "--height",
            "48",
        ]);
        run(&a).unwrap();
        let img = image_dims(&out);
        assert_eq!(img, (64, 48));
        let _ = std::fs::remove_file(&out);
    }

    /// Width and height from a PNG header.
    fn image_dims(path: &std::path::Path) -> (u32, u32) {
        let bytes = std::fs::read(path).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        let be = |i: usize| u32::from_be_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
        (be(16), be(20))
    }
}
