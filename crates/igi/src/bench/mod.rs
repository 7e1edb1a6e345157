//! `igi bench`: throughput measurements. `igi bench frame` times whole frames of the
//! instant-global-illumination pipeline. `igi bench rays` times the two ray kinds of an
//! instant-radiosity frame (primary rays, shadow rays to virtual point lights) on exactly the
//! workload of `../shared/tools/embree-bench`, so the two can be compared ray for ray.
//! `igi bench cluster` measures frames of a cluster job as its render nodes grow. `igi bench
//! quality` measures one frame and accumulated frames against a path-traced reference (FLIP,
//! RMSE) and the flicker of an animation. `igi bench scale` measures how the cost of a ray grows
//! with the triangle count.

pub mod camera_path;
pub mod cluster;
pub mod frame;
mod json_report;
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
    /// Image error of one frame and of accumulated frames against a path-traced reference
    /// (mean FLIP, RMSE), and the flicker of an animation.
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
