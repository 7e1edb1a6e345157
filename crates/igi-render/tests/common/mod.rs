//! Hand-built scenes for the physics tests: quads, materials and lights with known answers.

#![allow(dead_code)]

use glam::{Affine3A, Vec2, Vec3};
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
        igi_render::IgiSettings { width, height, clamp: 0.0, ..igi_render::IgiSettings::default() };
    igi_render::FrameState::new(camera, settings)
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
        Material { kind: igi_scene::MaterialKind::Mirror, specular: Vec3::splat(0.8), ..Material::default() },
        Material { kind: igi_scene::MaterialKind::Glass, ior: 1.5, ..Material::default() },
    ];
    let lights = vec![Light::Point { position: Vec3::new(-1.0, 1.5, 1.0), intensity: Vec3::splat(0.5) }];
    igi_render::PreparedScene::new(scene(meshes, materials, lights))
}
