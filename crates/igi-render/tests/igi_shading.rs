//! Surface shaders in both renderers: the built-in procedural room (marble, wood, brick with
//! bump, checker, glossy turbulence) converged with instant global illumination against the
//! path tracer, which reaches the same shader parameters one hit at a time.

mod common;

use common::*;
use igi_render::PreparedScene;
use igi_render::image::tonemap::luminance;

#[test]
fn converged_igi_matches_the_path_tracer_in_the_procedural_room() {
    let scene = igi_scene::builtin("procedural-room").expect("built-in procedural-room");
    let camera = scene.camera.expect("the room has its camera");
    let mut scene = PreparedScene::new(scene);
    let (mi, mp) = converged_means(&mut scene, camera, 32, 128, 256);
    eprintln!("procedural room: IGI {mi}, PT {mp}, ratio {}", luminance(mi) / luminance(mp));
    assert!(rel_err(mi, mp) < 0.03, "IGI mean {mi}, path-traced mean {mp}");
}
