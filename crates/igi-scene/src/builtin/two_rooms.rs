//! `two-rooms`: the hard case of light paths that start where the camera does not look
//! (issue 16; the paper's section 5 names occluded scenes as instant radiosity's weakness).
//! Two rooms joined by a doorway; the lamp hangs in one, the camera stands in the other and
//! sees only light that came through the door and bounced at least once.
//!
//! The rooms are 4 m wide (x), 2.8 m high (y) and 4 m deep (z) each, side by side along x
//! with the floor at y = 0: room A at x < 0, room B at x > 0, a 10 cm wall between them with
//! a doorway 0.9 m wide and 2.1 m high near its front end (z from 1.0 to 1.9). A 0.6 × 0.6 m
//! area light hangs 5 cm under room A's ceiling in its back corner, facing down, with a
//! radiance of (30, 28, 24) W/(sr m²). Room A's end wall is red, room B's blue, the rest white;
//! a box stands in each room. The camera stands in room B's front corner and looks across it
//! to its back wall and the dividing wall, away from the patches the lamp lights directly
//! through the doorway.

use glam::Vec3;

use super::shapes::{assemble, cuboid, quad};
use crate::model::{Camera, Material, Scene};
use crate::validate::Part;

const WHITE: u32 = 0;
const RED: u32 = 1;
const BLUE: u32 = 2;
const LIGHT: u32 = 3;

/// Height of the rooms.
const HEIGHT: f32 = 2.8;
/// Half the thickness of the dividing wall.
const WALL: f32 = 0.05;
/// The doorway: z from DOOR[0] to DOOR[1], up to DOOR_HEIGHT.
const DOOR: [f32; 2] = [1.0, 1.9];
const DOOR_HEIGHT: f32 = 2.1;

fn materials() -> Vec<Material> {
    let diffuse = Material::diffuse;
    vec![
        diffuse("white", Vec3::splat(0.75)),
        diffuse("red", Vec3::new(0.63, 0.1, 0.08)),
        diffuse("blue", Vec3::new(0.12, 0.22, 0.55)),
        Material { emission: Vec3::new(30.0, 28.0, 24.0), ..diffuse("light", Vec3::ZERO) },
    ]
}

/// A wall rectangle in the plane x = `x` facing `side` (±1 along x), over z0..z1 and y0..y1.
fn wall_face(x: f32, side: f32, [z0, z1]: [f32; 2], [y0, y1]: [f32; 2]) -> Part {
    let centre = Vec3::new(x, (y0 + y1) / 2.0, (z0 + z1) / 2.0);
    let (a, b) = (Vec3::Y * (y1 - y0) / 2.0, Vec3::Z * (z1 - z0) / 2.0);
    // Y × Z = +X.
    if side > 0.0 { quad(centre, a, b, WHITE) } else { quad(centre, b, a, WHITE) }
}

pub(super) fn scene() -> Scene {
    let mut parts = cuboid(Vec3::ZERO, Vec3::new(8.0, HEIGHT, 4.0), 0.0, true, WHITE);
    // `cuboid` lists the faces +X, −X, ...: room B's end wall, then room A's.
    parts[0].material = BLUE;
    parts[1].material = RED;
    // The dividing wall: both faces around the doorway, then the doorway's jambs and head.
    for (x, side) in [(WALL, 1.0), (-WALL, -1.0)] {
        parts.push(wall_face(x, side, [-2.0, DOOR[0]], [0.0, HEIGHT]));
        parts.push(wall_face(x, side, [DOOR[1], 2.0], [0.0, HEIGHT]));
        parts.push(wall_face(x, side, DOOR, [DOOR_HEIGHT, HEIGHT]));
    }
    let jamb = |z: f32, facing: f32| {
        let centre = Vec3::new(0.0, DOOR_HEIGHT / 2.0, z);
        let (a, b) = (Vec3::X * WALL, Vec3::Y * DOOR_HEIGHT / 2.0);
        // X × Y = +Z.
        if facing > 0.0 { quad(centre, a, b, WHITE) } else { quad(centre, b, a, WHITE) }
    };
    parts.push(jamb(DOOR[0], 1.0));
    parts.push(jamb(DOOR[1], -1.0));
    let head = Vec3::new(0.0, DOOR_HEIGHT, (DOOR[0] + DOOR[1]) / 2.0);
    // Z × X = +Y; the head faces down into the doorway.
    parts.push(quad(head, Vec3::X * WALL, Vec3::Z * (DOOR[1] - DOOR[0]) / 2.0, WHITE));
    // The lamp, facing down (X × Z = −Y).
    parts.push(quad(Vec3::new(-3.0, HEIGHT - 0.05, -1.2), Vec3::X * 0.3, Vec3::Z * 0.3, LIGHT));
    parts.extend(cuboid(Vec3::new(-2.0, 0.0, 0.6), Vec3::new(0.8, 0.8, 0.8), 20.0, false, WHITE));
    parts.extend(cuboid(Vec3::new(2.4, 0.0, -1.0), Vec3::new(0.6, 1.3, 0.6), -25.0, false, WHITE));
    let camera = Camera::looking_at(Vec3::new(3.6, 1.6, 1.7), Vec3::new(0.8, 0.9, -2.0), 60.0);
    assemble("two-rooms", parts, materials(), camera)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_closed_rooms_joined_by_a_doorway_with_the_lamp_in_the_other() {
        let scene = scene();
        let bounds = scene.bounds();
        assert_eq!((bounds.min, bounds.max), (Vec3::new(-4.0, 0.0, -2.0), Vec3::new(4.0, HEIGHT, 2.0)));
        let mesh = &scene.meshes[0];
        let lamp: Vec<usize> = (0..mesh.indices.len()).filter(|&t| mesh.material_ids[t] == LIGHT).collect();
        assert_eq!(lamp.len(), 2);
        for &t in &lamp {
            assert!((mesh.triangle_normal(t) - Vec3::NEG_Y).length() < 1e-6);
            let [a, ..] = mesh.indices[t].map(|i| mesh.positions[i as usize]);
            assert!(a.x < 0.0, "the lamp is in room A");
        }
        let camera = scene.camera.unwrap();
        assert!(camera.position.x > WALL && camera.position.x < 4.0, "the camera is in room B");
    }
}
