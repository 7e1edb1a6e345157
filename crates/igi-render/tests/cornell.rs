//! The built-in Cornell box end to end: the light shows its emitted radiance, the coloured
//! walls are where they belong, and the image does not depend on the thread count.

use glam::Vec3;
use igi_render::{PinholeCamera, PreparedScene, RenderSettings, render};

fn cornell() -> (PreparedScene, igi_scene::Camera) {
    let scene = igi_scene::builtin("cornell-box").expect("built-in cornell-box");
    let camera = scene.camera.expect("the Cornell box has its camera");
    (PreparedScene::new(scene), camera)
}

#[test]
fn cornell_box_looks_right() {
    let (scene, camera) = cornell();
    assert_eq!(scene.area_lights().len(), 2, "one quad light");
    let area: f32 = scene.area_lights().triangles().iter().map(|t| t.area).sum();
    assert!((area - 0.1786).abs() < 1e-3, "light area {area}");

    let s = RenderSettings { width: 128, height: 128, samples: 16, threads: 2, ..RenderSettings::default() };
    let film = render(&scene, &camera, &s);
    let pin = PinholeCamera::new(&camera, s.width, s.height);

    // The pixel looking at the light's centre (y = 1.98) shows L_e exactly.
    let centre = Vec3::new(-0.005, 1.98, -0.03);
    let d = (centre - camera.position).normalize();
    let (sx, sy) = (d.dot(pin.right) / d.dot(pin.forward), d.dot(pin.up) / d.dot(pin.forward));
    let x = ((sx / (pin.tan_half * pin.aspect) + 1.0) * 0.5 * s.width as f32) as u32;
    let y = ((1.0 - sy / pin.tan_half) * 0.5 * s.height as f32) as u32;
    assert_eq!(film.get(x, y), Vec3::new(17.0, 12.0, 4.0), "light pixel ({x}, {y})");

    // Red wall on the left, green on the right, at mid height.
    let left = film.get(10, 64);
    let right = film.get(117, 64);
    assert!(left.x > 2.0 * left.y && left.x > 0.0, "left wall {left}");
    assert!(right.y > 1.5 * right.x && right.y > 0.0, "right wall {right}");
    // The ceiling is lit only by its own light, which faces away: black in direct light.
    assert_eq!(film.get(64, 1), Vec3::ZERO);
    // Every value is finite and non-negative.
    assert!(film.pixels().iter().all(|p| p.is_finite() && p.min_element() >= 0.0));
}

#[test]
fn cornell_box_is_the_same_for_one_and_two_threads() {
    let (scene, camera) = cornell();
    let s1 = RenderSettings { width: 90, height: 70, samples: 4, threads: 1, ..RenderSettings::default() };
    let s2 = RenderSettings { threads: 2, ..s1.clone() };
    let bits =
        |f: &igi_render::Film| f.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    assert!(bits(&render(&scene, &camera, &s1)) == bits(&render(&scene, &camera, &s2)));
}
