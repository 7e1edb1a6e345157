//! Hand-built scenes for the physics tests: quads, materials and lights with known answers,
//! the closed-form cases both renderers are checked against, and the helpers that render them.

#![allow(dead_code)]

use glam::{Affine3A, Vec2, Vec3};
use igi_render::{Estimator, Film, FrameRenderer, FrameSource, FrameState, PixelFormat, PreparedScene};
use igi_scene::{Camera, Instance, Light, Material, Mesh, Scene};

/// A quad `p0 p1 p2 p3` (two triangles 0-1-2, 0-2-3) with winding normal
/// `(p1 - p0) × (p2 - p0)`, all of material `material`.
pub fn quad(name: &str, p: [Vec3; 4], material: u32) -> Mesh {
    Mesh {
        name: name.into(),
        positions: p.to_vec(),
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material_ids: vec![material; 2],
    }
}

/// The horizontal rectangle centred at `centre` with half extents `half` (x, z), facing up
/// (+Y) or down.
pub fn horizontal_square(name: &str, centre: Vec3, half: Vec2, up: bool, material: u32) -> Mesh {
    let corner = |sx: f32, sz: f32| centre + Vec3::new(sx * half.x, 0.0, sz * half.y);
    let (a, b, c, d) = (corner(-1.0, 1.0), corner(1.0, 1.0), corner(1.0, -1.0), corner(-1.0, -1.0));
    if up { quad(name, [a, b, c, d], material) } else { quad(name, [a, d, c, b], material) }
}

/// A grey Lambertian material with reflectance `rho`.
pub fn diffuse(name: &str, rho: f32) -> Material {
    Material { name: name.into(), diffuse: Vec3::splat(rho), ..Material::default() }
}

/// A black emitter of radiance `le`.
pub fn emitter(name: &str, le: Vec3) -> Material {
    Material { name: name.into(), diffuse: Vec3::ZERO, emission: le, ..Material::default() }
}

/// A scene of `meshes`, each placed once with the identity transform.
pub fn scene(meshes: Vec<Mesh>, materials: Vec<Material>, lights: Vec<Light>) -> Scene {
    let instances =
        (0..meshes.len() as u32).map(|mesh| Instance { mesh, transform: Affine3A::IDENTITY }).collect();
    Scene { meshes, instances, materials, lights, ..Scene::default() }
}

/// A camera at `position` looking at `target`, +Y up unless the view is vertical.
pub fn camera(position: Vec3, target: Vec3, fov_y_deg: f32) -> Camera {
    let up = if (target - position).normalize().y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    Camera { position, target, up, fov_y_deg }
}

/// Relative difference of two colours (largest channel).
pub fn rel_err(got: Vec3, want: Vec3) -> f32 {
    ((got - want).abs() / want.abs().max(Vec3::splat(1e-12))).max_element()
}

// ---- Helpers of the IGI renderer tests (tests/igi_*.rs). ----

/// The IGI frame of the brief: `width` × `height`, default settings (12 VPLs per pixel, 3 × 3
/// interleave, aa 4, filter on, tile 32) but clamp 0 (unbiased), linear tone map, frame 0,
/// seed 0.
pub fn igi_frame(camera: Camera, width: u32, height: u32) -> igi_render::FrameState {
    let settings =
        igi_render::FrameSettings { width, height, clamp: 0.0, ..igi_render::FrameSettings::default() };
    igi_render::FrameState::new(camera, settings)
}

/// One IGI frame on two threads.
pub fn render_igi(scene: &mut PreparedScene, frame: &FrameState) -> Film {
    FrameRenderer::new(2).render(scene, frame, &|_, _| {}).expect("valid settings").image.into_film().unwrap()
}

/// [`igi_frame`] with aa 1 (pixel-centre rays) and the filter off: each pixel is the value at
/// the point its centre ray hits, exact where the lighting is.
pub fn exact_frame(camera: Camera, width: u32, height: u32) -> FrameState {
    let mut f = igi_frame(camera, width, height);
    f.settings.aa = 1;
    f.settings.filter = false;
    f
}

/// The image means of `scene` seen through `camera` at `size` × `size`: instant global
/// illumination accumulated over `frames` frames ([`igi_frame`]: unclamped, so unbiased up to
/// the bounce cap) and the path tracer with `spp` paths per pixel, in that order.
pub fn converged_means(
    scene: &mut PreparedScene,
    camera: Camera,
    size: u32,
    frames: u32,
    spp: u32,
) -> (Vec3, Vec3) {
    let mut renderer = FrameRenderer::new(2);
    let frame = igi_frame(camera, size, size);
    let (pt, _) = path_traced(scene, &frame, spp, 2);
    let igi = renderer
        .render_accumulated(scene, &frame, frames, &|_, _| {})
        .expect("valid settings")
        .image
        .into_film()
        .unwrap();
    (film_mean(&igi), film_mean(&pt))
}

/// The quad `p` wound so that its normal points toward `toward`.
pub fn quad_facing(name: &str, p: [Vec3; 4], toward: Vec3, material: u32) -> Mesh {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let centre = 0.25 * (p[0] + p[1] + p[2] + p[3]);
    if n.dot(toward - centre) > 0.0 {
        quad(name, p, material)
    } else {
        quad(name, [p[0], p[3], p[2], p[1]], material)
    }
}

/// A square of half size `half` in the plane z = `z`, facing toward `toward`.
pub fn square_z(z: f32, half: f32, toward: Vec3, material: u32) -> Mesh {
    let p = [
        Vec3::new(-half, -half, z),
        Vec3::new(half, -half, z),
        Vec3::new(half, half, z),
        Vec3::new(-half, half, z),
    ];
    quad_facing("square", p, toward, material)
}

/// The six faces of the box `centre ± half`, wound to face inward (`inward`) or outward.
pub fn box_faces(centre: Vec3, half: Vec3, inward: bool, material: u32) -> Vec<Mesh> {
    let mut faces = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let corner = |a: f32, b: f32| {
                let mut c = [0.0; 3];
                c[axis] = sign;
                c[(axis + 1) % 3] = a;
                c[(axis + 2) % 3] = b;
                centre + Vec3::from(c) * half
            };
            let p = [corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)];
            let face_centre = 0.25 * (p[0] + p[1] + p[2] + p[3]);
            let toward = if inward { centre } else { 2.0 * face_centre - centre };
            faces.push(quad_facing("face", p, toward, material));
        }
    }
    faces
}

/// Mean of a film's pixels, accumulated in f64.
pub fn film_mean(film: &igi_render::Film) -> Vec3 {
    let sum = film.pixels().iter().fold([0.0f64; 3], |acc, p| {
        [acc[0] + f64::from(p.x), acc[1] + f64::from(p.y), acc[2] + f64::from(p.z)]
    });
    let n = film.pixels().len().max(1) as f64;
    Vec3::new((sum[0] / n) as f32, (sum[1] / n) as f32, (sum[2] / n) as f32)
}

/// A film's pixels as raw bits, for bit-for-bit comparisons.
pub fn film_bits(film: &igi_render::Film) -> Vec<[u32; 3]> {
    film.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

/// Where the ray from `origin` along `d` meets the plane y = 0 inside |x|, |z| < `half`.
pub fn hit_floor(origin: Vec3, d: Vec3, half: f32) -> Option<Vec3> {
    if d.y >= 0.0 {
        return None;
    }
    let p = origin - origin.y / d.y * d;
    (p.x.abs() < half && p.z.abs() < half).then_some(p)
}

/// Radiance of a Lambertian surface of albedo `rho` at `p` (normal +Y) under a point light
/// of intensity `intensity` at `light`: ρ/π · I · cosθ / d².
pub fn point_lit(p: Vec3, light: Vec3, intensity: Vec3, rho: f32) -> Vec3 {
    let l = light - p;
    rho / std::f32::consts::PI * intensity * (l.y / l.length()) / l.length_squared()
}

/// Form factor from a differential area to a parallel rectangle `a` × `b` at distance `h`
/// whose corner lies straight above it (Howell's catalogue, B-3); odd in `a` and in `b`, so
/// signed rectangles add up.
pub fn corner_form_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// Form factor from a differential area at (`px`, `pz`) of the plane y = 0, facing up, to the
/// rectangle |x| ≤ `hx`, |z| ≤ `hz` at height `h` facing down: four corner rectangles.
pub fn rectangle_form_factor(px: f64, pz: f64, hx: f64, hz: f64, h: f64) -> f64 {
    corner_form_factor(hx - px, hz - pz, h)
        + corner_form_factor(hx + px, hz - pz, h)
        + corner_form_factor(hx - px, hz + pz, h)
        + corner_form_factor(hx + px, hz + pz, h)
}

// ---- The grey plane under one light: cases with a closed-form image, checked against both
// ---- renderers (tests/igi_physics.rs and tests/path_tracer.rs). The plane cannot see itself,
// ---- so it has no indirect light: its radiance is the light's direct light, exactly.

/// Reflectance of the grey plane of [`plane_scene`].
pub const RHO: f32 = 0.5;

/// A 20 × 20 grey plane (reflectance [`RHO`]) at y = 0 facing up, plus `extra` meshes
/// (materials 1..).
pub fn plane_scene(extra: Vec<Mesh>, mut materials: Vec<Material>, lights: Vec<Light>) -> Scene {
    let mut meshes = vec![horizontal_square("plane", Vec3::ZERO, Vec2::new(10.0, 10.0), true, 0)];
    meshes.extend(extra);
    materials.insert(0, diffuse("grey", RHO));
    scene(meshes, materials, lights)
}

/// A point light over the plane, a camera that sees the plane fill most of its image, and the
/// plane's radiance at a point.
pub fn point_light_case() -> (PreparedScene, Camera, impl Fn(Vec3) -> Vec3) {
    let light = Vec3::new(0.3, 2.0, -0.2);
    let intensity = Vec3::new(3.0, 2.0, 1.0);
    let prepared =
        PreparedScene::new(plane_scene(vec![], vec![], vec![Light::Point { position: light, intensity }]));
    let cam = camera(Vec3::new(0.0, 3.0, 4.0), Vec3::ZERO, 40.0);
    (prepared, cam, move |p| point_lit(p, light, intensity, RHO))
}

/// A directional light on the plane, a camera, and the plane's radiance: ρ/π E cosθ, the same
/// everywhere.
pub fn directional_light_case() -> (PreparedScene, Camera, Vec3) {
    let direction = Vec3::new(0.3, -1.0, 0.2).normalize();
    let irradiance = Vec3::new(2.0, 1.5, 1.0);
    let prepared =
        PreparedScene::new(plane_scene(vec![], vec![], vec![Light::Directional { direction, irradiance }]));
    let cam = camera(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.0, -1.0), 50.0);
    (prepared, cam, RHO / std::f32::consts::PI * irradiance * -direction.y)
}

/// A spot light 2 above the plane pointing down, full opening 60°: the cone meets the plane
/// at radius 2 tan 30° = 1.155. A camera, and the plane's radiance at a point inside the cone
/// (outside it is black).
pub fn spot_light_case() -> (PreparedScene, Camera, impl Fn(Vec3) -> Vec3) {
    let light = Vec3::new(0.0, 2.0, 0.0);
    let intensity = Vec3::splat(5.0);
    let spot = Light::Spot { position: light, direction: -Vec3::Y, angle_deg: 60.0, intensity };
    let prepared = PreparedScene::new(plane_scene(vec![], vec![], vec![spot]));
    let cam = camera(Vec3::new(0.0, 4.0, 3.0), Vec3::ZERO, 50.0);
    (prepared, cam, move |p| point_lit(p, light, intensity, RHO))
}

/// A point light 2 above the plane and a black 0.4 × 0.4 blocker half way up: its shadow on
/// the plane is |x|, |z| < 0.4, exactly 0 (the blocker is black, so the light its underside
/// would reflect does not reach the shadow). A camera, and the plane's radiance at a point
/// outside the shadow.
pub fn blocker_case() -> (PreparedScene, Camera, impl Fn(Vec3) -> Vec3) {
    let light = Vec3::new(0.0, 2.0, 0.0);
    let intensity = Vec3::splat(4.0);
    let blocker = horizontal_square("blocker", Vec3::new(0.0, 1.0, 0.0), Vec2::new(0.2, 0.2), true, 1);
    let prepared = PreparedScene::new(plane_scene(
        vec![blocker],
        vec![diffuse("black", 0.0)],
        vec![Light::Point { position: light, intensity }],
    ));
    let cam = camera(Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, 40.0);
    (prepared, cam, move |p| point_lit(p, light, intensity, RHO))
}

/// A down-facing black emitter of radiance `le` (returned) at y = 1 over the plane, a camera
/// below it looking up at its front side (L_e and nothing else) and one above it looking down
/// at its back (black: no emission, no reflection).
pub fn emitter_case() -> (PreparedScene, Vec3, Camera, Camera) {
    let le = Vec3::new(5.0, 4.0, 3.0);
    let light = horizontal_square("light", Vec3::new(0.0, 1.0, 0.0), Vec2::new(1.0, 1.0), false, 1);
    let prepared = PreparedScene::new(plane_scene(vec![light], vec![emitter("light", le)], vec![]));
    let below = camera(Vec3::new(0.0, 0.2, 0.0), Vec3::new(0.0, 1.0, 0.0), 40.0);
    let above = camera(Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 40.0);
    (prepared, le, below, above)
}

/// The plane without any light (lit by the headlight) and a camera.
pub fn headlight_case() -> (PreparedScene, Camera) {
    let prepared = PreparedScene::new(plane_scene(vec![], vec![], vec![]));
    (prepared, camera(Vec3::new(0.0, 2.0, 2.0), Vec3::ZERO, 45.0))
}

/// The white furnace: a closed box whose walls all emit L_e inward and reflect with albedo a =
/// 0.5, so the radiance is the same everywhere, L = L_e + a L = L_e / (1 − a) = 2 L_e
/// (returned). A wide camera from off the centre, with edges and corners in sight.
pub fn white_furnace_case() -> (PreparedScene, Camera, Vec3) {
    let (a, le) = (0.5, Vec3::new(1.0, 0.5, 0.25));
    let wall = Material { diffuse: Vec3::splat(a), emission: le, ..Material::default() };
    let prepared = PreparedScene::new(scene(box_faces(Vec3::ZERO, Vec3::ONE, true, 0), vec![wall], vec![]));
    let cam = camera(Vec3::new(0.2, -0.1, 0.6), Vec3::new(-0.3, 0.2, -1.0), 100.0);
    (prepared, cam, le / (1.0 - a))
}

/// A small room in which every code path runs: floor, area light, point light, a blocker, a
/// mirror and a glass pane.
pub fn every_path_room() -> igi_render::PreparedScene {
    let meshes = vec![
        horizontal_square("floor", Vec3::ZERO, Vec2::new(2.0, 2.0), true, 0),
        horizontal_square("light", Vec3::new(0.0, 1.9, 0.0), Vec2::new(0.4, 0.3), false, 1),
        horizontal_square("blocker", Vec3::new(0.2, 0.7, 0.1), Vec2::new(0.3, 0.3), true, 2),
        quad(
            "mirror",
            [
                Vec3::new(-2.0, 0.0, -1.5),
                Vec3::new(2.0, 0.0, -1.5),
                Vec3::new(2.0, 2.0, -1.5),
                Vec3::new(-2.0, 2.0, -1.5),
            ],
            3,
        ),
        quad(
            "pane",
            [
                Vec3::new(-1.0, 0.0, 0.5),
                Vec3::new(-0.2, 0.0, 0.5),
                Vec3::new(-0.2, 1.0, 0.2),
                Vec3::new(-1.0, 1.0, 0.2),
            ],
            4,
        ),
    ];
    let materials = vec![
        diffuse("floor", 0.7),
        emitter("light", Vec3::new(17.0, 12.0, 4.0)),
        Material { diffuse: Vec3::new(0.6, 0.1, 0.1), ..Material::default() },
        Material { kind: igi_scene::MaterialKind::Mirror, glossy: Vec3::splat(0.8), ..Material::default() },
        Material { kind: igi_scene::MaterialKind::Glass, ior: 1.5, ..Material::default() },
    ];
    let lights = vec![Light::Point { position: Vec3::new(-1.0, 1.5, 1.0), intensity: Vec3::splat(0.5) }];
    igi_render::PreparedScene::new(scene(meshes, materials, lights))
}

/// The path tracer's image of `frame` with `spp` paths per pixel on `threads` threads, and
/// the rays it traced: a frame of [`Estimator::PathTracer`] rendered as every frame is.
pub fn path_traced(scene: &mut PreparedScene, frame: &FrameState, spp: u32, threads: usize) -> (Film, u64) {
    let traced =
        FrameState { estimator: Estimator::PathTracer { spp }, pixels: PixelFormat::Linear, ..frame.clone() };
    let out = FrameRenderer::new(threads).render(scene, &traced, &|_, _| {}).expect("valid settings");
    (out.image.into_film().expect("linear radiance"), out.rays.total())
}
