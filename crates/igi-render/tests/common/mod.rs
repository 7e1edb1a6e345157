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
    Scene { meshes, instances, materials, textures: Vec::new(), lights, camera: None }
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
