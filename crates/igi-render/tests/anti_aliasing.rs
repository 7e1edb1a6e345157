//! Anti-aliasing at the cost of primary rays (paper 3.3; ARCHITECTURE.md, "Anti-aliasing"): a
//! pixel whose N samples all see one surface is shaded and lit once, by its whole VPL set; the
//! samples still decide where geometry and hard shadows cross the pixel.

mod common;

use common::*;
use glam::Vec3;
use igi_render::{FrameRenderer, PinholeCamera};

const SIZE: u32 = 64;

/// A hard shadow's edge across a pixel that sees only the plane is anti-aliased: the exact
/// light is seen from each sample's position, so such a pixel takes 0, 1/4, 1/2, 3/4 or all
/// of the light its samples would get lit, and the pixels along the edge take the fractions
/// between. With one ray per pixel there are none.
#[test]
fn hard_shadow_edges_stay_anti_aliased_where_a_pixel_is_shaded_once() {
    let (mut scene, camera, lit) = blocker_case();
    let pin = PinholeCamera::new(&camera, SIZE, SIZE);
    // Pixels near the shadow (|x|, |z| < 0.6; it covers |x|, |z| < 0.4) whose corners and
    // centre all see the plane (no blocker edge inside), with the light their centre would get
    // without the blocker.
    let plane_pixels: Vec<(usize, Vec3)> = (0..SIZE * SIZE)
        .filter_map(|i| {
            let (x, y) = (i % SIZE, i / SIZE);
            let points = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)];
            let hits = points.map(|(dx, dy)| scene.accel().intersect(&pin.ray_at(x, y, dx, dy)));
            let ray = pin.ray_at(x, y, 0.5, 0.5);
            let p = ray.origin + ray.dir * hits[4].t;
            let near = p.x.abs() < 0.6 && p.z.abs() < 0.6;
            (near && hits.iter().all(|h| h.is_hit() && h.instance == 0)).then(|| (i as usize, lit(p)))
        })
        .collect();
    assert!(plane_pixels.len() > 200, "{} pixels", plane_pixels.len());

    let mut fractions = |aa: u32| -> Vec<f32> {
        let mut frame = igi_frame(camera, SIZE, SIZE);
        frame.settings.aa = aa;
        let film = render_igi(&mut scene, &frame);
        plane_pixels.iter().map(|&(i, l)| film.pixels()[i].x / l.x).collect()
    };
    let between = |f: &[f32]| f.iter().filter(|&&f| (0.1..0.9).contains(&f)).count();

    let aa4 = fractions(4);
    for &f in &aa4 {
        // The light varies by well under 3 % across a pixel here.
        let quarter = (f * 4.0).round() / 4.0;
        assert!((0.0..=1.0).contains(&quarter) && (f - quarter).abs() < 0.03, "fraction {f} of the light");
    }
    // The shadow's outline is about 100 pixels long in this view.
    assert!(between(&aa4) >= 30, "{} pixels of the shadow's edge are partly lit", between(&aa4));
    let aa1 = fractions(1);
    assert_eq!(between(&aa1), 0, "one ray per pixel sees each pixel lit or not");
}

/// N samples per pixel cost N primary rays, but a pixel whose samples see one surface is one
/// shading point: the clamp's bias compensation, one ray per shading point, traces about as
/// many rays at aa 4 as at aa 1 (more only along edges and creases).
#[test]
fn a_pixel_that_sees_one_surface_is_shaded_once() {
    let scene = igi_scene::builtin("cornell-box").expect("built-in cornell-box");
    let camera = scene.camera.expect("the Cornell box has its camera");
    let mut scene = igi_render::PreparedScene::new(scene);
    let renderer = FrameRenderer::new(2);
    let mut rays = |aa: u32| {
        let mut frame = igi_frame(camera, SIZE, SIZE);
        frame.settings.aa = aa;
        frame.settings.clamp = 0.1;
        frame.settings.compensate_clamp = true;
        renderer.render(&mut scene, &frame, &|_, _| {}).expect("valid settings").rays
    };
    let (one, four) = (rays(1), rays(4));
    assert_eq!(four.primary, 4 * one.primary);
    let ratio = four.compensation as f64 / one.compensation as f64;
    assert!((0.9..1.3).contains(&ratio), "compensation rays at aa 4 / aa 1: {ratio}");
}
