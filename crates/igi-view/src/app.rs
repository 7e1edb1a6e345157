//! [`ViewerApp`]: the eframe application. The UI thread never renders: a small waker thread
//! waits for the render loop's next frame and asks egui to repaint, and a repaint uploads the
//! newest frame into one texture. So the window shows every frame it can and the renderer
//! never waits for the display. The frame fills the area beside the panel; when that area or
//! the resolution changes and stays so for `RESIZE_SETTLE` (120 ms), the session is asked for frames
//! of the new size.

use crate::ViewOptions;
use crate::panel::Panel;
use eframe::egui::{self, ColorImage, Key, PointerButton, Sense, TextureHandle, TextureOptions};
use igi_session::{Button, Frame, Input, Refusals, RenderLoop};
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Wheel points per scroll notch (egui reports a notch of a line as 50 points).
const POINTS_PER_NOTCH: f32 = 50.0;

/// How long a new image-area size must hold before the session renders at it: dragging a
/// window's edge passes through many sizes, and each new size restarts the frame.
const RESIZE_SETTLE: Duration = Duration::from_millis(120);

/// The window.
pub struct ViewerApp {
    render_loop: Arc<RenderLoop>,
    /// Why the session refused this window's inputs; a message asks for a repaint, which
    /// shows it.
    refusals: Refusals,
    options: ViewOptions,
    texture: Option<TextureHandle>,
    shown: Option<Arc<Frame>>,
    frames_shown: u32,
    /// When the first frame was shown (for the summary of `--exit-after-frames` runs).
    first_shown: Option<std::time::Instant>,
    screenshot_requested: bool,
    /// The window was asked to close.
    closing: bool,
    panel: Panel,
    waker_stop: Arc<AtomicBool>,
    /// The render size asked for last, and the size waiting to settle with when it was seen.
    asked: Option<[u32; 2]>,
    settling: Option<([u32; 2], Instant)>,
    /// The key and mouse help is open (H or ?).
    help: bool,
}

impl ViewerApp {
    /// Sets up the window's state and starts the thread that wakes it for new frames; the
    /// panel offers to open `scenes` (names of the session's catalog).
    pub fn new(
        cc: &eframe::CreationContext<'_>,
        render_loop: Arc<RenderLoop>,
        options: ViewOptions,
        scenes: Vec<String>,
    ) -> Self {
        // Physical pixels = points: the image shows 1:1 and screenshots are comparable.
        cc.egui_ctx.set_pixels_per_point(1.0);
        let waker_stop = Arc::new(AtomicBool::new(false));
        {
            let (ctx, render_loop, stop) = (cc.egui_ctx.clone(), render_loop.clone(), waker_stop.clone());
            std::thread::Builder::new()
                .name("igi-view-waker".into())
                .spawn(move || {
                    let mut last = 0;
                    while !stop.load(Ordering::SeqCst) {
                        if let Some(frame) = render_loop.latest().wait_newer(last, Duration::from_millis(100))
                        {
                            last = frame.stats.id;
                            ctx.request_repaint();
                        }
                    }
                })
                .expect("spawning the waker thread");
        }
        let refusals = {
            let ctx = cc.egui_ctx.clone();
            render_loop.refusals(move || ctx.request_repaint())
        };
        Self {
            render_loop,
            refusals,
            texture: None,
            shown: None,
            frames_shown: 0,
            first_shown: None,
            screenshot_requested: false,
            closing: false,
            panel: Panel::new(options.resolution, scenes),
            options,
            waker_stop,
            asked: None,
            settling: None,
            help: false,
        }
    }

    /// Asks the session for frames of the size the image area and the resolution call for,
    /// once that size has held for [`RESIZE_SETTLE`].
    fn follow_area(&mut self, ctx: &egui::Context, area: egui::Vec2) {
        let Some(frame) = &self.shown else { return };
        let wanted = self.panel.resolution.render_size([area.x, area.y]);
        let current = [frame.stats.settings.frame.width, frame.stats.settings.frame.height];
        if self.asked.unwrap_or(current) == wanted {
            self.settling = None;
            return;
        }
        match self.settling {
            Some((size, since)) if size == wanted && since.elapsed() >= RESIZE_SETTLE => {
                let mut settings = frame.stats.settings.clone();
                [settings.frame.width, settings.frame.height] = wanted;
                self.render_loop.send(Input::Settings { settings }, &self.refusals);
                self.asked = Some(wanted);
                self.settling = None;
            }
            Some((size, _)) if size == wanted => ctx.request_repaint_after(RESIZE_SETTLE),
            _ => {
                self.settling = Some((wanted, Instant::now()));
                ctx.request_repaint_after(RESIZE_SETTLE);
            }
        }
    }

    /// Uploads the newest frame if it is new.
    fn take_newest_frame(&mut self, ctx: &egui::Context) {
        let Some(frame) = self.render_loop.latest().get() else { return };
        if self.shown.as_ref().is_some_and(|s| s.stats.id == frame.stats.id) {
            return;
        }
        let size = [frame.stats.width as usize, frame.stats.height as usize];
        let image = ColorImage::from_rgb(size, frame.image.srgb8());
        // Scaled up (a resolution below full), the image is interpolated; at full resolution
        // one texel is one window pixel either way.
        match &mut self.texture {
            Some(texture) => texture.set(image, TextureOptions::LINEAR),
            None => self.texture = Some(ctx.load_texture("frame", image, TextureOptions::LINEAR)),
        }
        self.frames_shown += 1;
        self.first_shown.get_or_insert_with(std::time::Instant::now);
        let scene = |f: &Frame| f.stats.scene.clone();
        if let Some(name) = scene(&frame).filter(|_| self.shown.as_deref().map(scene) != Some(scene(&frame)))
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(format!("igi: {name}")));
        }
        self.panel.frame_shown(&frame.stats);
        self.shown = Some(frame);
    }

    /// Mouse and wheel over the image, keys anywhere outside text fields.
    fn handle_input(&self, ctx: &egui::Context, response: &egui::Response) {
        let send = |input| {
            self.render_loop.send(input, &self.refusals);
        };
        for (button, which) in
            [(PointerButton::Primary, Button::Primary), (PointerButton::Secondary, Button::Secondary)]
        {
            if let (true, Some(frame)) = (response.dragged_by(button), &self.shown) {
                // Window points to image pixels, as for a pick.
                let delta = response.drag_delta() * frame.stats.width as f32 / response.rect.width();
                if delta != egui::Vec2::ZERO {
                    send(Input::Drag { dx: delta.x, dy: delta.y, button: which });
                }
            }
        }
        if response.clicked() {
            if let (Some(pos), Some(frame)) = (response.interact_pointer_pos(), &self.shown) {
                // Window pixels to image pixels: the image is scaled to the rectangle.
                let p = pos - response.rect.min;
                let x = p.x * frame.stats.width as f32 / response.rect.width();
                let y = p.y * frame.stats.height as f32 / response.rect.height();
                send(Input::Pick { x, y });
            }
        }
        if response.hovered() {
            let scroll = ctx.input(|i| i.raw_scroll_delta.y);
            if scroll != 0.0 {
                send(Input::Scroll { delta: scroll / POINTS_PER_NOTCH });
            }
        }
        if !ctx.wants_keyboard_input() {
            let keys: Vec<(igi_session::Key, bool)> = ctx.input(|i| {
                i.events
                    .iter()
                    .filter_map(|e| match e {
                        egui::Event::Key { key, pressed, repeat: false, .. } => {
                            Some((fly_key(*key)?, *pressed))
                        }
                        _ => None,
                    })
                    .collect()
            });
            for (key, down) in keys {
                send(Input::Key { key, down });
            }
        }
    }

    /// F12: the displayed image as PNG and its linear radiance as EXR.
    fn snapshot(&mut self) {
        let Some(frame) = &self.shown else { return };
        let stamp =
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default().as_secs();
        // In the current folder, said with its full path.
        let folder = std::env::current_dir().unwrap_or_default();
        let base = folder.join(format!("igi-{stamp}"));
        let png = base.with_extension("png");
        let exr = base.with_extension("exr");
        let result =
            save_png(&png, frame.image.srgb8(), frame.stats.width, frame.stats.height).and_then(|()| {
                frame
                    .image
                    .film()
                    .map(|film| igi_render::write_exr(film, &exr).map_err(|e| e.to_string()))
                    .transpose()
            });
        self.panel.message = match result {
            Ok(Some(())) => format!("saved {} and {}", png.display(), exr.display()),
            // A cluster sends 8-bit pixels while the view moves; linear ones once it is still.
            Ok(None) => format!("saved {} (no EXR: this frame came as 8-bit pixels)", png.display()),
            Err(e) => format!("cannot save the snapshot: {e}"),
        };
    }

    /// One line for runs that exit by themselves: the frames the window showed per second
    /// against the renderer's own rate (the display must not slow the renderer).
    fn print_summary(&self) {
        let (Some(first), Some(frame)) = (self.first_shown, &self.shown) else { return };
        let seconds = first.elapsed().as_secs_f64();
        let shown = f64::from(self.frames_shown.saturating_sub(1));
        println!(
            "window: {} frames shown, {:.2} frames per second after the first; renderer {:.2} fps",
            self.frames_shown,
            shown / seconds.max(1e-9),
            frame.stats.fps
        );
    }

    /// True once `--exit-after-frames` frames were shown, or fewer if the renderer has
    /// nothing more to render (a still view without accumulation renders one frame).
    fn enough_frames(&self, ctx: &egui::Context) -> bool {
        // A frame of the image area's size is on its way.
        let shown = self.shown.as_ref().map(|f| [f.stats.width, f.stats.height]);
        if self.settling.is_some() || self.asked.is_some_and(|size| Some(size) != shown) {
            ctx.request_repaint_after(Duration::from_millis(50));
            return false;
        }
        let wanted = self.options.exit_after_frames.unwrap_or(1);
        if self.frames_shown >= wanted {
            return true;
        }
        let newest = self.render_loop.latest().get().map(|f| f.stats.id);
        let caught_up = newest.is_some() && newest == self.shown.as_ref().map(|f| f.stats.id);
        if caught_up && self.render_loop.is_idle() {
            return true;
        }
        // An idle renderer wakes nobody: look again shortly.
        ctx.request_repaint_after(Duration::from_millis(50));
        false
    }

    /// In `--screenshot` mode: asks for the window's framebuffer after enough frames and
    /// writes it when it comes.
    fn screenshot(&mut self, ctx: &egui::Context, image_rect: egui::Rect) {
        let Some(path) = self.options.screenshot.clone() else { return };
        if !self.screenshot_requested && self.enough_frames(ctx) {
            self.screenshot_requested = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(Default::default()));
        }
        let shot = ctx.input(|i| {
            i.events.iter().find_map(|e| match e {
                egui::Event::Screenshot { image, .. } => Some(image.clone()),
                _ => None,
            })
        });
        let Some(shot) = shot else {
            if self.screenshot_requested {
                ctx.request_repaint();
            }
            return;
        };
        let rgb: Vec<u8> = shot.pixels.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect();
        let frame = self.shown.as_ref().map_or([0, 0], |f| [f.stats.width, f.stats.height]);
        match save_png(&path, &rgb, shot.size[0] as u32, shot.size[1] as u32) {
            Ok(()) => println!(
                "image at {},{} size {}x{} from a {}x{} frame in window screenshot {}x{} -> {}",
                image_rect.min.x.round() as i32,
                image_rect.min.y.round() as i32,
                image_rect.width().round() as i32,
                image_rect.height().round() as i32,
                frame[0],
                frame[1],
                shot.size[0],
                shot.size[1],
                path.display()
            ),
            Err(e) => eprintln!("error: cannot write the screenshot {}: {e}", path.display()),
        }
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

impl eframe::App for ViewerApp {
    fn update(&mut self, ctx: &egui::Context, _frame: &mut eframe::Frame) {
        self.take_newest_frame(ctx);
        if ctx.input(|i| i.key_pressed(Key::F12)) {
            self.snapshot();
        }
        if !ctx.wants_keyboard_input()
            && ctx.input(|i| i.key_pressed(Key::H) || i.key_pressed(Key::Questionmark))
        {
            self.help = !self.help;
        }
        egui::Window::new("Keys and mouse (H or ? closes)").open(&mut self.help).collapsible(false).show(
            ctx,
            |ui| {
                egui::Grid::new("help").num_columns(2).striped(true).show(ui, |ui| {
                    for (what, how) in HELP {
                        ui.strong(*what);
                        ui.label(*how);
                        ui.end_row();
                    }
                });
            },
        );
        for error in self.refusals.take() {
            self.panel.refused(error);
        }
        if let Some(input) = self.panel.show(ctx, self.shown.as_deref()) {
            // A refused value's message goes with the next edit (and comes back if the value
            // is still wrong).
            if matches!(input, Input::Settings { .. }) {
                self.panel.message.clear();
            }
            self.render_loop.send(input, &self.refusals);
        }
        let mut image_rect = egui::Rect::NOTHING;
        let mut area = egui::Vec2::ZERO;
        egui::CentralPanel::default().frame(egui::Frame::NONE).show(ctx, |ui| {
            area = ui.available_size();
            if let Some(texture) = &self.texture {
                // The frame scaled to fill the area, keeping its aspect (it has the area's
                // once a frame of the new size comes).
                let size = texture.size_vec2();
                let fit = size * (area.x / size.x).min(area.y / size.y);
                let image = egui::Image::new(texture).fit_to_exact_size(fit.floor());
                let response = ui.add(image.sense(Sense::click_and_drag()));
                image_rect = response.rect;
                // The camera mode, always in sight.
                if let Some(frame) = &self.shown {
                    if let Some(selected) = &frame.stats.selected {
                        draw_outline(&ui.painter_at(image_rect), image_rect, frame.stats.width, selected);
                    }
                    let hint = match frame.stats.mode {
                        igi_session::CameraMode::Fly => "fly: WASD/QE move, drag looks, wheel speed · H help",
                        igi_session::CameraMode::Orbit => "orbit: drag turns, wheel zooms · H help",
                    };
                    let at = image_rect.left_top() + egui::vec2(8.0, 8.0);
                    let galley = ui.painter().layout_no_wrap(
                        hint.into(),
                        egui::FontId::proportional(13.0),
                        egui::Color32::WHITE,
                    );
                    let back = egui::Rect::from_min_size(at, galley.size()).expand(4.0);
                    ui.painter().rect_filled(back, 4.0, egui::Color32::from_black_alpha(140));
                    ui.painter().galley(at, galley, egui::Color32::WHITE);
                }
                self.handle_input(ctx, &response);
            }
        });
        self.follow_area(ctx, area);
        self.screenshot(ctx, image_rect);
        if self.options.screenshot.is_none()
            && self.options.exit_after_frames.is_some()
            && !self.closing
            && self.enough_frames(ctx)
        {
            self.closing = true;
            self.print_summary();
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        self.waker_stop.store(true, Ordering::SeqCst);
    }
}

/// The selected object's bounding box over the image in `rect` (of a frame `width` pixels
/// wide), in Blender's selection orange.
fn draw_outline(painter: &egui::Painter, rect: egui::Rect, width: u32, selected: &igi_session::Selection) {
    let scale = rect.width() / width.max(1) as f32;
    let stroke = egui::Stroke::new(1.5, egui::Color32::from_rgb(255, 160, 48));
    for &[x0, y0, x1, y1] in &selected.outline {
        let at = |x: f32, y: f32| rect.min + egui::vec2(x, y) * scale;
        painter.line_segment([at(x0, y0), at(x1, y1)], stroke);
    }
}

/// The help window's lines: what, and how.
const HELP: &[(&str, &str)] = &[
    ("fly mode", "W A S D move, Q E down and up, drag looks around, the wheel sets the speed"),
    ("orbit mode", "drag turns around the point in front of the camera, the wheel moves closer or away"),
    ("click", "selects the object under the pointer (its name shows in the statistics)"),
    (
        "right-drag",
        "moves the selected object in the view plane, or the light chosen in the panel's Lights (a sun turns)",
    ),
    ("F12", "saves the image as PNG and EXR in the current folder"),
    ("H or ?", "this help"),
];

/// The fly-camera key of a keyboard key.
fn fly_key(key: Key) -> Option<igi_session::Key> {
    use igi_session::Key as K;
    Some(match key {
        Key::W => K::W,
        Key::A => K::A,
        Key::S => K::S,
        Key::D => K::D,
        Key::Q => K::Q,
        Key::E => K::E,
        _ => return None,
    })
}

fn save_png(path: &Path, rgb: &[u8], width: u32, height: u32) -> Result<(), String> {
    igi_render::image::output::write_png_rgb8(rgb, width, height, path).map_err(|e| e.to_string())
}
