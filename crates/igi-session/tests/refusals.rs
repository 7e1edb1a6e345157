//! Refused inputs are answered to the viewer that sent them and to no other, stay few and
//! short for a viewer that never reads them, and go with the viewer (issue 35: 30,000 refused
//! `view` messages with 15.5 KB names took `igi serve` from 22 MB to 470 MB, stored for nobody
//! and never freed).

use igi_render::PreparedScene;
use igi_session::refusals::{MAX_CHARS, MAX_KEPT};
use igi_session::{Button, Input, RenderLoop, SceneCatalog, Session, ViewerSettings};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

/// The Cornell box, 40x40, still and not accumulating, with a list of scenes in which
/// `missing_mesh.toml` does not open.
fn render_loop() -> RenderLoop {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    let camera = *scene.camera().unwrap();
    let mut settings = ViewerSettings::for_scene(scene.bounds().diagonal());
    (settings.frame.width, settings.frame.height, settings.accumulate) = (40, 40, false);
    let mut session = Session::new(scene, camera, settings, 1).unwrap();
    let names = vec!["cornell-box".to_string(), "missing_mesh.toml".to_string()];
    let open = |name: &str| match igi_scene::builtin(name) {
        Some(scene) => Ok(PreparedScene::new(scene)),
        None => Err("mesh file missing.obj: No such file or directory (os error 2)".to_string()),
    };
    session.set_catalog(SceneCatalog::new(names, Box::new(open)), "cornell-box");
    RenderLoop::spawn(session)
}

/// Waits until the loop has handled every input sent so far: sends a drag (from a viewer of
/// its own) and waits for the frame that includes it.
fn handled(render_loop: &RenderLoop) {
    let own = render_loop.refusals(|| {});
    let seq = render_loop.send(Input::Drag { dx: 1.0, dy: 0.0, button: Button::Primary }, &own);
    let mut after = 0;
    loop {
        let frame = render_loop.latest().wait_newer(after, Duration::from_secs(60)).expect("a frame in 60 s");
        if frame.stats.input_seq >= seq {
            return;
        }
        after = frame.stats.id;
    }
}

#[test]
fn a_refusal_goes_to_the_viewer_that_caused_it() {
    let render_loop = render_loop();
    let woken = Arc::new(AtomicUsize::new(0));
    let opener = {
        let woken = woken.clone();
        render_loop.refusals(move || {
            woken.fetch_add(1, Ordering::SeqCst);
        })
    };
    let other = render_loop.refusals(|| {});
    render_loop.send(Input::Open { name: "missing_mesh.toml".into() }, &opener);
    render_loop.send(Input::View { name: "roof".into() }, &other);
    handled(&render_loop);
    assert_eq!(
        opener.take(),
        ["open: mesh file missing.obj: No such file or directory (os error 2)"],
        "the viewer that opened it is told why"
    );
    assert_eq!(woken.load(Ordering::SeqCst), 1, "and woken: a still view sends no frame to carry it");
    assert_eq!(other.take(), ["view: the scene has no view \"roof\""], "the other viewer hears its own only");
}

#[test]
fn refusals_nobody_reads_stay_few_and_short_and_go_with_their_viewer() {
    let render_loop = render_loop();
    // The probe's messages: names of 15.5 KB, every input that names something.
    let name = "v".repeat(15_500);
    let refused = |i: usize| match i % 4 {
        0 => Input::View { name: name.clone() },
        1 => Input::Open { name: name.clone() },
        2 => Input::SelectLight { index: 1000 + i },
        _ => Input::EditLight { index: 1000 + i, intensity: 1.0, colour: [1.0; 3] },
    };
    let unread = render_loop.refusals(|| {});
    for i in 0..3_000 {
        render_loop.send(refused(i), &unread);
    }
    handled(&render_loop);
    let (count, chars) = unread.kept();
    assert_eq!(count, MAX_KEPT, "the newest few are kept");
    assert!(chars <= MAX_KEPT * MAX_CHARS, "{chars} characters kept");
    let messages = unread.take();
    assert!(messages.iter().all(|m| m.chars().count() <= MAX_CHARS));
    let view = messages.iter().find(|m| m.starts_with("view: ")).unwrap();
    assert!(view.ends_with("…\" (15500 bytes)"), "a long name is cut and its length said: {view}");
    let open = messages.iter().find(|m| m.starts_with("open: ")).unwrap();
    assert!(open.ends_with(" (15500 bytes) is not in the list of scenes"), "{open}");

    // A viewer that goes with inputs still waiting: what it would be told is freed with it
    // (its wake function, holding `alive`, is dropped at once), and nothing is kept for it.
    let alive = Arc::new(());
    let gone = {
        let alive = alive.clone();
        render_loop.refusals(move || {
            let _ = &alive;
        })
    };
    for i in 0..1000 {
        render_loop.send(refused(i), &gone);
    }
    drop(gone);
    assert_eq!(Arc::strong_count(&alive), 1, "the viewer's messages are freed with it");
    handled(&render_loop);
}
