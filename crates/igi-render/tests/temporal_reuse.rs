//! Temporal reuse (issue 32): the history follows the camera and moved objects, is refused where
//! a surface comes into view or is seen from its other side, and a still view's history is the
//! plain mean of its frames. Frames here are constant images, so every pixel's value says
//! exactly how many frames and which ones it averages. A frame's diffuse layer is what the
//! history carries across a move; the rest of its radiance comes from the new frame.

use glam::{Affine3A, Vec3};
use igi_render::{
    DiffuseLayer, Film, FrameRenderer, FrameSettings, FrameState, Motion, PinholeCamera, PixelFormat,
    PreparedScene, ScenePose, SurfaceBuffer, TemporalHistory,
};
use igi_scene::Camera;

const W: u32 = 96;
const H: u32 = 72;

fn constant(value: f32) -> Film {
    Film::from_pixels(W, H, vec![Vec3::splat(value); (W * H) as usize])
}

fn room() -> (PreparedScene, Camera) {
    let scene = PreparedScene::new(igi_scene::builtin("animated-room").expect("a built-in scene"));
    let camera = *scene.camera().expect("the room has a camera");
    (scene, camera)
}

fn surfaces(scene: &PreparedScene, camera: &Camera) -> SurfaceBuffer {
    SurfaceBuffer::trace(scene, PinholeCamera::new(camera, W, H))
}

#[test]
fn a_still_views_history_is_the_mean_of_its_frames() {
    let (scene, camera) = room();
    let mut history = TemporalHistory::new();
    history.add(&constant(1.0), None, Motion::Moved(surfaces(&scene, &camera)), f32::INFINITY);
    history.add(&constant(2.0), None, Motion::Still, f32::INFINITY);
    let mean = history.add(&constant(6.0), None, Motion::Still, f32::INFINITY);
    assert!(mean.pixels().iter().all(|&p| p == Vec3::splat(3.0)), "(1 + 2 + 6) / 3");
    assert_eq!((history.kept(), history.mean_frames()), (1.0, 3.0));
    // A moving view's history stands for at most the caller's limit of frames.
    let limited = history.add(&constant(0.0), None, Motion::Still, 1.0);
    assert!(limited.pixels().iter().all(|&p| p == Vec3::splat(1.5)), "(3 + 0) / 2");
}

#[test]
fn the_history_follows_the_camera_and_is_refused_where_surfaces_come_into_view() {
    let (scene, camera) = room();
    let mut history = TemporalHistory::new();
    history.add(&constant(2.0), None, Motion::Moved(surfaces(&scene, &camera)), 15.0);
    // Step sideways: most of what the camera saw is still in view, a strip at one side is new.
    let right = (camera.target - camera.position).cross(camera.up).normalize();
    let step = 0.02 * scene.bounds().diagonal() * right;
    let moved = Camera { position: camera.position + step, target: camera.target + step, ..camera };
    let out = history.add(&constant(4.0), None, Motion::Moved(surfaces(&scene, &moved)), 15.0);
    // Either the mean of both frames or the new frame alone (a new surface, or a silhouette
    // where the history is clamped into the new frame's neighbourhood): nothing else.
    assert!(out.pixels().iter().all(|p| (p.x - 3.0).abs() < 1e-5 || p.x == 4.0));
    let kept = out.pixels().iter().filter(|p| (p.x - 3.0).abs() < 1e-5).count() as f64 / f64::from(W * H);
    assert!(
        history.kept() > 0.8 && kept > 0.6 && history.kept() < 1.0,
        "{} kept, {kept} blended",
        history.kept()
    );
}

#[test]
fn a_moved_object_carries_its_history_and_leaves_no_ghost() {
    let (mut scene, camera) = room();
    let buffer = |scene: &PreparedScene| surfaces(scene, &camera);
    let before = buffer(&scene);
    // The first frame: the statue 10, everything else 2.
    let first = Film::from_pixels(
        W,
        H,
        before.instance.iter().map(|&i| Vec3::splat(if i == 1 { 10.0 } else { 2.0 })).collect(),
    );
    let mut history = TemporalHistory::new();
    history.add(&first, None, Motion::Moved(before.clone()), 15.0);
    // The statue (instance 1) moves sideways.
    let right = (camera.target - camera.position).cross(camera.up).normalize();
    let offset = 0.05 * scene.bounds().diagonal() * right;
    scene.pose(&ScenePose { moved: vec![(1, Affine3A::from_translation(offset))], ..ScenePose::at(0.0) });
    let after = buffer(&scene);
    let out = history.add(&constant(4.0), None, Motion::Moved(after.clone()), 15.0);
    let (mut statue_kept, mut statue, mut uncovered, mut ghost) = (0, 0, 0, 0);
    for i in 0..(W * H) as usize {
        let value = out.pixels()[i].x;
        if after.instance[i] == 1 {
            // The statue's history moved with it: (10 + 4) / 2 where it was kept.
            statue += 1;
            statue_kept += usize::from((value - 7.0).abs() < 1e-5);
        } else if before.instance[i] == 1 {
            // Where the statue stood and no longer does: the background came into view, with
            // the background's history (3) or none (4), never the statue's.
            uncovered += 1;
            ghost += usize::from(value > 3.0 + 1e-5 && value != 4.0);
        }
    }
    assert!(statue > 50 && uncovered > 20, "{statue} statue pixels, {uncovered} uncovered");
    assert_eq!(ghost, 0, "{ghost} of {uncovered} uncovered pixels show the statue's history");
    assert!(
        statue_kept as f64 > 0.5 * f64::from(statue),
        "{statue_kept} of {statue} statue pixels kept their history"
    );
}

#[test]
fn only_the_diffuse_layer_crosses_a_move_and_the_rest_is_averaged_while_still() {
    let (scene, camera) = room();
    let layer = |v: f32| DiffuseLayer(constant(v));
    let mut history = TemporalHistory::new();
    // Radiance 5 of which the layer is 2 (the rest, say a glossy highlight, 3).
    history.add(&constant(5.0), Some(&layer(2.0)), Motion::Moved(surfaces(&scene, &camera)), 15.0);
    // The view moves a little: the layer's history is carried (2 + 4) / 2, the rest is the new
    // frame's own 5, never the 3 an earlier view saw.
    let right = (camera.target - camera.position).cross(camera.up).normalize();
    let step = 0.01 * scene.bounds().diagonal() * right;
    let moved = Camera { position: camera.position + step, target: camera.target + step, ..camera };
    let out = history.add(&constant(9.0), Some(&layer(4.0)), Motion::Moved(surfaces(&scene, &moved)), 15.0);
    let kept = out.pixels().iter().filter(|p| (p.x - 8.0).abs() < 1e-5).count();
    assert!(
        out.pixels().iter().all(|p| (p.x - 8.0).abs() < 1e-5 || p.x == 9.0),
        "3 + 5 or the new frame alone"
    );
    assert!(kept as f64 > 0.6 * f64::from(W * H), "{kept} pixels kept the layer's history");
    // The view stands still: both parts are averaged in place, the layer over all three
    // frames (2 + 4 + 4) / 3, the rest over the frames since the move (5 + 3) / 2.
    let still = history.add(&constant(7.0), Some(&layer(4.0)), Motion::Still, f32::INFINITY);
    let expected = 10.0 / 3.0 + 4.0;
    assert!(still.pixels().iter().any(|p| (p.x - expected).abs() < 1e-5), "kept pixels average both parts");
}

#[test]
fn a_layered_frame_has_the_same_radiance_and_its_layer_holds_no_emission() {
    let mut scene = PreparedScene::new(igi_scene::builtin("cornell-box").expect("a built-in scene"));
    let camera = *scene.camera().expect("the box has a camera");
    let settings =
        FrameSettings { width: 64, height: 64, aa: 1, clamp: 0.0, seed: 5, ..FrameSettings::default() };
    let linear = FrameState::new(camera, settings);
    let layered = FrameState { pixels: PixelFormat::Layered, ..linear.clone() };
    let renderer = FrameRenderer::new(2);
    let a = renderer.render(&mut scene, &linear, &|_, _| {}).unwrap().image;
    let b = renderer.render(&mut scene, &layered, &|_, _| {}).unwrap().image;
    assert_eq!(a.film().unwrap().pixels(), b.film().unwrap().pixels(), "the layer changes no pixel");
    assert!(a.diffuse_layer().is_none(), "a linear frame carries no layer");
    let DiffuseLayer(layer) = b.diffuse_layer().expect("a layered IGI frame has its layer");
    let radiance = b.film().unwrap().pixels();
    // The layer is part of the radiance, and most of it on the box's diffuse walls ...
    let (mut walls, mut lit) = (0, 0);
    for (&l, &r) in layer.pixels().iter().zip(radiance) {
        assert!(l.cmple(r + Vec3::splat(1e-4)).all(), "layer {l} above its radiance {r}");
        if r.max_element() > 0.0 && r.max_element() < 1.0 {
            walls += 1;
            lit += usize::from(l.max_element() > 0.5 * r.max_element());
        }
    }
    assert!(
        walls > 1000 && lit as f64 > 0.8 * walls as f64,
        "{lit} of {walls} wall pixels are mostly VPL light"
    );
    // ... but the lamp's own emission is not in it: the brightest pixels are the lamp's.
    let brightest = (0..radiance.len()).max_by(|&i, &j| radiance[i].x.total_cmp(&radiance[j].x)).unwrap();
    assert!(layer.pixels()[brightest].max_element() < 0.1 * radiance[brightest].max_element());
}

#[test]
fn the_exact_lights_diffuse_light_is_in_the_layer_and_highlights_are_not() {
    // The room's point light lights diffuse walls and a glossy statue.
    let (mut scene, camera) = room();
    let settings = FrameSettings { width: 64, height: 48, aa: 1, seed: 2, ..FrameSettings::default() };
    let frame = FrameState { pixels: PixelFormat::Layered, ..FrameState::new(camera, settings) };
    let out = FrameRenderer::new(2).render(&mut scene, &frame, &|_, _| {}).unwrap().image;
    let DiffuseLayer(layer) = out.diffuse_layer().expect("a layered IGI frame has its layer");
    // Reflected light (below the lamp's emission): all in the layer on diffuse surfaces, the
    // point light's included; on the statue its glossy part is not.
    let (mut reflected, mut all_layer) = (0, 0);
    for (&l, &r) in layer.pixels().iter().zip(out.film().unwrap().pixels()) {
        if r.max_element() > 0.0 && r.max_element() < 5.0 {
            reflected += 1;
            all_layer += usize::from((l - r).abs().max_element() <= 1e-4 * r.max_element());
        }
    }
    let glossy = reflected - all_layer;
    assert!(
        reflected > 2000 && all_layer as f64 > 0.9 * reflected as f64 && glossy > 20,
        "{all_layer} of {reflected} reflecting pixels are all layer, {glossy} have glossy light"
    );
}
