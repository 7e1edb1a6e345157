//! The command line: the top-level argument types (clap derive), logging set-up and
//! subcommand dispatch.

use crate::{bench, cmd_info, cmd_render, cmd_serve, cmd_view, cmd_worker};
use anyhow::Result;
use clap::{Parser, Subcommand};

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

/// Logs to stderr, filtered by `RUST_LOG` (default: warnings and errors).
pub fn init_logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn"));
    tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).with_target(false).init();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cli_is_consistent() {
        <Cli as clap::CommandFactory>::command().debug_assert();
    }
}
