//! The built-in scenes, and the built-in Cornell box against the shared OBJ it reproduces.

mod common;

use common::scenes_dir;
use glam::Vec3;
use igi_scene::{Scene, builtin, builtin_names, builtin_spec, closest_builtin, load, load_named};

/// Every instanced triangle as (material name, corners), each rotated to start at its
/// smallest corner so that the winding is kept but the starting vertex does not matter.
fn triangles(scene: &Scene) -> Vec<(String, [[u32; 3]; 3])> {
    let mut all = Vec::new();
    for instance in &scene.instances {
        let mesh = &scene.meshes[instance.mesh as usize];
        for (t, &material) in mesh.material_ids.iter().enumerate() {
            let corners =
                mesh.triangle(t).map(|p| instance.transform.transform_point3(p).to_array().map(f32::to_bits));
            let first = (0..3).min_by_key(|&i| corners[i]).unwrap();
            let rotated = [0, 1, 2].map(|i| corners[(first + i) % 3]);
            all.push((scene.materials[material as usize].name.clone(), rotated));
        }
    }
    all.sort();
    all
}

#[test]
fn cornell_box_matches_the_shared_obj() {
    let Some(dir) = scenes_dir("cornell_box_matches_the_shared_obj") else { return };
    let file = load(dir.join("cornell-box/CornellBox-Original.obj")).unwrap();
    let built = builtin("cornell-box").unwrap();
    assert_eq!(triangles(&built), triangles(&file));
    assert_eq!(built.materials, file.materials);
    assert_eq!(built.bounds(), file.bounds());
    assert_eq!(file.camera, None, "the OBJ has no camera; the built-in has the README's");
    let camera = built.camera.unwrap();
    assert_eq!(
        (camera.position, camera.target, camera.up),
        (Vec3::new(0.0, 1.0, 3.5), Vec3::new(0.0, 1.0, 0.0), Vec3::Y)
    );
}

#[test]
fn names_load_through_load_named() {
    for name in builtin_names() {
        if matches!(*name, "power-plant" | "maple-tree" | "displaced-sphere") {
            // Their default size takes seconds and gigabytes; a smaller one through its spec.
            let spec = format!("{name}:triangles=700k");
            let scene = load_named(&spec).unwrap();
            assert_eq!(
                scene.digest(),
                builtin_spec(&spec).unwrap().unwrap().digest(),
                "{spec}: generated alike"
            );
            continue;
        }
        let scene = load_named(name).unwrap();
        assert_eq!(scene.triangle_count(), builtin(name).unwrap().triangle_count());
    }
    assert_eq!(builtin("shirley-room").unwrap().triangle_count(), 722);
    let err = load_named("no-such-scene").unwrap_err().to_string();
    assert!(err.contains("neither a built-in scene nor a scene file"), "{err}");
    assert!(!err.contains("Did you mean"), "nothing is close to no-such-scene: {err}");
    assert!(builtin_names().iter().all(|n| err.contains(n)), "the message lists the built-ins: {err}");
}

#[test]
fn a_mistyped_name_gets_the_closest_built_in() {
    for (typed, meant) in [
        ("cornel-box", "cornell-box"),
        ("Cornell-Box", "cornell-box"),
        ("maple-tre:triangles=1M", "maple-tree"),
        ("powerplant", "power-plant"),
        ("shirley", "shirley-room"),
        ("two-room", "two-rooms"),
    ] {
        assert_eq!(closest_builtin(typed), Some(meant), "{typed}");
        let err = load_named(typed).unwrap_err().to_string();
        assert!(err.contains(&format!("Did you mean {meant}?")), "{typed}: {err}");
    }
    assert_eq!(closest_builtin("sponza.fbx"), None);
}

#[test]
fn a_folder_gets_its_scene_files_listed() {
    let dir = tempfile::tempdir().unwrap();
    let err = load_named(dir.path().to_str().unwrap()).unwrap_err().to_string();
    assert!(err.contains("is a folder with no scene file"), "{err}");
    assert!(err.contains("cornell-box"), "an empty folder's message lists the built-ins: {err}");
    for file in ["b.obj", "a.gltf", "notes.txt"] {
        std::fs::write(dir.path().join(file), "").unwrap();
    }
    let err = load_named(dir.path().to_str().unwrap()).unwrap_err().to_string();
    assert!(err.contains("give one of its scene files (a.gltf, b.obj)"), "{err}");
}
