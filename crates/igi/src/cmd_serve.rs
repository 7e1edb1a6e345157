//! `igi serve SCENE [--listen ADDR]`: the browser viewer (`igi-serve`) on a session of the
//! scene.

use crate::viewer_args::ViewerArgs;
use anyhow::Result;
use clap::Args;
use std::net::SocketAddr;

/// Arguments of `igi serve`.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Address to listen on. The default serves this machine only; another address lets
    /// anyone who can reach it watch and steer the session.
    #[arg(long, default_value = "127.0.0.1:8080")]
    pub listen: SocketAddr,
    /// Scene and frame options.
    #[command(flatten)]
    pub viewer: ViewerArgs,
}

/// Runs `igi serve` until Ctrl-C.
pub fn run(args: &ServeArgs) -> Result<()> {
    let Some(session) = args.viewer.session()? else { return Ok(()) };
    igi_serve::run(session, args.listen)
}
