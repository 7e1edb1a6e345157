//! `igi serve SCENE [--listen ADDR]`: the browser viewer (`igi-serve`) on a session of the
//! scene.

use crate::viewer_args::ViewerArgs;
use anyhow::Result;
use clap::Args;
use igi_serve::{FrameBudget, Limits};
use std::net::SocketAddr;

/// Arguments of `igi serve`.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Address to listen on. The default serves this machine only; another address lets
    /// anyone who can reach it watch and steer the session.
    #[arg(long, default_value = "127.0.0.1:8080")]
    pub listen: SocketAddr,
    /// The most one frame may cost, in millions of rays: width × height × (AA samples + VPLs
    /// per pixel). Settings from a browser beyond it are refused, and so are starting
    /// settings. The default allows the panel's whole ranges at 640x480.
    #[arg(long, default_value_t = FrameBudget::DEFAULT.max_mrays, value_parser = clap::value_parser!(u64).range(1..))]
    pub max_frame_mrays: u64,
    /// Connections open at once (page loads and viewers); more are closed when accepted. A
    /// client also has 10 s to send a request's headers, and an HTTP connection closes after
    /// 10 s without a request (an open viewer's WebSocket does not).
    #[arg(long, default_value_t = Limits::MAX_CONNECTIONS as u64, value_parser = clap::value_parser!(u64).range(1..=4096))]
    pub max_connections: u64,
    /// Scene and frame options.
    #[command(flatten)]
    pub viewer: ViewerArgs,
}

/// Runs `igi serve` until SIGINT (Ctrl-C) or SIGTERM.
pub fn run(args: &ServeArgs) -> Result<()> {
    let Some(session) = args.viewer.session()? else { return Ok(()) };
    let limits = Limits {
        frame: FrameBudget { max_mrays: args.max_frame_mrays },
        // At most 4096: the parser checked.
        max_connections: args.max_connections as usize,
        ..Limits::default()
    };
    igi_serve::run(session, args.listen, limits)
}
