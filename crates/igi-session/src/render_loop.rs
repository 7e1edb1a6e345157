//! [`RenderLoop`]: a [`Session`] on its own thread. Viewers post inputs and take the newest
//! frame; the loop renders the next frame while the viewer shows the current one, and a
//! viewer that is slower than the renderer simply skips frames (newest frame wins, nothing
//! queues up).

use crate::input::Input;
use crate::session::{Frame, Session};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, TryRecvError};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

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
    inputs: Sender<Input>,
    sent: AtomicU64,
    latest: Arc<LatestFrame>,
    errors: Arc<Mutex<Vec<String>>>,
    stop: Arc<AtomicBool>,
    idle: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl RenderLoop {
    /// Starts rendering `session` on a new thread.
    pub fn spawn(session: Session) -> Self {
        let (inputs, receiver) = std::sync::mpsc::channel();
        let latest = Arc::new(LatestFrame::default());
        let errors = Arc::new(Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let idle = Arc::new(AtomicBool::new(false));
        let thread = {
            let (latest, errors, stop, idle) = (latest.clone(), errors.clone(), stop.clone(), idle.clone());
            std::thread::Builder::new()
                .name("igi-render-loop".into())
                .spawn(move || run(session, &receiver, &latest, &errors, &stop, &idle))
                .expect("spawning the render thread")
        };
        Self { inputs, sent: AtomicU64::new(0), latest, errors, stop, idle, thread: Some(thread) }
    }

    /// Posts an input; returns its sequence number: the first frame whose
    /// [`FrameStats::input_seq`](crate::FrameStats::input_seq) is at least this number
    /// includes it.
    pub fn send(&self, input: Input) -> u64 {
        let seq = self.sent.fetch_add(1, Ordering::SeqCst) + 1;
        // The thread only ends when the loop is dropped, so a send cannot fail before that.
        let _ = self.inputs.send(input);
        seq
    }

    /// The newest frame and its waiting.
    pub fn latest(&self) -> &Arc<LatestFrame> {
        &self.latest
    }

    /// True while the loop waits for input with nothing to render (a still view whose
    /// accumulation is off or complete): no newer frame comes until an input arrives.
    pub fn is_idle(&self) -> bool {
        self.idle.load(Ordering::SeqCst)
    }

    /// Messages of refused inputs (invalid settings) since the last call.
    pub fn take_errors(&self) -> Vec<String> {
        std::mem::take(&mut *self.errors.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

impl Drop for RenderLoop {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        // Wake a thread waiting for input.
        let (dummy, _) = std::sync::mpsc::channel();
        drop(std::mem::replace(&mut self.inputs, dummy));
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn run(
    mut session: Session,
    inputs: &Receiver<Input>,
    latest: &LatestFrame,
    errors: &Mutex<Vec<String>>,
    stop: &AtomicBool,
    idle: &AtomicBool,
) {
    let mut last = Instant::now();
    while !stop.load(Ordering::SeqCst) {
        // Take every pending input; when nothing needs rendering, sleep until one comes.
        loop {
            let input = if session.needs_frame() {
                match inputs.try_recv() {
                    Ok(input) => input,
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => return,
                }
            } else {
                idle.store(true, Ordering::SeqCst);
                let received = inputs.recv();
                idle.store(false, Ordering::SeqCst);
                match received {
                    Ok(input) => {
                        // Idle time is not animation time.
                        last = Instant::now();
                        input
                    }
                    Err(_) => return,
                }
            };
            if let Err(e) = session.handle(&input) {
                errors.lock().unwrap_or_else(|e| e.into_inner()).push(e.to_string());
            }
        }
        if stop.load(Ordering::SeqCst) {
            return;
        }
        let now = Instant::now();
        let dt = now.duration_since(last).as_secs_f32();
        last = now;
        match session.render(dt) {
            Ok(frame) => latest.publish(frame),
            Err(e) => errors.lock().unwrap_or_else(|e| e.into_inner()).push(e.to_string()),
        }
    }
}
