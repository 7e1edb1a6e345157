//! The command line: argument types (clap derive), logging set-up, subcommand dispatch, and
//! helpers the subcommands share (vector arguments, camera overrides).

use crate::{bench, cmd_info, cmd_render, cmd_serve, cmd_view, cmd_worker};
use anyhow::Result;
use clap::{Parser, Subcommand};
use glam::Vec3;
use igi_render::default_camera;
use igi_scene::{Camera, Scene};

/// Interactive global illumination (Benthin, Wald & Slusallek 2003) on the CPU.
#[derive(Debug, Parser)]
#[command(name = "igi", version, about, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render a scene to a PNG (tone-mapped) or EXR (linear) file.
    Render(cmd_render::RenderArgs),
    /// Print what a scene contains: geometry, materials, lights, bounds, camera.
    Info(cmd_info::InfoArgs),
    /// Explore a scene in a window: fly or orbit, move objects, change settings.
    View(cmd_view::ViewArgs),
    /// Explore a scene in a browser: serve a viewer page and stream the frames to it.
    Serve(cmd_serve::ServeArgs),
    /// Render tiles for rank 0 of an MPI job (the split launch of a cluster viewer).
    Worker(cmd_worker::WorkerArgs),
    /// Measure throughput (`igi bench frame`, `igi bench rays`, `igi bench cluster`).
    #[command(subcommand)]
    Bench(bench::BenchCommand),
}

/// Runs one subcommand.
pub fn dispatch(command: Command) -> Result<()> {
    match command {
        Command::Render(args) => cmd_render::run(&args),
        Command::Info(args) => cmd_info::run(&args),
        Command::View(args) => cmd_view::run(&args),
        Command::Serve(args) => cmd_serve::run(&args),
        Command::Worker(args) => cmd_worker::run(&args),
        Command::Bench(cmd) => bench::run(cmd),
    }
}

/// Writes one line to stdout; a closed pipe ends the process with status 0 (the reader has
/// what it wanted), any other write error with status 1.
pub fn write_stdout_line(args: std::fmt::Arguments) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.write_all(b"\n")) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("igi: error: cannot write to stdout: {e}");
        std::process::exit(1);
    }
}

/// Logs to stderr, filtered by `RUST_LOG` (default: warnings and errors).
pub fn init_logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn"));
    tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).with_target(false).init();
}

/// Parses `x,y,z` into a vector (for `--camera-position` and friends).
pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!("{s:?} is not three comma-separated numbers x,y,z"));
    };
    let num = |v: &str| v.parse::<f32>().ok().filter(|f| f.is_finite());
    match (num(x), num(y), num(z)) {
        (Some(x), Some(y), Some(z)) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("{s:?} is not three finite numbers x,y,z")),
    }
}

/// `x,y,z`, as [`parse_vec3`] reads it.
fn vec3_text(v: Vec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

/// The camera options shared by `render` and `bench`: each replaces one field of the scene's
/// camera (or of a default camera framing the scene).
#[derive(Debug, Default, clap::Args)]
pub struct CameraArgs {
    /// Camera position x,y,z (default: the scene's camera, else one framing the scene).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_position: Option<Vec3>,
    /// Camera target x,y,z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_target: Option<Vec3>,
    /// Camera up vector x,y,z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_up: Option<Vec3>,
    /// Vertical field of view in degrees.
    #[arg(long)]
    pub fov: Option<f32>,
}

impl CameraArgs {
    /// The scene's camera (or a default one framing its bounds) with the given fields
    /// replaced; an error naming the flag for a camera that frames no image
    /// ([`Camera::check`], the scene files' check).
    pub fn resolve(&self, scene: &Scene) -> Result<Camera> {
        let mut camera = scene.camera.unwrap_or_else(|| default_camera(&scene.bounds()));
        camera.position = self.camera_position.unwrap_or(camera.position);
        camera.target = self.camera_target.unwrap_or(camera.target);
        camera.up = self.camera_up.unwrap_or(camera.up);
        camera.fov_y_deg = self.fov.unwrap_or(camera.fov_y_deg);
        camera.check().map_err(|defect| {
            let (flag, value) = match defect.field {
                "position" => ("--camera-position", vec3_text(camera.position)),
                "target" => ("--camera-target", vec3_text(camera.target)),
                "up" => ("--camera-up", vec3_text(camera.up)),
                _ => ("--fov", camera.fov_y_deg.to_string()),
            };
            anyhow::anyhow!("{flag} {value}: {}", defect.problem)
        })?;
        Ok(camera)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vec3_arguments() {
        assert_eq!(parse_vec3("1,-2.5, 3e1"), Ok(Vec3::new(1.0, -2.5, 30.0)));
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,2,x").is_err());
        assert!(parse_vec3("1,2,inf").is_err());
    }

    fn camera_error(flags: &[&str]) -> String {
        let mut line = vec!["igi", "render", "cornell-box", "-o", "x.png"];
        line.extend_from_slice(flags);
        let Command::Render(args) = Cli::try_parse_from(line).expect("valid command line").command else {
            panic!("not a render command")
        };
        let scene = igi_scene::load_named("cornell-box").unwrap();
        args.frame.camera.resolve(&scene).unwrap_err().to_string()
    }

    #[test]
    fn cameras_that_frame_no_image_are_refused_naming_the_flag() {
        assert_eq!(camera_error(&["--camera-up", "0,0,0"]), "--camera-up 0,0,0: must not be zero");
        // The Cornell box's camera looks along -z.
        assert_eq!(
            camera_error(&["--camera-up", "0,0,-2"]),
            "--camera-up 0,0,-2: must not be parallel to the view direction"
        );
        let err = camera_error(&["--camera-position", "1,2,3", "--camera-target", "1,2,3"]);
        assert!(err.starts_with("--camera-target 1,2,3: must lie a finite, non-zero distance"), "{err}");
        let err = camera_error(&["--camera-position", "3e38,0,0", "--camera-target", "-3e38,0,0"]);
        assert!(err.starts_with("--camera-target -300000000000000000000000000000000000000,0,0"), "{err}");
        assert!(camera_error(&["--fov", "180"]).starts_with("--fov 180: "));
        assert!(camera_error(&["--fov", "NaN"]).starts_with("--fov NaN: "));
    }

    #[test]
    fn cli_is_consistent() {
        <Cli as clap::CommandFactory>::command().debug_assert();
    }
}
