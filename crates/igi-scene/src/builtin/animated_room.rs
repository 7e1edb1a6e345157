//! `animated-room`: a dynamic scene in the spirit of the paper's Figure 1 (left), where a
//! moving lamp changes the lighting of the whole room from one frame to the next.
//!
//! A closed 6 × 3 × 6 m room centred on the origin (floor at y = 0): white floor, ceiling
//! and back wall, a red wall on the left (x = −3), a blue one on the right, a white front
//! wall behind the camera. Three things move, all looping:
//! - a lamp, a 0.4 × 0.4 m area light of radiance (30, 27, 22) W/(sr m²) facing down, hangs
//!   1 m under a pivot at the ceiling and swings ±40° about the Z axis (smooth keys, 5 s);
//! - a statue, a 0.5 × 1.2 × 0.5 m box with a sphere on top, turns once about +Y every 12 s
//!   (linear keys) under the lamp's path;
//! - a point light circles the statue at 2.2 m height every 8 s and changes colour from warm
//!   to cool and back (linear keys).
//!
//! The room, the statue and the lamp are separate meshes with one instance each, so a frame
//! moves two instances and rebuilds only the top-level BVH.

use std::f32::consts::TAU;

use glam::{Affine3A, Vec3};

use super::shapes::{cuboid, quad, sphere};
use crate::animation::{AnimatedInstance, AnimatedLight, Animation, AnimationNode, RotationTrack, Track};
use crate::light::Light;
use crate::model::{Camera, Instance, Material, SavedView, Scene};
use crate::validate::{MeshBuilder, Part};

const WHITE: u32 = 0;
const RED: u32 = 1;
const BLUE: u32 = 2;
const STATUE: u32 = 3;
const LAMP: u32 = 4;

/// Half the room's width and depth.
const HALF: f32 = 3.0;
/// Room height.
const HEIGHT: f32 = 3.0;
/// Length of the lamp's pendulum, from the pivot at the ceiling to the lamp.
const PENDULUM: f32 = 1.0;

fn materials() -> Vec<Material> {
    let plain = |name: &str, diffuse: Vec3| Material { name: name.into(), diffuse, ..Material::default() };
    vec![
        plain("white", Vec3::splat(0.75)),
        plain("red", Vec3::new(0.7, 0.12, 0.1)),
        plain("blue", Vec3::new(0.12, 0.2, 0.65)),
        Material { glossy: Vec3::splat(0.1), exponent: 40.0, ..plain("statue", Vec3::new(0.8, 0.75, 0.6)) },
        Material { emission: Vec3::new(30.0, 27.0, 22.0), ..plain("lamp", Vec3::ZERO) },
    ]
}

fn mesh(name: &str, parts: Vec<Part>) -> crate::model::Mesh {
    let mut builder = MeshBuilder::new(name);
    for part in parts {
        builder.add(part).expect("built-in geometry is finite and indexed in range");
    }
    builder.finish().mesh
}

/// The room's walls, facing inside.
fn room() -> Vec<Part> {
    let (h, y) = (HALF, HEIGHT / 2.0);
    vec![
        quad(Vec3::ZERO, Vec3::Z * h, Vec3::X * h, WHITE),
        quad(Vec3::Y * HEIGHT, Vec3::X * h, Vec3::Z * h, WHITE),
        quad(Vec3::new(0.0, y, -h), Vec3::X * h, Vec3::Y * y, WHITE),
        quad(Vec3::new(0.0, y, h), Vec3::Y * y, Vec3::X * h, WHITE),
        quad(Vec3::new(-h, y, 0.0), Vec3::Y * y, Vec3::Z * h, RED),
        quad(Vec3::new(h, y, 0.0), Vec3::Z * h, Vec3::Y * y, BLUE),
    ]
}

/// The statue in its own space: standing on the origin, turning about +Y.
fn statue() -> Vec<Part> {
    let mut parts = cuboid(Vec3::ZERO, Vec3::new(0.5, 1.2, 0.5), 0.0, false, STATUE);
    parts.push(sphere(Vec3::new(0.0, 1.45, 0.0), 0.25, 24, 12, STATUE));
    parts
}

fn key_track<T: crate::animation::Keyable + crate::animation::Finite>(
    keys: Vec<(f32, T)>,
    smooth: bool,
) -> Track<T> {
    let (times, values): (Vec<f32>, Vec<T>) = keys.into_iter().unzip();
    let period = *times.last().expect("keys");
    let track = if smooth { Track::smooth(times, values) } else { Track::linear(times, values) };
    track.expect("built-in keys increase and are finite").looping(period)
}

/// `animated-room`.
pub(super) fn scene() -> Scene {
    let meshes = vec![
        mesh("room", room()),
        mesh("statue", statue()),
        mesh("lamp", vec![quad(Vec3::ZERO, Vec3::X * 0.2, Vec3::Z * 0.2, LAMP)]),
    ];
    let statue_at = Vec3::new(0.4, 0.0, -0.6);
    let pivot = Vec3::new(0.4, HEIGHT - 0.02, -0.6);

    // Node 0 turns the statue; node 1 is the pendulum's pivot, node 2 the lamp at its end.
    let turn = key_track(
        vec![(0.0, Vec3::ZERO), (6.0, Vec3::new(0.0, 180.0, 0.0)), (12.0, Vec3::new(0.0, 360.0, 0.0))],
        false,
    );
    let swing = key_track(
        vec![
            (0.0, Vec3::new(0.0, 0.0, -40.0)),
            (2.5, Vec3::new(0.0, 0.0, 40.0)),
            (5.0, Vec3::new(0.0, 0.0, -40.0)),
        ],
        true,
    );
    let nodes = vec![
        AnimationNode {
            rotation: Some(RotationTrack::EulerDegrees(turn)),
            ..AnimationNode::fixed(None, Affine3A::from_translation(statue_at))
        },
        AnimationNode {
            rotation: Some(RotationTrack::EulerDegrees(swing)),
            ..AnimationNode::fixed(None, Affine3A::from_translation(pivot))
        },
        AnimationNode::fixed(Some(1), Affine3A::from_translation(Vec3::NEG_Y * PENDULUM)),
    ];

    // The point light circles the statue, warm at the back, cool at the front.
    let circle: Vec<(f32, Vec3)> = (0..=8)
        .map(|k| {
            let angle = TAU * k as f32 / 8.0;
            (k as f32, statue_at + Vec3::new(1.6 * angle.cos(), 2.2, 1.6 * angle.sin()))
        })
        .collect();
    let warm = Vec3::new(3.0, 1.6, 0.6);
    let cool = Vec3::new(0.6, 1.4, 3.0);
    let colour = key_track(vec![(0.0, warm), (4.0, cool), (8.0, warm)], false);
    let orbit = Light::Point { position: circle[0].1, intensity: warm };

    let animation = Animation {
        nodes,
        instances: vec![
            AnimatedInstance { instance: 1, node: 0, local: Affine3A::IDENTITY },
            AnimatedInstance { instance: 2, node: 2, local: Affine3A::IDENTITY },
        ],
        lights: vec![AnimatedLight {
            light: 0,
            rest: orbit.clone(),
            node: None,
            position: Some(key_track(circle, false)),
            direction: None,
            power: Some(colour),
        }],
    };
    let pose = animation.pose(0.0);
    let instances = (0..3u32)
        .map(|i| {
            let transform =
                pose.instances.iter().find(|(j, _)| *j == i).map_or(Affine3A::IDENTITY, |(_, m)| *m);
            Instance { mesh: i, transform }
        })
        .collect();
    let camera = Camera::looking_at(Vec3::new(0.0, 1.5, HALF - 0.2), Vec3::new(0.2, 1.1, -1.0), 60.0);
    Scene {
        instances,
        lights: vec![orbit],
        views: vec![
            SavedView {
                name: "statue".into(),
                camera: Camera::looking_at(Vec3::new(1.4, 1.6, 1.6), Vec3::new(0.0, 1.0, 0.0), 50.0),
            },
            SavedView {
                name: "high corner".into(),
                camera: Camera::looking_at(
                    Vec3::new(-HALF + 0.2, HEIGHT - 0.2, HALF - 0.2),
                    Vec3::new(0.5, 0.6, -0.5),
                    70.0,
                ),
            },
        ],
        animation,
        ..Scene::placed_once(meshes, materials(), camera)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lamp_swings_under_its_pivot_and_the_statue_turns() {
        let scene = scene();
        scene.animation.validate(scene.instances.len(), scene.lights.len()).unwrap();
        // At t = 0 the pendulum is turned −40° about Z: Rz(θ) takes −Y to (sin θ, −cos θ),
        // so the lamp hangs 1 m from the pivot towards −X.
        let pose = scene.animation.pose(0.0);
        let lamp = pose.instances.iter().find(|(i, _)| *i == 2).unwrap().1.transform_point3(Vec3::ZERO);
        let pivot = Vec3::new(0.4, HEIGHT - 0.02, -0.6);
        assert!(((lamp - pivot).length() - PENDULUM).abs() < 1e-5);
        let (sin, cos) = (-40f32).to_radians().sin_cos();
        let expected = pivot + PENDULUM * Vec3::new(sin, -cos, 0.0);
        assert!((lamp - expected).length() < 1e-5, "{lamp} vs {expected}");
        // Halfway through the swing it hangs straight down (smooth keys are symmetric).
        let lamp = scene.animation.pose(1.25).instances[1].1.transform_point3(Vec3::ZERO);
        assert!((lamp - (pivot - Vec3::Y * PENDULUM)).length() < 1e-4, "{lamp}");
        // A quarter turn of the statue after 3 s: its +X face looks to −Z.
        let statue = scene.animation.pose(3.0).instances[0].1;
        assert!((statue.transform_vector3(Vec3::X) - Vec3::NEG_Z).length() < 1e-5);
        // The lamp stays inside the room at every time, above the statue's top.
        for k in 0..50 {
            let m = scene.animation.pose(k as f32 * 0.1).instances[1].1;
            let p = m.transform_point3(Vec3::ZERO);
            assert!(p.y > 1.7 + 0.1 && p.x.abs() < HALF && p.z.abs() < HALF, "{p}");
        }
        assert_eq!(scene.emissive_triangle_count(), 2);
    }
}
