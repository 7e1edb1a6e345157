//! Glossy surfaces in the instant-global-illumination renderer: the 8-wide modified Phong BRDF
//! shader of the VPL loop against its closed form, and glossy VPLs (whose emission follows the
//! BRDF at the VPL) against the path tracer, which samples the same lobes one direction at a
//! time.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_render::lights::luminance;
use igi_render::vpl::VplSets;
use igi_render::{PinholeCamera, PreparedScene};
use igi_scene::{Light, Material};
use std::f32::consts::PI;

/// The glossy plane's lobes.
const RHO_D: f32 = 0.3;
const RHO_S: f32 = 0.5;
const EXPONENT: f32 = 40.0;

fn glossy(name: &str) -> Material {
    Material {
        name: name.into(),
        diffuse: Vec3::splat(RHO_D),
        glossy: Vec3::splat(RHO_S),
        exponent: EXPONENT,
        ..Material::default()
    }
}

/// Where the ray from `origin` along `d` meets the plane y = 0 inside |x|, |z| < `half`.
fn floor_point(origin: Vec3, d: Vec3, half: f32) -> Option<Vec3> {
    (d.y < 0.0).then(|| origin - origin.y / d.y * d).filter(|p| p.x.abs() < half && p.z.abs() < half)
}

#[test]
fn point_light_highlight_on_a_glossy_plane_matches_the_closed_form() {
    // One frame, pixel-centre rays, no filter: a point light over a plane that cannot light
    // itself is exact, so every pixel is (ρ_d/π + ρ_s (n+2)/(2π) cosⁿα) I cos θ / d², with α
    // between the light direction and the mirror direction of the view direction. The camera
    // looks at the highlight, so the glossy term dominates near its centre.
    let light = Vec3::new(0.0, 1.5, -1.0);
    let intensity = Vec3::new(2.0, 1.5, 1.0);
    let mut prepared = PreparedScene::new(scene(
        vec![horizontal_square("plane", Vec3::ZERO, Vec2::new(10.0, 10.0), true, 0)],
        vec![glossy("plane")],
        vec![Light::Point { position: light, intensity }],
    ));
    let eye = Vec3::new(0.0, 1.5, 1.0);
    let cam = camera(eye, Vec3::ZERO, 50.0);
    let (w, h) = (48, 36);
    let mut frame = igi_frame(cam, w, h);
    frame.settings.aa = 1;
    frame.settings.filter = None;
    let film = render_igi(&mut prepared, &frame);
    let pin = PinholeCamera::new(&cam, w, h);
    let (mut checked, mut highlight) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let Some(p) = floor_point(eye, pin.direction(x, y), 9.0) else { continue };
            let (wo, l) = ((eye - p).normalize(), light - p);
            let wi = l.normalize();
            let r = Vec3::new(-wo.x, wo.y, -wo.z);
            let cos_alpha = r.dot(wi).max(0.0);
            let lobe = (EXPONENT + 2.0) / (2.0 * PI) * cos_alpha.powf(EXPONENT);
            let want = (RHO_D / PI + RHO_S * lobe) * intensity * wi.y / l.length_squared();
            let got = film.get(x, y);
            assert!(rel_err(got, want) < 1e-4, "pixel ({x}, {y}) at {p}: got {got}, want {want}");
            checked += 1;
            highlight += usize::from(RHO_S * lobe > 2.0 * RHO_D / PI);
        }
    }
    assert!(checked > 1000 && highlight > 20, "{checked} pixels, {highlight} in the highlight");
}

#[test]
fn a_vpl_on_a_glossy_surface_carries_its_lobe_around_the_mirror_direction() {
    // A point light straight above a glossy floor: every first-bounce VPL on the floor has
    // diffuse power Φ·ρ_d, glossy power Φ·ρ_s (in that ratio) and its lobe axis is the mirror
    // direction of the direction back to the light.
    let light = Vec3::new(0.2, 2.0, -0.3);
    let prepared = PreparedScene::new(scene(
        vec![horizontal_square("floor", Vec3::ZERO, Vec2::new(4.0, 4.0), true, 0)],
        vec![glossy("floor")],
        vec![Light::Point { position: light, intensity: Vec3::splat(1.0) }],
    ));
    let frame = igi_frame(camera(Vec3::new(0.0, 2.0, 3.0), Vec3::ZERO, 50.0), 32, 32);
    let vpls = VplSets::generate(&prepared, &frame);
    let mut seen = 0;
    for s in 0..vpls.set_count() {
        for vpl in vpls.set(s) {
            assert!(vpl.is_glossy());
            assert!((vpl.glossy.x / vpl.power.x - RHO_S / RHO_D).abs() < 1e-4, "{vpl:?}");
            let to_light = (light - vpl.position).normalize();
            let mirror = Vec3::new(-to_light.x, to_light.y, -to_light.z);
            assert!(vpl.axis.dot(mirror) > 1.0 - 1e-5, "axis {} vs mirror {mirror}", vpl.axis);
            assert_eq!(vpl.exponent, EXPONENT);
            seen += 1;
        }
    }
    assert!(seen > 50, "{seen} VPLs");
}

/// The built-in Cornell box with glossy white walls, floor and boxes: half their reflectance
/// moved into a Phong lobe of exponent 20.
fn glossy_cornell() -> (PreparedScene, igi_scene::Camera) {
    let mut scene = igi_scene::builtin("cornell-box").expect("built-in cornell-box");
    for m in &mut scene.materials {
        if !m.is_emissive() {
            m.glossy = 0.5 * m.diffuse;
            m.diffuse *= 0.5;
            m.exponent = 20.0;
        }
    }
    let camera = scene.camera.expect("the Cornell box has its camera");
    (PreparedScene::new(scene), camera)
}

#[test]
fn converged_igi_with_glossy_vpls_matches_the_path_tracer() {
    // Glossy receivers and glossy VPLs: unclamped IGI is unbiased (up to the bounce cap), so
    // its converged image mean must match the path tracer's, which reaches the same lobes by
    // sampling. Dropping the VPLs' lobes (treating them as Lambertian emitters) changes the
    // indirect light by more than the tolerance.
    let (mut scene, camera) = glossy_cornell();
    let (mi, mp) = converged_means(&mut scene, camera, 32, 256, 512);
    eprintln!("glossy Cornell: IGI {mi}, PT {mp}, ratio {}", luminance(mi) / luminance(mp));
    assert!(rel_err(mi, mp) < 0.03, "IGI mean {mi}, path-traced mean {mp}");
}
