//! `procedural-room` and its benchmark twin `procedural-room-lambert`: a closed room in the
//! spirit of the paper's Figure 3 (programmable shading, paper 3.2), every pattern of
//! [`Pattern`] on show.
//!
//! The room is 6 m wide (x), 3 m high (y) and 6 m deep (z), centred on the origin with the
//! floor at y = 0: a glossy marble floor, brick walls with recessed mortar (bump mapped) at the
//! back (z = −3) and on the left (x = −3), a pale green plaster wall on the right, white front
//! wall and ceiling. A 1 × 1 m area light hangs 5 cm under the ceiling, facing down, with a
//! radiance of (10, 9.5, 8.5) W/(sr m²), about 90 W, and a warm point light of 4 W/sr stands
//! in the front right corner. Inside: a wooden table (growth rings, slightly bumped) carrying a
//! glossy sphere of bumped turbulence, and a checkered box turned by 25°. The camera stands
//! near the front wall and looks into the room. 710 triangles.
//!
//! The brick is a solid texture, so a flat wall shows clean courses only where it cuts the
//! brick cells a quarter of a cell from their depth joints: the brick length and depth are
//! 3 / 12.25 m so that the walls at x = −3 and z = −3 lie there.
//!
//! `procedural-room-lambert` has the same geometry, lights and camera, with every shader
//! replaced by a constant Lambert material of about the pattern's mean colour plus its glossy
//! reflectance (the same total reflectance, so light paths leave as many VPLs): the baseline
//! for the cost of procedural shading (the procedural room should lose at most 15 % of the
//! frame rate against it).

use glam::Vec3;

use super::shapes::{assemble, cuboid, quad, sphere};
use crate::light::Light;
use crate::model::{Camera, Material, Scene};
use crate::shader::{Pattern, ShaderDesc};

const WHITE: u32 = 0;
const MARBLE: u32 = 1;
const BRICK: u32 = 2;
const PLASTER: u32 = 3;
const WOOD: u32 = 4;
const CHECKER: u32 = 5;
const TURBULENCE: u32 = 6;
const LIGHT: u32 = 7;

/// Half the room's width and depth.
const HALF: f32 = 3.0;

/// A shaded material and the mean blend factor of its pattern (estimated from the pattern's
/// geometry: the share of mortar and bevel for brick, the mean of a band for marble and wood,
/// the mean turbulence), which the Lambert twin turns into a constant colour.
fn shaded(name: &str, desc: ShaderDesc, mean_t: f32) -> (Material, f32) {
    let material = Material {
        name: name.into(),
        diffuse: desc.colors[0],
        glossy: desc.glossy,
        exponent: desc.exponent,
        shader: Some(desc),
        ..Material::default()
    };
    (material, mean_t)
}

fn materials() -> Vec<(Material, f32)> {
    let constant =
        |name: &str, diffuse: Vec3| (Material { name: name.into(), diffuse, ..Material::default() }, 0.0);
    let brick_len = HALF / 12.25;
    vec![
        constant("white", Vec3::splat(0.75)),
        shaded(
            "marble",
            ShaderDesc {
                pattern: Pattern::Marble { octaves: 4, turbulence: 3.0 },
                scale: 1.2,
                colors: [Vec3::new(0.85, 0.84, 0.8), Vec3::new(0.25, 0.25, 0.28)],
                glossy: Vec3::splat(0.08),
                exponent: 60.0,
                bump: 0.0,
            },
            0.5,
        ),
        shaded(
            "brick",
            ShaderDesc {
                pattern: Pattern::Brick { size: Vec3::new(brick_len, 0.085, brick_len), mortar: 0.012 },
                scale: 1.0,
                colors: [Vec3::new(0.55, 0.18, 0.1), Vec3::new(0.7, 0.68, 0.62)],
                glossy: Vec3::ZERO,
                exponent: 1.0,
                bump: 0.01,
            },
            0.3,
        ),
        constant("plaster", Vec3::new(0.55, 0.62, 0.5)),
        shaded(
            "wood",
            ShaderDesc {
                pattern: Pattern::Wood { rings: 6.0, turbulence: 0.6 },
                scale: 2.0,
                colors: [Vec3::new(0.55, 0.36, 0.18), Vec3::new(0.3, 0.17, 0.08)],
                glossy: Vec3::splat(0.05),
                exponent: 30.0,
                bump: 0.001,
            },
            0.5,
        ),
        shaded(
            "checker",
            ShaderDesc {
                pattern: Pattern::Checker,
                scale: 4.0,
                colors: [Vec3::splat(0.8), Vec3::new(0.1, 0.1, 0.12)],
                glossy: Vec3::ZERO,
                exponent: 1.0,
                bump: 0.0,
            },
            0.5,
        ),
        shaded(
            "turbulence",
            ShaderDesc {
                pattern: Pattern::Turbulence { octaves: 5 },
                scale: 3.0,
                colors: [Vec3::new(0.1, 0.2, 0.55), Vec3::new(0.8, 0.85, 0.9)],
                glossy: Vec3::splat(0.3),
                exponent: 80.0,
                bump: 0.004,
            },
            0.4,
        ),
        (Material { emission: Vec3::new(10.0, 9.5, 8.5), ..constant("light", Vec3::ZERO).0 }, 0.0),
    ]
}

/// The room with the given materials (indexed by the constants above).
fn room(name: &str, materials: Vec<Material>) -> Scene {
    let size = Vec3::new(2.0 * HALF, 3.0, 2.0 * HALF);
    let mut parts = cuboid(Vec3::ZERO, size, 0.0, true, WHITE);
    // `cuboid` lists the faces +X, −X, +Y, −Y, +Z, −Z.
    parts[0].material = PLASTER;
    parts[1].material = BRICK;
    parts[3].material = MARBLE;
    parts[5].material = BRICK;
    parts.push(quad(
        Vec3::new(0.0, size.y - 0.05, 0.0),
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.5),
        LIGHT,
    ));
    let table = Vec3::new(0.4, 0.0, -0.6);
    let (top_height, top_thickness) = (0.72, 0.06);
    let top = Vec3::new(1.6, top_thickness, 0.9);
    parts.extend(cuboid(table + Vec3::Y * (top_height - top_thickness), top, 0.0, false, WOOD));
    for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        let leg = table + Vec3::new(sx * (top.x / 2.0 - 0.08), 0.0, sz * (top.z / 2.0 - 0.08));
        parts.extend(cuboid(leg, Vec3::new(0.07, top_height - top_thickness, 0.07), 0.0, false, WOOD));
    }
    let radius = 0.3;
    parts.push(sphere(table + Vec3::new(0.2, top_height + radius, 0.0), radius, 24, 14, TURBULENCE));
    parts.extend(cuboid(Vec3::new(-1.55, 0.0, -1.35), Vec3::splat(0.7), 25.0, false, CHECKER));
    let camera = Camera::looking_at(Vec3::new(0.3, 1.6, HALF - 0.25), Vec3::new(-0.2, 0.8, -1.0), 60.0);
    let mut scene = assemble(name, parts, materials, camera);
    scene.lights.push(Light::Point {
        position: Vec3::new(HALF - 0.6, 2.2, HALF - 0.8),
        intensity: Vec3::new(4.0, 3.4, 2.6),
    });
    scene
}

/// `procedural-room`: procedural shaders on floor, walls, table, sphere and box.
pub(super) fn scene() -> Scene {
    room("procedural-room", materials().into_iter().map(|(m, _)| m).collect())
}

/// `procedural-room-lambert`: the same room with constant Lambert materials of about the
/// patterns' mean colours plus their glossy reflectance.
pub(super) fn lambert_scene() -> Scene {
    let lambert = |(m, mean_t): (Material, f32)| match &m.shader {
        Some(desc) => Material {
            name: format!("{}-lambert", m.name),
            diffuse: (desc.colors[0].lerp(desc.colors[1], mean_t) + desc.glossy).min(Vec3::ONE),
            ..Material::default()
        },
        None => m,
    };
    room("procedural-room-lambert", materials().into_iter().map(lambert).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_room_with_lights_and_every_pattern() {
        let scene = scene();
        assert_eq!(scene.triangle_count(), 710);
        let bounds = scene.bounds();
        assert_eq!(bounds.min, Vec3::new(-HALF, 0.0, -HALF));
        assert_eq!(bounds.max, Vec3::new(HALF, 3.0, HALF));
        let mesh = &scene.meshes[0];
        for t in 0..mesh.indices.len() {
            if mesh.material_ids[t] == LIGHT {
                assert!((mesh.triangle_normal(t) - Vec3::NEG_Y).length() < 1e-6);
            }
            if mesh.material_ids[t] == BRICK {
                // The walls cut the brick cells a quarter cell from a depth joint.
                let p = mesh.positions[mesh.indices[t][0] as usize];
                let depth = if mesh.triangle_normal(t).x.abs() > 0.5 { p.x } else { p.z };
                let f = (depth / (HALF / 12.25)).rem_euclid(1.0);
                assert!((f - 0.25).abs() < 1e-3 || (f - 0.75).abs() < 1e-3, "{f}");
            }
        }
        assert_eq!(scene.emissive_triangle_count(), 2);
        assert_eq!(scene.lights.len(), 1);
        let patterns: Vec<_> =
            scene.materials.iter().filter_map(|m| m.shader.as_ref().map(|s| s.pattern)).collect();
        assert!(matches!(
            patterns[..],
            [
                Pattern::Marble { .. },
                Pattern::Brick { .. },
                Pattern::Wood { .. },
                Pattern::Checker,
                Pattern::Turbulence { .. }
            ]
        ));
    }

    #[test]
    fn lambert_twin_differs_only_in_materials() {
        let (a, b) = (scene(), lambert_scene());
        assert_eq!(a.meshes[0].positions, b.meshes[0].positions);
        assert_eq!(a.meshes[0].indices, b.meshes[0].indices);
        assert_eq!(a.meshes[0].material_ids, b.meshes[0].material_ids);
        assert_eq!(a.lights, b.lights);
        assert_eq!(a.camera, b.camera);
        assert_eq!(a.materials.len(), b.materials.len());
        for (m, l) in a.materials.iter().zip(&b.materials) {
            assert!(l.shader.is_none());
            assert_eq!(m.emission, l.emission);
            if let Some(desc) = &m.shader {
                assert_eq!(l.glossy, Vec3::ZERO);
                // The constant colour is a blend of the pattern's two colours plus the glossy
                // reflectance (the same total reflectance).
                let (lo, hi) = (desc.colors[0].min(desc.colors[1]), desc.colors[0].max(desc.colors[1]));
                let diffuse = l.diffuse - desc.glossy;
                let eps = Vec3::splat(1e-6);
                assert!(diffuse.cmpge(lo - eps).all() && diffuse.cmple(hi + eps).all(), "{}", m.name);
            } else {
                assert_eq!(m, l);
            }
        }
    }
}
