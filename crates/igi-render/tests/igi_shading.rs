//! Surface shaders in both renderers: the built-in procedural room (marble, wood, brick with
//! bump, checker, glossy turbulence) converged with instant global illumination against the
//! path tracer, which reaches the same shader parameters one hit at a time.

mod common;

use common::*;
use glam::Vec3;
use igi_render::lights::luminance;
use igi_render::path_tracer::render_path_traced;
use igi_render::{FrameRenderer, PreparedScene};

fn mean(film: &igi_render::Film) -> Vec3 {
    film.pixels().iter().sum::<Vec3>() / film.pixels().len() as f32
}

#[test]
fn converged_igi_matches_the_path_tracer_in_the_procedural_room() {
    let scene = igi_scene::builtin("procedural-room").expect("built-in procedural-room");
    let camera = scene.camera.expect("the room has its camera");
    let mut scene = PreparedScene::new(scene);
    const SIZE: u32 = 32;
    let renderer = FrameRenderer::new(2);
    let frame = igi_frame(camera, SIZE, SIZE);
    let (pt, _) = render_path_traced(&mut scene, &frame, 256, renderer.scheduler(), &|_, _| {});
    let igi = renderer
        .render_accumulated(&mut scene, &frame, 128, &|_, _| {})
        .expect("valid settings")
        .image
        .into_film()
        .unwrap();
    let (mi, mp) = (mean(&igi), mean(&pt));
    eprintln!("procedural room: IGI {mi}, PT {mp}, ratio {}", luminance(mi) / luminance(mp));
    assert!(rel_err(mi, mp) < 0.03, "IGI mean {mi}, path-traced mean {mp}");
}
