//! The side panel laid out by egui without a window or a display: at the window's default
//! 1200x760 and at smaller sizes, the frame-time plot lies wholly inside the window and is not
//! clipped (issue 34: at 1200x760 it lay below the visible end of the panel's scrolled list),
//! and the figures above it take the room they need, up to half of what is left.

use eframe::egui;
use eframe::egui::containers::panel::PanelState;
use igi_render::PreparedScene;
use igi_session::{Frame, Session, ViewerSettings};
use igi_view::DEFAULT_WINDOW;
use igi_view::panel::Panel;
use igi_view::resolution::Resolution;
use igi_view::statistics::plot_id;

/// A small frame of the animated room (two lights, two views: the panel's longest lists).
fn frame() -> Frame {
    let scene = PreparedScene::new(igi_scene::builtin("animated-room").unwrap());
    let camera = *scene.camera().unwrap();
    let mut settings = ViewerSettings::for_scene(scene.bounds().diagonal());
    (settings.frame.width, settings.frame.height) = (32, 24);
    Session::new(scene, camera, settings, 1).unwrap().render(0.0).unwrap()
}

/// Where the plot lies after the panel was laid out in a window of `size`: its rectangle, the
/// part of it that is not clipped, and the rectangle of the figures above it.
fn plot_in_window(frame: &Frame, size: [u32; 2]) -> (egui::Rect, egui::Rect, egui::Rect) {
    let ctx = egui::Context::default();
    let scenes = vec!["animated-room".to_string(), "cornell-box".to_string()];
    let mut panel = Panel::new(Resolution::Auto, scenes);
    panel.frame_shown(&frame.stats);
    panel.refused("open: a refusal takes a line of the panel too".into());
    let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(size[0] as f32, size[1] as f32));
    // Panels size themselves from the pass before: a few passes settle the layout.
    for _ in 0..4 {
        let input = egui::RawInput { screen_rect: Some(screen), ..Default::default() };
        let _ = ctx.run(input, |ctx| {
            panel.show(ctx, Some(frame));
            egui::CentralPanel::default().show(ctx, |_| {});
        });
    }
    let plot = ctx.read_response(plot_id()).expect("the plot is laid out");
    let figures = PanelState::load(&ctx, egui::Id::new("figures")).expect("the figures are laid out");
    (plot.rect, plot.interact_rect, figures.rect)
}

#[test]
fn the_frame_time_plot_is_in_sight_at_the_default_size_and_smaller() {
    let frame = frame();
    for size in [DEFAULT_WINDOW, [1200, 600], [1000, 480], [800, 360], [640, 240]] {
        let window = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(size[0] as f32, size[1] as f32));
        let (rect, visible, figures) = plot_in_window(&frame, size);
        eprintln!("{}x{}: plot at {rect:?}, figures at {figures:?}", size[0], size[1]);
        assert!(window.contains_rect(rect), "{size:?}: the plot {rect:?} is not inside the window");
        assert_eq!(visible, rect, "{size:?}: the plot {rect:?} is clipped to {visible:?}");
        assert!(rect.height() >= 60.0 && rect.width() >= 200.0, "{size:?}: the plot is {rect:?}");
        // The settings keep about half of the room above the plot (the margins aside).
        assert!(figures.height() <= 0.55 * rect.top(), "{size:?}: the figures take {figures:?}");
        if size == DEFAULT_WINDOW {
            // A line of message, the statistics' eleven lines and their headings, unscrolled
            // (224 points): not cut to a scrolled sliver.
            assert!(figures.height() >= 200.0, "the figures are cut to {figures:?}");
        }
    }
}
