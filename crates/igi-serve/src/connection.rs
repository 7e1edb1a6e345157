//! One WebSocket connection: its input messages go to the shared render loop, the newest
//! encoded frame goes out whenever the previous send has completed (see the crate doc for the
//! wire format). A bad message closes this connection only.
//!
//! The connection has its own [`igi_session::Refusals`]: why the session refused one of its inputs (a
//! scene that does not open, a view or light the scene lacks) or the connection refused its
//! settings goes out with the next frame, sent at once with the newest frame again, since a
//! still view renders none. They are bounded however many come unread, and go with the
//! connection (issue 35).

use crate::budget::FrameBudget;
use crate::encoder::EncodedFrame;
use crate::places::Tenure;
use axum::extract::ws::{CloseFrame, Message, WebSocket, close_code};
use futures_util::{SinkExt, StreamExt};
use igi_session::{FrameStats, Input, RenderLoop, ViewerSettings};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use tokio::sync::{Notify, watch};

/// Longest message a client may send; input messages are a few hundred bytes.
pub const MAX_MESSAGE_BYTES: usize = 16 * 1024;
/// How long a close frame may take to go out before the socket is dropped without it.
const CLOSE_WAIT: std::time::Duration = std::time::Duration::from_secs(1);
/// Inputs of one connection waiting for the frame that includes them; a client that sends
/// faster than frames come loses the oldest acknowledgements, not memory.
const MAX_PENDING: usize = 1024;

/// A message from the page.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClientMessage {
    /// The client's number for this input, acknowledged in the first frame that includes it.
    #[serde(default)]
    pub id: Option<u64>,
    /// The input.
    pub input: Input,
}

/// The JSON part of a frame message.
#[derive(Debug, Serialize)]
pub struct FrameHeader<'a> {
    /// Statistics and settings of the frame.
    pub stats: &'a FrameStats,
    /// The highest `id` of this connection's inputs that the frame includes, if a new one.
    pub acked: Option<u64>,
    /// Why inputs this connection sent were refused (the newest
    /// [`igi_session::refusals::MAX_KEPT`] since the last frame it was sent).
    pub errors: Vec<String>,
}

/// What this connection has sent and not yet seen acknowledged: (render-loop sequence
/// number, client id) in sending order.
type Pending = VecDeque<(u64, u64)>;

/// Why a connection ends.
struct Closing {
    code: u16,
    reason: String,
}

impl Closing {
    /// Why a message could not be read, with the close code RFC 6455 (section 7.4.1) gives to
    /// it: a broken frame is a protocol error (1002), text that is not UTF-8 inconsistent data
    /// (1007), a message over [`MAX_MESSAGE_BYTES`] too big (1009). `None` if the connection
    /// is gone (reset or failed): no close frame would reach the client.
    fn unreadable(error: axum::Error) -> Option<Self> {
        use tungstenite::Error;
        use tungstenite::error::ProtocolError;
        let reason = format!("bad message: {error}");
        let code = match error.into_inner().downcast::<Error>().map(|e| *e) {
            Ok(Error::Capacity(_)) => close_code::SIZE,
            Ok(Error::Utf8(_)) => close_code::INVALID,
            Ok(Error::Protocol(ProtocolError::ResetWithoutClosingHandshake)) => return None,
            Ok(Error::Protocol(_)) => close_code::PROTOCOL,
            _ => return None,
        };
        Some(Self { code, reason })
    }
}

/// Serves one WebSocket until it closes, misbehaves or is replaced ([`Tenure`]).
pub async fn handle(
    socket: WebSocket,
    render_loop: Arc<RenderLoop>,
    mut frames: watch::Receiver<Option<Arc<EncodedFrame>>>,
    budget: FrameBudget,
    tenure: Tenure,
) {
    // The session renders while at least one viewer is connected.
    let _watching = render_loop.watch();
    let (mut sink, mut stream) = socket.split();
    let pending = Arc::new(Mutex::new(Pending::new()));
    // A refusal wakes the sender, which says it with the newest frame.
    let refusal = Arc::new(Notify::new());
    let refusals = {
        let refusal = refusal.clone();
        render_loop.refusals(move || refusal.notify_one())
    };
    // The newest frame goes out at once to a new viewer.
    frames.mark_changed();

    let receive = {
        let (pending, refusals, tenure) = (pending.clone(), &refusals, &tenure);
        async move {
            while let Some(message) = stream.next().await {
                let text = match message {
                    Ok(Message::Text(text)) => {
                        tenure.input();
                        text
                    }
                    Ok(Message::Binary(_)) => {
                        return Some(Closing {
                            code: close_code::UNSUPPORTED,
                            reason: "binary messages are not accepted".into(),
                        });
                    }
                    Ok(Message::Ping(_) | Message::Pong(_)) => continue,
                    // The WebSocket answers the client's close (RFC 6455, section 5.5.1) when it is
                    // read once more, and then ends.
                    Ok(Message::Close(_)) => continue,
                    Err(e) => return Closing::unreadable(e),
                };
                let message: ClientMessage = match serde_json::from_str(&text) {
                    Ok(m) => m,
                    Err(e) => {
                        return Some(Closing {
                            code: close_code::INVALID,
                            reason: format!("malformed input: {e}"),
                        });
                    }
                };
                if let Input::Settings { settings } = &message.input {
                    // Refused here, so the error reaches the connection that sent them.
                    let refused = match settings.validate() {
                        Err(e) => Some(ViewerSettings::panel_message(&e)),
                        Ok(()) => budget.check(settings).err().map(|e| e.to_string()),
                    };
                    if let Some(why) = refused {
                        refusals.push(&why);
                        continue;
                    }
                }
                let seq = render_loop.send(message.input, refusals);
                if let Some(id) = message.id {
                    let mut p = lock(&pending);
                    if p.len() == MAX_PENDING {
                        p.pop_front();
                    }
                    p.push_back((seq, id));
                }
            }
            // The client closed (its close answered) or went away: nothing more to say.
            None
        }
    };

    let send = async {
        loop {
            tokio::select! {
                changed = frames.changed() => if changed.is_err() { return },
                () = refusal.notified() => {}
            }
            let Some(frame) = frames.borrow_and_update().clone() else { continue };
            let acked = {
                let mut p = lock(&pending);
                let mut acked = None;
                while p.front().is_some_and(|&(seq, _)| seq <= frame.stats.input_seq) {
                    acked = p.pop_front().map(|(_, id)| id);
                }
                acked
            };
            let errors = refusals.take();
            let header = FrameHeader { stats: &frame.stats, acked, errors };
            let Ok(json) = serde_json::to_vec(&header) else { return };
            let mut bytes = Vec::with_capacity(5 + json.len() + frame.bytes.len());
            bytes.push(frame.kind as u8);
            bytes.extend_from_slice(&u32::try_from(json.len()).unwrap_or(u32::MAX).to_le_bytes());
            bytes.extend_from_slice(&json);
            bytes.extend_from_slice(&frame.bytes);
            if sink.send(Message::Binary(bytes.into())).await.is_err() {
                return;
            }
        }
    };

    let closing = tokio::select! {
        closing = receive => closing,
        () = send => None,
        () = tenure.replaced() => Some(Closing {
            code: close_code::AGAIN,
            reason: "every place is taken: a newcomer replaced this viewer, the longest idle".into(),
        }),
    };
    if let Some(Closing { code, reason }) = closing {
        tracing::info!("closing a viewer connection: {reason}");
        // The reason of a close frame is limited to 123 bytes.
        let reason: String = reason.chars().take(100).collect();
        // A client that reads nothing would hold the place while the close frame waits.
        let close = sink.send(Message::Close(Some(CloseFrame { code, reason: reason.into() })));
        let _ = tokio::time::timeout(CLOSE_WAIT, close).await;
    }
}

fn lock(pending: &Mutex<Pending>) -> std::sync::MutexGuard<'_, Pending> {
    pending.lock().unwrap_or_else(|e| e.into_inner())
}
