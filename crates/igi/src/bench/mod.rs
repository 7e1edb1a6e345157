//! `igi bench`: throughput measurements. `igi bench frame` times whole frames of the
//! instant-global-illumination pipeline. `igi bench rays` times the two ray kinds of an
//! instant-radiosity frame (primary rays, shadow rays to virtual point lights) on exactly the
//! workload of `../shared/tools/embree-bench`, so the two can be compared ray for ray.
//! `igi bench cluster` measures frames of a cluster job as its render nodes grow. `igi bench
//! quality` measures the default image, one frame and accumulated frames against a path-traced
//! reference (FLIP, blotch10, RMSE), the flicker of an animation, an orbiting camera with and
//! without temporal reuse, and the lag of a change of the light. `igi bench scale` measures how the cost of a ray grows
//! with the triangle count.

pub mod camera_path;
pub mod cluster;
pub mod frame;
mod json_report;
pub mod light_lag;
pub mod quality;
pub mod rays;
pub mod scale;
mod workload;

use clap::{Args, Subcommand};

/// The scene a frame-rate benchmark renders and how many of its frames it times.
#[derive(Debug, Args)]
pub struct TimedFrames {
    /// Built-in scene name or scene file.
    pub scene: String,
    /// Timed frames (after the warm-up).
    #[arg(long, default_value_t = 20)]
    pub frames: u32,
    /// Untimed frames first (thread start-up, caches).
    #[arg(long, default_value_t = 2)]
    pub warmup: u32,
}

/// The benchmarks.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Frames per second of the whole pipeline, with the time per phase.
    Frame(frame::FrameBenchArgs),
    /// Ray throughput of the traversal kernels on the instant-radiosity workload.
    Rays(rays::RaysArgs),
    /// Cluster frame rate, traffic and scaling from 1 to N render nodes (under mpirun).
    Cluster(cluster::ClusterBenchArgs),
    /// Image error of the default image, one frame and accumulated frames against a reference
    /// (mean FLIP, blotch10, RMSE), the flicker of an animation, an orbiting camera, the lag of
    /// a change of the light.
    Quality(quality::QualityBenchArgs),
    /// Build time, memory and time per primary and shadow ray as the same view's triangle count
    /// grows by tenfold steps (10^4 to 10^7 unique, then instanced to 10^8).
    Scale(scale::ScaleArgs),
}

/// Runs one benchmark.
pub fn run(cmd: BenchCommand) -> anyhow::Result<()> {
    match cmd {
        BenchCommand::Frame(args) => frame::run(&args),
        BenchCommand::Rays(args) => rays::run(&args),
        BenchCommand::Cluster(args) => cluster::run(&args),
        BenchCommand::Quality(args) => quality::run(&args),
        BenchCommand::Scale(args) => scale::run(&args),
    }
}
