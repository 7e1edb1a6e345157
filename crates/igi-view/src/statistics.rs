//! [`Statistics`]: what the panel says about the frames shown: the newest frame's figures,
//! the window's own frame rate, and a plot of the last frames' render times.

use eframe::egui::{self, Ui};
use igi_session::FrameStats;
use std::collections::VecDeque;
use std::time::Instant;

/// Frame times kept for the plot.
const HISTORY: usize = 120;
/// Height of the plot, points.
const PLOT_HEIGHT: f32 = 70.0;

/// The widget id of the frame-time plot, by which egui knows where it lies
/// ([`egui::Context::read_response`]).
pub fn plot_id() -> egui::Id {
    egui::Id::new("frame-time plot")
}

/// The frames shown so far, as far as the statistics need them.
#[derive(Debug, Default)]
pub struct Statistics {
    frame_ms: VecDeque<f32>,
    shown_at: VecDeque<Instant>,
}

impl Statistics {
    /// Records a newly shown frame (for the plot and the window's frame rate).
    pub fn frame_shown(&mut self, stats: &FrameStats) {
        if self.frame_ms.len() == HISTORY {
            self.frame_ms.pop_front();
            self.shown_at.pop_front();
        }
        self.frame_ms.push_back(stats.render_ms as f32);
        self.shown_at.push_back(Instant::now());
    }

    /// Frames shown per second over the recorded ones.
    fn shown_fps(&self) -> f64 {
        match (self.shown_at.front(), self.shown_at.back()) {
            (Some(a), Some(b)) if self.shown_at.len() > 1 => {
                (self.shown_at.len() - 1) as f64 / b.duration_since(*a).as_secs_f64().max(1e-9)
            }
            _ => 0.0,
        }
    }

    /// The figures of the frame of `stats`, and its time per phase in a folded section.
    pub fn show(&self, ui: &mut Ui, stats: &FrameStats) {
        let text = format!(
            "render fps   {:.1}\nwindow fps   {:.1}\nframe        {:.1} ms\nMrays/s      {:.1}\n\
             VPLs         {}\ntriangles    {}\naccumulated  {}\ntime         {:.2} s\nselected     {}\n\
             image        {}x{}",
            stats.fps,
            self.shown_fps(),
            stats.render_ms,
            stats.mrays_per_s,
            stats.vpls,
            stats.triangles,
            stats.accumulated,
            stats.time,
            stats.selected.as_ref().map_or("none", |s| s.name.as_str()),
            stats.width,
            stats.height,
        );
        ui.monospace(text);
        egui::CollapsingHeader::new("ms per phase").default_open(false).show(ui, |ui| {
            let phases: String =
                stats.phases_ms.iter().map(|(name, ms)| format!("{name:<15} {ms:.2} ms\n")).collect();
            ui.monospace(phases.trim_end());
        });
    }

    /// The last frames' render times as a line, scaled to the largest, over the width of `ui`.
    pub fn plot(&self, ui: &mut Ui) {
        let (_, rect) = ui.allocate_space(egui::vec2(ui.available_width(), PLOT_HEIGHT));
        ui.interact(rect, plot_id(), egui::Sense::hover())
            .on_hover_text(format!("render time of the last {HISTORY} frames shown"));
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, egui::Color32::from_gray(20));
        let top = self.frame_ms.iter().copied().fold(1.0f32, f32::max) * 1.1;
        let points: Vec<egui::Pos2> = self
            .frame_ms
            .iter()
            .enumerate()
            .map(|(i, ms)| {
                egui::pos2(
                    rect.left() + rect.width() * i as f32 / HISTORY as f32,
                    rect.bottom() - rect.height() * ms / top,
                )
            })
            .collect();
        painter.add(egui::Shape::line(points, egui::Stroke::new(1.5, egui::Color32::LIGHT_GREEN)));
        painter.text(
            rect.left_top() + egui::vec2(4.0, 2.0),
            egui::Align2::LEFT_TOP,
            format!("frame time, max {top:.0} ms"),
            egui::FontId::monospace(10.0),
            egui::Color32::GRAY,
        );
    }
}
