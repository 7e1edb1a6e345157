//! The HTTP side: `GET /` serves the page, `GET /ws` the stream, `GET /scenes` the names of the
//! scenes the viewer may open; nothing else exists (404).
//! One render loop and one encoder serve every connection, so several browsers watch and
//! steer the same session.
//!
//! Connections are bounded ([`Limits`]): a client has [`Limits::header_timeout`] to send a
//! request's headers, and as long between requests on a kept-alive connection (hyper's header
//! read timeout covers both), and [`places`](crate::places) holds the number of open sockets
//! to [`Limits::max_connections`]. An open WebSocket has no timeout: a viewer may watch a
//! still image for hours, unless every place is taken and a newcomer replaces it.

use crate::access;
use crate::budget::FrameBudget;
use crate::connection::{self, MAX_MESSAGE_BYTES};
use crate::encoder::{EncodedFrame, Encoder};
use crate::places::Places;
use anyhow::Context;
use axum::Router;
use axum::extract::State;
use axum::extract::ws::WebSocketUpgrade;
use axum::http::{HeaderMap, StatusCode};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::service::TowerToHyperService;
use igi_session::{RenderLoop, Session};
use std::future::Future;
use std::io;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;
use tokio::net::TcpListener;
use tokio::sync::watch;

/// How long the server waits before accepting again after `accept` failed (out of file
/// descriptors, say), instead of spinning.
const ACCEPT_RETRY: Duration = Duration::from_millis(100);

/// What the server allows its clients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// The most one frame may cost; settings from a browser beyond it are refused.
    pub frame: FrameBudget,
    /// Connections open at once, WebSockets included.
    pub max_connections: usize,
    /// How long a client may take to send a request's headers, and may leave an HTTP
    /// connection idle between requests.
    pub header_timeout: Duration,
    /// How long a viewer may send no input before a newcomer who finds every place taken
    /// may take its place.
    pub viewer_idle: Duration,
}

impl Limits {
    /// Default of [`Limits::max_connections`]: many viewers, well below a process's usual
    /// 1024 file descriptors (or the 256 of a tight `ulimit -n`).
    pub const MAX_CONNECTIONS: usize = 64;
    /// Default of [`Limits::header_timeout`].
    pub const HEADER_TIMEOUT: Duration = Duration::from_secs(10);
    /// Default of [`Limits::viewer_idle`]: as long as a half-open request keeps its place.
    pub const VIEWER_IDLE: Duration = Self::HEADER_TIMEOUT;
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            frame: FrameBudget::DEFAULT,
            max_connections: Self::MAX_CONNECTIONS,
            header_timeout: Self::HEADER_TIMEOUT,
            viewer_idle: Self::VIEWER_IDLE,
        }
    }
}

/// The viewer page: HTML, CSS and JavaScript in one file, compiled into the binary.
const PAGE: &str = include_str!("../page/index.html");

#[derive(Clone)]
struct AppState {
    render_loop: Arc<RenderLoop>,
    frames: watch::Receiver<Option<Arc<EncodedFrame>>>,
    /// The server listens on a loopback address: it answers to loopback names only.
    loopback: bool,
    budget: FrameBudget,
    /// The names of the scenes the session may open (`GET /scenes`).
    scenes: Arc<Vec<String>>,
    places: Arc<Places>,
}

/// Serves the viewer of `render_loop` on `listener` within `limits` until `shutdown`
/// completes; the page offers to open `scenes` (the session's catalog).
pub async fn serve(
    render_loop: Arc<RenderLoop>,
    scenes: Vec<String>,
    listener: TcpListener,
    limits: Limits,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> io::Result<()> {
    let loopback = listener.local_addr()?.ip().is_loopback();
    let encoder = Encoder::spawn(render_loop.clone());
    let places = Places::new(&limits);
    let state = AppState {
        render_loop,
        frames: encoder.subscribe(),
        loopback,
        budget: limits.frame,
        scenes: Arc::new(scenes),
        places: places.clone(),
    };
    let app = Router::new()
        .route("/", get(page))
        .route("/ws", get(stream))
        .route("/scenes", get(scene_list))
        .with_state(state);
    // Open WebSockets would hold a graceful shutdown forever: stop serving at once instead.
    tokio::select! {
        () = accept(listener, app, places, limits) => Ok(()),
        () = shutdown => Ok(()),
    }
}

/// Accepts connections and serves each on its own task, HTTP/1.1 with upgrades (the
/// WebSocket), within `limits`.
async fn accept(listener: TcpListener, app: Router, places: Arc<Places>, limits: Limits) {
    let mut http = hyper::server::conn::http1::Builder::new();
    http.timer(TokioTimer::new()).header_read_timeout(limits.header_timeout);
    loop {
        let (stream, peer) = match listener.accept().await {
            Ok(accepted) => accepted,
            Err(e) => {
                tracing::warn!("cannot accept a connection: {e}");
                tokio::time::sleep(ACCEPT_RETRY).await;
                continue;
            }
        };
        let (places, app, http) = (places.clone(), app.clone(), http.clone());
        tokio::spawn(async move {
            let Some(stream) = places.take(stream).await else {
                tracing::debug!("closing a connection from {peer}: {} are open", limits.max_connections);
                return;
            };
            let connection =
                http.serve_connection(TokioIo::new(stream), TowerToHyperService::new(app)).with_upgrades();
            if let Err(e) = connection.await {
                tracing::debug!("connection from {peer}: {e}");
            }
        });
    }
}

/// The page, with headers that keep other sites from framing it and the browser from
/// loading anything but the page's own script, style and stream: its script and style are
/// inline in the one file, the frames arrive over the WebSocket and are drawn from blobs.
async fn page() -> Response {
    const POLICY: &str = "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; \
                          connect-src 'self'; img-src 'self' blob: data:; frame-ancestors 'none'; \
                          base-uri 'none'; form-action 'none'";
    (
        [
            (axum::http::header::CONTENT_SECURITY_POLICY, POLICY),
            (axum::http::header::X_FRAME_OPTIONS, "DENY"),
            (axum::http::header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
        ],
        Html(PAGE),
    )
        .into_response()
}

/// The names of the scenes the page may ask to open, as a JSON array (a page names one of
/// them, never a path).
async fn scene_list(headers: HeaderMap, State(state): State<AppState>) -> Response {
    if let Err(why) = access::check(&headers, state.loopback) {
        return (StatusCode::FORBIDDEN, why).into_response();
    }
    let json = serde_json::to_string(state.scenes.as_ref()).unwrap_or_else(|_| "[]".into());
    ([(axum::http::header::CONTENT_TYPE, "application/json")], json).into_response()
}

async fn stream(upgrade: WebSocketUpgrade, headers: HeaderMap, State(state): State<AppState>) -> Response {
    if let Err(why) = access::check(&headers, state.loopback) {
        return (StatusCode::FORBIDDEN, why).into_response();
    }
    upgrade
        .max_message_size(MAX_MESSAGE_BYTES)
        .max_frame_size(MAX_MESSAGE_BYTES)
        .on_upgrade(move |socket| {
            connection::handle(socket, state.render_loop, state.frames, state.budget, state.places.viewer())
        })
        .into_response()
}

/// Listens on `listen` and says where: the address a browser opens, and a warning if it is not
/// this machine's own. Bound before the scene loads, so a port in use is reported at once and a
/// browser opened meanwhile waits for the page instead of being refused.
pub fn bind(listen: SocketAddr) -> anyhow::Result<std::net::TcpListener> {
    let listener =
        std::net::TcpListener::bind(listen).with_context(|| format!("cannot listen on {listen}"))?;
    // Tokio takes a listener that does not block.
    listener.set_nonblocking(true).context("cannot set up the listening socket")?;
    let address = listener.local_addr()?;
    println!("igi serve: open http://{address}/ in a browser (Ctrl-C stops)");
    if !address.ip().is_loopback() {
        tracing::warn!("listening on {address}: anyone who can reach it can watch and steer this session");
    }
    Ok(listener)
}

/// Runs the browser viewer of `session` on `listener` ([`bind`]) within `limits` until SIGINT
/// (Ctrl-C) or SIGTERM. Settings over the frame budget are refused from the start.
pub fn run(session: Session, listener: std::net::TcpListener, limits: Limits) -> anyhow::Result<()> {
    limits.frame.check(session.settings()).context("the starting settings are over the frame budget")?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("cannot start the async runtime")?;
    runtime.block_on(async {
        let listener = TcpListener::from_std(listener).context("cannot serve on the listening socket")?;
        // Nothing is rendered while no browser is connected.
        let scenes = session.scene_names().to_vec();
        let render_loop = Arc::new(RenderLoop::spawn_on_demand(session));
        serve(render_loop, scenes, listener, limits, stop_signal()).await.context("the server failed")
    })
}

/// Completes on SIGINT or SIGTERM (on Unix; Ctrl-C elsewhere). Dropping the render loop then
/// cancels the frame in progress, so the process ends within a second whatever it renders.
async fn stop_signal() {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{SignalKind, signal};
        match signal(SignalKind::terminate()) {
            Ok(mut terminate) => {
                tokio::select! {
                    _ = tokio::signal::ctrl_c() => {}
                    _ = terminate.recv() => {}
                }
            }
            Err(e) => {
                tracing::warn!("cannot listen for SIGTERM: {e}");
                let _ = tokio::signal::ctrl_c().await;
            }
        }
    }
    #[cfg(not(unix))]
    let _ = tokio::signal::ctrl_c().await;
}
