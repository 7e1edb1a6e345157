//! [`RenderLoop`]: a [`Session`] on its own thread. Viewers post inputs and take the newest
//! frame; the loop renders the next frame while the viewer shows the current one, and a
//! viewer that is slower than the renderer simply skips frames (newest frame wins, nothing
//! queues up).
//!
//! A frame that takes long is not waited for: once an input is waiting and the frame has run
//! [`PATIENCE`] times as long as the last finished frame took, its [`CancelToken`] stops it
//! between tiles and the next frame, with the input, starts at once. Frames of the usual
//! length finish (a user dragging the view still sees every frame), while a frame of minutes
//! that new settings started gives way to the next input within a tile. A frame cancelled
//! that way makes the next one more patient: it may run [`PATIENCE`] times as long as the
//! cancelled one ran, so under input that never stops (a drag from the moment a viewer
//! connects, before any frame has finished) the patience doubles until a frame, with the
//! newest input, finishes (issue 35). Dropping the loop cancels the frame in progress.
//!
//! Each viewer sends its inputs with its own [`Refusals`] ([`RenderLoop::refusals`]): why an
//! input was refused goes to the viewer that sent it, and why a frame failed to every viewer.
//! Inputs wait while a frame renders or a scene loads; at most [`MAX_WAITING`] of them, with
//! at most [`MAX_WAITING_NAME_BYTES`] of names, so that a client sending faster than the
//! session takes its inputs cannot grow the process: one more is refused at once. Of several
//! scenes asked for while they wait, only the last is opened, and the inputs before it that
//! the new scene would undo are passed over ([`Input::outlasts_open`]).
//!
//! A loop started with [`RenderLoop::spawn_on_demand`] renders only while someone watches
//! ([`RenderLoop::watch`]): a server with no browser connected does not spend its cores.

use crate::input::{Input, InputError};
use crate::refusals::{Mailbox, Refusals, quote_name};
use crate::session::{Frame, Session};
use igi_render::CancelToken;
use igi_render::FrameError;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, Weak};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How many times the last finished frame's duration (or, if longer, that of a frame cancelled
/// since) a frame may run while an input waits.
pub const PATIENCE: u32 = 2;

/// The most inputs that wait to be handled: at a 120 Hz pointer, more than 30 s of a scene
/// that loads.
pub const MAX_WAITING: usize = 4096;
/// The most bytes of scene and view names the waiting inputs hold (a browser may name 16 KiB
/// at a time; a person picks a name from a list).
pub const MAX_WAITING_NAME_BYTES: usize = 1 << 20;

/// How long dropping a [`RenderLoop`] waits for the render threads to finish their tiles; a
/// longer tile is left to finish on its own (or to the end of the process), so that a viewer
/// closes, or ends on a signal, within a second whatever the frame costs.
pub const STOP_WAIT: Duration = Duration::from_millis(500);

/// The newest frame, shared between the render thread and any number of viewers.
#[derive(Debug, Default)]
pub struct LatestFrame {
    frame: Mutex<Option<Arc<Frame>>>,
    fresh: Condvar,
}

impl LatestFrame {
    /// The newest frame, if any.
    pub fn get(&self) -> Option<Arc<Frame>> {
        self.frame.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// Waits up to `timeout` for a frame newer than `after` (a frame id; 0 for any).
    pub fn wait_newer(&self, after: u64, timeout: Duration) -> Option<Arc<Frame>> {
        let guard = self.frame.lock().unwrap_or_else(|e| e.into_inner());
        let (guard, _) = self
            .fresh
            .wait_timeout_while(guard, timeout, |f| f.as_ref().is_none_or(|f| f.stats.id <= after))
            .unwrap_or_else(|e| e.into_inner());
        guard.as_ref().filter(|f| f.stats.id > after).cloned()
    }

    fn publish(&self, frame: Frame) {
        *self.frame.lock().unwrap_or_else(|e| e.into_inner()) = Some(Arc::new(frame));
        self.fresh.notify_all();
    }
}

/// A session rendering on a background thread.
#[derive(Debug)]
pub struct RenderLoop {
    shared: Arc<Shared>,
    latest: Arc<LatestFrame>,
    thread: Option<JoinHandle<()>>,
}

/// What the viewers and the render thread share.
#[derive(Debug, Default)]
struct Shared {
    state: Mutex<State>,
    /// Signalled when an input or the stop request comes, and when the thread ends.
    changed: Condvar,
}

#[derive(Debug, Default)]
struct State {
    /// Inputs not yet handled, oldest first, each with where its refusal goes (nowhere once
    /// its viewer has gone).
    inputs: Vec<(Input, Weak<Mailbox>)>,
    /// Bytes of names held by `inputs`.
    name_bytes: usize,
    /// Inputs posted so far.
    sent: u64,
    /// Every viewer's messages, for a frame that failed; viewers that have gone are dropped
    /// from the list as new ones come.
    viewers: Vec<Weak<Mailbox>>,
    /// The frame being rendered, if any.
    frame: Option<FrameInFlight>,
    /// The loop waits for input with nothing to render.
    idle: bool,
    /// Viewers watching a loop that renders on demand; `None` for a loop that always renders.
    watchers: Option<usize>,
    /// The loop is asked to end.
    stop: bool,
    /// The render thread has ended (and dropped the session).
    ended: bool,
}

#[derive(Debug)]
struct FrameInFlight {
    cancel: CancelToken,
    /// Until when an input may wait for this frame.
    patience_ends: Instant,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A viewer watching a [`RenderLoop`]; the loop stops rendering when the last one is dropped.
#[derive(Debug)]
pub struct Watching {
    shared: Arc<Shared>,
}

impl Drop for Watching {
    fn drop(&mut self) {
        if let Some(n) = &mut self.shared.lock().watchers {
            *n -= 1;
        }
        self.shared.changed.notify_all();
    }
}

impl RenderLoop {
    /// Starts rendering `session` on a new thread.
    pub fn spawn(session: Session) -> Self {
        Self::start(session, None)
    }

    /// Starts `session` on a new thread that renders only while at least one [`Watching`]
    /// from [`RenderLoop::watch`] is alive. Inputs are taken all the same, so a viewer that
    /// comes sees the session as the others left it.
    pub fn spawn_on_demand(session: Session) -> Self {
        Self::start(session, Some(0))
    }

    /// Marks a viewer as watching until the returned guard is dropped.
    pub fn watch(&self) -> Watching {
        if let Some(n) = &mut self.shared.lock().watchers {
            *n += 1;
        }
        self.shared.changed.notify_all();
        Watching { shared: self.shared.clone() }
    }

    fn start(session: Session, watchers: Option<usize>) -> Self {
        let shared = Arc::new(Shared::default());
        shared.lock().watchers = watchers;
        let latest = Arc::new(LatestFrame::default());
        let thread = {
            let (shared, latest) = (shared.clone(), latest.clone());
            std::thread::Builder::new()
                .name("igi-render-loop".into())
                .spawn(move || {
                    run(session, &shared, &latest);
                    shared.lock().ended = true;
                    shared.changed.notify_all();
                })
                .expect("spawning the render thread")
        };
        Self { shared, latest, thread: Some(thread) }
    }

    /// A new viewer's messages: why its inputs were refused, and why frames failed. `wake` is
    /// called after each message that comes (from the render thread: it must not block).
    pub fn refusals(&self, wake: impl Fn() + Send + Sync + 'static) -> Refusals {
        let refusals = Refusals::new(wake);
        let mut state = self.shared.lock();
        state.viewers.retain(|v| v.strong_count() > 0);
        state.viewers.push(refusals.downgrade());
        refusals
    }

    /// Posts an input from the viewer of `from`, where its refusal goes if the session
    /// refuses it; returns its sequence number: the first frame whose
    /// [`FrameStats::input_seq`](crate::FrameStats::input_seq) is at least this number
    /// includes it. A frame in progress that has run out of patience is cancelled. With
    /// [`MAX_WAITING`] inputs or [`MAX_WAITING_NAME_BYTES`] of names waiting, the input is
    /// refused at once (said to `from`) and gets the number of the input before it.
    pub fn send(&self, input: Input, from: &Refusals) -> u64 {
        let name_bytes = match &input {
            Input::Open { name } | Input::View { name } => name.len(),
            _ => 0,
        };
        let mut state = self.shared.lock();
        if state.inputs.len() >= MAX_WAITING || state.name_bytes + name_bytes > MAX_WAITING_NAME_BYTES {
            let (waiting, sent) = (state.inputs.len(), state.sent);
            drop(state);
            from.push(&format!(
                "busy: {waiting} inputs wait for the session (a frame or a scene load); this one was dropped"
            ));
            return sent;
        }
        state.name_bytes += name_bytes;
        state.inputs.push((input, from.downgrade()));
        state.sent += 1;
        if let Some(frame) = &state.frame {
            frame.cancel.cancel_at(frame.patience_ends);
        }
        self.shared.changed.notify_all();
        state.sent
    }

    /// The newest frame and its waiting.
    pub fn latest(&self) -> &Arc<LatestFrame> {
        &self.latest
    }

    /// True while the loop waits for input with nothing to render (a still view whose
    /// accumulation is off or complete, or nobody watching a loop that renders on demand): no
    /// newer frame comes until an input or a viewer arrives.
    pub fn is_idle(&self) -> bool {
        self.shared.lock().idle
    }
}

impl Drop for RenderLoop {
    /// Cancels the frame in progress and waits up to [`STOP_WAIT`] for the thread to end.
    fn drop(&mut self) {
        let mut state = self.shared.lock();
        state.stop = true;
        if let Some(frame) = &state.frame {
            frame.cancel.cancel();
        }
        self.shared.changed.notify_all();
        let (state, _) = self
            .shared
            .changed
            .wait_timeout_while(state, STOP_WAIT, |s| !s.ended)
            .unwrap_or_else(|e| e.into_inner());
        let ended = state.ended;
        drop(state);
        match self.thread.take() {
            Some(thread) if ended => {
                let _ = thread.join();
            }
            _ => tracing::warn!("the render thread is still in a tile; it ends by itself"),
        }
    }
}

fn run(mut session: Session, shared: &Shared, latest: &LatestFrame) {
    let mut last = Instant::now();
    // How long an input waits for the frame in progress, over `PATIENCE`: the wall time of the
    // last finished frame, or of the frame cancelled after it, whichever is longer.
    let mut frame_time = Duration::ZERO;
    // A frame failed: render again only once an input comes (a failure that repeats would
    // otherwise spin).
    let mut failed = false;
    let mut state = shared.lock();
    while !state.stop {
        // Every pending input goes into the next frame; when nothing needs rendering, sleep
        // until one comes.
        let inputs = std::mem::take(&mut state.inputs);
        state.name_bytes = 0;
        if !inputs.is_empty() {
            drop(state);
            failed = false;
            // Of several scenes asked for at once only the last is opened: a load takes seconds,
            // and each earlier scene would be replaced as soon as it had loaded (twenty opens
            // from one client held every viewer's frames for twenty loads, issue 35). What the
            // inputs before it did to the scene it replaces would be undone as well, and a view
            // or light of a scene passed over would be refused by the current one.
            let last_open = inputs.iter().rposition(|(input, _)| matches!(input, Input::Open { .. }));
            for (k, (input, from)) in inputs.iter().enumerate() {
                if last_open.is_some_and(|last| k < last) && !input.outlasts_open() {
                    session.pass_over();
                    // The viewer that asked for a scene passed over is told, so that its page
                    // does not wait for it.
                    if let Input::Open { name } = input
                        && let Some(mailbox) = from.upgrade()
                    {
                        let why = format!("{}: not opened, a later request replaced it", quote_name(name));
                        mailbox.push(&InputError::Open(why).panel_message());
                    }
                    continue;
                }
                if let Err(e) = session.handle(input) {
                    // A viewer that has gone is told nothing, and nothing is kept for it.
                    if let Some(mailbox) = from.upgrade() {
                        mailbox.push(&e.panel_message());
                    }
                }
            }
            state = shared.lock();
            continue;
        }
        let needs_frame = session.needs_frame() && !failed;
        if !needs_frame || state.watchers == Some(0) {
            state.idle = true;
            state = shared
                .changed
                .wait_while(state, |s| {
                    s.inputs.is_empty() && !s.stop && !(needs_frame && s.watchers != Some(0))
                })
                .unwrap_or_else(|e| e.into_inner());
            state.idle = false;
            // Idle time is not animation time.
            last = Instant::now();
            continue;
        }
        // Set under the same lock as the (empty) input queue was seen: an input that comes
        // from now on finds the frame's token.
        let cancel = CancelToken::new();
        let start = Instant::now();
        state.frame =
            Some(FrameInFlight { cancel: cancel.clone(), patience_ends: start + frame_time * PATIENCE });
        drop(state);
        let dt = start.duration_since(last).as_secs_f32();
        last = start;
        let result = session.render_cancellable(dt, &cancel);
        state = shared.lock();
        state.frame = None;
        match result {
            Ok(frame) => {
                frame_time = start.elapsed();
                latest.publish(frame);
            }
            // The next frame may run as long as this one did, times `PATIENCE`: frames that
            // input keeps cancelling get twice the time each, until one finishes.
            Err(FrameError::Cancelled(_)) => frame_time = frame_time.max(start.elapsed()),
            Err(e) => {
                tracing::error!("a frame failed: {e}");
                let viewers: Vec<_> = state.viewers.iter().filter_map(Weak::upgrade).collect();
                drop(state);
                for mailbox in viewers {
                    mailbox.push(&e.to_string());
                }
                state = shared.lock();
                failed = true;
            }
        }
    }
}
