//! Who may open the stream. A WebSocket is not bound by the browser's same-origin policy, so
//! without a check any web page the user visits could connect to `ws://127.0.0.1:8080/ws`
//! and steer the session (cross-site WebSocket hijacking), and a site whose name is made to
//! resolve to 127.0.0.1 could do the same with a matching Origin (DNS rebinding).
//!
//! The rule: a browser's `Origin`, when sent, must name the host and port the request went to
//! (`Host`), and a server listening on loopback answers only to loopback names. Clients that
//! send no Origin are not browsers; a page cannot make a browser omit it.

use axum::http::HeaderMap;
use axum::http::header::{HOST, ORIGIN};

/// Why a connection was refused.
pub type Refusal = &'static str;

/// Checks the headers of a WebSocket upgrade for a server listening on a loopback address
/// (`loopback`) or on another one.
pub fn check(headers: &HeaderMap, loopback: bool) -> Result<(), Refusal> {
    let host = headers.get(HOST).and_then(|h| h.to_str().ok()).ok_or("no Host header")?;
    if loopback && !is_loopback_name(host) {
        return Err("this server answers to localhost names only");
    }
    let Some(origin) = headers.get(ORIGIN) else { return Ok(()) };
    let origin = origin.to_str().map_err(|_| "the Origin header is not text")?;
    // The server speaks plain HTTP, so its own pages come from `http://` only.
    let authority = origin.strip_prefix("http://");
    match authority {
        Some(authority) if authority.eq_ignore_ascii_case(host) => Ok(()),
        _ => Err("the page comes from another origin"),
    }
}

/// `localhost`, `127.x.y.z` or `[::1]`, with or without a port, and nothing else: a `Host`
/// such as `[::1]evil.example:8080` or `127.0.0.1:8080@evil.example` names another host.
fn is_loopback_name(host: &str) -> bool {
    let port_ok =
        |port: Option<&str>| port.is_none_or(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
    let (name, port) = if let Some(rest) = host.strip_prefix('[') {
        let Some((name, after)) = rest.split_once(']') else { return false };
        match after {
            "" => (name, None),
            _ => match after.strip_prefix(':') {
                Some(port) => (name, Some(port)),
                None => return false,
            },
        }
    } else {
        match host.split_once(':') {
            Some((name, port)) => (name, Some(port)),
            None => (host, None),
        }
    };
    port_ok(port)
        && (name.eq_ignore_ascii_case("localhost")
            || name.parse::<std::net::IpAddr>().is_ok_and(|ip| ip.is_loopback()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(host: &str, origin: Option<&str>) -> HeaderMap {
        let mut h = HeaderMap::new();
        h.insert(HOST, host.parse().unwrap());
        if let Some(o) = origin {
            h.insert(ORIGIN, o.parse().unwrap());
        }
        h
    }

    #[test]
    fn same_origin_pages_and_plain_clients_pass() {
        assert_eq!(check(&headers("127.0.0.1:8080", Some("http://127.0.0.1:8080")), true), Ok(()));
        assert_eq!(check(&headers("localhost:8080", Some("http://localhost:8080")), true), Ok(()));
        assert_eq!(check(&headers("[::1]:8080", None), true), Ok(()));
        assert_eq!(check(&headers("render.example:80", Some("http://render.example:80")), false), Ok(()));
    }

    #[test]
    fn other_origins_and_rebound_names_are_refused() {
        assert!(check(&headers("127.0.0.1:8080", Some("http://evil.example")), true).is_err());
        assert!(check(&headers("127.0.0.1:8080", Some("null")), true).is_err());
        // DNS rebinding: the attacker's name resolves to 127.0.0.1, and its Origin matches.
        assert!(check(&headers("evil.example:8080", Some("http://evil.example:8080")), true).is_err());
        assert!(check(&headers("render.example", Some("http://evil.example")), false).is_err());
        assert!(check(&HeaderMap::new(), true).is_err());
        // Names with a loopback prefix, and an https page for this http server (issue 35).
        assert!(check(&headers("[::1]evil.example:8080", None), true).is_err());
        assert!(check(&headers("127.0.0.1:8080@evil.example", None), true).is_err());
        assert!(check(&headers("localhost:80x", None), true).is_err());
        assert!(check(&headers("127.0.0.1:8080", Some("https://127.0.0.1:8080")), true).is_err());
        assert_eq!(check(&headers("[::1]", None), true), Ok(()));
        assert_eq!(check(&headers("localhost", None), true), Ok(()));
    }
}
