//! The built-in `two-rooms` scene is the hard case it is meant to be (issue 16): its camera
//! sees no surface the lamp lights directly, so every pixel it shows is indirect light, and
//! instant radiosity still lights all of it.

mod common;

use common::*;
use igi_render::image::tonemap::luminance;
use igi_render::{FrameState, PreparedScene};

fn frame(scene: &PreparedScene, bounces: u32) -> FrameState {
    let mut frame = igi_frame(*scene.camera().expect("a built-in camera"), 160, 120);
    frame.settings.bounces = bounces;
    frame
}

#[test]
fn the_camera_sees_only_indirect_light_and_all_of_it_is_lit() {
    let mut scene = PreparedScene::new(igi_scene::builtin("two-rooms").unwrap());
    let direct_only = frame(&scene, 0);
    let direct = render_igi(&mut scene, &direct_only);
    assert!(direct.pixels().iter().all(|&p| p == glam::Vec3::ZERO), "a directly lit surface is in view");
    let bounced = frame(&scene, igi_render::FrameSettings::default().bounces);
    let lit = render_igi(&mut scene, &bounced);
    let lit_pixels = lit.pixels().iter().filter(|&&p| luminance(p) > 0.0).count();
    assert!(
        lit_pixels as f64 >= 0.99 * lit.pixels().len() as f64,
        "{lit_pixels} of {} pixels lit by bounced light",
        lit.pixels().len()
    );
}
