//! `igi render`: load a scene, render it with direct lighting and write a PNG or EXR file,
//! then print one summary line (resolution, triangles, time, rays/s).

use anyhow::{Context, Result, bail};
use clap::Args;
use igi_render::output::ImageFormat;
use igi_render::{PreparedScene, RenderSettings, render_with_stats, write_image};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Arguments of `igi render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Built-in scene name (e.g. cornell-box) or scene file (.obj, .ply, .gltf, .glb, .toml).
    pub scene: String,
    /// Output image: .png (tone-mapped sRGB) or .exr (linear radiance).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 480)]
    pub height: u32,
    /// Camera overrides.
    #[command(flatten)]
    pub camera: crate::cli::CameraArgs,
    /// Area-light samples (shadow rays to emissive triangles) per pixel.
    #[arg(long, default_value_t = 4)]
    pub samples: u32,
    /// Seed of the sample patterns (same seed, same image).
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Fixed exposure in stops for PNG output (default: automatic, Reinhard key 0.18).
    #[arg(long, allow_hyphen_values = true)]
    pub exposure: Option<f32>,
    /// Tile edge length in pixels.
    #[arg(long, default_value_t = 16)]
    pub tile_size: u32,
}

/// Runs `igi render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    if !(1..=16384).contains(&args.width) || !(1..=16384).contains(&args.height) {
        bail!("--width and --height must be between 1 and 16384");
    }
    if args.samples > igi_render::sampling::MAX_SAMPLES {
        bail!("--samples must be at most {}", igi_render::sampling::MAX_SAMPLES);
    }
    if !(1..=1024).contains(&args.tile_size) {
        bail!("--tile-size must be between 1 and 1024");
    }
    if args.exposure.is_some_and(|e| !e.is_finite()) {
        bail!("--exposure must be a finite number of stops");
    }
    ImageFormat::from_path(&args.output)?;

    let t_load = Instant::now();
    let scene = igi_scene::load_named(&args.scene).context("cannot load scene")?;
    let load = t_load.elapsed();
    let camera = args.camera.resolve(&scene)?;

    let t_build = Instant::now();
    let prepared = PreparedScene::new(scene);
    let build = t_build.elapsed();

    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        samples: args.samples,
        seed: args.seed,
        threads: args.threads,
        tile_size: args.tile_size,
        exposure: args.exposure,
    };
    let bar = LateProgress::new();
    let (film, stats) =
        render_with_stats(&prepared, &camera, &settings, &|done, total| bar.tile_done(done, total));
    bar.finish();

    write_image(&film, &args.output, settings.tone_map()).context("cannot write the image")?;

    outln!(
        "{}: {}x{}, {} triangles, {} area samples/px, {} thread(s): render {:.3} s (load {:.3} s, build {:.3} s), \
         {:.2} M rays ({:.2} M primary, {:.2} M shadow), {:.1} Mrays/s -> {}",
        args.scene,
        args.width,
        args.height,
        prepared.triangle_count(),
        settings.samples,
        stats.threads,
        stats.elapsed.as_secs_f64(),
        load.as_secs_f64(),
        build.as_secs_f64(),
        stats.rays.total() as f64 * 1e-6,
        stats.rays.primary as f64 * 1e-6,
        stats.rays.shadow as f64 * 1e-6,
        stats.rays_per_second() * 1e-6,
        args.output.display()
    );
    Ok(())
}

/// A progress bar that appears only once a render has taken more than a second (and only on
/// a terminal), so quick renders print nothing but their summary.
struct LateProgress {
    bar: ProgressBar,
    start: Instant,
    shown: AtomicBool,
}

impl LateProgress {
    const DELAY: Duration = Duration::from_secs(1);

    fn new() -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template("{bar:40} {pos}/{len} tiles, {elapsed} (eta {eta})") {
            bar.set_style(style);
        }
        Self { bar, start: Instant::now(), shown: AtomicBool::new(false) }
    }

    fn tile_done(&self, done: u32, total: u32) {
        if !self.shown.load(Ordering::Relaxed)
            && self.start.elapsed() > Self::DELAY
            && !self.shown.swap(true, Ordering::Relaxed)
        {
            self.bar.set_length(u64::from(total));
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
        self.bar.set_position(u64::from(done));
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn args(line: &[&str]) -> RenderArgs {
        let cli = crate::cli::Cli::try_parse_from(line).expect("valid command line");
        match cli.command {
            crate::cli::Command::Render(a) => a,
            other => panic!("not a render command: {other:?}"),
        }
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
