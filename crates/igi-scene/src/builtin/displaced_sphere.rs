//! `displaced-sphere`: the scene of the scale benchmark (`igi bench scale`, issue 17): a bumpy
//! unit sphere over a floor, lit by a point light, tessellated into as many triangles as asked
//! for. Its outline and its shading hardly change with the tessellation, so a view of it costs
//! what the ray tracer pays for the triangle count and nothing else.

use glam::Vec3;

use super::shapes::{self, quad};
use crate::light::Light;
use crate::model::{Camera, Material, Scene};
use crate::validate::{MeshBuilder, Part};

/// Triangles of the sphere unless asked otherwise.
pub(super) const DEFAULT_TRIANGLES: usize = 1_000_000;
/// The fewest triangles it can have: eight segments round, four rings.
pub(super) const MINIMUM_TRIANGLES: usize = 48;

const SPHERE: u32 = 0;
const FLOOR: u32 = 1;

/// The bumps: the radius along the unit direction `d`, between about 0.9 and 1.1.
fn radius(d: Vec3) -> f32 {
    1.0 + 0.06 * (9.0 * d.x).sin() * (8.0 * d.y).sin() * (7.0 * d.z).sin()
        + 0.03 * (23.0 * d.x + 1.0).sin() * (19.0 * d.z + 2.0).sin()
}

/// The displaced sphere as one part of about `triangles` flat-shaded triangles: a UV sphere of
/// `rings` rings and twice as many segments round, 2 · segments · (rings − 1) triangles, each
/// vertex pushed out to [`radius`] along its direction.
fn sphere(triangles: usize) -> Part {
    let gaps = ((triangles as f64 / 4.0).sqrt().round() as u32).max(3);
    let segments = ((triangles as f64 / (2.0 * gaps as f64)).round() as u32).max(8);
    let mut part = shapes::sphere(Vec3::ZERO, 1.0, segments, gaps + 1, SPHERE);
    for p in &mut part.positions {
        *p *= radius(*p);
    }
    part.normals = None;
    part
}

/// The sphere of about `triangles` triangles (mesh 0) over a 6 m floor (mesh 1) with a point
/// light above and in front of it and a camera in which it fills about a third of the frame.
pub(super) fn scene(triangles: usize) -> Scene {
    let mut sphere_mesh = MeshBuilder::new("displaced-sphere");
    sphere_mesh.add(sphere(triangles)).expect("finite sphere");
    let mut floor = MeshBuilder::new("floor");
    floor.add(quad(Vec3::NEG_Y * 1.1, Vec3::Z * 3.0, Vec3::X * 3.0, FLOOR)).expect("a finite quad");
    let diffuse = Material::diffuse;
    let meshes = vec![sphere_mesh.finish().mesh, floor.finish().mesh];
    let materials = vec![diffuse("sphere", Vec3::new(0.7, 0.55, 0.4)), diffuse("floor", Vec3::splat(0.6))];
    let camera = Camera::looking_at(Vec3::new(0.0, 0.3, 3.4), Vec3::new(0.0, -0.05, 0.0), 45.0);
    Scene {
        lights: vec![Light::Point { position: Vec3::new(1.5, 2.5, 2.0), intensity: Vec3::splat(8.0) }],
        ..Scene::placed_once(meshes, materials, camera)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tessellated_to_about_the_count_asked_for() {
        for asked in [MINIMUM_TRIANGLES, 10_000, 123_456] {
            let made = sphere(asked).triangles.len();
            assert!((made as f64 - asked as f64).abs() <= 0.01 * asked as f64 + 8.0, "{made} for {asked}");
        }
        let scene = scene(20_000);
        let bounds = scene.meshes[0].bounds();
        assert!(bounds.min.cmpgt(Vec3::splat(-1.1)).all() && bounds.max.cmplt(Vec3::splat(1.1)).all());
    }
}
