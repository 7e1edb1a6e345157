//! [`Panel`]: the window's side panel: the scene, the camera and the settings of the session
//! (edited on a copy; a change goes out as one [`Input::Settings`]), and under them a line for
//! the user, the frame's figures and a plot of the last frame times ([`Statistics`]).
//!
//! The plot keeps the panel's bottom edge, and the figures the room above it (at most half
//! the panel, scrolling beyond); the scene and the settings scroll in what is left. So the
//! plot, the figures and a refusal stay in sight at any window height (issue 34: in one
//! scrolled list, at the window's default 1200x760, the plot lay below the list's visible end).

use crate::resolution::Resolution;
use crate::statistics::Statistics;
use eframe::egui::{self, DragValue, Ui};
use igi_render::frame::limits::MAX_BOUNCES;
use igi_render::image::tonemap::ToneCurve;
use igi_session::{CameraMode, Frame, FrameStats, Input, LightKind};

/// Width of the panel, points.
pub const WIDTH: f32 = 280.0;

/// The panel's state.
#[derive(Debug, Default)]
pub struct Panel {
    /// A line for the user (a saved snapshot, a refused setting).
    pub message: String,
    /// The render size for the image area (the window's, not the session's).
    pub resolution: Resolution,
    statistics: Statistics,
    /// The scenes the session may open instead.
    scenes: Vec<String>,
    /// The scene asked for and not shown yet.
    opening: Option<String>,
}

/// A section of the panel that folds, open at first or not.
fn section(title: &str, open: bool) -> egui::CollapsingHeader {
    egui::CollapsingHeader::new(title).default_open(open)
}

/// A labelled number field.
fn row(ui: &mut Ui, label: &str, widget: DragValue) {
    ui.horizontal(|ui| {
        ui.label(label);
        ui.add(widget);
    });
}

impl Panel {
    /// A panel starting at `resolution`, offering to open `scenes`.
    pub fn new(resolution: Resolution, scenes: Vec<String>) -> Self {
        Self { resolution, scenes, ..Self::default() }
    }

    /// Records a newly shown frame (for the plot and the window's frame rate).
    pub fn frame_shown(&mut self, stats: &FrameStats) {
        self.statistics.frame_shown(stats);
        if self.opening.is_some() && self.opening == stats.scene {
            self.opening = None;
            self.message.clear();
        }
    }

    /// Says why the session refused an input (a scene being opened is not any more).
    pub fn refused(&mut self, error: String) {
        self.message = error;
        self.opening = None;
    }

    /// Draws the panel at the right edge of the window for the shown frame; returns the input
    /// a widget produced.
    pub fn show(&mut self, ctx: &egui::Context, frame: Option<&Frame>) -> Option<Input> {
        egui::SidePanel::right("panel")
            .exact_width(WIDTH)
            .resizable(false)
            .show(ctx, |ui| {
                let Some(frame) = frame else {
                    ui.label("rendering the first frame…");
                    return None;
                };
                let stats = &frame.stats;
                // Bottom up: the plot, then the figures, then the settings in what is left.
                let flat = egui::Frame::NONE.inner_margin(egui::Margin::symmetric(0, 4));
                egui::TopBottomPanel::bottom("plot")
                    .frame(flat)
                    .resizable(false)
                    .show_inside(ui, |ui| self.statistics.plot(ui));
                // As tall as the figures, up to half the panel: the panel takes the height its
                // content had the pass before, so the scroll area asks for its own.
                let half = ui.available_height() / 2.0;
                egui::TopBottomPanel::bottom("figures").frame(flat).resizable(false).show_inside(ui, |ui| {
                    egui::ScrollArea::vertical()
                        .id_salt("figures")
                        .max_height(half)
                        .min_scrolled_height(half)
                        .show(ui, |ui| self.figures(ui, stats));
                });
                egui::CentralPanel::default()
                    .frame(egui::Frame::NONE)
                    .show_inside(ui, |ui| {
                        egui::ScrollArea::vertical()
                            .id_salt("settings")
                            .show(ui, |ui| self.settings(ui, stats))
                            .inner
                    })
                    .inner
            })
            .inner
    }

    /// The line for the user, the convergence and the frame's figures.
    fn figures(&self, ui: &mut Ui, stats: &FrameStats) {
        if !self.message.is_empty() {
            ui.colored_label(egui::Color32::LIGHT_RED, &self.message);
        }
        if stats.converged {
            ui.colored_label(
                egui::Color32::LIGHT_GREEN,
                format!("converged: {} frames in {:.1} s", stats.accumulated, stats.accumulated_seconds),
            );
        } else if stats.settings.accumulate && stats.accumulated > 1 {
            ui.label(format!(
                "converging: {} of {} frames, {:.1} s",
                stats.accumulated, stats.settings.converge_frames, stats.accumulated_seconds
            ));
        }
        match stats.history_kept {
            Some(0.0) => {
                ui.label("history refused (a cut): the frame stands alone");
            }
            Some(kept) if kept < 0.999 => {
                ui.label(format!("history kept in {:.0} % of the image", 100.0 * kept));
            }
            _ => {}
        }
        section("Statistics", true).show(ui, |ui| self.statistics.show(ui, stats));
    }

    /// The scene, the camera and the settings; returns the input a widget produced.
    fn settings(&mut self, ui: &mut Ui, stats: &FrameStats) -> Option<Input> {
        let mut input = None;
        if !self.scenes.is_empty() {
            // Another scene, from the session's list (built-ins, files under the start
            // folder); the view stays until it is loaded.
            let mut chosen = None;
            let current = stats.scene.as_deref().unwrap_or("");
            egui::ComboBox::from_label("scene").selected_text(current).show_ui(ui, |ui| {
                for name in &self.scenes {
                    if ui.selectable_label(name == current, name).clicked() && name != current {
                        chosen = Some(name.clone());
                    }
                }
            });
            if let Some(name) = chosen {
                self.message = format!("opening {name}…");
                self.opening = Some(name.clone());
                input = Some(Input::Open { name });
            }
        }
        ui.heading("Camera");
        let mut mode = stats.mode;
        ui.horizontal(|ui| {
            ui.selectable_value(&mut mode, CameraMode::Fly, "fly");
            ui.selectable_value(&mut mode, CameraMode::Orbit, "orbit");
        });
        if mode != stats.mode {
            input = Some(Input::Mode { mode });
        }
        ui.horizontal(|ui| {
            if ui.button("reset camera and objects").clicked() {
                input = Some(Input::Reset);
            }
            if ui
                .button("save view")
                .on_hover_text("the camera as a scene-file snippet, printed and copied")
                .clicked()
            {
                let snippet = stats.camera.scene_file_snippet();
                println!("{snippet}");
                ui.ctx().copy_text(snippet.clone());
                self.message = format!("view printed and copied, for a scene file:\n{snippet}");
            }
        });
        if !stats.views.is_empty() {
            // The scene's named cameras; choosing one moves the camera there.
            let mut chosen = None;
            egui::ComboBox::from_label("scene views").selected_text("look from…").show_ui(ui, |ui| {
                for name in &stats.views {
                    if ui.selectable_label(false, name).clicked() {
                        chosen = Some(name.clone());
                    }
                }
            });
            if let Some(name) = chosen {
                input = Some(Input::View { name });
            }
        }
        ui.small("H or ?: keys and mouse; F12 saves the image");

        let mut s = stats.settings.clone();
        ui.checkbox(&mut s.path_tracer, "path tracer (reference; slow)").on_hover_text(
            "one path per pixel and frame, averaged while still: the ground truth IGI approximates",
        );
        // The sections changed least start folded.
        section("Lighting", true).show(ui, |ui| {
            row(ui, "VPLs per pixel", DragValue::new(&mut s.frame.vpls_per_pixel).range(1..=4096));
            ui.horizontal(|ui| {
                ui.label("interleave");
                ui.add(DragValue::new(&mut s.frame.interleave[0]).range(1..=16));
                ui.label("×");
                ui.add(DragValue::new(&mut s.frame.interleave[1]).range(1..=16));
            });
            row(ui, "light bounces", DragValue::new(&mut s.frame.bounces).range(0..=MAX_BOUNCES));
            row(ui, "clamp d_min", DragValue::new(&mut s.frame.clamp).range(0.0..=f32::MAX).speed(0.01));
            row(ui, "AA samples", DragValue::new(&mut s.frame.aa).range(1..=64));
            row(ui, "specular bounces", DragValue::new(&mut s.frame.specular_bounces).range(0..=16));
            row(
                ui,
                "sky strength (0: off)",
                DragValue::new(&mut s.sky).range(0.0..=igi_session::settings::MAX_SKY).speed(0.05),
            );
        });
        section(&format!("Lights ({})", stats.lights.len()), false).show(ui, |ui| {
            if let Some(light) = self.lights(ui, stats) {
                input = Some(light);
            }
        });
        section("Filter", false).show(ui, |ui| {
            ui.checkbox(&mut s.frame.filter, "discontinuity filter");
            row(
                ui,
                "coarse interleave K (1: off)",
                DragValue::new(&mut s.frame.coarse_interleave).range(1..=4),
            );
            row(
                ui,
                "normal cosine ≥",
                DragValue::new(&mut s.frame.filter_normal).range(-1.0..=1.0).speed(0.01),
            );
            row(ui, "depth ratio ≤", DragValue::new(&mut s.frame.filter_depth).range(0.0..=10.0).speed(0.01));
        });
        section("Display", true).show(ui, |ui| {
            let mut fixed = s.exposure.is_some();
            ui.checkbox(&mut fixed, "fixed exposure");
            let mut stops = s.exposure.unwrap_or(0.0);
            if fixed {
                row(ui, "exposure (stops)", DragValue::new(&mut stops).range(-64.0..=64.0).speed(0.1));
            } else {
                ui.horizontal(|ui| {
                    ui.label("tone curve");
                    let curve = &mut s.frame.tone_curve;
                    egui::ComboBox::from_id_salt("tone curve").selected_text(curve_name(*curve)).show_ui(ui, |ui| {
                        for c in [ToneCurve::Filmic, ToneCurve::Reinhard] {
                            ui.selectable_value(curve, c, curve_name(c));
                        }
                    });
                });
                row(ui, "key (middle grey)", DragValue::new(&mut s.key).range(0.01..=1.0).speed(0.01));
            }
            s.exposure = fixed.then_some(stops);
            ui.checkbox(&mut s.accumulate, "accumulate while still");
            ui.checkbox(&mut s.temporal, "temporal reuse while moving")
                .on_hover_text("blend each frame with the reprojected history of the earlier ones while the camera or objects move");
            row(
                ui,
                "converged after frames",
                DragValue::new(&mut s.converge_frames).range(1..=igi_session::settings::MAX_ACCUMULATION),
            );
            row(
                ui,
                "or after seconds (0: none)",
                DragValue::new(&mut s.converge_seconds)
                    .range(0.0..=igi_session::settings::MAX_CONVERGE_SECONDS)
                    .speed(0.1),
            );
            ui.horizontal(|ui| {
                ui.label("resolution");
                egui::ComboBox::from_id_salt("resolution").selected_text(self.resolution.to_string()).show_ui(
                    ui,
                    |ui| {
                        for r in Resolution::ALL {
                            ui.selectable_value(&mut self.resolution, r, r.to_string());
                        }
                    },
                );
            })
            .response
            .on_hover_text("the image is rendered at the size of the area beside the panel times this; auto: full, or less so that it has at most 614,400 pixels");
        });
        section("Animation", false).show(ui, |ui| {
            ui.checkbox(&mut s.playing, "play");
            row(
                ui,
                "speed",
                DragValue::new(&mut s.speed).range(0.0..=igi_session::settings::MAX_SPEED).speed(0.05),
            );
        });
        if s != stats.settings && input.is_none() {
            input = Some(Input::Settings { settings: s });
        }
        input
    }

    /// The scene's light sources: a click selects one; the selected one's intensity and
    /// colour can be edited, and a hint says how a drag moves it.
    fn lights(&mut self, ui: &mut Ui, stats: &FrameStats) -> Option<Input> {
        let selected = stats.selected.as_ref().and_then(|s| s.light);
        let mut input = None;
        for (index, light) in stats.lights.iter().enumerate() {
            if ui.selectable_label(selected == Some(index), &light.name).clicked() {
                input = Some(Input::SelectLight { index });
            }
            if selected != Some(index) {
                continue;
            }
            let (mut intensity, mut colour) = (light.intensity, light.colour);
            ui.horizontal(|ui| {
                ui.label("intensity ×");
                ui.add(
                    DragValue::new(&mut intensity)
                        .range(0.0..=igi_session::light_control::MAX_INTENSITY)
                        .speed(0.02),
                );
                ui.label("colour");
                ui.color_edit_button_rgb(&mut colour);
            });
            ui.small(match light.kind {
                LightKind::Point => "right-drag in the image moves it",
                LightKind::Sun => "right-drag in the image turns it",
                LightKind::Emissive => "click its object in the image; right-drag moves it",
            });
            if (intensity, colour) != (light.intensity, light.colour) {
                input = Some(Input::EditLight { index, intensity, colour });
            }
        }
        input
    }
}

/// How the panel names a tone curve.
fn curve_name(curve: ToneCurve) -> &'static str {
    match curve {
        ToneCurve::Filmic => "filmic",
        ToneCurve::Reinhard => "Reinhard",
    }
}
