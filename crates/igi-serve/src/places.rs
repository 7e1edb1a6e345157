//! The server's places for connections: at most [`Limits::max_connections`] sockets are open
//! at once, WebSockets included, so half-open requests cannot take every file descriptor of
//! the process (beyond them, at most [`MAX_NEWCOMERS`] wait a moment for a place, below). A
//! request's place frees when its socket closes (hyper's header timeout closes the idle and
//! the slow ones). A WebSocket keeps the socket it was upgraded from, and so the place, for as
//! long as the viewer watches: hours, on a still image. So that viewers that send nothing
//! cannot lock everyone out, the page included (issue 35), a newcomer who finds every place
//! taken and sends a request takes the place of the viewer that has sent no input for
//! longest, if that is at least [`Limits::viewer_idle`]; that viewer is closed with 1013 ("try
//! again later") and its page says why. A socket that sends nothing (a port scan, a browser's
//! speculative connection) replaces no one.

use crate::server::Limits;
use std::io;
use std::pin::Pin;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll};
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::TcpStream;
use tokio::sync::{Notify, OwnedSemaphorePermit, Semaphore};
use tokio::time::Instant;

/// How long a newcomer waits for the place of the viewer it replaces to free.
const REPLACE_WAIT: Duration = Duration::from_secs(2);
/// How long a newcomer who finds every place taken may take to send the first byte of its
/// request.
const REQUEST_WAIT: Duration = Duration::from_secs(2);
/// Newcomers who find every place taken that may wait at once (for their request, then for a
/// viewer's place); more are closed at once.
pub const MAX_NEWCOMERS: usize = 8;

/// The places of one server.
pub struct Places {
    free: Arc<Semaphore>,
    newcomers: Semaphore,
    viewers: Mutex<Vec<Viewer>>,
    next_viewer: AtomicU64,
    viewer_idle: Duration,
}

/// An open WebSocket, as the places see it.
struct Viewer {
    id: u64,
    last_input: Instant,
    leave: Arc<Notify>,
}

impl Places {
    /// The places `limits` allows.
    pub fn new(limits: &Limits) -> Arc<Self> {
        Arc::new(Self {
            free: Arc::new(Semaphore::new(limits.max_connections)),
            newcomers: Semaphore::new(MAX_NEWCOMERS),
            viewers: Mutex::new(Vec::new()),
            next_viewer: AtomicU64::new(0),
            viewer_idle: limits.viewer_idle,
        })
    }

    /// A place for `stream`: a free one, else, once it has sent a request, the place of the
    /// viewer idle longest (if at least [`Limits::viewer_idle`]) once that has closed. `None`
    /// if every place is taken by a request or a viewer that sent input lately, or `stream`
    /// sends nothing: the caller closes `stream`.
    pub async fn take(&self, stream: TcpStream) -> Option<Counted> {
        if let Ok(place) = self.free.clone().try_acquire_owned() {
            return Some(Counted { stream, _place: place });
        }
        let _waiting = self.newcomers.try_acquire().ok()?;
        let mut first = [0u8];
        match tokio::time::timeout(REQUEST_WAIT, stream.peek(&mut first)).await {
            Ok(Ok(n)) if n > 0 => {}
            _ => return None,
        }
        let leave = {
            let mut viewers = lock(&self.viewers);
            let now = Instant::now();
            let longest = viewers
                .iter()
                .enumerate()
                .filter(|(_, v)| now.duration_since(v.last_input) >= self.viewer_idle)
                .min_by_key(|(_, v)| v.last_input)
                .map(|(i, _)| i)?;
            // Out of the list, so that the next newcomer replaces another.
            viewers.swap_remove(longest).leave
        };
        leave.notify_one();
        let Ok(Ok(place)) = tokio::time::timeout(REPLACE_WAIT, self.free.clone().acquire_owned()).await
        else {
            tracing::warn!("a viewer was closed for a newcomer, but no place freed within {REPLACE_WAIT:?}");
            return None;
        };
        Some(Counted { stream, _place: place })
    }

    /// Registers a WebSocket upgraded on one of the places; it stays registered until the
    /// [`Tenure`] drops.
    pub fn viewer(self: &Arc<Self>) -> Tenure {
        let id = self.next_viewer.fetch_add(1, Ordering::Relaxed);
        let leave = Arc::new(Notify::new());
        lock(&self.viewers).push(Viewer { id, last_input: Instant::now(), leave: leave.clone() });
        Tenure { places: self.clone(), id, leave }
    }
}

/// A viewer's hold on its place.
pub struct Tenure {
    places: Arc<Places>,
    id: u64,
    leave: Arc<Notify>,
}

impl Tenure {
    /// The viewer sent input: it is not idle.
    pub fn input(&self) {
        if let Some(v) = lock(&self.places.viewers).iter_mut().find(|v| v.id == self.id) {
            v.last_input = Instant::now();
        }
    }

    /// Completes when a newcomer takes this viewer's place.
    pub async fn replaced(&self) {
        self.leave.notified().await;
    }
}

impl Drop for Tenure {
    fn drop(&mut self) {
        lock(&self.places.viewers).retain(|v| v.id != self.id);
    }
}

fn lock(viewers: &Mutex<Vec<Viewer>>) -> std::sync::MutexGuard<'_, Vec<Viewer>> {
    viewers.lock().unwrap_or_else(|e| e.into_inner())
}

/// A connection's socket, holding its place until it closes.
pub struct Counted {
    stream: TcpStream,
    _place: OwnedSemaphorePermit,
}

impl AsyncRead for Counted {
    fn poll_read(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &mut ReadBuf<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_read(cx, buf)
    }
}

impl AsyncWrite for Counted {
    fn poll_write(self: Pin<&mut Self>, cx: &mut Context<'_>, buf: &[u8]) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.get_mut().stream).poll_write(cx, buf)
    }

    fn poll_write_vectored(
        self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        Pin::new(&mut self.get_mut().stream).poll_write_vectored(cx, bufs)
    }

    fn is_write_vectored(&self) -> bool {
        self.stream.is_write_vectored()
    }

    fn poll_flush(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_flush(cx)
    }

    fn poll_shutdown(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.get_mut().stream).poll_shutdown(cx)
    }
}
