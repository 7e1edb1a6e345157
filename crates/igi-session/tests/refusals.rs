//! Refused inputs are answered to the viewer that sent them and to no other, stay few and
//! short for a viewer that never reads them, and go with the viewer (issue 35: 30,000 refused
//! `view` messages with 15.5 KB names took `igi serve` from 22 MB to 470 MB, stored for nobody
//! and never freed); inputs that come faster than the session takes them wait in a bounded
//! queue, and the rest are refused at once.

use igi_render::PreparedScene;
use igi_session::refusals::{MAX_CHARS, MAX_KEPT};
use igi_session::render_loop::{MAX_WAITING, MAX_WAITING_NAME_BYTES};
use igi_session::{Button, Input, RenderLoop, SceneCatalog, Session, ViewerSettings};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How long `slow.toml` takes to fail to load.
const SLOW_LOAD: Duration = Duration::from_secs(3);

/// The Cornell box, 40x40, still and not accumulating, with a list of scenes in which
/// `missing_mesh.toml` does not open, nor `slow.toml`, after [`SLOW_LOAD`].
fn render_loop() -> RenderLoop {
    render_loop_logging_opens(Arc::default())
}

/// [`render_loop`], noting in `opened` each scene it opens (or tries to).
fn render_loop_logging_opens(opened: Arc<Mutex<Vec<String>>>) -> RenderLoop {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    let camera = *scene.camera().unwrap();
    let mut settings = ViewerSettings::for_scene(scene.bounds().diagonal());
    (settings.frame.width, settings.frame.height, settings.accumulate) = (40, 40, false);
    let mut session = Session::new(scene, camera, settings, 1).unwrap();
    let names: Vec<String> = ["cornell-box", "missing_mesh.toml", "slow.toml"].map(String::from).into();
    let open = move |name: &str| {
        opened.lock().unwrap().push(name.to_string());
        match igi_scene::builtin(name) {
            Some(scene) => Ok(PreparedScene::new(scene)),
            None if name == "slow.toml" => {
                std::thread::sleep(SLOW_LOAD);
                Err("slow.toml: took its time and failed".to_string())
            }
            None => Err("mesh file missing.obj: No such file or directory (os error 2)".to_string()),
        }
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
    // What the newest are depends on how many waited at once (beyond the queue's bound they
    // are refused as "busy"); a long name is cut and its length said.
    for message in unread.take() {
        assert!(message.chars().count() <= MAX_CHARS, "{message}");
        let said = match message.split_once(": ").map(|(what, _)| what) {
            Some("view") => message.ends_with("…\" (15500 bytes)"),
            // Refused, or passed over for a later open in the same batch.
            Some("open") => {
                message.ends_with(" (15500 bytes) is not in the list of scenes")
                    || message.ends_with(" (15500 bytes): not opened, a later request replaced it")
            }
            Some("light") => message.contains(" light sources, not "),
            Some("busy") => message.ends_with("this one was dropped"),
            _ => false,
        };
        assert!(said, "{message}");
    }

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
    // The render thread may be telling it something at this instant (a message is pushed
    // through a reference it holds for that long).
    let deadline = std::time::Instant::now() + Duration::from_secs(2);
    while Arc::strong_count(&alive) > 1 && std::time::Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(1));
    }
    assert_eq!(Arc::strong_count(&alive), 1, "the viewer's messages are freed with it");
    handled(&render_loop);
}

#[test]
fn inputs_that_come_while_a_scene_loads_wait_in_a_bounded_queue() {
    let render_loop = render_loop();
    let viewer = render_loop.refusals(|| {});
    let opened = render_loop.send(Input::Open { name: "slow.toml".into() }, &viewer);
    // The render thread is in the load from here on.
    std::thread::sleep(SLOW_LOAD / 10);
    let name = "v".repeat(15_500);
    let mut last = opened;
    for _ in 0..3_000 {
        last = render_loop.send(Input::View { name: name.clone() }, &viewer);
    }
    let names_waiting = last - opened;
    assert_eq!(names_waiting, (MAX_WAITING_NAME_BYTES / name.len()) as u64, "1 MiB of names wait");
    let key = Input::Key { key: igi_session::Key::W, down: false };
    for _ in 0..2 * MAX_WAITING {
        last = render_loop.send(key.clone(), &viewer);
    }
    assert_eq!(last - opened, MAX_WAITING as u64, "so many inputs wait, no more");
    let busy = viewer.take();
    assert!(busy.iter().all(|m| m.starts_with("busy: ") && m.ends_with("this one was dropped")), "{busy:?}");
    // Once the load has failed, the names that waited are handled (and refused).
    handled(&render_loop);
    let after = viewer.take();
    assert_eq!(after.len(), MAX_KEPT);
    assert!(after.iter().all(|m| m.starts_with("view: the scene has no view \"vvv")), "{after:?}");
}

#[test]
fn of_the_scenes_asked_for_while_one_loads_only_the_last_opens() {
    // Twenty opens from one client held every viewer's frames for twenty loads (issue 35).
    let opened = Arc::new(Mutex::new(Vec::new()));
    let render_loop = render_loop_logging_opens(opened.clone());
    let viewer = render_loop.refusals(|| {});
    render_loop.send(Input::Open { name: "slow.toml".into() }, &viewer);
    // The render thread is in the load from here on.
    std::thread::sleep(SLOW_LOAD / 10);
    let other = render_loop.refusals(|| {});
    for name in ["slow.toml", "missing_mesh.toml", "slow.toml"] {
        render_loop.send(Input::Open { name: name.into() }, &viewer);
        // A view the next scene may have, refused by the current one if it were applied.
        render_loop.send(Input::View { name: "roof".into() }, &viewer);
    }
    render_loop.send(Input::Open { name: "cornell-box".into() }, &other);
    // The passed-over inputs count as handled: the frame after them comes.
    handled(&render_loop);
    assert_eq!(*opened.lock().unwrap(), ["slow.toml", "cornell-box"]);
    // The viewer whose scenes were passed over is told (its page stops waiting for them).
    assert_eq!(
        viewer.take(),
        [
            "open: slow.toml: took its time and failed",
            "open: \"slow.toml\": not opened, a later request replaced it",
            "open: \"missing_mesh.toml\": not opened, a later request replaced it",
            "open: \"slow.toml\": not opened, a later request replaced it",
        ]
    );
    assert!(other.take().is_empty());
}
