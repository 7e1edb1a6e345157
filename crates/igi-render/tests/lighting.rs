//! Physics of the direct-lighting renderer against closed-form answers: point, spot and
//! directional lights on a Lambertian plane, a rectangular area light (form factor), shadows,
//! directly visible emitters and the headlight of a scene without lights.

mod common;

use common::*;
use glam::{Affine3A, Quat, Vec2, Vec3};
use igi_render::{PinholeCamera, PreparedScene, RenderSettings, lights::eye_light, render};
use igi_scene::{Instance, Light, Scene};
use std::f32::consts::PI;

const RHO: f32 = 0.5;

/// A 20 × 20 grey plane at y = 0 facing up, plus `extra` meshes (materials 1..).
fn plane_scene(
    extra: Vec<igi_scene::Mesh>,
    mut materials: Vec<igi_scene::Material>,
    lights: Vec<Light>,
) -> Scene {
    let mut meshes =
        vec![horizontal_square("plane", Vec3::new(0.0, 0.0, 0.0), Vec2::new(10.0, 10.0), true, 0)];
    meshes.extend(extra);
    materials.insert(0, diffuse("grey", RHO));
    scene(meshes, materials, lights)
}

fn settings(width: u32, height: u32, samples: u32) -> RenderSettings {
    RenderSettings { width, height, samples, threads: 2, ..RenderSettings::default() }
}

/// Calls `f(x, y, p)` for every pixel whose centre ray hits the plane y = 0 at `p` (computed
/// analytically), within `|p.x|, |p.z| < 9`.
fn for_plane_pixels(cam: &PinholeCamera, mut f: impl FnMut(u32, u32, Vec3)) -> usize {
    let mut n = 0;
    for y in 0..cam.height {
        for x in 0..cam.width {
            let d = cam.direction(x, y);
            if d.y >= 0.0 {
                continue;
            }
            let t = -cam.origin.y / d.y;
            let p = cam.origin + t * d;
            if p.x.abs() < 9.0 && p.z.abs() < 9.0 {
                f(x, y, p);
                n += 1;
            }
        }
    }
    n
}

#[test]
fn point_light_matches_inverse_square_law() {
    let light_pos = Vec3::new(0.3, 2.0, -0.2);
    let intensity = Vec3::new(3.0, 2.0, 1.0);
    let prepared = PreparedScene::new(plane_scene(
        vec![],
        vec![],
        vec![Light::Point { position: light_pos, intensity }],
    ));
    let cam = camera(Vec3::new(0.0, 3.0, 4.0), Vec3::ZERO, 40.0);
    let s = settings(64, 48, 4);
    let film = render(&prepared, &cam, &s);
    let pin = PinholeCamera::new(&cam, s.width, s.height);
    let n = for_plane_pixels(&pin, |x, y, p| {
        let l = light_pos - p;
        let cos = l.y / l.length();
        let want = RHO / PI * intensity * cos / l.length_squared();
        let got = film.get(x, y);
        assert!(rel_err(got, want) < 1e-3, "pixel ({x}, {y}) at {p}: got {got}, want {want}");
    });
    assert!(n > 1000, "the plane should fill most of the image, saw {n} pixels");
}

#[test]
fn directional_light_gives_rho_over_pi_e_cos() {
    let direction = Vec3::new(0.3, -1.0, 0.2).normalize();
    let irradiance = Vec3::new(2.0, 1.5, 1.0);
    let prepared =
        PreparedScene::new(plane_scene(vec![], vec![], vec![Light::Directional { direction, irradiance }]));
    let cam = camera(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.0, -1.0), 50.0);
    let s = settings(48, 32, 1);
    let film = render(&prepared, &cam, &s);
    let want = RHO / PI * irradiance * -direction.y;
    let n = for_plane_pixels(&PinholeCamera::new(&cam, s.width, s.height), |x, y, _| {
        let got = film.get(x, y);
        assert!(rel_err(got, want) < 1e-3, "pixel ({x}, {y}): got {got}, want {want}");
    });
    assert!(n > 500);
}

#[test]
fn spot_light_lights_its_cone_only() {
    let light_pos = Vec3::new(0.0, 2.0, 0.0);
    let intensity = Vec3::splat(5.0);
    // Full opening 60°: the cone meets the plane at radius 2 tan 30° = 1.155.
    let spot = Light::Spot { position: light_pos, direction: -Vec3::Y, angle_deg: 60.0, intensity };
    let prepared = PreparedScene::new(plane_scene(vec![], vec![], vec![spot]));
    let cam = camera(Vec3::new(0.0, 4.0, 3.0), Vec3::ZERO, 50.0);
    let s = settings(64, 48, 1);
    let film = render(&prepared, &cam, &s);
    let (mut inside, mut outside) = (0, 0);
    for_plane_pixels(&PinholeCamera::new(&cam, s.width, s.height), |x, y, p| {
        let r = (p.x * p.x + p.z * p.z).sqrt();
        let got = film.get(x, y);
        if r < 1.05 {
            let l = light_pos - p;
            let want = RHO / PI * intensity * (l.y / l.length()) / l.length_squared();
            assert!(rel_err(got, want) < 1e-3, "inside the cone at {p}: got {got}, want {want}");
            inside += 1;
        } else if r > 1.25 {
            assert_eq!(got, Vec3::ZERO, "outside the cone at {p}");
            outside += 1;
        }
    });
    assert!(inside > 50 && outside > 50, "inside {inside}, outside {outside}");
}

/// Form factor from a differential area to a parallel rectangle `a` × `b` at distance `h`
/// whose corner lies straight above it (Howell's catalogue, B-3).
fn corner_form_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

#[test]
fn area_light_converges_to_the_form_factor() {
    // A 2 × 1.5 emitter at height 1 facing down, built as a 1 × 0.75 quad scaled by 2 under
    // its instance transform (so the world-space area must come from the transform).
    let le = Vec3::new(4.0, 3.0, 2.0);
    let (half_x, half_z, h) = (1.0f32, 0.75f32, 1.0f32);
    let light_mesh =
        horizontal_square("light", Vec3::new(0.0, 0.0, 0.0), Vec2::new(half_x / 2.0, half_z / 2.0), false, 1);
    let mut sc = plane_scene(vec![light_mesh], vec![emitter("light", le)], vec![]);
    sc.instances[1] = Instance {
        mesh: 1,
        transform: Affine3A::from_scale_rotation_translation(
            Vec3::splat(2.0),
            Quat::IDENTITY,
            Vec3::new(0.0, h, 0.0),
        ),
    };
    let prepared = PreparedScene::new(sc);
    let total_area: f32 = prepared.area_lights().triangles().iter().map(|t| t.area).sum();
    assert!((total_area - 4.0 * half_x * half_z).abs() < 1e-5, "light area {total_area}");

    let cam = camera(Vec3::new(0.0, 0.5, 2.5), Vec3::new(0.0, 0.0, 0.0), 30.0);
    let s = settings(24, 16, 1024);
    let film = render(&prepared, &cam, &s);
    let mut checked = 0;
    let mut worst = 0.0f32;
    for_plane_pixels(&PinholeCamera::new(&cam, s.width, s.height), |x, y, p| {
        // Only points under the light, where the four-corner decomposition applies.
        if p.x.abs() > 0.8 * half_x || p.z.abs() > 0.8 * half_z {
            return;
        }
        let (px, pz, h) = (f64::from(p.x), f64::from(p.z), f64::from(h));
        let (hx, hz) = (f64::from(half_x), f64::from(half_z));
        let f = corner_form_factor(hx - px, hz - pz, h)
            + corner_form_factor(hx + px, hz - pz, h)
            + corner_form_factor(hx - px, hz + pz, h)
            + corner_form_factor(hx + px, hz + pz, h);
        // E = π L_e F, and the Lambertian plane reflects ρ/π E.
        let want = RHO * le * f as f32;
        let e = rel_err(film.get(x, y), want);
        worst = worst.max(e);
        checked += 1;
    });
    assert!(checked > 20, "only {checked} pixels under the light");
    assert!(worst < 0.02, "worst relative error {worst}");
}

#[test]
fn occluded_points_are_black() {
    let light_pos = Vec3::new(0.0, 2.0, 0.0);
    let intensity = Vec3::splat(4.0);
    // A 0.4 × 0.4 blocker half way up: its shadow on the plane is 0.8 × 0.8.
    let blocker = horizontal_square("blocker", Vec3::new(0.0, 1.0, 0.0), Vec2::new(0.2, 0.2), true, 0);
    let prepared = PreparedScene::new(plane_scene(
        vec![blocker],
        vec![],
        vec![Light::Point { position: light_pos, intensity }],
    ));
    let cam = camera(Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, 40.0);
    let s = settings(64, 48, 1);
    let film = render(&prepared, &cam, &s);
    let (mut dark, mut lit) = (0, 0);
    for_plane_pixels(&PinholeCamera::new(&cam, s.width, s.height), |x, y, p| {
        let got = film.get(x, y);
        if p.x.abs() < 0.35 && p.z.abs() < 0.35 {
            assert_eq!(got, Vec3::ZERO, "pixel ({x}, {y}) at {p} is behind the blocker");
            dark += 1;
        } else if p.x.abs() > 0.45 || p.z.abs() > 0.45 {
            let l = light_pos - p;
            let want = RHO / PI * intensity * (l.y / l.length()) / l.length_squared();
            assert!(rel_err(got, want) < 1e-3, "pixel ({x}, {y}) at {p}: got {got}, want {want}");
            lit += 1;
        }
    });
    assert!(dark > 20 && lit > 100, "dark {dark}, lit {lit}");
}

#[test]
fn emitters_show_their_radiance_on_the_front_side_only() {
    let le = Vec3::new(5.0, 4.0, 3.0);
    // A down-facing emitter at y = 1 over the plane.
    let light = horizontal_square("light", Vec3::new(0.0, 1.0, 0.0), Vec2::new(1.0, 1.0), false, 1);
    let prepared = PreparedScene::new(plane_scene(vec![light], vec![emitter("light", le)], vec![]));
    let s = settings(8, 8, 4);
    // From below, looking up at the front side.
    let below = camera(Vec3::new(0.0, 0.2, 0.0), Vec3::new(0.0, 1.0, 0.0), 40.0);
    let film = render(&prepared, &below, &s);
    assert!(film.pixels().iter().all(|&p| p == le), "front side must show L_e exactly");
    // From above, the back side: no emission, black albedo.
    let above = camera(Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 40.0);
    let film = render(&prepared, &above, &s);
    assert!(film.pixels().iter().all(|&p| p == Vec3::ZERO), "back side must be black");
}

#[test]
fn scene_without_lights_gets_a_headlight() {
    let prepared = PreparedScene::new(plane_scene(vec![], vec![], vec![]));
    assert!(!prepared.has_lights());
    let cam = camera(Vec3::new(0.0, 2.0, 2.0), Vec3::ZERO, 45.0);
    let Light::Point { position, intensity } = eye_light(&prepared, &cam) else {
        panic!("headlight is a point light")
    };
    assert_eq!(position, cam.position);
    let s = settings(32, 24, 1);
    let film = render(&prepared, &cam, &s);
    let n = for_plane_pixels(&PinholeCamera::new(&cam, s.width, s.height), |x, y, p| {
        let l = position - p;
        let want = RHO / PI * intensity * (l.y / l.length()) / l.length_squared();
        let got = film.get(x, y);
        assert!(
            got.min_element() > 0.0 && rel_err(got, want) < 1e-3,
            "pixel ({x}, {y}): got {got}, want {want}"
        );
    });
    assert!(n > 100);
}

#[test]
fn instance_transform_moves_shading_normals_and_lights() {
    // A down-facing unit square with down-pointing vertex normals, turned over by a 180°
    // rotation about X and scaled by 10: geometric and shading normals must come out facing up.
    let mesh = horizontal_square("plane", Vec3::new(0.0, 0.0, 0.0), Vec2::new(1.0, 1.0), false, 0);
    let mut sc = scene(vec![mesh], vec![diffuse("grey", RHO)], vec![]);
    sc.meshes[0].normals = Some(vec![-Vec3::Y; 4]);
    sc.instances[0].transform =
        Affine3A::from_scale_rotation_translation(Vec3::splat(10.0), Quat::from_rotation_x(PI), Vec3::ZERO);
    let light_pos = Vec3::new(0.5, 2.0, 0.0);
    let intensity = Vec3::splat(2.0);
    sc.lights.push(Light::Point { position: light_pos, intensity });
    let prepared = PreparedScene::new(sc);
    let cam = camera(Vec3::new(0.0, 3.0, 4.0), Vec3::ZERO, 40.0);
    let s = settings(32, 24, 1);
    let film = render(&prepared, &cam, &s);
    let n = for_plane_pixels(&PinholeCamera::new(&cam, s.width, s.height), |x, y, p| {
        let l = light_pos - p;
        let want = RHO / PI * intensity * (l.y / l.length()) / l.length_squared();
        let got = film.get(x, y);
        assert!(rel_err(got, want) < 1e-3, "pixel ({x}, {y}) at {p}: got {got}, want {want}");
    });
    assert!(n > 300);
}

#[test]
fn diffuse_texture_multiplies_the_albedo() {
    let direction = Vec3::new(0.0, -1.0, 0.0);
    let irradiance = Vec3::splat(2.0);
    let mut sc = plane_scene(vec![], vec![], vec![Light::Directional { direction, irradiance }]);
    sc.meshes[0].uvs = Some(vec![glam::Vec2::ZERO; 4]);
    sc.materials[0].diffuse = Vec3::splat(0.8);
    sc.materials[0].diffuse_texture = Some(0);
    sc.textures.push(igi_scene::Texture {
        name: "flat".into(),
        width: 1,
        height: 1,
        texels: vec![[0.5, 0.25, 1.0, 1.0]],
    });
    let prepared = PreparedScene::new(sc);
    let cam = camera(Vec3::new(0.0, 2.0, 2.0), Vec3::ZERO, 40.0);
    let s = settings(16, 12, 1);
    let film = render(&prepared, &cam, &s);
    let want = Vec3::new(0.4, 0.2, 0.8) / PI * irradiance;
    let n = for_plane_pixels(&PinholeCamera::new(&cam, s.width, s.height), |x, y, _| {
        let got = film.get(x, y);
        assert!(rel_err(got, want) < 1e-5, "pixel ({x}, {y}): got {got}, want {want}");
    });
    assert!(n > 50);
}
