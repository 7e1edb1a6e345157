//! The HTTP side: `GET /` serves the page, `GET /ws` the stream; nothing else exists (404).
//! One render loop and one encoder serve every connection, so several browsers watch and
//! steer the same session.

use crate::access;
use crate::connection::{self, MAX_MESSAGE_BYTES};
use crate::encoder::{EncodedFrame, Encoder};
use anyhow::Context;
use axum::Router;
use axum::extract::State;
use axum::extract::ws::WebSocketUpgrade;
use axum::http::{HeaderMap, StatusCode};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;
use igi_session::{RenderLoop, Session};
use std::future::Future;
use std::net::SocketAddr;
use std::sync::Arc;
use tokio::net::TcpListener;
use tokio::sync::watch;

/// The viewer page: HTML, CSS and JavaScript in one file, compiled into the binary.
const PAGE: &str = include_str!("../page/index.html");

#[derive(Clone)]
struct AppState {
    render_loop: Arc<RenderLoop>,
    frames: watch::Receiver<Option<Arc<EncodedFrame>>>,
    /// The server listens on a loopback address: it answers to loopback names only.
    loopback: bool,
}

/// Serves the viewer of `render_loop` on `listener` until `shutdown` completes.
pub async fn serve(
    render_loop: Arc<RenderLoop>,
    listener: TcpListener,
    shutdown: impl Future<Output = ()> + Send + 'static,
) -> std::io::Result<()> {
    let loopback = listener.local_addr()?.ip().is_loopback();
    let encoder = Encoder::spawn(render_loop.clone());
    let state = AppState { render_loop, frames: encoder.subscribe(), loopback };
    let app = Router::new().route("/", get(page)).route("/ws", get(stream)).with_state(state);
    // Open WebSockets would hold a graceful shutdown forever: stop serving at once instead.
    tokio::select! {
        result = axum::serve(listener, app) => result,
        () = shutdown => Ok(()),
    }
}

async fn page() -> Html<&'static str> {
    Html(PAGE)
}

async fn stream(upgrade: WebSocketUpgrade, headers: HeaderMap, State(state): State<AppState>) -> Response {
    if let Err(why) = access::check(&headers, state.loopback) {
        return (StatusCode::FORBIDDEN, why).into_response();
    }
    upgrade
        .max_message_size(MAX_MESSAGE_BYTES)
        .max_frame_size(MAX_MESSAGE_BYTES)
        .on_upgrade(move |socket| connection::handle(socket, state.render_loop, state.frames))
        .into_response()
}

/// Runs the browser viewer of `session` on `listen` until Ctrl-C.
pub fn run(session: Session, listen: SocketAddr) -> anyhow::Result<()> {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("cannot start the async runtime")?;
    runtime.block_on(async {
        let listener =
            TcpListener::bind(listen).await.with_context(|| format!("cannot listen on {listen}"))?;
        let address = listener.local_addr()?;
        println!("igi serve: open http://{address}/ in a browser (Ctrl-C stops)");
        if !address.ip().is_loopback() {
            tracing::warn!(
                "listening on {address}: anyone who can reach it can watch and steer this session"
            );
        }
        let render_loop = Arc::new(RenderLoop::spawn(session));
        serve(render_loop, listener, async {
            let _ = tokio::signal::ctrl_c().await;
        })
        .await
        .context("the server failed")
    })
}
