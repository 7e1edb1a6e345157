//! [`StopSignals`]: SIGINT (Ctrl-C) and SIGTERM close the window as its close button does, so
//! the viewer ends the same way: the render loop cancels its frame in progress between tiles
//! (or gives up on it after [`igi_session::render_loop::STOP_WAIT`]) and the session ends (a
//! cluster session stops its nodes), within a second even in the middle of a long frame. The
//! default action of either signal would kill the process at once, leaving a cluster's nodes
//! waiting.

use eframe::egui;
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::{Handle, Signals};

/// SIGINT and SIGTERM, caught from creation on, and delivered to a window once it exists.
pub struct StopSignals {
    signals: Signals,
}

impl StopSignals {
    /// Catches SIGINT and SIGTERM from now on (one that comes before the window exists closes
    /// it as soon as it does).
    pub fn catch() -> std::io::Result<Self> {
        Ok(Self { signals: Signals::new([SIGINT, SIGTERM])? })
    }

    /// The handle that stops the delivery ([`Handle::close`]) once the window is gone.
    pub fn handle(&self) -> Handle {
        self.signals.handle()
    }

    /// Asks `ctx`'s window to close at each signal, on a thread of its own.
    pub fn close_window(mut self, ctx: egui::Context) -> std::io::Result<()> {
        std::thread::Builder::new().name("igi-view-signals".into()).spawn(move || {
            for _ in self.signals.forever() {
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                ctx.request_repaint();
            }
        })?;
        Ok(())
    }
}
