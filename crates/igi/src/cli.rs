//! The command line: the top-level argument types (clap derive), logging set-up and
//! subcommand dispatch.

use crate::{bench, cmd_info, cmd_render, cmd_serve, cmd_view, cmd_worker};
use anyhow::Result;
use clap::{Parser, Subcommand};
use std::io::IsTerminal;

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
    /// Measure: frame rate (`bench frame`), ray throughput (`bench rays`), image quality
    /// (`bench quality`), cost against scene size (`bench scale`), cluster scaling (`bench
    /// cluster`).
    #[command(subcommand)]
    Bench(bench::BenchCommand),
}

/// The built-in scenes, for the end of the help of the commands that take a scene.
pub fn scenes_help() -> String {
    format!(
        "Built-in scenes: {}. The generated ones take a size: power-plant:triangles=2M, \
         maple-tree:triangles=300k.",
        igi_scene::builtin_names().join(", ")
    )
}

/// Runs one subcommand.
pub fn dispatch(command: Command) -> Result<()> {
    if matches!(command, Command::Render(_) | Command::Bench(_)) {
        crate::interrupt::end_writes_on_signal()?;
    }
    match command {
        Command::Render(args) => cmd_render::run(&args),
        Command::Info(args) => cmd_info::run(&args),
        Command::View(args) => cmd_view::run(&args),
        Command::Serve(args) => cmd_serve::run(&args),
        Command::Worker(args) => cmd_worker::run(&args),
        Command::Bench(cmd) => bench::run(cmd),
    }
}

/// Logs to stderr, filtered by `RUST_LOG` (default: warnings and errors). On a terminal with
/// colours and times; into a pipe or a file as plain `LEVEL message` lines, which is what a log
/// file or a CI transcript wants.
pub fn init_logging() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn"));
    let terminal = std::io::stderr().is_terminal();
    let log = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_target(false)
        .with_ansi(terminal);
    if terminal { log.init() } else { log.without_time().init() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cli_is_consistent() {
        <Cli as clap::CommandFactory>::command().debug_assert();
    }
}
