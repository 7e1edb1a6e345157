//! `igi serve SCENE [--listen ADDR]`: the browser viewer (`igi-serve`) on a session of the
//! scene.

use crate::viewer_args::ViewerArgs;
use anyhow::Result;
use clap::Args;
use igi_serve::{FrameBudget, Limits};
use std::net::{SocketAddr, ToSocketAddrs};

/// Arguments of `igi serve`.
#[derive(Debug, Args)]
#[command(after_help = crate::cli::scenes_help())]
pub struct ServeArgs {
    /// Address to listen on: a port (8080, on this machine), host:port (localhost:8080) or
    /// address:port (0.0.0.0:8080). The default serves this machine only; another address lets
    /// anyone who can reach it watch and steer the session.
    #[arg(long, default_value = "127.0.0.1:8080", value_parser = parse_listen, help_heading = "Server")]
    pub listen: SocketAddr,
    /// The most one frame may cost, in millions of rays: width × height × (AA samples + VPLs
    /// per pixel). Settings from a browser beyond it are refused, and so are starting
    /// settings. The default allows the panel's whole ranges at 640x480.
    #[arg(
        long,
        default_value_t = FrameBudget::DEFAULT.max_mrays,
        value_parser = clap::value_parser!(u64).range(1..),
        help_heading = "Server"
    )]
    pub max_frame_mrays: u64,
    /// Connections open at once (page loads and viewers); more are closed when accepted. A
    /// client also has 10 s to send a request's headers, and an HTTP connection closes after
    /// 10 s without a request (an open viewer's WebSocket does not).
    #[arg(
        long,
        default_value_t = Limits::MAX_CONNECTIONS as u64,
        value_parser = clap::value_parser!(u64).range(1..=4096),
        help_heading = "Server"
    )]
    pub max_connections: u64,
    /// Scene and frame options.
    #[command(flatten)]
    pub viewer: ViewerArgs,
}

/// Parses `--listen`: a bare port means this machine (127.0.0.1), a host name is resolved
/// (its first IPv4 address if it has one, as `localhost` should mean 127.0.0.1).
fn parse_listen(s: &str) -> Result<SocketAddr, String> {
    if let Ok(port) = s.parse::<u16>() {
        return Ok(SocketAddr::from(([127, 0, 0, 1], port)));
    }
    if let Ok(addr) = s.parse::<SocketAddr>() {
        return Ok(addr);
    }
    let usage = "expected a port (8080), host:port (localhost:8080) or address:port (0.0.0.0:8080)";
    let addrs: Vec<SocketAddr> = s.to_socket_addrs().map_err(|e| format!("{usage}; {s}: {e}"))?.collect();
    addrs
        .iter()
        .find(|a| a.is_ipv4())
        .or(addrs.first())
        .copied()
        .ok_or_else(|| format!("{usage}; {s} has no address"))
}

/// Runs `igi serve` until SIGINT (Ctrl-C) or SIGTERM. A local session listens before its
/// scene loads (a large one takes a while), so the address is printed at once; on a cluster
/// only rank 0 serves, and which rank this is is known once the job has started.
pub fn run(args: &ServeArgs) -> Result<()> {
    let listener = (!args.viewer.cluster.cluster).then(|| igi_serve::bind(args.listen)).transpose()?;
    let Some(session) = args.viewer.session()? else { return Ok(()) };
    let limits = Limits {
        frame: FrameBudget { max_mrays: args.max_frame_mrays },
        // At most 4096: the parser checked.
        max_connections: args.max_connections as usize,
        ..Limits::default()
    };
    let listener = match listener {
        Some(listener) => listener,
        None => igi_serve::bind(args.listen)?,
    };
    igi_serve::run(session, listener, limits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn listen_takes_a_port_a_host_or_an_address() {
        assert_eq!(parse_listen("8080"), Ok(SocketAddr::from(([127, 0, 0, 1], 8080))));
        assert_eq!(parse_listen("localhost:8081"), Ok(SocketAddr::from(([127, 0, 0, 1], 8081))));
        assert_eq!(parse_listen("0.0.0.0:80"), Ok(SocketAddr::from(([0, 0, 0, 0], 80))));
        assert_eq!(parse_listen("[::1]:8080"), Ok("[::1]:8080".parse().unwrap()));
        for bad in ["", "80800", "localhost", "http://localhost:8080"] {
            let err = parse_listen(bad).unwrap_err();
            assert!(err.starts_with("expected a port (8080)"), "{bad}: {err}");
        }
    }
}
