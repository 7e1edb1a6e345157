//! `igi view`: a native window on an [`igi_session::Session`], with eframe/egui on OpenGL
//! (glow). The session renders on its own thread ([`igi_session::RenderLoop`]); the window
//! shows the newest frame over the area beside the panel, rendered at that area's size times
//! the [`resolution::Resolution`], turns mouse and keys into
//! [`igi_session::Input`]s, and has a side panel with the settings, the statistics and a
//! frame-time plot.
//!
//! - [`app`]: the eframe application (image, input, screenshots, F12 snapshots).
//! - [`panel`]: the side panel (settings widgets, and the statistics and plot in sight
//!   under them).
//! - [`statistics`]: the frames' figures and the frame-time plot.
//! - [`resolution`]: the render size for the image area.
//! - `signals` (Unix): SIGINT and SIGTERM close the window.

pub mod app;
pub mod panel;
pub mod resolution;
#[cfg(unix)]
pub mod signals;
pub mod statistics;

use anyhow::{Context, Result, bail};
use igi_session::{RenderLoop, Session};
use std::path::PathBuf;
use std::sync::Arc;

/// The default inner size of the window: the whole panel shows, and the image area beside it
/// is 920x760.
pub const DEFAULT_WINDOW: [u32; 2] = [1200, 760];

/// How `igi view` runs.
#[derive(Clone, Debug, Default)]
pub struct ViewOptions {
    /// After [`ViewOptions::exit_after_frames`] frames, write a screenshot of the whole window
    /// (PNG) here before closing.
    pub screenshot: Option<PathBuf>,
    /// Close the window after this many frames were shown.
    pub exit_after_frames: Option<u32>,
    /// The window title.
    pub title: String,
    /// The window's inner size in pixels; `None`: the default, [`DEFAULT_WINDOW`] or larger to
    /// hold the session's starting image beside the panel.
    pub window_size: Option<[u32; 2]>,
    /// The render size for the image area, until changed in the panel.
    pub resolution: resolution::Resolution,
}

/// Opens the window on `session` and runs until it is closed (or SIGINT or SIGTERM closes it).
pub fn run(session: Session, options: ViewOptions) -> Result<()> {
    if let Some(path) = &options.screenshot {
        igi_render::image::output::check_writable(path).context("--screenshot")?;
    }
    if cfg!(target_os = "linux")
        && std::env::var_os("DISPLAY").is_none()
        && std::env::var_os("WAYLAND_DISPLAY").is_none()
    {
        bail!(
            "igi view needs a display (DISPLAY or WAYLAND_DISPLAY is not set); run it under \
             `xvfb-run`, or use `igi serve` for a viewer in the browser"
        );
    }
    let settings = session.settings();
    let size = options.window_size.unwrap_or([
        (settings.frame.width + panel::WIDTH as u32).max(DEFAULT_WINDOW[0]),
        settings.frame.height.max(DEFAULT_WINDOW[1]),
    ]);
    let size = size.map(|s| s as f32);
    let scenes = session.scene_names().to_vec();
    let render_loop = Arc::new(RenderLoop::spawn(session));
    let native = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default().with_inner_size(size).with_title(&options.title),
        renderer: eframe::Renderer::Glow,
        ..Default::default()
    };
    let title = options.title.clone();
    let app_loop = render_loop.clone();
    #[cfg(unix)]
    let signals = signals::StopSignals::catch().context("cannot catch SIGINT and SIGTERM")?;
    #[cfg(unix)]
    let signal_handle = signals.handle();
    let result = eframe::run_native(
        &title,
        native,
        Box::new(move |cc| {
            #[cfg(unix)]
            signals.close_window(cc.egui_ctx.clone())?;
            Ok(Box::new(app::ViewerApp::new(cc, app_loop, options, scenes)))
        }),
    )
    .map_err(|e| anyhow::anyhow!("cannot open the window: {e} (is there a display with OpenGL?)"));
    #[cfg(unix)]
    signal_handle.close();
    end_session(render_loop);
    result
}

/// Stops the render loop and drops the session once the window and its waker thread have let
/// go of it (the waker looks ten times a second), so whatever the session holds ends cleanly:
/// a cluster session tells its nodes to stop and finalises MPI.
fn end_session(mut render_loop: Arc<RenderLoop>) {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(2);
    loop {
        match Arc::try_unwrap(render_loop) {
            Ok(only) => return drop(only),
            Err(_) if std::time::Instant::now() > deadline => return,
            Err(shared) => {
                render_loop = shared;
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
        }
    }
}
