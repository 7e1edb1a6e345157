//! `igi view SCENE`: the native window viewer (`igi-view`) on a session of the scene.

use crate::viewer_args::ViewerArgs;
use anyhow::Result;
use clap::Args;
use clap::ValueEnum;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use igi_view::resolution::{AUTO_PIXELS, Resolution};
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
    /// Render size for the image area beside the panel (also in the panel).
    #[arg(long, default_value = "auto", value_parser = resolutions(), help_heading = "Viewer")]
    pub resolution: Resolution,
    /// Scene and frame options.
    #[command(flatten)]
    pub viewer: ViewerArgs,
}

/// The values of `--resolution` with help written for the command line: clap would take each
/// value's help from the documentation of `Resolution`'s variants, which is written for rustdoc
/// (links such as [`AUTO_PIXELS`] printed as they are).
fn resolutions() -> impl TypedValueParser<Value = Resolution> {
    let help = |r: Resolution| match r {
        Resolution::Auto => {
            format!(
                "full, or less so that the image has at most {AUTO_PIXELS} pixels (large windows stay interactive)"
            )
        }
        Resolution::Full => "one image pixel per window pixel".into(),
        Resolution::Half => "half the window's pixels along each axis".into(),
        Resolution::Quarter => "a quarter along each axis".into(),
    };
    let values = Resolution::ALL.into_iter().filter_map(|r| r.to_possible_value().map(|v| v.help(help(r))));
    PossibleValuesParser::new(values)
        .map(|name| Resolution::from_str(&name, false).expect("one of the values listed"))
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
