//! Geometry helpers for the built-in scenes: quads, boxes and spheres as [`Part`]s, and the
//! assembly of parts into a one-mesh [`Scene`].

use std::f32::consts::{PI, TAU};

use glam::{Affine3A, Quat, Vec3};

use crate::animation::Animation;
use crate::model::{Camera, Instance, Material, Scene};
use crate::validate::{MeshBuilder, Part};

/// A planar quad from its four corners, split along the 0–2 diagonal like an OBJ quad.
pub(super) fn quad_corners(corners: [Vec3; 4], material: u32) -> Part {
    Part { positions: corners.to_vec(), triangles: vec![[0, 1, 2], [0, 2, 3]], material, ..Part::default() }
}

/// A flat-shaded quad centred at `centre` with half-edge vectors `a` and `b`, facing
/// `a × b` (counter-clockwise seen from that side).
pub(super) fn quad(centre: Vec3, a: Vec3, b: Vec3, material: u32) -> Part {
    let normal = a.cross(b).normalize();
    let mut part = quad_corners([centre - a - b, centre + a - b, centre + a + b, centre - a + b], material);
    part.normals = Some(vec![normal; 4]);
    part
}

/// The six faces of a box as (outward normal, tangent a, tangent b) with a × b = normal.
const FACES: [(Vec3, Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::Y, Vec3::Z),
    (Vec3::NEG_X, Vec3::Z, Vec3::Y),
    (Vec3::Y, Vec3::Z, Vec3::X),
    (Vec3::NEG_Y, Vec3::X, Vec3::Z),
    (Vec3::Z, Vec3::X, Vec3::Y),
    (Vec3::NEG_Z, Vec3::Y, Vec3::X),
];

/// A box standing on `base` (the centre of its bottom face), `size` wide/high/deep, turned by
/// `yaw_deg` about +Y. With `inward`, the faces look inside (a room).
pub(super) fn cuboid(base: Vec3, size: Vec3, yaw_deg: f32, inward: bool, material: u32) -> Vec<Part> {
    let turn = Quat::from_rotation_y(yaw_deg.to_radians());
    let half = size / 2.0;
    let centre = base + Vec3::Y * half.y;
    FACES
        .iter()
        .map(|&(n, a, b)| {
            let face_centre = centre + turn * (n * half);
            let (a, b) = (turn * (a * half), turn * (b * half));
            if inward { quad(face_centre, b, a, material) } else { quad(face_centre, a, b, material) }
        })
        .collect()
}

/// A smooth UV sphere: `segments` around the Y axis, `rings` from pole to pole, triangles
/// counter-clockwise seen from outside.
pub(super) fn sphere(centre: Vec3, radius: f32, segments: u32, rings: u32, material: u32) -> Part {
    let mut normals = vec![Vec3::Y];
    for ring in 1..rings {
        let theta = PI * ring as f32 / rings as f32;
        for segment in 0..segments {
            let phi = TAU * segment as f32 / segments as f32;
            normals.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()));
        }
    }
    normals.push(Vec3::NEG_Y);
    let bottom = normals.len() as u32 - 1;
    let at = |ring: u32, segment: u32| 1 + (ring - 1) * segments + segment % segments;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, at(1, s), at(1, s + 1)]);
        for ring in 1..rings - 1 {
            let (a, b) = (at(ring, s), at(ring, s + 1));
            let (c, d) = (at(ring + 1, s), at(ring + 1, s + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
        triangles.push([bottom, at(rings - 1, s + 1), at(rings - 1, s)]);
    }
    Part {
        positions: normals.iter().map(|&n| centre + n * radius).collect(),
        normals: Some(normals),
        uvs: None,
        triangles,
        material,
    }
}

/// One mesh of all `parts`, placed once, with the given materials and camera.
pub(super) fn assemble(name: &str, parts: Vec<Part>, materials: Vec<Material>, camera: Camera) -> Scene {
    let mut builder = MeshBuilder::new(name);
    for part in parts {
        builder.add(part).expect("built-in geometry is finite and indexed in range");
    }
    Scene {
        meshes: vec![builder.finish().mesh],
        instances: vec![Instance { mesh: 0, transform: Affine3A::IDENTITY }],
        materials,
        textures: Vec::new(),
        lights: Vec::new(),
        environment: None,
        camera: Some(camera),
        front: None,
        animation: Animation::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(part: &Part, centre: Vec3) -> bool {
        part.triangles.iter().all(|&[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|i| part.positions[i as usize]);
            (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) > 0.0
        })
    }

    #[test]
    fn windings_face_the_intended_side() {
        let s = sphere(Vec3::ONE, 0.5, 12, 8, 0);
        assert_eq!(s.triangles.len(), 12 * 2 + 12 * 6 * 2);
        assert!(outward(&s, Vec3::ONE));
        let centre = Vec3::new(0.0, 0.5, 0.0);
        for face in cuboid(Vec3::ZERO, Vec3::ONE, 30.0, false, 0) {
            assert!(outward(&face, centre));
        }
        for face in cuboid(Vec3::ZERO, Vec3::ONE, 0.0, true, 0) {
            assert!(!outward(&face, centre));
        }
    }
}
