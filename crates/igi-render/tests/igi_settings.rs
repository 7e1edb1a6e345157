//! Bad input never panics: [`FrameSettings::validate`] rejects every out-of-range setting and
//! names its command-line flag, [`FrameRenderer`] returns that error instead of rendering, and
//! odd but valid scenes and cameras (no lights, no geometry, the camera inside a closed box,
//! degenerate or non-finite cameras) give finite images.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_render::frame::{FilterSettings, FrameState, SettingsError, limits};
use igi_render::{FrameError, FrameSource};
use igi_render::{FrameRenderer, FrameSettings, PreparedScene};
use igi_scene::{Camera, Light, Scene};

/// Applies `change` to valid settings and returns the validation error.
fn rejected(change: impl Fn(&mut FrameSettings)) -> SettingsError {
    let mut s = FrameSettings { width: 64, height: 48, ..FrameSettings::default() };
    change(&mut s);
    s.validate().expect_err(&format!("{s:?} should be rejected"))
}

/// A flag and a change of the settings that makes that flag invalid.
type BadCase = (&'static str, Box<dyn Fn(&mut FrameSettings)>);

#[test]
fn validate_rejects_each_bad_setting_and_names_its_flag() {
    assert_eq!(FrameSettings::default().validate(), Ok(()));
    let nan = f32::NAN;
    let cases: Vec<BadCase> = vec![
        ("width", Box::new(|s| s.width = 0)),
        ("width", Box::new(|s| s.width = limits::MAX_SIDE + 1)),
        ("height", Box::new(|s| s.height = 0)),
        ("height", Box::new(|s| s.height = u32::MAX)),
        ("vpls", Box::new(|s| s.vpls_per_pixel = 0)),
        ("vpls", Box::new(|s| s.vpls_per_pixel = limits::MAX_VPLS_PER_PIXEL + 1)),
        ("interleave", Box::new(|s| s.interleave = [0, 3])),
        ("interleave", Box::new(|s| s.interleave = [3, 0])),
        ("interleave", Box::new(|s| s.interleave = [limits::MAX_INTERLEAVE + 1, 1])),
        ("coarse-interleave", Box::new(|s| s.coarse_interleave = 0)),
        ("coarse-interleave", Box::new(|s| s.coarse_interleave = limits::MAX_COARSE_INTERLEAVE + 1)),
        ("aa", Box::new(|s| s.aa = 0)),
        ("aa", Box::new(|s| s.aa = limits::MAX_AA + 1)),
        ("clamp", Box::new(|s| s.clamp = -0.1)),
        ("clamp", Box::new(move |s| s.clamp = nan)),
        ("clamp", Box::new(|s| s.clamp = f32::INFINITY)),
        ("specular-bounces", Box::new(|s| s.specular_bounces = limits::MAX_SPECULAR_BOUNCES + 1)),
        ("tile-size", Box::new(|s| s.tile_size = 0)),
        ("tile-size", Box::new(|s| s.tile_size = limits::MAX_TILE + 1)),
        (
            "filter-normal",
            Box::new(|s| {
                s.set_discontinuity_filter(Some(FilterSettings { min_normal_cos: 1.5, ..Default::default() }))
            }),
        ),
        (
            "filter-normal",
            Box::new(move |s| {
                s.set_discontinuity_filter(Some(FilterSettings { min_normal_cos: nan, ..Default::default() }))
            }),
        ),
        (
            "filter-depth",
            Box::new(|s| {
                s.set_discontinuity_filter(Some(FilterSettings {
                    max_depth_ratio: -1.0,
                    ..Default::default()
                }))
            }),
        ),
        (
            "filter-depth",
            Box::new(move |s| {
                s.set_discontinuity_filter(Some(FilterSettings {
                    max_depth_ratio: nan,
                    ..Default::default()
                }))
            }),
        ),
    ];
    for (field, change) in &cases {
        let e = rejected(change);
        assert_eq!(e.field, *field, "{e}");
        assert!(e.to_string().starts_with(&format!("--{field}: ")), "message should lead with the flag: {e}");
    }
    // The edges of every range are valid.
    let edges = FrameSettings {
        width: limits::MAX_SIDE,
        height: 1,
        vpls_per_pixel: limits::MAX_VPLS_PER_PIXEL,
        interleave: [1, limits::MAX_INTERLEAVE],
        coarse_interleave: limits::MAX_COARSE_INTERLEAVE,
        aa: limits::MAX_AA,
        filter: true,
        filter_normal: -1.0,
        filter_depth: 0.0,
        clamp: 0.0,
        compensate_clamp: true,
        specular_bounces: limits::MAX_SPECULAR_BOUNCES,
        bounces: igi_render::frame::limits::MAX_BOUNCES,
        tile_size: limits::MAX_TILE,
        seed: u32::MAX,
        tone_curve: Default::default(),
    };
    assert_eq!(edges.validate(), Ok(()));
}

/// A grey floor under a point light, seen from above.
fn lit_floor() -> PreparedScene {
    PreparedScene::new(scene(
        vec![horizontal_square("floor", Vec3::ZERO, Vec2::new(2.0, 2.0), true, 0)],
        vec![diffuse("grey", 0.5)],
        vec![Light::Point { position: Vec3::new(0.0, 2.0, 0.0), intensity: Vec3::splat(3.0) }],
    ))
}

fn view() -> Camera {
    camera(Vec3::new(0.0, 2.0, 3.0), Vec3::ZERO, 45.0)
}

#[test]
fn renderer_returns_the_settings_error_instead_of_rendering() {
    let mut scene = lit_floor();
    let mut r = FrameRenderer::new(2);
    for (field, change) in [
        ("vpls", (|s: &mut FrameSettings| s.vpls_per_pixel = 0) as fn(&mut FrameSettings)),
        ("interleave", |s| s.interleave = [0, 3]),
        ("aa", |s| s.aa = 0),
        ("clamp", |s| s.clamp = f32::NAN),
        ("width", |s| s.width = 100_000),
    ] {
        let mut f = igi_frame(view(), 16, 16);
        change(&mut f.settings);
        let progress = |_: u32, _: u32| panic!("no tile may be rendered with bad settings");
        assert_eq!(r.render(&mut scene, &f, &progress).expect_err("bad settings").field, field);
        match r.render_accumulated(&mut scene, &f, 4, &progress) {
            Err(FrameError::Settings(e)) => assert_eq!(e.field, field),
            other => panic!("{field}: bad settings must be refused, not {other:?}"),
        }
    }
}

/// Renders `frame` and asserts every pixel is finite and non-negative; returns the image.
fn render_finite(scene: &mut PreparedScene, frame: &FrameState, what: &str) -> igi_render::Film {
    let film = FrameRenderer::new(2)
        .render(scene, frame, &|_, _| {})
        .expect("valid settings")
        .image
        .into_film()
        .unwrap();
    let bad: Vec<(usize, Vec3)> = film
        .pixels()
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, p)| !(p.is_finite() && p.min_element() >= 0.0))
        .collect();
    assert!(bad.is_empty(), "{what}: {} non-finite or negative pixels, first {:?}", bad.len(), bad.first());
    film
}

#[test]
fn scenes_without_lights_or_geometry_render() {
    // No light: the headlight at the camera lights the floor.
    let mut dark = PreparedScene::new(scene(
        vec![horizontal_square("floor", Vec3::ZERO, Vec2::new(2.0, 2.0), true, 0)],
        vec![diffuse("grey", 0.5)],
        vec![],
    ));
    let film = render_finite(&mut dark, &igi_frame(view(), 24, 16), "no lights");
    assert!(film.pixels().iter().any(|p| p.min_element() > 0.0), "the headlight should light the floor");

    // No geometry at all: black.
    let mut empty = PreparedScene::new(Scene::default());
    let film = render_finite(&mut empty, &igi_frame(view(), 24, 16), "empty scene");
    assert!(film.pixels().iter().all(|&p| p == Vec3::ZERO), "an empty scene is black");

    // Lights of zero power and a black floor: black, no NaN from 0/0 in the light choice.
    let mut off = PreparedScene::new(scene(
        vec![horizontal_square("floor", Vec3::ZERO, Vec2::new(2.0, 2.0), true, 0)],
        vec![diffuse("black", 0.0)],
        vec![Light::Point { position: Vec3::Y, intensity: Vec3::ZERO }],
    ));
    let film = render_finite(&mut off, &igi_frame(view(), 24, 16), "zero-power light");
    assert!(film.pixels().iter().all(|&p| p == Vec3::ZERO));
}

#[test]
fn camera_inside_a_closed_box_sees_black_or_its_headlight() {
    // A closed box with outward-facing walls, lit by a point light outside: no light gets in
    // (shadow rays and VPLs stay outside), so the inside is black, exactly.
    let walls = box_faces(Vec3::ZERO, Vec3::ONE, false, 0);
    let light = Light::Point { position: Vec3::new(3.0, 2.0, 1.0), intensity: Vec3::splat(10.0) };
    let mut closed = PreparedScene::new(scene(walls.clone(), vec![diffuse("grey", 0.5)], vec![light]));
    let inside = camera(Vec3::new(0.1, -0.2, 0.3), Vec3::new(0.5, 0.1, -1.0), 90.0);
    let film = render_finite(&mut closed, &igi_frame(inside, 24, 24), "inside a box lit from outside");
    assert!(film.pixels().iter().all(|&p| p == Vec3::ZERO), "light leaked into the closed box");

    // Without any light the headlight sits at the camera, inside: the walls are lit.
    let mut unlit = PreparedScene::new(scene(walls, vec![diffuse("grey", 0.5)], vec![]));
    let film = render_finite(&mut unlit, &igi_frame(inside, 24, 24), "inside a box with the headlight");
    assert!(film.pixels().iter().all(|p| p.min_element() > 0.0), "the headlight should light every wall");
}

#[test]
fn odd_but_valid_settings_render() {
    let mut scene = lit_floor();
    let f = |change: fn(&mut FrameSettings)| {
        let mut f = igi_frame(view(), 13, 9);
        change(&mut f.settings);
        f
    };
    for (what, frame) in [
        ("one pixel", f(|s| (s.width, s.height) = (1, 1))),
        ("one VPL, largest interleave", f(|s| (s.vpls_per_pixel, s.interleave) = (1, [16, 16]))),
        ("largest aa, tile 1", f(|s| (s.aa, s.tile_size) = (64, 1))),
        ("specular bounces 0", f(|s| s.specular_bounces = 0)),
        (
            "filter accepting everything",
            f(|s| {
                s.set_discontinuity_filter(Some(FilterSettings {
                    min_normal_cos: -1.0,
                    max_depth_ratio: 1e30,
                }))
            }),
        ),
        (
            "filter accepting nothing",
            f(|s| {
                s.set_discontinuity_filter(Some(FilterSettings { min_normal_cos: 1.0, max_depth_ratio: 0.0 }))
            }),
        ),
        ("large clamp", f(|s| s.clamp = 1e30)),
    ] {
        render_finite(&mut scene, &frame, what);
    }
}

#[test]
fn strictest_filter_keeps_each_pixel_its_own_value() {
    // min_normal_cos = 1 and max_depth_ratio = 0 (both valid) leave only the pixel itself
    // "similar"; on a tilted plane a unit normal's dot product with itself can round below 1,
    // and the pixel must still count itself (else 0 / 0 = NaN). The result equals the
    // unfiltered image.
    // Tilt the plane until both triangles' unit normals (as the renderer computes them) have
    // n · n < 1 in f32 (about a third of all directions do).
    let self_dot_below_one = |mesh: &igi_scene::Mesh| {
        mesh.indices.iter().all(|&[a, b, c]| {
            let p = |i: u32| mesh.positions[i as usize];
            let g = (p(b) - p(a)).cross(p(c) - p(a)).normalize();
            g.dot(g) < 1.0
        })
    };
    let (n, mesh) = (0..1000)
        .map(|i| {
            let n = Vec3::new(0.3 + 0.001 * i as f32, 1.0, 0.7).normalize();
            let (t, b) = n.any_orthonormal_pair();
            let corners = [-t - b, t - b, t + b, -t + b].map(|c| 2.0 * c);
            (n, quad_facing("tilted", corners, n, 0))
        })
        .find(|(_, mesh)| self_dot_below_one(mesh))
        .expect("a tilt whose normals have n · n < 1");
    let mut tilted = PreparedScene::new(scene(
        vec![mesh],
        vec![diffuse("grey", 0.5)],
        vec![Light::Point { position: 2.0 * n, intensity: Vec3::splat(3.0) }],
    ));
    let mut f = igi_frame(camera(3.0 * n + Vec3::new(0.5, 0.2, 0.1), Vec3::ZERO, 45.0), 32, 32);
    f.settings.set_discontinuity_filter(Some(FilterSettings { min_normal_cos: 1.0, max_depth_ratio: 0.0 }));
    let strict = render_finite(&mut tilted, &f, "strictest filter");
    f.settings.filter = false;
    let raw = render_finite(&mut tilted, &f, "no filter");
    assert!(film_bits(&strict) == film_bits(&raw), "the strictest filter must change nothing");
}

#[test]
fn degenerate_cameras_give_finite_images() {
    // The camera is not part of FrameSettings::validate; whatever it is, rendering must not
    // panic, and a camera without a view direction or with non-finite numbers should give a
    // finite (black) image rather than NaN pixels.
    let mut scene = lit_floor();
    let nan = f32::NAN;
    for (what, cam) in [
        (
            "position = target",
            Camera { position: Vec3::ONE, target: Vec3::ONE, up: Vec3::Y, fov_y_deg: 45.0 },
        ),
        (
            "up along the view",
            Camera { position: Vec3::new(0.0, 3.0, 0.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 },
        ),
        ("zero fov", Camera { fov_y_deg: 0.0, ..view() }),
        ("180° fov", Camera { fov_y_deg: 180.0, ..view() }),
        ("NaN position", Camera { position: Vec3::new(nan, 1.0, 1.0), ..view() }),
        ("NaN target", Camera { target: Vec3::splat(nan), ..view() }),
        ("NaN fov", Camera { fov_y_deg: nan, ..view() }),
        ("infinite position", Camera { position: Vec3::new(0.0, f32::INFINITY, 0.0), ..view() }),
    ] {
        let film = render_finite(&mut scene, &igi_frame(cam, 8, 8), what);
        // What the library does today: a camera with non-finite numbers (or no view
        // direction) sends rays that hit nothing, so the image is black.
        if !(cam.position.is_finite() && cam.target.is_finite() && cam.fov_y_deg.is_finite())
            || cam.position == cam.target
        {
            assert!(film.pixels().iter().all(|&p| p == Vec3::ZERO), "{what}: expected a black image");
        }
        // And the same without lights, where the headlight sits at the odd camera.
        let mut dark = PreparedScene::new(scene_without_lights());
        render_finite(&mut dark, &igi_frame(cam, 8, 8), &format!("{what}, headlight"));
    }
}

fn scene_without_lights() -> Scene {
    scene(
        vec![horizontal_square("floor", Vec3::ZERO, Vec2::new(2.0, 2.0), true, 0)],
        vec![diffuse("grey", 0.5)],
        vec![],
    )
}
