//! `shirley-room`: a closed room for indirect-light tests, in the spirit of the "Shirley"
//! scenes the interactive GI papers used (a furnished room lit from the ceiling, most of it
//! seen only by bounced light).
//!
//! The room is 5 m wide (x), 3 m high (y) and 5 m deep (z), centred on the origin with the
//! floor at y = 0: white floor, ceiling, back and front walls, a red left wall and a blue right
//! wall. A 1 × 1 m area light hangs 5 cm under the ceiling, facing down, with a radiance of
//! (12, 11, 9) W/(sr m²), about 100 W in all. Inside: a tall and a short white box, turned, and
//! a low wooden table carrying a glossy blue sphere. The camera stands near the front wall and
//! looks into the room. 722 triangles.

use glam::Vec3;

use super::shapes::{assemble, cuboid, quad, sphere};
use crate::model::{Camera, Material, Scene};

const WHITE: u32 = 0;
const RED: u32 = 1;
const BLUE: u32 = 2;
const WOOD: u32 = 3;
const GLOSSY: u32 = 4;
const LIGHT: u32 = 5;

fn materials() -> Vec<Material> {
    let diffuse = Material::diffuse;
    vec![
        diffuse("white", Vec3::splat(0.75)),
        diffuse("red", Vec3::new(0.63, 0.1, 0.08)),
        diffuse("blue", Vec3::new(0.12, 0.22, 0.55)),
        diffuse("wood", Vec3::new(0.5, 0.34, 0.2)),
        Material {
            glossy: Vec3::splat(0.25),
            exponent: 60.0,
            ..diffuse("glossy", Vec3::new(0.15, 0.25, 0.6))
        },
        Material { emission: Vec3::new(12.0, 11.0, 9.0), ..diffuse("light", Vec3::ZERO) },
    ]
}

pub(super) fn scene() -> Scene {
    let room = Vec3::new(5.0, 3.0, 5.0);
    let mut parts = cuboid(Vec3::ZERO, room, 0.0, true, WHITE);
    // `cuboid` lists the faces +X, −X, ...: colour the side walls.
    parts[0].material = BLUE;
    parts[1].material = RED;
    parts.push(quad(
        Vec3::new(0.0, room.y - 0.05, 0.0),
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.5),
        LIGHT,
    ));
    parts.extend(cuboid(Vec3::new(-1.3, 0.0, -1.3), Vec3::new(0.6, 1.4, 0.6), 20.0, false, WHITE));
    parts.extend(cuboid(Vec3::new(1.4, 0.0, -1.0), Vec3::new(0.8, 0.5, 0.8), -15.0, false, WHITE));
    let table = Vec3::new(0.2, 0.0, 0.6);
    let (top_height, top_thickness) = (0.7, 0.06);
    let top = Vec3::new(1.4, top_thickness, 0.8);
    parts.extend(cuboid(table + Vec3::Y * (top_height - top_thickness), top, 0.0, false, WOOD));
    for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        let leg = table + Vec3::new(sx * (top.x / 2.0 - 0.08), 0.0, sz * (top.z / 2.0 - 0.08));
        parts.extend(cuboid(leg, Vec3::new(0.06, top_height - top_thickness, 0.06), 0.0, false, WOOD));
    }
    let radius = 0.3;
    parts.push(sphere(table + Vec3::Y * (top_height + radius), radius, 24, 14, GLOSSY));
    let camera = Camera::looking_at(Vec3::new(0.0, 1.6, room.z / 2.0 - 0.2), Vec3::new(0.0, 0.9, 0.0), 60.0);
    assemble("shirley-room", parts, materials(), camera)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_room_with_a_downward_light() {
        let scene = scene();
        assert_eq!(scene.triangle_count(), 722);
        let bounds = scene.bounds();
        assert_eq!(bounds.min, Vec3::new(-2.5, 0.0, -2.5));
        assert_eq!(bounds.max, Vec3::new(2.5, 3.0, 2.5));
        let mesh = &scene.meshes[0];
        for t in 0..mesh.indices.len() {
            if mesh.material_ids[t] == LIGHT {
                assert!((mesh.triangle_normal(t) - Vec3::NEG_Y).length() < 1e-6);
            }
        }
        assert_eq!(scene.emissive_triangle_count(), 2);
        assert!(mesh.normals.is_some(), "the sphere is smooth");
    }
}
