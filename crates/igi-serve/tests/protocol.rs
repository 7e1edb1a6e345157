//! The WebSocket protocol spoken by a Rust client: frames arrive as documented and decode to
//! the session's image, inputs are acknowledged by the frame that includes them, settings
//! round-trip, refused inputs are answered to the connection that sent them (bounded), and
//! malformed, oversized and binary messages close only their own connection. The HTTP side
//! serves the page and nothing else.

mod common;

use futures_util::{SinkExt, StreamExt};
use serde_json::{Value, json};
use std::io::{Read, Write};
use std::time::Duration;
use tokio_tungstenite::tungstenite::Message;

type Socket = tokio_tungstenite::WebSocketStream<tokio_tungstenite::MaybeTlsStream<tokio::net::TcpStream>>;

/// A decoded frame message.
struct Frame {
    kind: u8,
    header: Value,
    image: image::RgbImage,
}

async fn connect(server: &common::TestServer) -> Socket {
    let url = format!("ws://{}/ws", server.address);
    tokio_tungstenite::connect_async(url).await.expect("websocket connects").0
}

/// The next frame message (skipping pings), within 30 s.
async fn next_frame(socket: &mut Socket) -> Frame {
    loop {
        let message = tokio::time::timeout(Duration::from_secs(30), socket.next())
            .await
            .expect("a frame within 30 s")
            .expect("the connection stays open")
            .expect("a valid message");
        let Message::Binary(bytes) = message else { continue };
        let kind = bytes[0];
        let length = u32::from_le_bytes(bytes[1..5].try_into().unwrap()) as usize;
        let header: Value = serde_json::from_slice(&bytes[5..5 + length]).unwrap();
        let format = if kind == 0 { image::ImageFormat::Jpeg } else { image::ImageFormat::Png };
        let image = image::load_from_memory_with_format(&bytes[5 + length..], format).unwrap().to_rgb8();
        return Frame { kind, header, image };
    }
}

/// Frames until one satisfies `done`.
async fn frame_where(socket: &mut Socket, mut done: impl FnMut(&Frame) -> bool) -> Frame {
    for _ in 0..200 {
        let frame = next_frame(socket).await;
        if done(&frame) {
            return frame;
        }
    }
    panic!("no frame satisfied the condition");
}

/// Sends a raw message and expects the server to close the connection (with a close frame or
/// by ending the stream) within 10 s.
async fn expect_closed(socket: &mut Socket, message: Message) -> Option<u16> {
    socket.send(message).await.ok();
    let deadline = tokio::time::Instant::now() + Duration::from_secs(10);
    loop {
        match tokio::time::timeout_at(deadline, socket.next()).await.expect("the server closes within 10 s") {
            Some(Ok(Message::Close(frame))) => return frame.map(|f| u16::from(f.code)),
            Some(Ok(_)) => continue,
            Some(Err(_)) | None => return None,
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn frames_inputs_settings_and_bad_messages() {
    let server = common::start(160, 120);
    let mut viewer = connect(&server).await;

    // A frame of the session's size that is not blank.
    let first = next_frame(&mut viewer).await;
    assert_eq!(first.image.dimensions(), (160, 120));
    let (lo, hi) = first.image.pixels().fold((255u8, 0u8), |(lo, hi), p| (lo.min(p[1]), hi.max(p[1])));
    assert!(hi > lo + 20, "the image has content ({lo}..{hi})");
    assert_eq!(first.header["stats"]["width"], 160);
    assert!(first.header["stats"]["settings"]["vpls_per_pixel"].as_u64().unwrap() > 0);

    // A drag with an id: the frame that includes it says so, and shows the turned view.
    let drag = json!({"id": 7, "input": {"type": "drag", "dx": 40, "dy": 0, "button": "primary"}});
    viewer.send(Message::Text(drag.to_string().into())).await.unwrap();
    let turned = frame_where(&mut viewer, |f| f.header["acked"] == 7).await;
    assert_ne!(turned.image.as_raw(), first.image.as_raw());

    // Settings round-trip: the frames carry the new value.
    let mut settings = turned.header["stats"]["settings"].clone();
    settings["filter"] = json!(false);
    let message = json!({"id": 8, "input": {"type": "settings", "settings": settings}});
    viewer.send(Message::Text(message.to_string().into())).await.unwrap();
    let unfiltered = frame_where(&mut viewer, |f| f.header["acked"] == 8).await;
    assert_eq!(unfiltered.header["stats"]["settings"]["filter"], false);

    // Invalid settings are refused with the reason, to this connection, and change nothing.
    settings["aa"] = json!(0);
    let message = json!({"id": 9, "input": {"type": "settings", "settings": settings}});
    viewer.send(Message::Text(message.to_string().into())).await.unwrap();
    let nudge = json!({"id": 10, "input": {"type": "drag", "dx": 5, "dy": 0, "button": "primary"}});
    viewer.send(Message::Text(nudge.to_string().into())).await.unwrap();
    let mut errors = Vec::new();
    let after = frame_where(&mut viewer, |f| {
        errors.extend(f.header["errors"].as_array().into_iter().flatten().map(|e| e.to_string()));
        f.header["acked"] == 10
    })
    .await;
    assert!(
        errors.iter().any(|e| e.starts_with("AA samples: ") || e.starts_with("\"AA samples: ")),
        "{errors:?}"
    );
    assert_eq!(after.header["stats"]["settings"]["aa"], 1);

    // Once nothing changes, the newest frame comes losslessly.
    let still = frame_where(&mut viewer, |f| f.kind == 1).await;
    assert_eq!(still.image.dimensions(), (160, 120));

    // Bad messages close their own connection only.
    let bad: [(Message, Option<u16>); 5] = [
        (Message::Text("{not json".into()), Some(1007)),
        (Message::Text(json!({"input": {"type": "explode"}}).to_string().into()), Some(1007)),
        (Message::Text(json!({"input": {"type": "reset"}, "extra": 1}).to_string().into()), Some(1007)),
        (Message::Binary(vec![0xde, 0xad, 0xbe, 0xef].into()), Some(1003)),
        (Message::Text("x".repeat(1 << 20).into()), None),
    ];
    for (message, code) in bad {
        let mut other = connect(&server).await;
        next_frame(&mut other).await;
        let closed = expect_closed(&mut other, message).await;
        if code.is_some() {
            assert_eq!(closed, code);
        }
    }
    // The first viewer still gets frames for its input.
    let alive = json!({"id": 11, "input": {"type": "drag", "dx": -30, "dy": 0, "button": "primary"}});
    viewer.send(Message::Text(alive.to_string().into())).await.unwrap();
    frame_where(&mut viewer, |f| f.header["acked"] == 11).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn settings_over_the_frame_budget_are_refused_to_their_sender() {
    let server = common::start(160, 120);
    let mut viewer = connect(&server).await;
    let first = next_frame(&mut viewer).await;
    let mut settings = first.header["stats"]["settings"].clone();

    // The probe's frame of hours: 4K UHD, 64 AA samples, 4096 VPLs per pixel. Each value is
    // valid; their product is not within the default budget.
    settings["width"] = json!(3840);
    settings["height"] = json!(2160);
    settings["aa"] = json!(64);
    settings["vpls_per_pixel"] = json!(4096);
    let message = json!({"id": 1, "input": {"type": "settings", "settings": settings}});
    viewer.send(Message::Text(message.to_string().into())).await.unwrap();
    let nudge = json!({"id": 2, "input": {"type": "drag", "dx": 5, "dy": 0, "button": "primary"}});
    viewer.send(Message::Text(nudge.to_string().into())).await.unwrap();
    let mut errors = Vec::new();
    let after = frame_where(&mut viewer, |f| {
        errors.extend(f.header["errors"].as_array().into_iter().flatten().map(|e| e.to_string()));
        f.header["acked"] == 2
    })
    .await;
    assert!(errors.iter().any(|e| e.contains("--max-frame-mrays")), "{errors:?}");
    assert_eq!(after.image.dimensions(), (160, 120), "the settings did not change");
    assert_eq!(
        after.header["stats"]["settings"]["vpls_per_pixel"],
        first.header["stats"]["settings"]["vpls_per_pixel"]
    );
}

/// The errors of the frames that come within `within`, until one says `done`.
async fn errors_until(
    socket: &mut Socket,
    within: Duration,
    done: impl Fn(&[String]) -> bool,
) -> Vec<String> {
    let mut errors = Vec::new();
    let deadline = tokio::time::Instant::now() + within;
    while !done(&errors) {
        let Ok(frame) = tokio::time::timeout_at(deadline, next_frame(socket)).await else { break };
        let said = frame.header["errors"].as_array().cloned().unwrap_or_default();
        errors.extend(said.iter().map(|e| e.as_str().unwrap().to_string()));
    }
    errors
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_scene_that_does_not_open_is_said_to_the_viewer_that_chose_it() {
    let server = common::start(160, 120);
    let mut chooser = connect(&server).await;
    let mut other = connect(&server).await;
    next_frame(&mut chooser).await;
    next_frame(&mut other).await;
    let open = json!({"id": 1, "input": {"type": "open", "name": "toml/missing_mesh.toml"}});
    chooser.send(Message::Text(open.to_string().into())).await.unwrap();
    // At once, with the newest frame again: the view is still and renders none.
    let errors = errors_until(&mut chooser, Duration::from_secs(10), |e| !e.is_empty()).await;
    assert_eq!(errors, [format!("open: {}", common::MISSING)], "the reason, to the viewer that chose it");
    let elsewhere = errors_until(&mut other, Duration::from_secs(1), |e| !e.is_empty()).await;
    assert!(elsewhere.is_empty(), "not to the other viewer: {elsewhere:?}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn thousands_of_refused_inputs_are_answered_in_a_few_short_messages() {
    let server = common::start(160, 120);
    let mut viewer = connect(&server).await;
    next_frame(&mut viewer).await;
    // The probe's messages: names of 15.5 KB, sent without reading what comes back.
    let name = "v".repeat(15_500);
    for _ in 0..3_000 {
        let view = json!({"input": {"type": "view", "name": name}});
        viewer.send(Message::Text(view.to_string().into())).await.unwrap();
    }
    let nudge = json!({"id": 2, "input": {"type": "drag", "dx": 5, "dy": 0, "button": "primary"}});
    viewer.send(Message::Text(nudge.to_string().into())).await.unwrap();
    // Many frames may wait unread (each answer comes with one): read until the drag's.
    let (mut errors, mut most) = (Vec::new(), 0);
    let deadline = tokio::time::Instant::now() + Duration::from_secs(60);
    loop {
        let frame =
            tokio::time::timeout_at(deadline, next_frame(&mut viewer)).await.expect("the drag's frame");
        let said = frame.header["errors"].as_array().cloned().unwrap_or_default();
        most = most.max(said.len());
        errors.extend(said.iter().map(|e| e.as_str().unwrap().to_string()));
        if frame.header["acked"] == 2 {
            break;
        }
    }
    assert!(!errors.is_empty(), "the refusals are answered");
    assert!(most <= igi_session::refusals::MAX_KEPT, "{most} errors in one frame");
    for error in &errors {
        // Refused by the session with the name cut, or at once if too many names waited.
        let view =
            error.starts_with("view: the scene has no view \"vvv") && error.ends_with("…\" (15500 bytes)");
        assert!(view || error.starts_with("busy: "), "{error}");
    }
}

/// A raw HTTP GET; returns the status line and the body.
fn get(address: std::net::SocketAddr, path: &str) -> (String, String) {
    let mut stream = std::net::TcpStream::connect(address).unwrap();
    write!(stream, "GET {path} HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n").unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    let status = response.lines().next().unwrap_or_default().to_string();
    let body = response.split_once("\r\n\r\n").map(|(_, b)| b.to_string()).unwrap_or_default();
    (status, body)
}

#[test]
fn the_page_forbids_framing_sniffing_and_loads_from_elsewhere() {
    // It had no Content-Security-Policy, X-Frame-Options or X-Content-Type-Options (issue 35).
    let server = common::start(32, 24);
    let mut stream = std::net::TcpStream::connect(server.address).unwrap();
    write!(stream, "GET / HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n").unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    let head = response.split_once("\r\n\r\n").map_or("", |(h, _)| h).to_ascii_lowercase();
    assert!(head.contains("x-frame-options: deny"), "{head}");
    assert!(head.contains("x-content-type-options: nosniff"), "{head}");
    let policy = head.lines().find(|l| l.starts_with("content-security-policy:")).expect("a policy");
    assert!(policy.contains("default-src 'none'") && policy.contains("frame-ancestors 'none'"), "{policy}");
}

#[test]
fn only_the_page_the_stream_and_the_scene_list_are_served() {
    let server = common::start(32, 24);
    let (status, body) = get(server.address, "/");
    assert!(status.contains("200"), "{status}");
    assert!(body.contains("<canvas") && body.contains("/ws"));
    // The names of the scenes the page may open, and nothing else about the file system.
    let (status, body) = get(server.address, "/scenes");
    assert!(status.contains("200"), "{status}");
    assert_eq!(body, r#"["animated-room","cornell-box","toml/missing_mesh.toml"]"#);
    for path in ["/etc/passwd", "/../Cargo.toml", "/index.html", "/page/index.html", "/src/lib.rs"] {
        let (status, _) = get(server.address, path);
        assert!(status.contains("404"), "{path}: {status}");
    }
    // The stream needs a WebSocket upgrade.
    let (status, _) = get(server.address, "/ws");
    assert!(!status.contains("200"), "{status}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn pages_of_other_sites_and_rebound_names_cannot_open_the_stream() {
    use tokio_tungstenite::tungstenite::client::IntoClientRequest;
    let server = common::start(32, 24);
    let request = |host: Option<&str>, origin: Option<&str>| {
        let mut r = format!("ws://{}/ws", server.address).into_client_request().unwrap();
        if let Some(h) = host {
            r.headers_mut().insert("Host", h.parse().unwrap());
        }
        if let Some(o) = origin {
            r.headers_mut().insert("Origin", o.parse().unwrap());
        }
        r
    };
    let refused = |result: Result<_, tokio_tungstenite::tungstenite::Error>| match result {
        Err(tokio_tungstenite::tungstenite::Error::Http(response)) => response.status() == 403,
        _ => false,
    };
    let same = format!("http://{}", server.address);
    assert!(tokio_tungstenite::connect_async(request(None, Some(&same))).await.is_ok());
    assert!(refused(tokio_tungstenite::connect_async(request(None, Some("http://evil.example"))).await));
    let port = server.address.port();
    let rebound = format!("evil.example:{port}");
    let rebound_origin = format!("http://{rebound}");
    assert!(refused(tokio_tungstenite::connect_async(request(Some(&rebound), Some(&rebound_origin))).await));
}

/// Opens the stream over a plain socket, so that frames no WebSocket library would send can
/// be written to it.
fn raw_websocket(address: std::net::SocketAddr) -> std::net::TcpStream {
    let mut stream = std::net::TcpStream::connect(address).unwrap();
    stream.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    write!(
        stream,
        "GET /ws HTTP/1.1\r\nHost: localhost\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n"
    )
    .unwrap();
    let mut head = Vec::new();
    let mut byte = [0u8];
    while !head.ends_with(b"\r\n\r\n") {
        stream.read_exact(&mut byte).unwrap();
        head.push(byte[0]);
    }
    assert!(head.starts_with(b"HTTP/1.1 101"), "{}", String::from_utf8_lossy(&head));
    stream
}

/// The code of the close frame the server sends after reading `frame`, skipping the frames
/// it sends before; `None` if the connection ends without one.
fn close_code_after(address: std::net::SocketAddr, frame: &[u8]) -> Option<u16> {
    let mut stream = raw_websocket(address);
    stream.write_all(frame).unwrap();
    loop {
        // Server frames are not masked: opcode, length (7, 16 or 64 bits), payload.
        let mut head = [0u8; 2];
        stream.read_exact(&mut head).ok()?;
        let length = match head[1] & 0x7f {
            126 => {
                let mut l = [0u8; 2];
                stream.read_exact(&mut l).ok()?;
                u64::from(u16::from_be_bytes(l))
            }
            127 => {
                let mut l = [0u8; 8];
                stream.read_exact(&mut l).ok()?;
                u64::from_be_bytes(l)
            }
            l => u64::from(l),
        };
        let mut payload = vec![0u8; usize::try_from(length).unwrap()];
        stream.read_exact(&mut payload).ok()?;
        if head[0] & 0x0f == 0x8 {
            return payload.get(..2).map(|c| u16::from_be_bytes([c[0], c[1]]));
        }
    }
}

/// A client frame: FIN, `opcode`, masked with a zero key (so the payload reads as is).
fn client_frame(opcode: u8, payload: &[u8]) -> Vec<u8> {
    let mut frame = vec![0x80 | opcode];
    match payload.len() {
        l @ 0..=125 => frame.push(0x80 | l as u8),
        l => {
            frame.push(0x80 | 126);
            frame.extend_from_slice(&u16::try_from(l).unwrap().to_be_bytes());
        }
    }
    frame.extend_from_slice(&[0; 4]);
    frame.extend_from_slice(payload);
    frame
}

#[test]
fn unreadable_messages_close_with_the_code_rfc_6455_gives_them() {
    // Every one of them closed with 1009, "too big" (issue 35).
    let server = common::start(32, 24);
    // Protocol errors (1002): an unmasked client frame, reserved bits, an unknown opcode.
    assert_eq!(close_code_after(server.address, &[0x81, 0x02, b'h', b'i']), Some(1002));
    assert_eq!(close_code_after(server.address, &[0xf1, 0x80, 0, 0, 0, 0]), Some(1002));
    assert_eq!(close_code_after(server.address, &client_frame(0x3, b"")), Some(1002));
    // Text that is not UTF-8 (1007).
    assert_eq!(close_code_after(server.address, &client_frame(0x1, &[0xff, 0xfe, 0xfd])), Some(1007));
    // A frame announcing 1 MiB, over the 16 KiB a message may have (1009).
    let mut big = vec![0x81, 0x80 | 127];
    big.extend_from_slice(&(1u64 << 20).to_be_bytes());
    big.extend_from_slice(&[0; 4]);
    assert_eq!(close_code_after(server.address, &big), Some(1009));
    // A client's close is answered with its code (it was met by a dropped socket), and a code
    // no endpoint may send (999) is a protocol error.
    assert_eq!(close_code_after(server.address, &client_frame(0x8, &1000u16.to_be_bytes())), Some(1000));
    assert_eq!(close_code_after(server.address, &client_frame(0x8, &999u16.to_be_bytes())), Some(1002));
    // A well-formed message that is not an input stays inconsistent data (1007).
    assert_eq!(close_code_after(server.address, &client_frame(0x1, b"{not json")), Some(1007));
}
