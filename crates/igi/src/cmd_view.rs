//! `igi view SCENE`: the native window viewer (`igi-view`) on a session of the scene.

use crate::viewer_args::ViewerArgs;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `igi view`.
#[derive(Debug, Args)]
#[command(after_help = crate::cli::scenes_help())]
pub struct ViewArgs {
    /// Write a screenshot of the window (PNG) after `--exit-after-frames` frames, then exit.
    #[arg(long, requires = "exit_after_frames")]
    pub screenshot: Option<PathBuf>,
    /// Close the window after this many frames were shown.
    #[arg(long)]
    pub exit_after_frames: Option<u32>,
    /// Scene and frame options.
    #[command(flatten)]
    pub viewer: ViewerArgs,
}

/// Runs `igi view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let Some(session) = args.viewer.session()? else { return Ok(()) };
    let options = igi_view::ViewOptions {
        screenshot: args.screenshot.clone(),
        exit_after_frames: args.exit_after_frames,
        title: format!("igi: {}", args.viewer.scene),
    };
    igi_view::run(session, options)
}
