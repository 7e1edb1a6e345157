//! The server's bounds on its clients: a request whose headers do not come within the header
//! timeout is closed, so is a kept-alive connection that idles that long, while a WebSocket
//! lives on; connections beyond the cap are closed, and the cap frees as connections
//! close. So half-open requests cannot exhaust the process's file descriptors, and viewers
//! that send nothing cannot lock everyone out: a newcomer replaces the one idle longest.

mod common;

use futures_util::{SinkExt, StreamExt};
use igi_serve::Limits;
use serde_json::json;
use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};
use tokio_tungstenite::tungstenite::Message;

/// True if the server closes `stream` within `within` (reading it ends or fails); false if
/// it stays open, sending nothing.
fn closed_within(stream: &mut TcpStream, within: Duration) -> bool {
    stream.set_read_timeout(Some(within)).unwrap();
    let mut bytes = Vec::new();
    match stream.read_to_end(&mut bytes) {
        Ok(_) => true,
        Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => false,
        Err(_) => true,
    }
}

#[test]
fn slow_headers_and_idle_connections_are_closed_after_the_header_timeout() {
    let timeout = Duration::from_secs(1);
    let server = common::start_with(64, 48, Limits { header_timeout: timeout, ..Limits::default() });

    // Headers that never end.
    let mut half_open = TcpStream::connect(server.address).unwrap();
    half_open.write_all(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n").unwrap();
    let start = Instant::now();
    assert!(
        closed_within(&mut half_open, Duration::from_secs(10)),
        "still open 10 s after a partial request"
    );
    assert!(start.elapsed() >= timeout / 2, "closed after {:?}, before the timeout", start.elapsed());

    // A kept-alive connection after its response.
    let mut idle = TcpStream::connect(server.address).unwrap();
    idle.write_all(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n").unwrap();
    let mut head = [0u8; 12];
    idle.read_exact(&mut head).unwrap();
    assert_eq!(&head, b"HTTP/1.1 200");
    assert!(closed_within(&mut idle, Duration::from_secs(10)), "an idle connection still open after 10 s");

    // A WebSocket has no timeout: after twice the header timeout it still answers.
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    runtime.block_on(async {
        let url = format!("ws://{}/ws", server.address);
        let (mut socket, _) = tokio_tungstenite::connect_async(url).await.unwrap();
        tokio::time::sleep(2 * timeout).await;
        let input = json!({"id": 1, "input": {"type": "drag", "dx": 3, "dy": 0, "button": "primary"}});
        socket.send(Message::Text(input.to_string().into())).await.unwrap();
        let acked = async {
            while let Some(Ok(message)) = socket.next().await {
                let Message::Binary(bytes) = message else { continue };
                let length = u32::from_le_bytes(bytes[1..5].try_into().unwrap()) as usize;
                let header: serde_json::Value = serde_json::from_slice(&bytes[5..5 + length]).unwrap();
                if header["acked"] == 1 {
                    return true;
                }
            }
            false
        };
        let acked = tokio::time::timeout(Duration::from_secs(30), acked).await;
        assert_eq!(acked, Ok(true), "the WebSocket answers after twice the header timeout");
    });
}

#[test]
fn connections_beyond_the_cap_are_closed() {
    let cap = 4;
    let server = common::start_with(64, 48, Limits { max_connections: cap, ..Limits::default() });
    // `cap` connections that send nothing: the server keeps them (until the header timeout).
    let mut silent: Vec<TcpStream> = (0..cap).map(|_| TcpStream::connect(server.address).unwrap()).collect();
    std::thread::sleep(Duration::from_millis(200));
    // One more is closed: at once if it sent a request, after a moment if it sends nothing.
    let mut extra = TcpStream::connect(server.address).unwrap();
    assert!(closed_within(&mut extra, Duration::from_secs(5)), "a connection beyond the cap stays open");
    assert!(!closed_within(&mut silent[0], Duration::from_millis(100)), "the first ones are kept");

    // A closed connection frees its place: a page load succeeds again.
    drop(silent.pop());
    let deadline = Instant::now() + Duration::from_secs(10);
    while !page_loads(server.address) {
        assert!(Instant::now() < deadline, "no place freed 10 s after a connection closed");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// True if `GET /` answers with the page.
fn page_loads(address: std::net::SocketAddr) -> bool {
    let mut client = TcpStream::connect(address).unwrap();
    client.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    let _ = client.write_all(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
    let mut response = String::new();
    let _ = client.read_to_string(&mut response);
    response.starts_with("HTTP/1.1 200")
}

#[test]
fn a_newcomer_replaces_the_viewer_idle_longest_when_every_place_is_taken() {
    // 64 WebSockets that sent nothing locked out everyone, the page included (issue 35).
    let (cap, idle) = (3, Duration::from_millis(500));
    let server =
        common::start_with(64, 48, Limits { max_connections: cap, viewer_idle: idle, ..Limits::default() });
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
    let url = format!("ws://{}/ws", server.address);
    let mut viewers: Vec<_> = (0..cap)
        .map(|_| {
            let viewer = runtime.block_on(tokio_tungstenite::connect_async(url.as_str())).unwrap().0;
            std::thread::sleep(Duration::from_millis(20));
            viewer
        })
        .collect();
    // Every place is taken by viewers that were active a moment ago: a newcomer is refused.
    assert!(!page_loads(server.address), "a page loaded beyond the cap");

    // Once they are idle, the oldest viewer sends input, so the second is the one idle longest.
    std::thread::sleep(idle + Duration::from_millis(100));
    let input = json!({"id": 1, "input": {"type": "drag", "dx": 3, "dy": 0, "button": "primary"}});
    runtime.block_on(viewers[0].send(Message::Text(input.to_string().into()))).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    // A socket that sends nothing (a port scan, a browser's speculative connection) replaces
    // no one: it is closed after a while.
    let mut silent = TcpStream::connect(server.address).unwrap();
    assert!(closed_within(&mut silent, Duration::from_secs(5)), "a silent newcomer stays open");
    assert!(page_loads(server.address), "the page did not replace an idle viewer");

    // The second viewer was told why it closed; the others stay open.
    let close_code = |viewer: &mut tokio_tungstenite::WebSocketStream<_>| {
        runtime.block_on(async {
            let read = async {
                while let Some(Ok(message)) = viewer.next().await {
                    if let Message::Close(frame) = message {
                        return frame.map(|f| u16::from(f.code));
                    }
                }
                None
            };
            tokio::time::timeout(Duration::from_millis(500), read).await.ok()
        })
    };
    assert_eq!(close_code(&mut viewers[1]), Some(Some(1013)));
    assert_eq!(close_code(&mut viewers[0]), None, "the active viewer was closed");
    assert_eq!(close_code(&mut viewers[2]), None, "two viewers were replaced for one newcomer");
}
