//! Physics of the reference path tracer against closed-form answers: a white furnace (every
//! bounce, next-event estimation and emission together), direct light from point, spot,
//! directional and area lights on a plane that cannot see itself (so the answers are exact),
//! shadows, a mirror and a glass slab; then determinism and the handling of bad spp values.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_render::frame::{FrameSettings, FrameState};
use igi_render::path_tracer::{MAX_VERTICES, PathTracer};
use igi_render::sampling::MAX_SAMPLES;
use igi_render::{Film, PinholeCamera, PreparedScene, prepared::lights::eye_light};
use igi_scene::{Camera, Light, Material, MaterialKind};

fn frame(camera: Camera, width: u32, height: u32, seed: u32, tile_size: u32) -> FrameState {
    FrameState::new(camera, FrameSettings { width, height, tile_size, seed, ..FrameSettings::default() })
}

/// The whole image on two threads.
fn render(scene: &mut PreparedScene, frame: &FrameState, spp: u32) -> Film {
    path_traced(scene, frame, spp, 2).0
}

/// The closed-form radiance over one pixel, from `f` at a 9 × 9 grid of points spanning the
/// pixel, corners included.
#[derive(Clone, Copy, Debug)]
struct Expected {
    /// The pixel's value under the box filter the path tracer samples (trapezoidal rule,
    /// second order).
    mean: Vec3,
    /// Smallest value per channel.
    min: Vec3,
    /// Largest value per channel.
    max: Vec3,
}

/// [`Expected`] of pixel (x, y), where `f` gets the unit camera direction and returns `None`
/// where the answer is not known in closed form; then so does this.
fn expected(cam: &PinholeCamera, x: u32, y: u32, f: impl Fn(Vec3) -> Option<Vec3>) -> Option<Expected> {
    const K: u32 = 8;
    let weight = |i: u32| if i == 0 || i == K { 0.5 } else { 1.0 };
    let (mut mean, mut min, mut max) = (Vec3::ZERO, Vec3::INFINITY, Vec3::NEG_INFINITY);
    for j in 0..=K {
        for i in 0..=K {
            let v = f(cam.direction_at(x, y, i as f32 / K as f32, j as f32 / K as f32))?;
            mean += weight(i) * weight(j) * v;
            (min, max) = (min.min(v), max.max(v));
        }
    }
    Some(Expected { mean: mean / (K * K) as f32, min, max })
}

/// Calls `check(x, y, got, expected)` for every pixel whose closed-form value `f` knows at all
/// of its points; returns how many.
fn for_known_pixels(
    film: &Film,
    cam: &PinholeCamera,
    f: impl Fn(Vec3) -> Option<Vec3>,
    mut check: impl FnMut(u32, u32, Vec3, Expected),
) -> usize {
    let mut n = 0;
    for y in 0..cam.height {
        for x in 0..cam.width {
            if let Some(e) = expected(cam, x, y, &f) {
                check(x, y, film.get(x, y), e);
                n += 1;
            }
        }
    }
    n
}

/// Asserts that the path tracer's pixels lie between the smallest and largest closed-form
/// value `f` gives over each pixel (up to float rounding), for the pixels of a 3072 × 2304 view
/// through `cam` on a grid 48 pixels apart (64 × 48 probes); returns how many `f` knew.
///
/// For direct light from punctual lights on a surface that sees no other, the only noise is
/// the sub-pixel position: a pixel is the mean of the radiance at a few of its points, so it
/// lies in that range whatever the points. At this resolution a pixel spans a tiny piece of
/// the scene, and the range of most pixels is below 0.1 % (asserted), so a wrong cosine,
/// distance or albedo fails.
fn assert_in_range(scene: &PreparedScene, cam: &Camera, f: impl Fn(Vec3) -> Option<Vec3>) -> usize {
    const ROUNDING: f32 = 1e-4;
    const STEP: usize = 48;
    let (width, height) = (64 * STEP as u32, 48 * STEP as u32);
    let tracer = PathTracer::new(scene, &frame(*cam, width, height, 0, 16), 4);
    let pin = PinholeCamera::new(cam, width, height);
    let (mut n, mut sharp, mut rays) = (0, 0, 0);
    for y in (STEP as u32 / 2..height).step_by(STEP) {
        for x in (STEP as u32 / 2..width).step_by(STEP) {
            let Some(e) = expected(&pin, x, y, &f) else { continue };
            let got = tracer.pixel(x, y, &mut rays);
            let (lo, hi) = (e.min * (1.0 - ROUNDING), e.max * (1.0 + ROUNDING));
            assert!(got.cmpge(lo).all() && got.cmple(hi).all(), "pixel ({x}, {y}): got {got}, want {e:?}");
            n += 1;
            if (e.max - e.min).max_element() <= 5e-3 * e.mean.max_element() {
                sharp += 1;
            }
        }
    }
    assert!(2 * sharp >= n, "only {sharp} of {n} pixels span less than 0.5 %");
    n
}

#[test]
fn white_furnace_converges_to_le_over_one_minus_albedo() {
    // Inside a closed box whose walls all emit L_e and reflect with albedo a, the radiance is
    // the same everywhere: L = L_e + a L, so L = L_e / (1 − a) = 2 L_e for a = 0.5. The camera
    // ray's hit adds L_e; each diffuse vertex adds a L_e split between next-event estimation
    // and the emitter its cosine bounce hits (MIS weights), so this checks emission, both
    // halves of the MIS and their weights, the bounce and Russian roulette together: a
    // double-counted emitter gives up to 3 L_e, a lost one L_e.
    // The camera's wide view has edges and corners in sight: where an emitting wall meets the
    // lit one, the shadow-ray estimate alone would be the noisiest.
    let (mut prepared, cam, want) = white_furnace_case();
    let film = render(&mut prepared, &frame(cam, 24, 24, 3, 8), 64);
    // 576 pixels × 64 paths: the mean comes out within 0.03 %; 0.5 % leaves room for another
    // sample pattern and still fails any wrong weight by far.
    let mean = film.pixels().iter().sum::<Vec3>() / film.pixels().len() as f32;
    assert!(rel_err(mean, want) < 0.005, "image mean {mean}, want {want}");
    // Each pixel on its own, 64 paths: median error 1.3 %, worst 8 %; bound 15 %.
    for (i, p) in film.pixels().iter().enumerate() {
        assert!(rel_err(*p, want) < 0.15, "pixel {i}: {p}, want {want}");
    }
}

#[test]
fn point_light_matches_inverse_square_law() {
    let (prepared, cam, want) = point_light_case();
    let n = assert_in_range(&prepared, &cam, |d| hit_floor(cam.position, d, 9.0).map(&want));
    assert!(n > 1000, "the plane should fill most of the image, saw {n} pixels");
}

#[test]
fn directional_light_gives_rho_over_pi_e_cos() {
    let (prepared, cam, want) = directional_light_case();
    // Constant radiance, so the range test asks for the value itself (to 1e-4).
    let n = assert_in_range(&prepared, &cam, |d| hit_floor(cam.position, d, 9.0).map(|_| want));
    assert!(n > 300, "{n} plane pixels");
}

#[test]
fn spot_light_lights_its_cone_only() {
    // The cone meets the plane at radius 1.155.
    let (prepared, cam, radiance) = spot_light_case();
    let radius = |p: Vec3| (p.x * p.x + p.z * p.z).sqrt();
    let inside = assert_in_range(&prepared, &cam, |d| {
        hit_floor(cam.position, d, 9.0).filter(|&p| radius(p) < 1.1).map(&radiance)
    });
    // Outside the cone, exactly nothing (the range is [0, 0]).
    let outside = assert_in_range(&prepared, &cam, |d| {
        hit_floor(cam.position, d, 9.0).filter(|&p| radius(p) > 1.2).map(|_| Vec3::ZERO)
    });
    assert!(inside > 50 && outside > 50, "inside {inside}, outside {outside}");
}

#[test]
fn area_light_converges_to_the_form_factor() {
    // A 2 × 1.5 emitter at height 1 facing down (black, so it reflects nothing back).
    let le = Vec3::new(4.0, 3.0, 2.0);
    let (hx, hz, h) = (1.0f32, 0.75f32, 1.0f32);
    let light = horizontal_square("light", Vec3::new(0.0, h, 0.0), Vec2::new(hx, hz), false, 1);
    let mut prepared = PreparedScene::new(plane_scene(vec![light], vec![emitter("light", le)], vec![]));
    let cam = camera(Vec3::new(0.0, 0.5, 2.5), Vec3::ZERO, 30.0);
    let spp = 512;
    let film = render(&mut prepared, &frame(cam, 24, 16, 0, 8), spp);
    let mut worst = 0.0f32;
    let under_light = |d| {
        // Only points under the light, where the four-corner decomposition applies.
        let p = hit_floor(cam.position, d, 0.8 * hz)?;
        if p.x.abs() > 0.8 * hx {
            return None;
        }
        let f =
            rectangle_form_factor(f64::from(p.x), f64::from(p.z), f64::from(hx), f64::from(hz), f64::from(h));
        // E = π L_e F, and the Lambertian plane reflects ρ/π E.
        Some(RHO * le * f as f32)
    };
    let n = for_known_pixels(&film, &PinholeCamera::new(&cam, 24, 16), under_light, |_, _, got, e| {
        worst = worst.max(rel_err(got, e.mean));
    });
    assert!(n > 20, "only {n} pixels under the light");
    // One area-light sample per path, 512 stratified ones of a smooth integrand per pixel
    // (the sub-pixel range is far smaller).
    assert!(worst < 0.01, "worst relative error {worst}");
}

#[test]
fn occluded_points_are_black() {
    let (prepared, cam, radiance) = blocker_case();
    let dark = assert_in_range(&prepared, &cam, |d| hit_floor(cam.position, d, 0.35).map(|_| Vec3::ZERO));
    let lit = assert_in_range(&prepared, &cam, |d| {
        hit_floor(cam.position, d, 9.0).filter(|p| p.x.abs() > 0.45 || p.z.abs() > 0.45).map(&radiance)
    });
    assert!(dark > 20 && lit > 100, "dark {dark}, lit {lit}");
}

#[test]
fn emitters_show_their_radiance_on_the_front_side_only() {
    let (mut prepared, le, below, above) = emitter_case();
    // From below, looking up at the front side: L_e exactly, nothing else (the emitter is black).
    let film = render(&mut prepared, &frame(below, 8, 8, 0, 4), 4);
    assert!(film.pixels().iter().all(|&p| p == le), "front side must show L_e exactly");
    // From above, the back side: no emission, black albedo.
    let film = render(&mut prepared, &frame(above, 8, 8, 0, 4), 4);
    assert!(film.pixels().iter().all(|&p| p == Vec3::ZERO), "back side must be black");
}

#[test]
fn scene_without_lights_gets_a_headlight() {
    let (prepared, cam) = headlight_case();
    let Light::Point { position, intensity } = eye_light(&prepared.bounds(), &cam) else {
        panic!("headlight is a point light")
    };
    assert_eq!(prepared.punctual_lights(&cam), [eye_light(&prepared.bounds(), &cam)]);
    let n = assert_in_range(&prepared, &cam, |d| {
        hit_floor(cam.position, d, 9.0).map(|p| point_lit(p, position, intensity, RHO))
    });
    assert!(n > 100, "{n} plane pixels");
}

#[test]
fn mirror_shows_the_lit_plane_times_its_reflectance() {
    // A 1 × 1 grey target at y = 0 under a spot light, seen only in a vertical mirror at x = 2.
    // The spot's 30° half angle keeps the light off the mirror (the mirror is at least 49° off
    // the axis), so there is no caustic, and the target cannot see itself in the mirror (rays
    // leaving it upward keep rising after the reflection): the answer is direct light only.
    let reflectance = Vec3::new(0.9, 0.8, 0.7);
    let mirror_material = Material {
        diffuse: Vec3::ZERO,
        glossy: reflectance,
        kind: MaterialKind::Mirror,
        ..Material::default()
    };
    let (y0, y1, zh) = (0.3, 3.0, 2.0);
    let mirror = quad_facing(
        "mirror",
        [Vec3::new(2.0, y0, -zh), Vec3::new(2.0, y0, zh), Vec3::new(2.0, y1, zh), Vec3::new(2.0, y1, -zh)],
        Vec3::ZERO,
        1,
    );
    let target = horizontal_square("target", Vec3::ZERO, Vec2::new(0.5, 0.5), true, 0);
    let light = Vec3::new(0.0, 2.0, 0.0);
    let intensity = Vec3::splat(6.0);
    let spot = Light::Spot { position: light, direction: -Vec3::Y, angle_deg: 60.0, intensity };
    let prepared = PreparedScene::new(scene(
        vec![target, mirror],
        vec![diffuse("grey", RHO), mirror_material],
        vec![spot],
    ));
    // The camera aims at the mirror point that shows the target's centre.
    let cam = camera(Vec3::new(0.0, 1.2, 0.0), Vec3::new(2.0, 0.6, 0.0), 20.0);
    let n = assert_in_range(&prepared, &cam, |d| {
        // Off the mirror plane x = 2, then onto the target.
        let t = (2.0 - cam.position.x) / d.x;
        let m = cam.position + t * d;
        if !(d.x > 0.0 && m.y > y0 && m.y < y1 && m.z.abs() < zh) {
            return None;
        }
        let p = hit_floor(m, Vec3::new(-d.x, d.y, d.z), 0.5)?;
        Some(reflectance * point_lit(p, light, intensity, RHO))
    });
    assert!(n > 40, "only {n} pixels see the target in the mirror");
}

#[test]
fn glass_slab_transmits_one_minus_f_over_one_plus_f() {
    // An emitter seen at normal incidence through a glass slab of index 1.5 (F = 0.04 at each
    // face). A path gets through after any even number of internal reflections, so the
    // transmitted fraction is the incoherent sum (1 − F)² Σ F^2k = (1 − F) / (1 + F) = 0.92308
    // (the single pass (1 − F)² = 0.9216 is 0.16 % lower). Light reflected off the slab leaves
    // toward the camera side, where nothing is: black.
    let le = Vec3::new(1.0, 2.0, 3.0);
    let glass = Material { diffuse: Vec3::ZERO, ior: 1.5, kind: MaterialKind::Glass, ..Material::default() };
    let meshes = vec![
        square_z(-2.0, 10.0, Vec3::ZERO, 0),
        // The slab between z = -1.1 and -0.9, faces wound outward.
        square_z(-0.9, 5.0, Vec3::new(0.0, 0.0, 1.0), 1),
        square_z(-1.1, 5.0, Vec3::new(0.0, 0.0, -2.0), 1),
    ];
    let mut prepared = PreparedScene::new(scene(meshes, vec![emitter("light", le), glass], vec![]));
    // A 2° view: every ray within 1.5° of the normal, where F differs from 0.04 by < 1e-8.
    let cam = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 2.0);
    let film = render(&mut prepared, &frame(cam, 16, 16, 0, 16), 1024);
    let mean = film.pixels().iter().sum::<Vec3>() / film.pixels().len() as f32;
    let f = 0.04f32;
    let want = le * (1.0 - f) / (1.0 + f);
    // 262144 stratified paths estimate the fraction to 5e-5 (measured); 3e-4 tells the two
    // answers (0.16 % apart) apart.
    assert!(rel_err(mean, want) < 3e-4, "mean {mean}, want {want} (single pass {})", le * (1.0 - f).powi(2));
}

#[test]
fn paths_between_two_perfect_mirrors_stop_at_the_cap() {
    // Two facing perfect mirrors (reflectance 1): the throughput never drops, so Russian
    // roulette never ends the path and only the cap does, after exactly MAX_VERTICES hits
    // each (which also runs the hashed random numbers past the Sobol dimensions). Nothing
    // emits, so the image is black.
    let mirror = Material {
        diffuse: Vec3::ZERO,
        glossy: Vec3::ONE,
        kind: MaterialKind::Mirror,
        ..Material::default()
    };
    let wall = |z: f32| {
        let h = 50.0;
        quad(
            "mirror",
            [Vec3::new(-h, -h, z), Vec3::new(h, -h, z), Vec3::new(h, h, z), Vec3::new(-h, h, z)],
            0,
        )
    };
    let mut prepared = PreparedScene::new(scene(vec![wall(-1.0), wall(1.0)], vec![mirror], vec![]));
    // A 1° view: after 64 bounces (128 units of travel) a ray has drifted at most 1.2 sideways.
    let cam = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 1.0);
    let (w, h, spp) = (4, 4, 2);
    let (film, rays) = path_traced(&mut prepared, &frame(cam, w, h, 0, 4), spp, 1);
    assert!(film.pixels().iter().all(|&p| p == Vec3::ZERO));
    assert_eq!(rays, u64::from(w * h * spp * MAX_VERTICES));
}

fn bits(film: &Film) -> Vec<[u32; 3]> {
    film.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn same_image_for_any_thread_count_and_tile_size() {
    let mut scene = every_path_room();
    let cam = camera(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.5, 0.0), 50.0);
    // A size that is a multiple of neither tile size.
    let (w, h, spp) = (37, 23, 4);
    let mut render_with = |threads, tile, seed| {
        let (film, rays) = path_traced(&mut scene, &frame(cam, w, h, seed, tile), spp, threads);
        (bits(&film), rays)
    };
    let one = render_with(1, 16, 7);
    assert!(one.1 > u64::from(w * h * spp), "rays {}", one.1);
    assert!(one == render_with(3, 16, 7), "3 threads differ from 1");
    assert!(one == render_with(3, 5, 7), "tile size 5 differs from 16");
    assert!(one.0 != render_with(1, 16, 8).0, "another seed must give another image");

    // A pixel alone equals its value in the image, rays included.
    let f = frame(cam, w, h, 7, 16);
    let tracer = PathTracer::new(&scene, &f, spp);
    let mut rays = 0;
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            pixels.push(tracer.pixel(x, y, &mut rays));
        }
    }
    assert!(bits(&Film::from_pixels(w, h, pixels)) == one.0 && rays == one.1);
}

#[test]
fn bad_spp_is_clamped() {
    // The library never panics on them: it clamps (`igi render` reports them, naming --spp).
    let scene = every_path_room();
    let f = frame(camera(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.5, 0.0), 50.0), 4, 4, 0, 4);
    assert_eq!(PathTracer::new(&scene, &f, 0).spp(), 1);
    assert_eq!(PathTracer::new(&scene, &f, u32::MAX).spp(), MAX_SAMPLES);
    let mut rays = 0;
    assert!(PathTracer::new(&scene, &f, 0).pixel(1, 1, &mut rays).is_finite());
}

#[test]
fn cornell_box_is_finite_and_lit_indirectly() {
    // End to end on the built-in scene: every value finite and non-negative, and the ceiling,
    // which its own light (facing down) cannot reach directly, lit by interreflection.
    let sc = igi_scene::builtin("cornell-box").expect("built-in cornell-box");
    let cam = sc.camera.expect("the Cornell box has its camera");
    let mut prepared = PreparedScene::new(sc);
    let film = render(&mut prepared, &frame(cam, 32, 32, 0, 16), 4);
    assert!(film.pixels().iter().all(|p| p.is_finite() && p.min_element() >= 0.0));
    let ceiling = (12..20).map(|x| film.get(x, 0)).sum::<Vec3>();
    assert!(ceiling.min_element() > 0.0, "ceiling {ceiling}");
    // Colour bleeding aside, the red wall is red and the green one green.
    let (left, right) = (film.get(2, 16), film.get(29, 16));
    assert!(left.x > 2.0 * left.y, "left wall {left}");
    assert!(right.y > 1.5 * right.x, "right wall {right}");
}
