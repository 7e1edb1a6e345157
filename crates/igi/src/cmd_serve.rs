//! `igi serve SCENE [--listen ADDR]`: the browser viewer (`igi-serve`) on a session of the
//! scene.

use crate::viewer_args::ViewerArgs;
use anyhow::Result;
use clap::Args;
use igi_serve::{FrameBudget, Limits};
use std::net::{IpAddr, SocketAddr};

/// Arguments of `igi serve`.
#[derive(Debug, Args)]
#[command(after_help = crate::cli::scenes_help())]
pub struct ServeArgs {
    /// Address to listen on: a port (8080, on this machine), an address with or without a port
    /// (0.0.0.0:8080, ::1, [::1]:8080) or localhost[:PORT]; names are not resolved. The default
    /// serves this machine only; another address lets anyone who can reach it watch and steer
    /// the session.
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
    /// Connections open at once (page loads and viewers); more are closed, unless a viewer
    /// has sent no input for 10 s: a newcomer that sends a request takes its place. A client
    /// also has 10 s to send a request's headers, and an HTTP connection closes after 10 s
    /// without a request (an open viewer's WebSocket does not).
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

/// The port `--listen` takes when it names only a host.
const DEFAULT_PORT: u16 = 8080;

/// Parses `--listen`: a port (on 127.0.0.1), an IPv4 or IPv6 address with or without a port
/// (`0.0.0.0:8080`, `::1`, `[::1]:8080`), or `localhost` with or without one. Nothing goes to
/// a name resolver: a listening address is this machine's own, and a name that resolves
/// elsewhere (or differently tomorrow) should not decide who can steer the session.
fn parse_listen(s: &str) -> Result<SocketAddr, String> {
    let usage = "expected a port (8080), an address with or without a port (127.0.0.1:8080, \
                 0.0.0.0, ::1, [::1]:8080) or localhost[:PORT]";
    if let Ok(port) = s.parse::<u16>() {
        return Ok(SocketAddr::from(([127, 0, 0, 1], port)));
    }
    if let Ok(addr) = s.parse::<SocketAddr>() {
        return Ok(addr);
    }
    let bare = s.strip_prefix('[').and_then(|s| s.strip_suffix(']')).unwrap_or(s);
    if let Ok(ip) = bare.parse::<IpAddr>() {
        return Ok(SocketAddr::new(ip, DEFAULT_PORT));
    }
    let (host, port) = match s.rsplit_once(':') {
        Some((host, port)) => {
            (host, port.parse::<u16>().map_err(|_| format!("{usage}; `{port}` is not a port"))?)
        }
        None => (s, DEFAULT_PORT),
    };
    if host.eq_ignore_ascii_case("localhost") {
        return Ok(SocketAddr::from(([127, 0, 0, 1], port)));
    }
    Err(format!("{usage}; `{host}` is neither an address nor localhost"))
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
    fn listen_takes_addresses_and_localhost_and_resolves_no_names() {
        let ok = |s: &str| parse_listen(s).unwrap().to_string();
        assert_eq!(ok("8081"), "127.0.0.1:8081");
        assert_eq!(ok("0.0.0.0:80"), "0.0.0.0:80");
        assert_eq!(ok("0.0.0.0"), "0.0.0.0:8080");
        assert_eq!(ok("::1"), "[::1]:8080");
        assert_eq!(ok("[::1]"), "[::1]:8080");
        assert_eq!(ok("[::1]:9000"), "[::1]:9000");
        assert_eq!(ok("localhost"), "127.0.0.1:8080");
        assert_eq!(ok("LOCALHOST:9000"), "127.0.0.1:9000");
        // A URL is not an address: it asks for a name after the scheme.
        assert!(parse_listen("http://localhost:8080").is_err());
        for bad in ["example.com", "example.com:80", "localhost:http", "127.0.0.1:99999", "80800", ""] {
            let err = parse_listen(bad).unwrap_err();
            assert!(err.starts_with("expected a port"), "{bad}: {err}");
        }
    }
}
