//! The Cornell box of `shared/scenes/cornell-box` (McGuire archive `CornellBox-Original`,
//! public domain), reproduced vertex for vertex.
//!
//! The quads are listed in file order with the file's corner order and are split the way the
//! OBJ loader splits them, so the built-in and the loaded file have the same triangles. That
//! includes the file's quirk of two "bottom" faces that repeat a side face of each box (the
//! real bottoms would lie on the floor, unseen): keeping the duplicates keeps the built-in
//! identical to the reference renders made from the file.

use glam::Vec3;

use super::shapes::{assemble, quad_corners};
use crate::model::{Camera, Material, Scene};

const LEFT_WALL: u32 = 0;
const RIGHT_WALL: u32 = 1;
const FLOOR: u32 = 2;
const CEILING: u32 = 3;
const BACK_WALL: u32 = 4;
const SHORT_BOX: u32 = 5;
const TALL_BOX: u32 = 6;
const LIGHT: u32 = 7;

const fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Every quad of the OBJ file with its material, in file order.
const QUADS: [(u32, [Vec3; 4]); 18] = [
    (FLOOR, [v(-1.01, 0.0, 0.99), v(1.0, 0.0, 0.99), v(1.0, 0.0, -1.04), v(-0.99, 0.0, -1.04)]),
    (CEILING, [v(-1.02, 1.99, 0.99), v(-1.02, 1.99, -1.04), v(1.0, 1.99, -1.04), v(1.0, 1.99, 0.99)]),
    (BACK_WALL, [v(-0.99, 0.0, -1.04), v(1.0, 0.0, -1.04), v(1.0, 1.99, -1.04), v(-1.02, 1.99, -1.04)]),
    (RIGHT_WALL, [v(1.0, 0.0, -1.04), v(1.0, 0.0, 0.99), v(1.0, 1.99, 0.99), v(1.0, 1.99, -1.04)]),
    (LEFT_WALL, [v(-1.01, 0.0, 0.99), v(-0.99, 0.0, -1.04), v(-1.02, 1.99, -1.04), v(-1.02, 1.99, 0.99)]),
    // Short box: top, left, front, right, back, and the "bottom" that repeats the right face.
    (SHORT_BOX, [v(0.53, 0.6, 0.75), v(0.7, 0.6, 0.17), v(0.13, 0.6, 0.0), v(-0.05, 0.6, 0.57)]),
    (SHORT_BOX, [v(-0.05, 0.0, 0.57), v(-0.05, 0.6, 0.57), v(0.13, 0.6, 0.0), v(0.13, 0.0, 0.0)]),
    (SHORT_BOX, [v(0.53, 0.0, 0.75), v(0.53, 0.6, 0.75), v(-0.05, 0.6, 0.57), v(-0.05, 0.0, 0.57)]),
    (SHORT_BOX, [v(0.7, 0.0, 0.17), v(0.7, 0.6, 0.17), v(0.53, 0.6, 0.75), v(0.53, 0.0, 0.75)]),
    (SHORT_BOX, [v(0.13, 0.0, 0.0), v(0.13, 0.6, 0.0), v(0.7, 0.6, 0.17), v(0.7, 0.0, 0.17)]),
    (SHORT_BOX, [v(0.7, 0.0, 0.17), v(0.7, 0.6, 0.17), v(0.53, 0.6, 0.75), v(0.53, 0.0, 0.75)]),
    // Tall box: top, left, back, right, front, and the "bottom" that repeats the front face.
    (TALL_BOX, [v(-0.53, 1.2, 0.09), v(0.04, 1.2, -0.09), v(-0.14, 1.2, -0.67), v(-0.71, 1.2, -0.49)]),
    (TALL_BOX, [v(-0.53, 0.0, 0.09), v(-0.53, 1.2, 0.09), v(-0.71, 1.2, -0.49), v(-0.71, 0.0, -0.49)]),
    (TALL_BOX, [v(-0.71, 0.0, -0.49), v(-0.71, 1.2, -0.49), v(-0.14, 1.2, -0.67), v(-0.14, 0.0, -0.67)]),
    (TALL_BOX, [v(-0.14, 0.0, -0.67), v(-0.14, 1.2, -0.67), v(0.04, 1.2, -0.09), v(0.04, 0.0, -0.09)]),
    (TALL_BOX, [v(0.04, 0.0, -0.09), v(0.04, 1.2, -0.09), v(-0.53, 1.2, 0.09), v(-0.53, 0.0, 0.09)]),
    (TALL_BOX, [v(0.04, 0.0, -0.09), v(0.04, 1.2, -0.09), v(-0.53, 1.2, 0.09), v(-0.53, 0.0, 0.09)]),
    // The light, wound so that it faces down (−Y), 1 cm under the ceiling.
    (LIGHT, [v(-0.24, 1.98, 0.16), v(-0.24, 1.98, -0.22), v(0.23, 1.98, -0.22), v(0.23, 1.98, 0.16)]),
];

/// The MTL's materials, in its order: `Ns 10`, `illum 2`, `Ks 0`, `Ni` as in the file.
fn materials() -> Vec<Material> {
    let white = Vec3::new(0.725, 0.71, 0.68);
    let plain = |name: &str, diffuse: Vec3, ior: f32| Material {
        name: name.into(),
        diffuse,
        exponent: 10.0,
        ior,
        ..Material::default()
    };
    vec![
        plain("leftWall", Vec3::new(0.63, 0.065, 0.05), 1.5),
        plain("rightWall", Vec3::new(0.14, 0.45, 0.091), 1.5),
        plain("floor", white, 1.0),
        plain("ceiling", white, 1.0),
        plain("backWall", white, 1.0),
        plain("shortBox", white, 1.0),
        plain("tallBox", white, 1.0),
        Material { emission: Vec3::new(17.0, 12.0, 4.0), ..plain("light", Vec3::splat(0.78), 1.0) },
    ]
}

/// The scene, with the standard camera of the README: the original Cornell camera's 35 mm
/// lens on 25 mm film, a vertical field of view of 2·atan(12.5 / 35) = 39.3077°.
pub(super) fn scene() -> Scene {
    let parts = QUADS.iter().map(|&(material, corners)| quad_corners(corners, material)).collect();
    let camera = Camera::looking_at(
        Vec3::new(0.0, 1.0, 3.5),
        Vec3::new(0.0, 1.0, 0.0),
        2.0 * (12.5f32 / 35.0).atan().to_degrees(),
    );
    assemble("cornell-box", parts, materials(), camera)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_faces_down_with_the_readme_area() {
        let scene = scene();
        let mesh = &scene.meshes[0];
        let lights: Vec<usize> = (0..mesh.indices.len()).filter(|&t| mesh.material_ids[t] == LIGHT).collect();
        assert_eq!(lights.len(), 2);
        let mut area = 0.0;
        for t in lights {
            assert!((mesh.triangle_normal(t) - Vec3::NEG_Y).length() < 1e-6);
            let [a, b, c] = mesh.triangle(t);
            area += 0.5 * (b - a).cross(c - a).length();
        }
        assert!((area - 0.1786).abs() < 1e-5, "{area}");
        assert!((scene.camera.unwrap().fov_y_deg - 39.3077).abs() < 1e-4);
        assert_eq!(scene.triangle_count(), 36);
    }
}
