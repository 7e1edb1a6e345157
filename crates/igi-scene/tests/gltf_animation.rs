//! glTF node animations (glTF 2.0 section 3.11, Appendix C): the shared sample files move as
//! values computed here by hand from their keyframes, and broken samplers load with a warning.
//! The sample tests are skipped, with a message, when the shared scenes are not beside the
//! repository.

mod common;

use std::f32::consts::{FRAC_1_SQRT_2, FRAC_PI_2, FRAC_PI_4};

use common::{Output, animated_gltf, scenes_dir};
use glam::{Affine3A, Quat, Vec3, Vec4};
use igi_scene::{Light, LoadReport, Scene, load_with_report};

/// Loads `relative` (under `shared/scenes/gltf-samples`), or `None` if the scenes are absent.
fn sample(test: &str, relative: &str) -> Option<(Scene, LoadReport)> {
    let path = scenes_dir(test)?.join("gltf-samples").join(relative);
    Some(load_with_report(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// Parses a hand-written document, which must load.
fn parse(json: &str) -> (Scene, LoadReport) {
    let mut report = LoadReport::default();
    let scene =
        igi_scene::parse_mesh(igi_scene::MeshFormat::Gltf, json.as_bytes(), "anim.gltf", None, &mut report)
            .unwrap();
    (scene, report)
}

/// The instances of the mesh named `name`.
fn instances_of(scene: &Scene, name: &str) -> Vec<u32> {
    (0..scene.instances.len() as u32)
        .filter(|&i| scene.meshes[scene.instances[i as usize].mesh as usize].name == name)
        .collect()
}

/// True if instance `instance` is animated.
fn is_animated(scene: &Scene, instance: u32) -> bool {
    scene.animation.instances.iter().any(|a| a.instance == instance)
}

/// The world transform of animated instance `instance` at time `t`.
fn posed(scene: &Scene, instance: u32, t: f32) -> Affine3A {
    let pose = scene.animation.pose(t);
    let found = pose.instances.iter().find(|(i, _)| *i == instance);
    found.unwrap_or_else(|| panic!("instance {instance} is not animated")).1
}

/// The world transform at time `t` of the one instance of the mesh named `name`.
fn posed_mesh(scene: &Scene, name: &str, t: f32) -> Affine3A {
    let instances = instances_of(scene, name);
    assert_eq!(instances.len(), 1, "{name}");
    posed(scene, instances[0], t)
}

#[track_caller]
fn assert_close(actual: Vec3, expected: Vec3, what: &str) {
    assert!((actual - expected).abs().max_element() < 1e-4, "{what}: {actual} instead of {expected}");
}

/// Asserts that `m` rotates as `q` does (an X and a Y axis are turned alike).
#[track_caller]
fn assert_rotation(m: &Affine3A, q: Quat, what: &str) {
    for axis in [Vec3::X, Vec3::Y] {
        assert_close(m.transform_vector3(axis).normalize(), q * axis, what);
    }
}

/// Spherical linear interpolation as glTF Appendix C writes it: the shorter way round.
fn slerp(a: Vec4, b: Vec4, s: f32) -> Quat {
    let d = a.dot(b);
    let (b, d) = if d < 0.0 { (-b, -d) } else { (b, d) };
    let angle = d.min(1.0).acos();
    let v = (a * ((1.0 - s) * angle).sin() + b * (s * angle).sin()) / angle.sin();
    Quat::from_vec4(v)
}

/// The cubic Hermite spline of glTF Appendix C between key k (value `v0`, out-tangent `b0`)
/// and key k + 1 (in-tangent `a1`, value `v1`), `dt` seconds apart, at fraction `s`.
fn hermite(v0: Vec4, b0: Vec4, a1: Vec4, v1: Vec4, dt: f32, s: f32) -> Vec4 {
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * v0
        + dt * (s3 - 2.0 * s2 + s) * b0
        + (-2.0 * s3 + 3.0 * s2) * v1
        + dt * (s3 - s2) * a1
}

#[test]
fn box_animated_moves_as_its_keyframes() {
    let Some((scene, report)) = sample("box_animated", "BoxAnimated/glTF-Binary/BoxAnimated.glb") else {
        return;
    };
    assert!(report.warnings.is_empty(), "{report:?}");
    let animation = &scene.animation;
    // Node 0 (translation keys) → node 1 (still) → node 2 (rotation keys, the inner box);
    // node 3, the outer box, is a still root and stays out of the animation.
    let parents: Vec<Option<u32>> = animation.nodes.iter().map(|n| n.parent).collect();
    assert_eq!(parents, [None, Some(0), Some(1)]);
    assert_eq!(animation.instances.len(), 1);
    let inner = animation.instances[0].instance;
    assert_eq!(animation.instances[0].node, 2);
    assert_eq!(scene.instances.len(), 2);
    // The translation keys: y = 0, 2.52, 2.52, 0 at 0, 1.25, 2.5 and 3.708 s.
    let last = 3.708_33;
    assert!((animation.duration() - last).abs() < 1e-4, "{}", animation.duration());
    // The rotation keys: the identity (written as −1) at 1.25 s, half a turn about X at 2.5 s.
    let q0 = Vec4::new(-0.0, -0.0, -0.0, -1.0);
    let q1 = Vec4::new(1.0, 0.0, 0.0, 4.489_659_3e-11);
    let cases = [
        // Halfway through the first translation segment, before the first rotation key.
        (0.625, 1.26, Quat::IDENTITY),
        // At the first rotation key and halfway between the two.
        (1.25, 2.52, Quat::from_vec4(q0)),
        (1.875, 2.52, slerp(q0, q1, 0.5)),
        // At the last rotation key, then holding it halfway through the last translation segment.
        (2.5, 2.52, Quat::from_vec4(q1)),
        ((2.5 + last) / 2.0, 1.26, Quat::from_vec4(q1)),
        // The animation starts over after its last key.
        (last + 0.625, 1.26, Quat::IDENTITY),
    ];
    for (t, y, rotation) in cases {
        let m = posed(&scene, inner, t);
        assert_close(m.translation.into(), Vec3::new(0.0, y, 0.0), &format!("translation at {t}"));
        assert_rotation(&m, rotation, &format!("rotation at {t}"));
        assert_eq!(animation.node_transforms(t)[2], m, "the instance sits on node 2");
    }
    // The slerp halfway is a quarter turn about X (the shorter way of the two).
    assert_rotation(&posed(&scene, inner, 1.875), Quat::from_rotation_x(FRAC_PI_2), "1.875");
}

#[test]
fn interpolation_test_steps_lerps_and_splines() {
    let Some((scene, report)) = sample("interpolation_test", "InterpolationTest/glTF/InterpolationTest.gltf")
    else {
        return;
    };
    assert!(report.warnings.is_empty(), "{report:?}");
    // Nine animations, one cube each, all root nodes; the plane (mesh "Plane.001") is still.
    assert_eq!(scene.animation.instances.len(), 9);
    assert!(!instances_of(&scene, "Plane.001").into_iter().any(|i| is_animated(&scene, i)));

    // Scale keys (all three samplers): 1, 0.5, 1, 0.5, 1 at these times.
    let scale_times = [0.041_666_668, 0.416_666_66, 0.875, 1.25, 1.666_666_6];
    let t = 0.6;
    let s = (t - scale_times[1]) / (scale_times[2] - scale_times[1]);
    let h01 = -2.0 * s * s * s + 3.0 * s * s;
    let scale_cases = [
        ("Cube", 0.5, Vec3::ZERO),                                        // STEP: key 1 holds
        ("Cube.001", 0.5 + 0.5 * s, Vec3::new(-3.296_33, 0.0, 6.461e-5)), // LINEAR
        // CUBICSPLINE with zero tangents: v0·h00 + v1·h01.
        ("Cube.002", 0.5 * (1.0 - h01) + h01, Vec3::new(3.340_12, 0.0, 0.008_945)),
    ];
    for (mesh, scale, translation) in scale_cases {
        let m = posed_mesh(&scene, mesh, t);
        let axes = Vec3::new(m.matrix3.x_axis.length(), m.matrix3.y_axis.length(), m.matrix3.z_axis.length());
        assert_close(axes, Vec3::splat(scale), &format!("{mesh} scale"));
        assert_close(m.translation.into(), translation, &format!("{mesh} keeps its rest translation"));
    }

    // Rotation keys: about −Z by 0°, 45°, 90°, 135°, 180° at these times.
    let rotation_times = [0.0, 0.416_666_66, 0.875, 1.25, 1.708_333_4];
    let key1 = Vec4::new(0.0, 0.0, -0.382_683_46, 0.923_879_56);
    let key2 = Vec4::new(0.0, 0.0, -FRAC_1_SQRT_2, FRAC_1_SQRT_2);
    let s = (t - rotation_times[1]) / (rotation_times[2] - rotation_times[1]);
    assert_rotation(&posed_mesh(&scene, "Cube.003", t), Quat::from_vec4(key1), "STEP rotation");
    assert_rotation(&posed_mesh(&scene, "Cube.005", t), slerp(key1, key2, s), "LINEAR rotation");
    // CUBICSPLINE rotation, between keys 0 and 1 where the tangents are not zero: key 0 has
    // value (0, 0, 0, 1) and out-tangent (0, 0, 0, 1), key 1 in-tangent
    // (0, 0, −0.0479, 0.9989) and value `key1`.
    let t = 0.25;
    let dt = rotation_times[1] - rotation_times[0];
    let spline = hermite(Vec4::W, Vec4::W, Vec4::new(0.0, 0.0, -0.047_890_9, 0.998_852_7), key1, dt, t / dt);
    let cubic = posed_mesh(&scene, "Cube.004", t);
    assert_rotation(&cubic, Quat::from_vec4(spline.normalize()), "CUBICSPLINE rotation");
    assert_close(cubic.translation.into(), Vec3::new(3.335_062, 3.356_412, 0.0), "rest translation");

    // Translation keys: y = 10, 6 at the times of keys 1 and 2 (STEP has its own times).
    let t = 0.6;
    let (t1, t2) = (0.416_666_66, 0.833_333_3);
    let s = (t - t1) / (t2 - t1);
    let h01 = -2.0 * s * s * s + 3.0 * s * s;
    let translation_cases = [
        // STEP: key 1 (at 0.458 s) holds.
        ("Cube.006", Vec3::new(0.0, 10.0, 0.0)),
        // CUBICSPLINE with zero tangents.
        ("Cube.008", Vec3::new(3.305_18, 10.0 * (1.0 - h01) + 6.0 * h01, 0.0)),
        // LINEAR.
        ("Cube.009", Vec3::new(-3.297_58, 10.0 - 4.0 * s, 0.0)),
    ];
    for (mesh, translation) in translation_cases {
        assert_close(posed_mesh(&scene, mesh, t).translation.into(), translation, mesh);
    }

    // Each animation loops with its own period, its last key time.
    for (mesh, period) in [("Cube", 1.666_666_6), ("Cube.003", 1.708_333_4), ("Cube.006", 1.708_333_4)] {
        let (a, b) = (posed_mesh(&scene, mesh, 0.6), posed_mesh(&scene, mesh, 0.6 + period));
        assert!(a.abs_diff_eq(b, 1e-4), "{mesh}: {a} and {b}");
    }
}

#[test]
fn cesium_milk_truck_turns_its_wheels_about_their_axles() {
    let Some((scene, report)) = sample("milk_truck", "CesiumMilkTruck/glTF/CesiumMilkTruck.gltf") else {
        return;
    };
    assert!(report.warnings.is_empty(), "{report:?}");
    let body = instances_of(&scene, "Cesium_Milk_Truck");
    assert!(!body.into_iter().any(|i| is_animated(&scene, i)), "the body stands still");
    let wheels = instances_of(&scene, "Wheels");
    assert_eq!(wheels.len(), 2);
    assert!(wheels.iter().all(|&i| is_animated(&scene, i)));
    // One animation of 31 LINEAR keys over 1.25 s; a quarter period lies halfway between
    // keys 7 (0.291667 s) and 8 (0.333333 s). Every key turns about Z: its angle is 2·atan2(z, w).
    let period = 1.25;
    let t = period / 4.0;
    let angle = |z: f32, w: f32| 2.0 * z.atan2(w);
    let (theta7, theta8) = (angle(0.718_029_1, -0.696_013_1), angle(0.785_019_8, -0.619_470_8));
    let s = (t - 0.291_667) / (0.333_333 - 0.291_667);
    // Relative to the rest rotation (key 0's), the wheels have turned this far about Z.
    let turn = theta7 + s * (theta8 - theta7) - angle(0.088_485_9, -0.996_077_4);
    assert!(turn.sin().abs() > 0.9, "about a quarter turn: {turn}");
    for wheel in wheels {
        let rest = scene.instances[wheel as usize].transform;
        let moved = posed(&scene, wheel, t);
        let axle = rest.transform_point3(Vec3::ZERO);
        assert_close(moved.transform_point3(Vec3::ZERO), axle, "the axle point stays");
        assert_close(
            moved.transform_vector3(Vec3::Z),
            rest.transform_vector3(Vec3::Z),
            "the axle direction stays",
        );
        for p in [Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.3, -0.2, 0.1)] {
            let expected = axle + Quat::from_rotation_z(turn) * (rest.transform_point3(p) - axle);
            assert_close(moved.transform_point3(p), expected, "a point of the wheel");
        }
        let again = posed(&scene, wheel, t + period);
        assert_close(again.transform_point3(Vec3::Y), moved.transform_point3(Vec3::Y), "one period later");
    }
    assert!((scene.animation.duration() - period).abs() < 1e-6);
}

#[test]
fn skins_and_morph_weights_are_not_animated_with_a_warning() {
    let Some((fox, report)) = sample("skins_and_morphs", "Fox/glTF/Fox.gltf") else { return };
    assert!(fox.animation.is_empty());
    let joints: Vec<_> = report.warnings.iter().filter(|w| w.contains("move skin joints")).collect();
    assert_eq!(joints.len(), 3, "one warning per animation: {report:?}");
    assert!(joints[0].contains("animations[0]: "), "{}", joints[0]);
    let (cube, report) = sample("skins_and_morphs", "AnimatedMorphCube/glTF/AnimatedMorphCube.gltf").unwrap();
    assert!(cube.animation.is_empty());
    assert!(
        report.warnings.iter().any(|w| w
            .ends_with("animations[0].channels[0]: morph-target weights are not animated; shown at rest")),
        "{report:?}"
    );
}

/// A document whose node moves along y: `ys` are the output values at key `times`.
fn lift(times: &[f32], ys: &[f32], interpolation: &str) -> String {
    let values: Vec<[f32; 3]> = ys.iter().map(|&y| [0.0, y, 0.0]).collect();
    animated_gltf(times, &Output::floats(&values), "translation", interpolation)
}

#[test]
fn hand_written_tracks_are_keyed_as_written() {
    // CUBICSPLINE: (in-tangent, value, out-tangent) per key, tangents per second: over 2 s
    // from 0 to 0 with out-tangent 1 at the first key, y(s) = dt·(s³ − 2s² + s). The tangents
    // before the first key and after the last (9) are not used.
    let (scene, report) = parse(&lift(&[0.0, 2.0], &[9.0, 0.0, 1.0, 0.0, 0.0, 9.0], "CUBICSPLINE"));
    assert!(report.warnings.is_empty(), "{report:?}");
    let s: f32 = 0.25;
    let y = posed(&scene, 0, 0.5).translation.y;
    assert!((y - 2.0 * (s * s * s - 2.0 * s * s + s)).abs() < 1e-6, "{y}");

    // Rotations may be stored as normalized shorts: a quarter turn about Y, halfway at 0.5 s.
    let quarter = (FRAC_1_SQRT_2 * 32767.0).round() as i16;
    let shorts: Vec<u8> = [[0i16, 0, 0, 32767], [0, quarter, 0, quarter]]
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let output = Output { bytes: shorts, component_type: 5122, kind: "VEC4", count: 2 };
    let (scene, report) = parse(&animated_gltf(&[0.0, 1.0], &output, "rotation", "LINEAR"));
    assert!(report.warnings.is_empty(), "{report:?}");
    assert_rotation(&posed(&scene, 0, 0.5), Quat::from_rotation_y(FRAC_PI_4), "i16 rotation");

    // A mirrored node (scale y = −1) keeps its mirror about its own y when keyed rotations
    // replace its rotation (a decomposition would move the sign onto x).
    let mirrored = json_with_rotation_keys()
        .replace(r#""nodes":[{"mesh":0}]"#, r#""nodes":[{"mesh":0,"scale":[1,-1,1]}]"#);
    let (scene, report) = parse(&mirrored);
    assert!(report.warnings.is_empty(), "{report:?}");
    let m = posed(&scene, 0, 0.5);
    let half = Quat::from_rotation_y(FRAC_PI_4);
    assert_close(m.transform_vector3(Vec3::X), half * Vec3::X, "x");
    assert_close(m.transform_vector3(Vec3::Y), half * Vec3::NEG_Y, "y");
}

/// A document whose node turns a quarter about Y in a second (LINEAR).
fn json_with_rotation_keys() -> String {
    let turn = Output::floats(&[Quat::IDENTITY.to_array(), Quat::from_rotation_y(FRAC_PI_2).to_array()]);
    animated_gltf(&[0.0, 1.0], &turn, "rotation", "LINEAR")
}

#[test]
fn broken_samplers_and_weights_warn_and_the_file_loads() {
    let rotation = |values: &[[f32; 4]], interpolation| {
        animated_gltf(&[0.0, 1.0], &Output::floats(values), "rotation", interpolation)
    };
    // (document, problem with the sampler)
    let samplers = [
        (
            lift(&[0.0, 1.0, 0.5], &[0.0, 1.0, 2.0], "LINEAR"),
            "key times must increase strictly (0.5 follows 1)",
        ),
        (lift(&[-1.0, 1.0], &[0.0, 1.0], "STEP"), "key time -1 is not a finite number ≥ 0"),
        (lift(&[0.0, f32::NAN], &[0.0, 1.0], "STEP"), "key time NaN is not a finite number ≥ 0"),
        (lift(&[0.0, 1.0], &[0.0, f32::NAN], "LINEAR"), "a key value is not finite"),
        (lift(&[0.0, 1.0], &[0.0, 1.0, 2.0], "LINEAR"), "3 output values for 2 key times"),
        (
            lift(&[0.0, 1.0], &[0.0, 1.0], "CUBICSPLINE"),
            "2 output values for 2 key times (CUBICSPLINE needs 3 per key)",
        ),
        (rotation(&[[0.0; 4], [0.0, 0.0, 0.0, 1.0]], "STEP"), "rotation key 0 is zero or not finite"),
        (
            animated_gltf(&[0.0, 1.0], &Output::floats(&[[0.0; 3], [1.0; 3]]), "rotation", "LINEAR"),
            "accessor 3: type F32 Vec3 is not supported here",
        ),
    ];
    let samplers = samplers.map(|(json, problem)| {
        (json, format!("animations[0].samplers[0]: {problem}; animations[0].channels[0] skipped"))
    });
    // (document, problem with the channel)
    let channels = [
        (
            animated_gltf(&[0.0, 1.0], &Output::floats(&[[0.0], [1.0]]), "weights", "LINEAR"),
            "morph-target weights are not animated; shown at rest",
        ),
        (
            lift(&[0.0, 1.0], &[0.0, 1.0], "LINEAR").replace(r#""node":0,"path""#, r#""node":7,"path""#),
            "target node 7 does not exist; skipped",
        ),
        (
            lift(&[0.0, 1.0], &[0.0, 1.0], "LINEAR").replace(r#""translation""#, r#""pointer""#),
            "unknown target path; skipped",
        ),
    ];
    let channels = channels.map(|(json, problem)| (json, format!("animations[0].channels[0]: {problem}")));
    for (json, warning) in samplers.into_iter().chain(channels) {
        let (scene, report) = parse(&json);
        assert_eq!(scene.triangle_count(), 1, "{warning}");
        assert!(scene.animation.is_empty(), "{warning}");
        assert_eq!(report.warnings, [format!("anim.gltf: {warning}")]);
    }
    // A sparse time accessor that claims a billion keys (`allocation.rs` checks that nothing
    // of that size is allocated).
    let (scene, report) = parse(&common::lying_key_times());
    assert!(scene.animation.is_empty());
    assert!(report.warnings[0].contains("key times do not increase"), "{report:?}");
}

#[test]
fn lights_ride_on_animated_nodes() {
    // Node 0 turns a quarter about Y in a second; its child, node 1, two units down its +Z,
    // carries a spot light. Node 2, a still root, carries a point light.
    let json = json_with_rotation_keys()
        .replace(
            r#""nodes":[{"mesh":0}]"#,
            concat!(
                r#""nodes":[{"mesh":0,"children":[1]},"#,
                r#"{"translation":[0,0,2],"extensions":{"KHR_lights_punctual":{"light":0}}},"#,
                r#"{"extensions":{"KHR_lights_punctual":{"light":1}}}]"#
            ),
        )
        .replace(r#""nodes":[0]"#, r#""nodes":[0,2]"#)
        .replace(
            r#""asset""#,
            concat!(
                r#""extensionsUsed":["KHR_lights_punctual"],"extensions":{"KHR_lights_punctual":{"lights":["#,
                r#"{"type":"spot","intensity":2,"spot":{"outerConeAngle":0.5}},{"type":"point"}]}},"asset""#
            ),
        );
    let (scene, report) = parse(&json);
    assert!(report.warnings.is_empty(), "{report:?}");
    assert_eq!(scene.lights.len(), 2);
    // At rest the spot sits where its node is; in the animation, in its node's space.
    let spot = |position: Vec3, direction: Vec3| Light::Spot {
        position,
        direction,
        angle_deg: 2.0 * 0.5f32.to_degrees(),
        intensity: Vec3::splat(2.0),
    };
    assert_eq!(scene.lights[0], spot(Vec3::new(0.0, 0.0, 2.0), Vec3::NEG_Z));
    let lights = &scene.animation.lights;
    assert_eq!(lights.len(), 1, "the point light on the still node stands still");
    assert_eq!((lights[0].light, lights[0].node), (0, Some(1)));
    assert_eq!(lights[0].rest, spot(Vec3::ZERO, Vec3::NEG_Z));
    // Half a second in, the node has turned by 45° (at one second the animation starts over).
    let Light::Spot { position, direction, .. } = scene.animation.pose(0.5).lights[0].1 else {
        panic!("a spot light")
    };
    let half = Quat::from_rotation_y(FRAC_PI_4);
    assert_close(position, half * Vec3::new(0.0, 0.0, 2.0), "position");
    assert_close(direction, half * Vec3::NEG_Z, "direction");
}

#[test]
fn a_scene_file_places_an_animated_gltf() {
    let dir = std::env::temp_dir().join(format!("igi-gltf-animation-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("turn.gltf"), json_with_rotation_keys()).unwrap();
    let toml = "[[mesh]]\nfile = \"turn.gltf\"\ntranslate = [10, 0, 0]\n";
    std::fs::write(dir.join("scene.toml"), toml).unwrap();
    let (scene, report) = load_with_report(dir.join("scene.toml")).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(report.warnings.is_empty(), "{report:?}");
    // The file's animation turns the triangle about its own origin, which the entry places.
    let m = posed(&scene, 0, 0.5);
    let expected = Vec3::new(10.0, 0.0, 0.0) + Quat::from_rotation_y(FRAC_PI_4) * Vec3::X;
    assert_close(m.transform_point3(Vec3::X), expected, "placed and turned");
}
