//! Temporal reuse in a viewer's session (issue 32): while the camera moves, each frame blends
//! in the reprojected history and has fresh VPLs; a change of the light, the settings or the
//! clock is a cut (the frame stands alone, so a moving lamp's light shows in the frame it
//! moves); the images do not depend on the thread count.

use igi_render::PreparedScene;
use igi_session::{Button, CameraMode, Frame, Input, Session, ViewerSettings};

fn session(name: &str, threads: usize, temporal: bool) -> Session {
    let scene = PreparedScene::new(igi_scene::builtin(name).unwrap());
    let camera = *scene.camera().unwrap();
    let defaults = ViewerSettings::for_scene(scene.bounds().diagonal());
    let settings = ViewerSettings {
        frame: igi_render::FrameSettings { width: 64, height: 48, ..defaults.frame },
        playing: false,
        temporal,
        ..defaults
    };
    let mut session = Session::new(scene, camera, settings, threads).unwrap();
    session.handle(&Input::Mode { mode: CameraMode::Orbit }).unwrap();
    session
}

/// Orbits by `frames` drags of half a pixel (3.75° each in an image 48 pixels high), returning
/// the frames.
fn orbit(session: &mut Session, frames: usize) -> Vec<Frame> {
    (0..frames)
        .map(|_| {
            session.handle(&Input::Drag { dx: 0.5, dy: 0.0, button: Button::Primary }).unwrap();
            session.render(0.04).unwrap()
        })
        .collect()
}

fn bits(frame: &Frame) -> Vec<u32> {
    frame.image.film().unwrap().pixels().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn a_moving_view_keeps_its_history_and_a_light_change_is_a_cut() {
    let mut s = session("animated-room", 2, true);
    let first = s.render(0.0).unwrap();
    assert_eq!(first.stats.history_kept, Some(0.0), "the first frame has no history");
    let moving = orbit(&mut s, 6);
    let last = moving.last().unwrap();
    let kept = last.stats.history_kept.unwrap();
    assert!(kept > 0.8, "an orbit of 3.75° a frame keeps most of the history: {kept}");
    assert!(last.stats.accumulated >= 4, "{} frames in the history", last.stats.accumulated);
    // Each moving frame has fresh VPLs: consecutive frames differ where the history is refused.
    assert_ne!(bits(&moving[4]), bits(&moving[5]));
    // The lamp changes: the next frame stands alone, lit by the new light at once.
    s.handle(&Input::EditLight { index: 0, intensity: 3.0, colour: [1.0, 0.5, 0.5] }).unwrap();
    let lit = s.render(0.04).unwrap();
    assert_eq!((lit.stats.history_kept, lit.stats.accumulated), (Some(0.0), 1));
    // Without temporal reuse nothing is kept.
    let mut off = session("animated-room", 2, false);
    off.render(0.0).unwrap();
    assert!(orbit(&mut off, 3).iter().all(|f| f.stats.history_kept.is_none() && f.stats.accumulated == 1));
}

#[test]
fn a_moving_views_images_do_not_depend_on_the_thread_count() {
    let mut one = session("cornell-box", 1, true);
    let mut two = session("cornell-box", 2, true);
    one.render(0.0).unwrap();
    two.render(0.0).unwrap();
    for (a, b) in orbit(&mut one, 4).iter().zip(&orbit(&mut two, 4)) {
        assert_eq!(bits(a), bits(b));
        assert_eq!(a.image.srgb8(), b.image.srgb8());
    }
}
