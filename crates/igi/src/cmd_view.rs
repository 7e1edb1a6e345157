//! `igi view SCENE`: the native window viewer (`igi-view`) on a session of the scene.

use crate::viewer_args::ViewerArgs;
use anyhow::Result;
use clap::Args;
use igi_view::resolution::Resolution;
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
    /// Inner size of the window, WxH (default 1200x760, or larger to hold --width x --height
    /// beside the panel).
    #[arg(long, value_parser = crate::frame_args::parse_nxm, help_heading = "Viewer")]
    pub window_size: Option<[u32; 2]>,
    /// Render size for the image area beside the panel (also in the panel): auto is full, or
    /// less so that the image has at most 614,400 pixels.
    #[arg(long, value_enum, default_value_t = Resolution::Auto, help_heading = "Viewer")]
    pub resolution: Resolution,
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
        window_size: args.window_size,
        resolution: args.resolution,
    };
    igi_view::run(session, options)
}
