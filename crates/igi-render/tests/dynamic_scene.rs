//! Dynamic scenes: moving the instances of a prepared scene (a top-level rebuild over the same
//! per-mesh BVHs) gives exactly the scene a fresh full build of the moved instances gives:
//! the same hits, the same area lights, the same lights, and so the same image.

use glam::Vec3;
use igi_bvh::Ray;
use igi_render::{FrameRenderer, FrameSettings, FrameState, PreparedScene, ScenePose};
use igi_scene::{Scene, builtin};

/// The animated room with its instances and lights moved to time `t` by hand.
fn posed_copy(t: f32) -> Scene {
    let mut scene = builtin("animated-room").unwrap();
    let pose = scene.animation.pose(t);
    for (i, m) in pose.instances {
        scene.instances[i as usize].transform = m;
    }
    for (i, light) in pose.lights {
        scene.lights[i as usize] = light;
    }
    scene.animation = Default::default();
    scene
}

/// Rays from a grid of points inside the room in many directions.
fn rays() -> Vec<Ray> {
    let mut rays = Vec::new();
    for k in 0..4000u32 {
        let u = (k as f32 * 0.618_034).fract();
        let v = (k as f32 * 0.754_877_7).fract();
        let w = (k as f32 * 0.569_840_3).fract();
        let origin = Vec3::new(-2.5 + 5.0 * u, 0.2 + 2.6 * v, -2.5 + 5.0 * w);
        let (z, phi) = (1.0 - 2.0 * ((k * 7919 % 4000) as f32 + 0.5) / 4000.0, k as f32 * 2.399_963);
        let r = (1.0 - z * z).sqrt();
        rays.push(Ray::new(origin, Vec3::new(r * phi.cos(), z, r * phi.sin())));
    }
    rays
}

#[test]
fn moving_instances_equals_a_fresh_build_of_the_moved_scene() {
    let mut moved = PreparedScene::new(builtin("animated-room").unwrap());
    let rays = rays();
    for t in [0.0, 0.7, 2.5, 3.9, 11.2] {
        moved.pose(&ScenePose::at(t));
        let fresh = PreparedScene::new(posed_copy(t));
        let mut hits_moving_geometry = 0;
        for ray in &rays {
            let (a, b) = (moved.accel().intersect(ray), fresh.accel().intersect(ray));
            assert_eq!((a.t, a.u, a.v, a.instance, a.prim), (b.t, b.u, b.v, b.instance, b.prim), "t = {t}");
            assert_eq!(moved.accel().occluded(ray), fresh.accel().occluded(ray));
            hits_moving_geometry += usize::from(a.t.is_finite() && a.instance > 0);
        }
        assert!(hits_moving_geometry > 50, "the rays see the statue and the lamp ({hits_moving_geometry})");
        assert_eq!(moved.lights(), fresh.lights(), "t = {t}");
        assert_eq!(moved.emissive_triangle_corners(), fresh.emissive_triangle_corners(), "t = {t}");
        assert_eq!(moved.bounds(), fresh.bounds());
    }
}

#[test]
fn a_moved_frame_is_the_frame_of_the_fresh_build() {
    let mut moved = PreparedScene::new(builtin("animated-room").unwrap());
    let mut fresh = PreparedScene::new(posed_copy(1.7));
    let settings =
        FrameSettings { width: 64, height: 48, aa: 1, clamp: 0.1, seed: 3, ..FrameSettings::default() };
    let camera = *fresh.camera().unwrap();
    let frame = FrameState { pose: ScenePose::at(1.7), ..FrameState::new(camera, settings) };
    let renderer = FrameRenderer::new(2);
    let a = renderer.render(&mut moved, &frame, &|_, _| {}).unwrap();
    let b = renderer.render(&mut fresh, &frame, &|_, _| {}).unwrap();
    assert_eq!(a.image.film().unwrap().pixels(), b.image.film().unwrap().pixels());
    // And the scene did move: the frame at another time differs.
    let c = renderer
        .render(&mut moved, &FrameState { pose: ScenePose::at(0.0), ..frame.clone() }, &|_, _| {})
        .unwrap();
    assert_ne!(a.image.film().unwrap().pixels(), c.image.film().unwrap().pixels());
}
