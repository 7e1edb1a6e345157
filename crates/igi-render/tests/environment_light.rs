//! The environment (sky) light in both renderers: a Lambertian plane under a uniform sky sees
//! the whole upper hemisphere, so it reflects exactly L = ρ · L_sky; rays that leave the scene
//! see the sky itself.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_render::FrameSource;
use igi_render::{FrameRenderer, PinholeCamera, PreparedScene};
use igi_scene::Environment;

const RHO: f32 = 0.6;
const SKY: Vec3 = Vec3::new(0.4, 0.6, 1.0);

/// A 20 × 20 plane under a uniform sky, seen from above at an angle so that the top rows of
/// the image see the sky.
fn plane_under_sky() -> (PreparedScene, igi_scene::Camera) {
    let mut sc = scene(
        vec![horizontal_square("plane", Vec3::ZERO, Vec2::new(10.0, 10.0), true, 0)],
        vec![diffuse("grey", RHO)],
        vec![],
    );
    sc.environment = Some(Environment::Constant { radiance: SKY });
    (PreparedScene::new(sc), camera(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.6, 0.0), 60.0))
}

/// Mean of the plane pixels (centre ray on the plane well inside its edge) and of the sky
/// pixels (centre ray above the horizon).
fn plane_and_sky_means(film: &igi_render::Film, cam: &igi_scene::Camera) -> (Vec3, Vec3, usize, usize) {
    let pin = PinholeCamera::new(cam, film.width(), film.height());
    let (mut plane, mut sky, mut np, mut ns) = (Vec3::ZERO, Vec3::ZERO, 0, 0);
    for y in 0..film.height() {
        for x in 0..film.width() {
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
            let dirs = corners.map(|(dx, dy)| pin.direction_at(x, y, dx, dy));
            if dirs.iter().all(|d| hit_floor(cam.position, *d, 8.0).is_some()) {
                plane += film.get(x, y);
                np += 1;
            } else if dirs.iter().all(|d| d.y > 0.0) {
                sky += film.get(x, y);
                ns += 1;
            }
        }
    }
    (plane / np as f32, sky / ns as f32, np, ns)
}

#[test]
fn igi_plane_under_a_uniform_sky_reflects_rho_times_the_sky() {
    // Sky VPLs (directional samples of the sky) light the plane; accumulated over frames they
    // converge to the hemisphere integral ρ/π · L · π = ρ L.
    let (mut scene, cam) = plane_under_sky();
    let frame = igi_frame(cam, 40, 30);
    let film = FrameRenderer::new(2)
        .render_accumulated(&mut scene, &frame, 64, &|_, _| {})
        .expect("valid settings")
        .image
        .into_film()
        .unwrap();
    let (plane, sky, np, ns) = plane_and_sky_means(&film, &cam);
    assert!(np > 300 && ns > 100, "{np} plane and {ns} sky pixels");
    assert!(rel_err(sky, SKY) < 1e-5, "the sky seen directly: {sky}");
    assert!(rel_err(plane, RHO * SKY) < 0.02, "plane {plane}, want {}", RHO * SKY);
}

#[test]
fn path_traced_plane_under_a_uniform_sky_reflects_rho_times_the_sky() {
    let (mut scene, cam) = plane_under_sky();
    let frame = igi_frame(cam, 40, 30);
    let (film, _) = path_traced(&mut scene, &frame, 64, 2);
    let (plane, sky, _, _) = plane_and_sky_means(&film, &cam);
    assert!(rel_err(sky, SKY) < 1e-5, "the sky seen directly: {sky}");
    assert!(rel_err(plane, RHO * SKY) < 0.01, "plane {plane}, want {}", RHO * SKY);
}
