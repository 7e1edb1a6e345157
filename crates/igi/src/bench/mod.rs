//! `igi bench`: throughput measurements. `igi bench frame` times whole frames of the
//! instant-global-illumination pipeline. `igi bench rays` times the two ray kinds of an
//! instant-radiosity frame (primary rays, shadow rays to virtual point lights) on exactly the
//! workload of `../shared/tools/embree-bench`, so the two can be compared ray for ray.
//! `igi bench cluster` measures frames of a cluster job as its render nodes grow.

pub mod cluster;
pub mod frame;
pub mod rays;
mod workload;

use anyhow::{Context, Result};
use clap::Subcommand;
use igi_render::output::{check_writable, write_atomically};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// The benchmarks.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Frames per second of the whole pipeline, with the time per phase.
    Frame(frame::FrameBenchArgs),
    /// Ray throughput of the traversal kernels on the instant-radiosity workload.
    Rays(rays::RaysArgs),
    /// Cluster frame rate, traffic and scaling from 1 to N render nodes (under mpirun).
    Cluster(cluster::ClusterBenchArgs),
}

/// Runs one benchmark.
pub fn run(cmd: BenchCommand) -> anyhow::Result<()> {
    match cmd {
        BenchCommand::Frame(args) => frame::run(&args),
        BenchCommand::Rays(args) => rays::run(&args),
        BenchCommand::Cluster(args) => cluster::run(&args),
    }
}

/// Checks, before a benchmark starts, that its `--json` report can be written.
fn check_json(json: Option<&Path>) -> Result<()> {
    json.map(check_writable).transpose().context("--json")?;
    Ok(())
}

/// Writes a benchmark's report as pretty JSON; `path` is replaced at once.
fn write_json(path: &Path, report: &impl Serialize) -> Result<()> {
    let json = serde_json::to_string_pretty(report)?;
    write_atomically(path, |out| out.write_all(json.as_bytes()))
        .with_context(|| format!("cannot write {}", path.display()))
}
