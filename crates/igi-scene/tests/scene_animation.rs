//! Keyframes in scene files: animated meshes (with their instances) and lights take the
//! values computed by hand at known times, and bad keys name the file, line and field.

mod common;

use common::directory;
use glam::{Affine3A, Vec3};
use igi_scene::{Light, LoadReport, SceneError, load, scene_file};

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-4
}

fn transform_at(scene: &igi_scene::Scene, t: f32, instance: u32) -> Affine3A {
    let pose = scene.animation.pose(t);
    pose.instances.iter().find(|(i, _)| *i == instance).map(|(_, m)| *m).expect("instance is animated")
}

#[test]
fn a_keyed_mesh_and_its_instances_move_by_the_keys() {
    let toml = r#"
[[mesh]]
file = "tri.obj"
translate = [0, 0, 5]
instances = [ { }, { translate = [10, 0, 0] } ]
[mesh.animation]
keys = [
  { time = 0, translate = [0, 0, 0] },
  { time = 2, translate = [4, 0, 0], rotate = [0, 0, 90] },
  { time = 4, translate = [4, 2, 0] },
]

[[mesh]]
file = "tri.obj"
"#;
    let dir = directory("anim-mesh", &[("tri.obj", TRIANGLE), ("scene.toml", toml)]);
    let scene = load(dir.join("scene.toml")).unwrap();
    assert_eq!(scene.instances.len(), 3);
    let animated: Vec<u32> = scene.animation.instances.iter().map(|a| a.instance).collect();
    assert_eq!(animated, [0, 1], "the second [[mesh]] stands still");
    // The keyed translate replaces the entry's own (0, 0, 5); rotate has one key and holds.
    // t = 1: translate (2, 0, 0), rotation 90° about Z: the vertex (1, 0, 0) goes to (0, 1, 0).
    let m = transform_at(&scene, 1.0, 0);
    assert!(close(m.transform_point3(Vec3::X), Vec3::new(2.0, 1.0, 0.0)), "{m:?}");
    // The second instance applies after: + (10, 0, 0).
    let m = transform_at(&scene, 1.0, 1);
    assert!(close(m.transform_point3(Vec3::X), Vec3::new(12.0, 1.0, 0.0)), "{m:?}");
    // t = 3: translate (4, 1, 0).
    assert!(close(transform_at(&scene, 3.0, 0).transform_point3(Vec3::ZERO), Vec3::new(4.0, 1.0, 0.0)));
    // Looping with period 4: t = 5 is t = 1.
    assert!(close(transform_at(&scene, 5.0, 0).transform_point3(Vec3::ZERO), Vec3::new(2.0, 0.0, 0.0)));
    // The rest transform is the pose at t = 0.
    assert_eq!(scene.instances[0].transform, transform_at(&scene, 0.0, 0));
}

#[test]
fn keyed_lights_interpolate_position_direction_and_power() {
    let toml = r#"
[[light]]
type = "spot"
position = [0, 3, 0]
direction = [0, -1, 0]
angle = 60
intensity = [1, 1, 1]
[light.animation]
interpolation = "linear"
loop = false
keys = [
  { time = 0, position = [0, 3, 0], intensity = [1, 0, 0] },
  { time = 1, direction = [1, -1, 0] },
  { time = 2, position = [2, 3, 0], intensity = [0, 0, 4], direction = [1, 0, 0] },
]

[[light]]
type = "quad"
position = [0, 2, 0]
u = [0.5, 0, 0]
v = [0, 0, 0.5]
radiance = [5, 5, 5]
[light.animation]
interpolation = "step"
loop = false
keys = [ { time = 0, position = [0, 2, 0] }, { time = 1, position = [1, 2, 0], rotate = [0, 90, 0] } ]
"#;
    let mut report = LoadReport::default();
    let scene = scene_file::parse(toml, "lights.toml", None, &mut report).unwrap();
    let pose = scene.animation.pose(1.5);
    let Light::Spot { position, direction, intensity, .. } = pose.lights[0].1 else { panic!() };
    assert!(close(position, Vec3::new(1.5, 3.0, 0.0)), "{position}");
    assert!(close(intensity, Vec3::new(0.25, 0.0, 3.0)), "{intensity}");
    // Keyed directions are unit vectors; halfway between them, normalised again.
    let halfway = (Vec3::new(1.0, -1.0, 0.0).normalize() + Vec3::X).normalize();
    assert!(close(direction, halfway), "{direction}");
    // Not looping: past the last key the last values hold.
    let Light::Spot { position, .. } = scene.animation.pose(7.0).lights[0].1 else { panic!() };
    assert!(close(position, Vec3::new(2.0, 3.0, 0.0)));
    // The quad steps to x = 1 at t = 1, turned 90° about Y about its centre: u → −Z.
    let quad = scene.instances.len() as u32 - 1;
    let m = transform_at(&scene, 1.2, quad);
    assert!(close(m.transform_point3(Vec3::ZERO), Vec3::new(1.0, 2.0, 0.0)));
    assert!(close(m.transform_vector3(Vec3::new(0.5, 0.0, 0.0)), Vec3::new(0.0, 0.0, -0.5)));
    assert!(close(transform_at(&scene, 0.9, quad).transform_point3(Vec3::ZERO), Vec3::new(0.0, 2.0, 0.0)));
}

fn error_of(toml: &str) -> String {
    let mut report = LoadReport::default();
    match scene_file::parse(toml, "bad.toml", None, &mut report) {
        Err(e @ (SceneError::Invalid { .. } | SceneError::Parse { .. })) => e.to_string(),
        other => panic!("expected an error, got {other:?}"),
    }
}

#[test]
fn bad_keys_name_the_file_line_and_field() {
    let point = "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, 1, 1]\n";
    let cases = [
        ("animation = { keys = [] }", "light[0].animation.keys", "at least one key"),
        (
            "animation = { keys = [ { time = -1, position = [0, 0, 0] } ] }",
            "light[0].animation.keys[0].time",
            "≥ 0",
        ),
        (
            "animation = { keys = [ { time = 0, direction = [0, 0, 1] } ] }",
            "keys[0].direction",
            "cannot animate",
        ),
        (
            "animation = { keys = [ { time = 1, position = [0, 0, 0] }, { time = 1, position = [1, 0, 0] } ] }",
            "light[0].animation.keys",
            "increase",
        ),
        ("animation = { keys = [ { time = 0, intensity = [-1, 0, 0] } ] }", "keys[0].intensity", "negative"),
        (
            "animation = { keys = [ { time = 0, position = [0, 0, 0] } ], interpolation = \"cubic\" }",
            "",
            "unknown variant",
        ),
        ("animation = { keys = [ { time = 0, spin = 3 } ] }", "", "unknown field"),
    ];
    for (animation, field, message) in cases {
        let error = error_of(&format!("{point}{animation}\n"));
        assert!(error.contains("bad.toml"), "{error}");
        assert!(error.contains(field) && error.contains(message), "{animation}: {error}");
        assert!(error.contains("line"), "{error}");
    }
}
