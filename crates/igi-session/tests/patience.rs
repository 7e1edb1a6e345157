//! Input that never stops does not starve the frames (issue 35: a browser dragging at 60 Hz
//! from the moment it connected got no frame in 10 s, each input cancelling the first frame;
//! a change to slower settings under the same drag starved the same way). A frame that input
//! keeps cancelling gets twice the time at each try, until one finishes with the newest input.

use igi_render::PreparedScene;
use igi_session::{Button, Input, Refusals, RenderLoop, Session, ViewerSettings};
use std::time::{Duration, Instant};

/// Drags by a pixel every 4 ms (250 Hz, four times a 60 Hz pointer) until `wanted` frames
/// that include input `since` and satisfy `fits` came, or `within` passed; returns how many
/// came and when the first did.
fn frames_under_drags(
    render_loop: &RenderLoop,
    viewer: &Refusals,
    since: u64,
    fits: impl Fn(&igi_session::FrameStats) -> bool,
    wanted: usize,
    within: Duration,
) -> (usize, Option<Duration>) {
    let start = Instant::now();
    let (mut seen, mut first) = (0, None);
    let mut last_id = 0;
    while seen < wanted && start.elapsed() < within {
        render_loop.send(Input::Drag { dx: 1.0, dy: 0.0, button: Button::Primary }, viewer);
        std::thread::sleep(Duration::from_millis(4));
        if let Some(frame) = render_loop.latest().get() {
            if frame.stats.id != last_id && frame.stats.input_seq >= since && fits(&frame.stats) {
                seen += 1;
                first.get_or_insert(start.elapsed());
            }
            last_id = frame.stats.id;
        }
    }
    (seen, first)
}

#[test]
fn frames_come_under_a_drag_that_never_stops() {
    // The Cornell box at 640x480: tens of milliseconds a frame on two threads, many drags' time.
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    let camera = *scene.camera().unwrap();
    let mut settings = ViewerSettings::for_scene(scene.bounds().diagonal());
    (settings.frame.width, settings.frame.height) = (640, 480);
    let session = Session::new(scene, camera, settings.clone(), 2).unwrap();
    let render_loop = RenderLoop::spawn(session);
    let viewer = render_loop.refusals(|| {});

    // From the start: before the fix, every drag cancelled the first frame.
    let (frames, first) = frames_under_drags(&render_loop, &viewer, 0, |_| true, 3, Duration::from_secs(20));
    let render_ms = render_loop.latest().get().map(|f| f.stats.render_ms);
    eprintln!("from the start: {frames} frames, the first after {first:?}, {render_ms:?} ms a frame");
    assert_eq!(frames, 3, "three frames within 20 s of dragging from the start");

    // Four times the pixels under the same drag: before the fix, each such frame was
    // cancelled at twice the time of the last one that finished.
    (settings.frame.width, settings.frame.height) = (1280, 960);
    let seq = render_loop.send(Input::Settings { settings }, &viewer);
    let (frames, first) =
        frames_under_drags(&render_loop, &viewer, seq, |s| s.width == 1280, 1, Duration::from_secs(30));
    eprintln!("at 1280x960: the first frame after {first:?}");
    assert_eq!(frames, 1, "a frame of the new size within 30 s of dragging");
}
