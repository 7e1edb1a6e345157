//! The interaction model on its own: progressive accumulation converges towards the path
//! tracer and resets on a change, the clock moves the animated scene, picking and dragging
//! move an object, and the render loop delivers the newest frame with the inputs it includes,
//! cancelling a long frame when input comes or the loop is dropped.

use glam::Vec3;
use igi_render::{
    CancelToken, Estimator, Film, FrameError, FrameOutput, FrameRenderer, FrameSource, FrameState,
    PreparedScene,
};
use igi_session::settings::MAX_ACCUMULATION;
use igi_session::{Button, Input, RenderLoop, Session, ViewerSettings};
use std::time::Duration;

const SIZE: u32 = 40;

fn settings(scene: &PreparedScene) -> ViewerSettings {
    ViewerSettings {
        frame: igi_render::FrameSettings {
            width: SIZE,
            height: SIZE,
            ..ViewerSettings::for_scene(scene.bounds().diagonal()).frame
        },
        playing: false,
        ..ViewerSettings::for_scene(scene.bounds().diagonal())
    }
}

fn session(name: &str, configure: impl FnOnce(&mut ViewerSettings)) -> Session {
    let scene = PreparedScene::new(igi_scene::builtin(name).unwrap());
    let camera = *scene.camera().unwrap();
    let mut s = settings(&scene);
    configure(&mut s);
    Session::new(scene, camera, s, 2).unwrap()
}

/// The path tracer's image of `frame` with `spp` paths per pixel.
fn path_traced(scene: &mut PreparedScene, frame: &FrameState, spp: u32) -> Film {
    let traced = FrameState { estimator: Estimator::PathTracer { spp }, ..frame.clone() };
    let out = FrameRenderer::new(2).render(scene, &traced, &|_, _| {}).expect("valid settings");
    out.image.into_film().expect("linear radiance")
}

fn rmse(a: &Film, b: &Film) -> f64 {
    let sum: f64 =
        a.pixels().iter().zip(b.pixels()).map(|(p, q)| f64::from((*p - *q).length_squared())).sum();
    (sum / a.pixels().len() as f64).sqrt()
}

#[test]
fn a_still_view_converges_towards_the_path_tracer_and_a_change_resets_it() {
    // Unclamped IGI is unbiased, so its mean converges to the path tracer's image. Without
    // temporal reuse a move restarts the mean.
    let mut session = session("cornell-box", |s| (s.frame.clamp, s.temporal) = (0.0, false));
    let reference = {
        let mut scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
        let settings = igi_render::FrameSettings { seed: 7, ..session.settings().frame };
        let frame = FrameState::new(session.camera().camera(), settings);
        path_traced(&mut scene, &frame, 2048)
    };
    let mut errors = Vec::new();
    for n in 1..=64u32 {
        let frame = session.render(0.01).unwrap();
        assert_eq!(frame.stats.accumulated, n);
        if n.is_power_of_two() {
            errors.push(rmse(frame.image.film().unwrap(), &reference));
        }
    }
    eprintln!("RMSE against the path tracer after 1, 2, 4, .. 64 frames: {errors:?}");
    assert!(errors.windows(2).filter(|w| w[1] < w[0]).count() >= 5, "{errors:?}");
    assert!(errors[6] < 0.5 * errors[0], "64 frames halve the error at least: {errors:?}");

    // A camera move shows the instant one-frame solution at once.
    session.handle(&Input::Drag { dx: 12.0, dy: 0.0, button: Button::Primary }).unwrap();
    let moved = session.render(0.01).unwrap();
    assert_eq!(moved.stats.accumulated, 1);
    let mut fresh = session_at(&session);
    let first = fresh.render(0.0).unwrap();
    // The fresh controller recomputes yaw and pitch from the camera, so rays may differ in
    // the last bit: compare within a tolerance far below the one-frame noise.
    let difference = rmse(moved.image.film().unwrap(), first.image.film().unwrap());
    assert!(difference < 0.05 * errors[0], "the instant frame is frame 0 of the new view: {difference}");
}

/// A new session with the same settings, at the camera of `other`.
fn session_at(other: &Session) -> Session {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    Session::new(scene, other.camera().camera(), other.settings().clone(), 2).unwrap()
}

#[test]
fn the_clock_moves_the_animation_and_every_frame_is_instant() {
    let mut session = session("animated-room", |s| s.playing = true);
    let a = session.render(0.1).unwrap();
    let b = session.render(0.1).unwrap();
    assert!((b.stats.time - 0.2).abs() < 1e-6 && a.stats.accumulated == 1 && b.stats.accumulated == 1);
    assert_ne!(a.image.srgb8(), b.image.srgb8(), "the lamp swung");
    // Paused, frames accumulate and the clock stands.
    let mut paused = session.settings().clone();
    paused.playing = false;
    session.handle(&Input::Settings { settings: paused }).unwrap();
    session.render(0.1).unwrap();
    let c = session.render(0.1).unwrap();
    assert_eq!((c.stats.time, c.stats.accumulated), (b.stats.time, 2));
}

#[test]
fn an_object_dragged_by_the_largest_floats_stays_where_floats_hold_it() {
    // Repeated right-drags of ±3.4e38 pixels moved the statue to infinity, where it vanished.
    let mut session = session("animated-room", |_| {});
    session.render(0.0).unwrap();
    let centre = SIZE as f32 / 2.0;
    session.handle(&Input::Pick { x: centre, y: centre }).unwrap();
    session.render(0.0).unwrap();
    let statue = |s: &Session| s.scene().accel().instance_transform(1).transform_point3(Vec3::ZERO);
    for dx in [3.4e38, 3.4e38, -3.4e38, 3.4e38, 3.4e38] {
        session.handle(&Input::Drag { dx, dy: -3.4e38, button: Button::Secondary }).unwrap();
        session.render(0.0).unwrap();
        let p = statue(&session);
        assert!(p.is_finite() && p.abs().max_element() <= igi_scene::MAX_COORDINATE, "{p}");
    }
}

#[test]
fn picking_and_dragging_moves_the_object_under_the_pointer() {
    let mut session = session("animated-room", |_| {});
    let before = session.render(0.0).unwrap();
    // The statue stands in the middle of the image.
    let centre = SIZE as f32 / 2.0;
    session.handle(&Input::Pick { x: centre, y: centre }).unwrap();
    let picked = session.render(0.0).unwrap();
    let selected = picked.stats.selected.as_ref().expect("the statue is picked");
    assert_eq!(selected.instance, Some(1), "the statue is instance 1");
    // Its outline surrounds the point that picked it.
    let (mut lo, mut hi) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
    for e in &selected.outline {
        for p in [glam::Vec2::new(e[0], e[1]), glam::Vec2::new(e[2], e[3])] {
            (lo, hi) = (lo.min(p), hi.max(p));
        }
    }
    assert_eq!(selected.outline.len(), 12);
    assert!(
        lo.cmplt(glam::Vec2::splat(centre)).all() && hi.cmpgt(glam::Vec2::splat(centre)).all(),
        "{lo} {hi}"
    );
    let statue = |s: &Session| s.scene().accel().instance_transform(1).transform_point3(Vec3::ZERO);
    let start = statue(&session);
    session.handle(&Input::Drag { dx: 4.0, dy: 0.0, button: Button::Secondary }).unwrap();
    let after = session.render(0.0).unwrap();
    let left = |f: &igi_session::Frame| {
        f.stats.selected.as_ref().unwrap().outline.iter().map(|e| e[0].min(e[2])).fold(f32::MAX, f32::min)
    };
    assert!(left(&after) > left(&picked) + 2.0, "the outline follows the statue to the right");
    let moved = statue(&session) - start;
    let right = session.camera().forward().cross(Vec3::Y).normalize();
    assert!(moved.dot(right) > 0.05 && moved.y.abs() < 1e-4, "moved {moved}");
    // The statue moved, not the camera or the light: the history follows it, and is refused
    // only where the statue was and no longer is.
    let kept = after.stats.history_kept.expect("temporal reuse is on");
    assert!(kept > 0.5 && kept < 1.0, "{kept} of the pixels kept their history");
    assert_ne!(after.image.srgb8(), before.image.srgb8());
    // Picking nothing (outside the image) clears the selection; a drag then moves nothing.
    session.handle(&Input::Pick { x: -1.0, y: 0.0 }).unwrap();
    session.handle(&Input::Drag { dx: 4.0, dy: 0.0, button: Button::Secondary }).unwrap();
    session.render(0.0).unwrap();
    assert!((statue(&session) - start - moved).length() < 1e-6);
    // Reset puts it back.
    session.handle(&Input::Reset).unwrap();
    session.render(0.0).unwrap();
    assert!((statue(&session) - start).length() < 1e-6);
}

#[test]
fn invalid_settings_are_refused_and_change_nothing() {
    let mut session = session("cornell-box", |_| {});
    let good = session.settings().clone();
    for bad in [
        ViewerSettings { frame: igi_render::FrameSettings { aa: 0, ..good.clone().frame }, ..good.clone() },
        ViewerSettings {
            frame: igi_render::FrameSettings { width: 100_000, ..good.clone().frame },
            ..good.clone()
        },
        ViewerSettings {
            frame: igi_render::FrameSettings { width: 8000, height: 8000, ..good.clone().frame },
            ..good.clone()
        },
        ViewerSettings { speed: f32::NAN, ..good.clone() },
        ViewerSettings { exposure: Some(f32::INFINITY), ..good.clone() },
    ] {
        assert!(session.handle(&Input::Settings { settings: bad }).is_err());
    }
    assert_eq!(session.settings(), &good);
}

#[test]
fn inputs_serialise_as_tagged_json() {
    let input: Input = serde_json::from_str(r#"{"type":"drag","dx":3,"dy":-1,"button":"primary"}"#).unwrap();
    assert_eq!(input, Input::Drag { dx: 3.0, dy: -1.0, button: Button::Primary });
    assert!(serde_json::from_str::<Input>(r#"{"type":"drag","dx":3}"#).is_err());
    assert!(serde_json::from_str::<Input>(r#"{"type":"explode"}"#).is_err());
}

#[test]
fn the_render_loop_delivers_newest_frames_with_their_inputs() {
    let session = session("cornell-box", |s| s.accumulate = false);
    let render_loop = RenderLoop::spawn(session);
    let refusals = render_loop.refusals(|| {});
    let first = render_loop.latest().wait_newer(0, Duration::from_secs(30)).expect("a first frame");
    let seq = render_loop.send(Input::Drag { dx: 30.0, dy: 0.0, button: Button::Primary }, &refusals);
    let mut frame = first.clone();
    while frame.stats.input_seq < seq {
        frame =
            render_loop.latest().wait_newer(frame.stats.id, Duration::from_secs(30)).expect("a newer frame");
    }
    assert_ne!(frame.image.srgb8(), first.image.srgb8(), "the frame with the drag shows the turned view");
    // Without accumulation and without changes the loop idles: no newer frame comes.
    std::thread::sleep(Duration::from_millis(100));
    let idle = render_loop.latest().get().unwrap();
    assert!(render_loop.latest().wait_newer(idle.stats.id, Duration::from_millis(300)).is_none());
    // Bad settings are reported, not applied.
    let mut bad = ViewerSettings::for_scene(1.0);
    bad.frame.aa = 0;
    render_loop.send(Input::Settings { settings: bad }, &refusals);
    let deadline = std::time::Instant::now() + Duration::from_secs(10);
    let mut errors = Vec::new();
    while errors.is_empty() && std::time::Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
        errors = refusals.take();
    }
    assert!(
        errors.iter().any(|e| e.starts_with("AA samples: ") || e.starts_with("\"AA samples: ")),
        "{errors:?}"
    );
}

#[test]
fn an_on_demand_loop_renders_only_while_watched() {
    // The animated room playing without accumulation: an always-rendering loop never idles.
    let session = session("animated-room", |s| {
        s.accumulate = false;
        s.playing = true;
    });
    let render_loop = RenderLoop::spawn_on_demand(session);
    assert!(render_loop.latest().wait_newer(0, Duration::from_millis(500)).is_none(), "nobody watches yet");
    let watching = render_loop.watch();
    let first = render_loop.latest().wait_newer(0, Duration::from_secs(30)).expect("a frame once watched");
    let later =
        render_loop.latest().wait_newer(first.stats.id, Duration::from_secs(30)).expect("frames go on");
    // Inputs are taken while nobody watches; the frame in flight may still come.
    drop(watching);
    let last = render_loop.latest().wait_newer(later.stats.id, Duration::from_millis(500)).unwrap_or(later);
    assert!(
        render_loop.latest().wait_newer(last.stats.id, Duration::from_millis(500)).is_none(),
        "no frames once the last viewer has gone"
    );
    assert!(render_loop.is_idle());
    let again = render_loop.watch();
    render_loop
        .latest()
        .wait_newer(last.stats.id, Duration::from_secs(30))
        .expect("frames when a viewer comes back");
    drop(again);
}

#[test]
fn the_path_tracer_switch_renders_the_reference_and_converges_towards_it() {
    // The path tracer's own mean over still frames against a 64-spp path-traced image.
    let mut session = session("cornell-box", |s| {
        s.path_tracer = true;
        s.converge_frames = 48;
    });
    let mut last = None;
    while session.needs_frame() {
        last = Some(session.render(0.0).unwrap());
    }
    let last = last.unwrap();
    assert_eq!((last.stats.vpls, last.stats.accumulated), (0, 48), "path-traced frames, accumulated");
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    let mut reference_scene = scene;
    let frame = FrameState::new(*reference_scene.camera().unwrap(), session.settings().frame);
    let reference = path_traced(&mut reference_scene, &frame, 64);
    let mean = last.image.film().expect("linear radiance");
    // Per pixel both are noisy; over the image, their brightness agrees.
    let brightness = |f: &Film| f.pixels().iter().map(|p| f64::from(p.x + p.y + p.z)).sum::<f64>();
    let ratio = brightness(mean) / brightness(&reference);
    assert!((ratio - 1.0).abs() < 0.05, "48 frames of 1 spp against 64 spp: brightness ratio {ratio}");
}

#[test]
fn the_sky_strength_scales_the_sky_and_zero_turns_it_off() {
    // The generated tree under its sun and sky.
    let scene = PreparedScene::new(igi_scene::builtin_spec("maple-tree:triangles=180k").unwrap().unwrap());
    let camera = *scene.camera().unwrap();
    let s = ViewerSettings { accumulate: false, playing: false, ..settings(&scene) };
    let mut session = Session::new(scene, camera, s, 2).unwrap();
    let mut sky_pixel = |strength: f32| {
        let settings = ViewerSettings { sky: strength, ..session.settings().clone() };
        session.handle(&Input::Settings { settings }).unwrap();
        let frame = session.render(0.0).unwrap();
        // The top right corner: open sky beside the tree.
        frame.image.film().expect("linear radiance").pixels()[SIZE as usize - 1]
    };
    let (one, two, off) = (sky_pixel(1.0), sky_pixel(2.0), sky_pixel(0.0));
    assert!(one.min_element() > 0.0, "the sky shows: {one}");
    assert!(
        (two - 2.0 * one).abs().max_element() <= 1e-4 * two.max_element(),
        "twice as strong: {one} {two}"
    );
    assert_eq!(off, glam::Vec3::ZERO, "sky off");
}

#[test]
fn a_still_view_stops_at_its_convergence_target() {
    let mut session = session("cornell-box", |s| s.converge_frames = 4);
    let mut frames = Vec::new();
    while session.needs_frame() {
        frames.push(session.render(0.0).unwrap().stats);
        assert!(frames.len() <= 4, "rendering goes on past the target of 4 frames");
    }
    assert_eq!(frames.len(), 4);
    assert!(frames[..3].iter().all(|f| !f.converged), "converged early");
    assert!(frames[3].converged && frames[3].accumulated == 4, "{:?}", frames[3]);
    assert!(
        frames[3].accumulated_seconds >= frames[..].iter().map(|f| f.render_ms).sum::<f64>() * 1e-3 * 0.5
    );
    // A time target ends the accumulation too; a change starts it over.
    let mut timed = session.settings().clone();
    timed.converge_frames = MAX_ACCUMULATION;
    timed.converge_seconds = 0.05;
    session.handle(&Input::Settings { settings: timed }).unwrap();
    let mut last = None;
    while session.needs_frame() {
        last = Some(session.render(0.0).unwrap().stats);
    }
    let last = last.expect("the change renders");
    assert!(last.converged && last.accumulated_seconds >= 0.05, "{last:?}");
    assert!(last.accumulated < MAX_ACCUMULATION);
    // Refused settings are named as the panels name them.
    let mut bad = session.settings().clone();
    bad.frame.vpls_per_pixel = 0;
    let error = session.handle(&Input::Settings { settings: bad }).unwrap_err();
    let message = error.panel_message();
    assert!(message.starts_with("VPLs per pixel: "), "{message}");
    assert!(!session.needs_frame(), "a refused change renders nothing");
}

/// The probe's settings, whose frame takes minutes on two threads: 3840x2160 pixels, each with
/// 64 primary rays and 4096 VPLs (about 2 · 10¹⁰ rays on the Cornell box, 57 Mrays/s per idle
/// core; one 64-pixel tile is 1/2040 of it).
fn slow(settings: &ViewerSettings) -> ViewerSettings {
    ViewerSettings {
        frame: igi_render::FrameSettings {
            width: 3840,
            height: 2160,
            vpls_per_pixel: 4096,
            aa: 64,
            ..settings.clone().frame
        },
        ..settings.clone()
    }
}

#[test]
fn new_input_cancels_a_long_frame_and_its_frame_comes_at_once() {
    let session = session("cornell-box", |s| s.accumulate = false);
    let fast = session.settings().clone();
    let render_loop = RenderLoop::spawn(session);
    let refusals = render_loop.refusals(|| {});
    render_loop.latest().wait_newer(0, Duration::from_secs(30)).expect("a first frame");
    render_loop.send(Input::Settings { settings: slow(&fast) }, &refusals);
    // Let the long frame start.
    std::thread::sleep(Duration::from_secs(1));
    let start = std::time::Instant::now();
    let seq = render_loop.send(Input::Settings { settings: fast.clone() }, &refusals);
    let mut frame = render_loop.latest().get().unwrap();
    while frame.stats.input_seq < seq {
        let Some(newer) = render_loop.latest().wait_newer(frame.stats.id, Duration::from_secs(10)) else {
            panic!("no frame within 10 s of the input: the long frame was not cancelled");
        };
        // The long frame was cancelled, not shown.
        assert_eq!(newer.stats.settings, fast, "frame {} has the long frame's settings", newer.stats.id);
        frame = newer;
    }
    eprintln!("the input's frame came {:?} after it", start.elapsed());
}

/// The local renderer, reporting each frame's settings and outcome.
#[derive(Debug)]
struct Reporting {
    renderer: FrameRenderer,
    outcomes: std::sync::mpsc::Sender<(igi_render::FrameSettings, Result<(), String>)>,
}

impl FrameSource for Reporting {
    fn render_frame(
        &mut self,
        scene: &mut PreparedScene,
        frame: &FrameState,
        cancel: &CancelToken,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<FrameOutput, FrameError> {
        let out = self.renderer.render_frame(scene, frame, cancel, progress);
        let _ = self.outcomes.send((frame.settings, out.as_ref().map(|_| ()).map_err(|e| e.to_string())));
        out
    }

    fn threads(&self) -> usize {
        self.renderer.threads()
    }
}

#[test]
fn dropping_the_loop_cancels_the_frame_in_progress() {
    let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
    let camera = *scene.camera().unwrap();
    let settings = slow(&settings(&scene));
    let (outcomes, outcome) = std::sync::mpsc::channel();
    let source = Reporting { renderer: FrameRenderer::new(2), outcomes };
    let session = Session::with_source(scene, camera, settings, Box::new(source)).unwrap();
    let render_loop = RenderLoop::spawn(session);
    std::thread::sleep(Duration::from_secs(1));
    drop(render_loop);
    let (_, result) = outcome.recv_timeout(Duration::from_secs(10)).expect("the frame ends within 10 s");
    assert_eq!(result, Err("the frame was cancelled".to_string()));
}

#[test]
fn a_pick_shows_in_the_next_frame_without_restarting_the_mean() {
    let mut session = session("animated-room", |s| {
        s.playing = false;
        s.converge_frames = 2;
    });
    while session.needs_frame() {
        session.render(0.0).unwrap();
    }
    let centre = SIZE as f32 / 2.0;
    session.handle(&Input::Pick { x: centre, y: centre }).unwrap();
    assert!(session.needs_frame(), "a converged view still shows a new selection");
    let frame = session.render(0.0).unwrap();
    assert!(frame.stats.selected.is_some());
    assert!(frame.stats.accumulated > 2, "the mean went on: {}", frame.stats.accumulated);
    assert!(!session.needs_frame());
}

#[test]
fn a_view_moves_the_camera_there_and_an_unknown_one_is_refused() {
    let mut session = session("animated-room", |s| s.playing = false);
    let first = session.render(0.0).unwrap();
    assert_eq!(first.stats.views, ["statue", "high corner"]);
    session.handle(&Input::Mode { mode: igi_session::CameraMode::Orbit }).unwrap();
    session.handle(&Input::View { name: "statue".into() }).unwrap();
    let there = session.render(0.0).unwrap();
    let view = &session.scene().views()[0].camera;
    assert!((there.stats.camera.position - view.position).length() < 1e-5);
    assert!((there.stats.camera.target - view.target).length() < 1e-4);
    assert_eq!(there.stats.mode, igi_session::CameraMode::Orbit, "the mode stays");
    assert_eq!(there.stats.accumulated, 1, "a new view starts the mean anew");
    assert_ne!(there.image.srgb8(), first.image.srgb8());
    let err = session.handle(&Input::View { name: "roof".into() }).unwrap_err();
    assert_eq!(err.panel_message(), "view: the scene has no view \"roof\"");
}

#[test]
fn lights_are_listed_edited_dragged_and_reset() {
    // A fixed exposure: the tone map does not follow the edits.
    let mut session = session("animated-room", |s| {
        s.playing = false;
        s.accumulate = false;
        s.exposure = Some(0.0);
    });
    let first = session.render(0.0).unwrap();
    let names: Vec<&str> = first.stats.lights.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["point light 0", "lamp"]);
    let mean = |f: &igi_session::Frame| f.image.srgb8().iter().map(|&b| f64::from(b)).sum::<f64>();

    // The lamp twice as bright: a brighter image, and the panel's values come back.
    session.handle(&Input::EditLight { index: 1, intensity: 2.0, colour: [1.0, 1.0, 1.0] }).unwrap();
    let brighter = session.render(0.0).unwrap();
    assert_eq!((brighter.stats.lights[1].intensity, brighter.stats.accumulated), (2.0, 1));
    assert!(mean(&brighter) > mean(&first));
    // Red only: no green left in the lamp's light (the point light still adds some).
    session.handle(&Input::EditLight { index: 1, intensity: 2.0, colour: [1.0, 0.0, 0.0] }).unwrap();
    assert_eq!(session.render(0.0).unwrap().stats.lights[1].colour, [1.0, 0.0, 0.0]);

    // The point light selected and dragged right moves along the view's right axis.
    session.handle(&Input::SelectLight { index: 0 }).unwrap();
    let selected = session.render(0.0).unwrap().stats.selected.unwrap();
    assert_eq!(
        (selected.light, selected.name.as_str(), selected.outline.len()),
        (Some(0), "point light 0", 6)
    );
    let position = |s: &Session| match s.scene().lights()[0] {
        igi_scene::Light::Point { position, .. } => position,
        _ => unreachable!(),
    };
    let before = position(&session);
    session.handle(&Input::Drag { dx: 10.0, dy: 0.0, button: Button::Secondary }).unwrap();
    session.render(0.0).unwrap();
    let right = session.camera().forward().cross(Vec3::Y).normalize();
    let moved = position(&session) - before;
    assert!(moved.dot(right) > 0.05 && moved.y.abs() < 1e-4, "moved {moved}");
    // Drags of the largest floats add up to no more than a scene's coordinates may reach: the
    // light stays where floats hold it instead of vanishing at infinity.
    for dx in [3.4e38, 3.4e38, -3.4e38, 3.4e38, 3.4e38] {
        session.handle(&Input::Drag { dx, dy: 3.4e38, button: Button::Secondary }).unwrap();
        session.render(0.0).unwrap();
        let p = position(&session);
        assert!(p.is_finite() && p.abs().max_element() <= igi_scene::MAX_COORDINATE, "{p}");
    }
    // Drags of the largest floats add up to no more than a scene's coordinates may reach: the
    // light stays where floats hold it instead of vanishing at infinity.
    for dx in [3.4e38, 3.4e38, -3.4e38, 3.4e38, 3.4e38] {
        session.handle(&Input::Drag { dx, dy: 3.4e38, button: Button::Secondary }).unwrap();
        session.render(0.0).unwrap();
        let p = position(&session);
        assert!(p.is_finite() && p.abs().max_element() <= igi_scene::MAX_COORDINATE, "{p}");
    }

    // Bad values are refused in the panel's words; reset puts every light back.
    let err = session.handle(&Input::EditLight { index: 1, intensity: -1.0, colour: [1.0; 3] }).unwrap_err();
    assert_eq!(err.panel_message(), "light: intensity -1 is not between 0 and 1000");
    let err = session.handle(&Input::SelectLight { index: 7 }).unwrap_err();
    assert_eq!(err.panel_message(), "light: the scene has 2 light sources, not 8");
    session.handle(&Input::Reset).unwrap();
    let reset = session.render(0.0).unwrap();
    assert_eq!((reset.stats.lights[1].intensity, reset.stats.lights[1].colour), (1.0, [1.0; 3]));
    assert!((position(&session) - before).length() < 1e-6);
    assert!(reset.image.srgb8() == first.image.srgb8(), "as at the start");
}

#[test]
fn a_listed_scene_opens_in_place_and_nothing_else_does() {
    let mut session = session("cornell-box", |s| s.playing = false);
    let err = session.handle(&Input::Open { name: "animated-room".into() }).unwrap_err();
    assert!(err.panel_message().starts_with("open: this viewer opens no other scenes"), "{err}");
    let names = vec!["cornell-box".to_string(), "animated-room".to_string(), "broken.obj".to_string()];
    let opener: igi_session::SceneOpener = Box::new(|name: &str| match igi_scene::builtin(name) {
        Some(scene) => Ok(PreparedScene::new(scene)),
        None => Err(format!("{name}: cannot load")),
    });
    session.set_catalog(igi_session::SceneCatalog::new(names.clone(), opener), "cornell-box");
    assert_eq!(session.scene_names(), names);
    let cornell = session.render(0.0).unwrap();
    assert_eq!(cornell.stats.scene.as_deref(), Some("cornell-box"));

    // Not in the list: refused before any file is looked at; a failing load changes nothing.
    for (name, message) in [
        ("../../etc/passwd", "open: \"../../etc/passwd\" is not in the list of scenes"),
        ("broken.obj", "open: broken.obj: cannot load"),
    ] {
        let err = session.handle(&Input::Open { name: name.into() }).unwrap_err();
        assert_eq!(err.panel_message(), message);
    }
    assert_eq!(session.render(0.0).unwrap().stats.triangles, cornell.stats.triangles);

    session.handle(&Input::Open { name: "animated-room".into() }).unwrap();
    let room = session.render(0.0).unwrap();
    assert_eq!(room.stats.scene.as_deref(), Some("animated-room"));
    assert_eq!((room.stats.accumulated, room.stats.time), (1, 0.0));
    assert_eq!(room.stats.lights.len(), 2);
    assert_eq!(room.stats.views, ["statue", "high corner"]);
    let start = igi_render::start_camera(session.scene());
    assert!((room.stats.camera.position - start.position).length() < 1e-5, "its own start camera");
    assert_ne!(room.stats.triangles, cornell.stats.triangles);
}

#[test]
fn a_still_view_compensates_the_clamp_and_a_moving_one_does_not() {
    // The Cornell box's creases and contacts are where the clamp removes light: a
    // compensated frame traces compensation rays there, a moving frame none.
    let mut session = session("cornell-box", |s| s.temporal = false);
    let compensation_ms = |frame: &igi_session::Frame| {
        frame.stats.phases_ms.iter().find(|(name, _)| name == "compensation").map_or(0.0, |&(_, ms)| ms)
    };
    let first = session.render(0.01).unwrap();
    assert_eq!(compensation_ms(&first), 0.0, "the first frame of a view is a moving frame");
    let still = session.render(0.01).unwrap();
    assert_eq!(still.stats.accumulated, 2);
    assert!(compensation_ms(&still) > 0.0, "a still view's frame compensates the clamp");
    session.handle(&Input::Drag { dx: 12.0, dy: 0.0, button: Button::Primary }).unwrap();
    let moved = session.render(0.01).unwrap();
    assert_eq!(moved.stats.accumulated, 1);
    assert_eq!(compensation_ms(&moved), 0.0, "a moving frame skips the compensation");
}

#[test]
fn a_still_view_accumulates_with_the_clamp_of_igi_render() {
    // A still view's mean is the mean `igi render --frames N` writes: with the scene's default
    // clamp its frames after the first take the larger clamp of compensation (with the moving
    // frames' d_min its near-field spots stayed in the mean: blotch10 2-5x that of
    // `igi render`'s at 16 frames), while a clamp the user chose is kept.
    use igi_render::FrameSettings;
    for temporal in [false, true] {
        for user_clamp in [None, Some(0.3)] {
            let scene = PreparedScene::new(igi_scene::builtin("cornell-box").unwrap());
            let diagonal = scene.bounds().diagonal();
            let camera = *scene.camera().unwrap();
            let mut settings = settings(&scene);
            settings.temporal = temporal;
            if let Some(clamp) = user_clamp {
                settings.frame.clamp = clamp;
            }
            let (outcomes, rendered) = std::sync::mpsc::channel();
            let source = Reporting { renderer: FrameRenderer::new(2), outcomes };
            let mut session = Session::with_source(scene, camera, settings, Box::new(source)).unwrap();
            for _ in 0..3 {
                session.render(0.01).unwrap();
            }
            let clamps: Vec<(f32, bool)> =
                rendered.try_iter().map(|(s, _)| (s.clamp, s.compensate_clamp)).collect();
            let moving = user_clamp.unwrap_or(FrameSettings::clamp_for(diagonal));
            let still = user_clamp.unwrap_or(FrameSettings::compensated_clamp_for(diagonal));
            assert_eq!(clamps, [(moving, false), (still, true), (still, true)], "temporal {temporal}");
        }
    }
}

#[test]
fn the_viewers_tone_map_follows_the_frames_tone_curve() {
    // `--tone-map` reaches the viewers: the automatic tone map is the frame's curve (filmic
    // by default), with the panel's key; a fixed exposure replaces it.
    use igi_render::ToneMap;
    use igi_render::image::tonemap::ToneCurve;
    let mut settings = ViewerSettings::for_scene(1.0);
    assert_eq!(settings.tone_map(), ToneMap::Filmic { key: settings.key });
    settings.frame.tone_curve = ToneCurve::Reinhard;
    settings.key = 0.25;
    assert_eq!(settings.tone_map(), ToneMap::Reinhard { key: 0.25 });
    settings.exposure = Some(1.0);
    assert_eq!(settings.tone_map(), ToneMap::Exposure { stops: 1.0 });
}
