//! Every scene in `shared/scenes` loads with the numbers its README states. Skipped, with a
//! message, when the shared scenes are not beside the repository.

mod common;

use common::{assert_bounds, scenes_dir};
use glam::Vec3;
use igi_scene::{LoadReport, MaterialKind, Scene, load_with_report};

/// Loads `relative` (under `shared/scenes`), or `None` if the scenes are absent.
fn load(test: &str, relative: &str) -> Option<(Scene, LoadReport)> {
    let path = scenes_dir(test)?.join(relative);
    Some(load_with_report(&path).unwrap_or_else(|e| panic!("{e}")))
}

/// Loads `name` from the repository's `scenes/` (scene files that place the shared scenes), or
/// `None` if the shared scenes are absent.
fn load_repository_scene(test: &str, name: &str) -> Option<(Scene, LoadReport)> {
    scenes_dir(test)?;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    Some(load_with_report(&path).unwrap_or_else(|e| panic!("{e}")))
}

fn material<'a>(scene: &'a Scene, name: &str) -> &'a igi_scene::Material {
    scene.materials.iter().rev().find(|m| m.name == name).unwrap_or_else(|| panic!("no material {name}"))
}

/// No warnings and nothing dropped.
fn assert_clean(report: &LoadReport) {
    assert_eq!((report.degenerate_dropped, report.warnings.as_slice()), (0, &[][..]));
}

#[test]
fn cornell_box() {
    let Some((scene, report)) = load("cornell_box", "cornell-box/CornellBox-Original.obj") else { return };
    // All 36 triangles are kept, including the two side faces the file repeats as "bottoms".
    assert_eq!(scene.triangle_count(), 36);
    assert_eq!(scene.materials.len(), 8);
    assert_eq!(scene.emissive_triangle_count(), 2);
    assert_eq!(material(&scene, "light").emission, Vec3::new(17.0, 12.0, 4.0));
    assert_eq!(material(&scene, "leftWall").diffuse, Vec3::new(0.63, 0.065, 0.05));
    assert_bounds(scene.bounds(), [-1.02, 0.0, -1.04], [1.0, 1.99, 0.99], 1e-6);
    assert_clean(&report);
    let read: Vec<_> = report.files.iter().filter_map(|f| f.file_name()).collect();
    assert_eq!(read, ["CornellBox-Original.obj", "CornellBox-Original.mtl"]);
}

#[test]
fn cornell_variants() {
    // (file, triangles, bbox max y, light emission)
    let cases: [(&str, usize, f32, Option<[f32; 3]>); 9] = [
        ("CornellBox-Glossy.obj", 1112, 1.59, Some([17.0, 12.0, 4.0])),
        ("CornellBox-Glossy-Floor.obj", 1112, 1.59, Some([17.0, 12.0, 4.0])),
        ("CornellBox-Sphere.obj", 2188, 1.59, Some([10.0, 10.0, 10.0])),
        ("CornellBox-Water.obj", 7088, 1.59, Some([10.0, 10.0, 10.0])),
        ("water.obj", 4900, 0.2524, None),
        ("CornellBox-Mirror.obj", 36, 1.99, Some([17.0, 12.0, 4.0])),
        ("CornellBox-Empty-RG.obj", 12, 1.99, Some([17.0, 12.0, 4.0])),
        ("CornellBox-Empty-CO.obj", 12, 1.99, Some([10.0, 10.0, 10.0])),
        ("CornellBox-Empty-White.obj", 12, 1.99, Some([10.0, 10.0, 10.0])),
    ];
    for (file, triangles, max_y, emission) in cases {
        let Some((scene, report)) = load("cornell_variants", &format!("cornell-variants/{file}")) else {
            return;
        };
        assert_eq!(scene.triangle_count(), triangles, "{file}");
        assert_eq!(report.degenerate_dropped, 0, "{file}");
        assert!((scene.bounds().max.y - max_y).abs() < 1e-3, "{file}: {:?}", scene.bounds());
        if let Some(emission) = emission {
            assert_eq!(material(&scene, "light").emission, Vec3::from(emission), "{file}");
        }
        if file != "water.obj" {
            assert_eq!(scene.emissive_triangle_count(), 2, "{file}: the ceiling quad");
        }
    }
    // The Glossy files use `usemtl light` without defining it: an emitter is substituted.
    let Some((_, report)) = load("cornell_variants", "cornell-variants/CornellBox-Glossy.obj") else {
        return;
    };
    assert!(report.warnings.iter().any(|w| w.contains("`light` is not defined")), "{report:?}");
    let (mirror, _) = load("cornell_variants", "cornell-variants/CornellBox-Mirror.obj").unwrap();
    assert_eq!(material(&mirror, "tallBox").kind, MaterialKind::Mirror, "illum 5, `newmtl tallBox `");
    let (water, _) = load("cornell_variants", "cornell-variants/CornellBox-Water.obj").unwrap();
    let glass = material(&water, "water");
    assert_eq!((glass.kind, glass.ior), (MaterialKind::Glass, 1.33));
    let (squashed, _) = load("cornell_variants", "cornell-variants/CornellBox-Empty-Squashed.obj").unwrap();
    assert_eq!(squashed.triangle_count(), 12, "only 6 quads use its 2,574 vertices");
}

#[test]
fn conference() {
    let Some((scene, report)) = load("conference", "conference/conference.obj") else { return };
    assert_eq!(scene.triangle_count(), 331_179);
    assert_eq!(report.degenerate_dropped, 0);
    assert_eq!(scene.materials.len(), 35);
    assert!(scene.textures.is_empty());
    assert_eq!(scene.emissive_triangle_count(), 0);
    assert_eq!(material(&scene, "mesh29_SG").diffuse, Vec3::ONE, "the second Kd wins");
    assert!(scene.meshes[0].uvs.is_none(), "no material is textured");
    assert_bounds(scene.bounds(), [-1020.13, -2.79, -1055.66], [1685.81, 650.29, 668.49], 0.01);
}

#[test]
fn sponza() {
    let Some((scene, report)) = load("sponza", "sponza-dabrovic/sponza.obj") else { return };
    // 66,450 in the file; 6 of them have collinear corners and are dropped.
    assert_eq!(report.degenerate_dropped, 6);
    assert_eq!(scene.triangle_count() + report.degenerate_dropped, 66_450);
    assert_eq!(report.warnings.len(), 1, "only the degenerate count, every texture resolves: {report:?}");
    assert_eq!(scene.materials.len(), 20);
    assert_eq!(scene.materials.iter().filter(|m| m.diffuse_texture.is_some()).count(), 19);
    assert_eq!(scene.materials.iter().filter(|m| m.bump_texture.is_some()).count(), 18);
    assert!(scene.materials.iter().all(|m| m.transparency == 0.0), "`d 1` and `Tr 0` mean opaque");
    assert!(scene.textures.iter().all(|t| t.image.is_complete()));
    let uvs = scene.meshes[0].uvs.as_ref().expect("textured");
    assert_eq!(uvs.len(), scene.meshes[0].positions.len());
    assert_bounds(scene.bounds(), [-17.403, -0.907, -7.799], [17.417, 15.653, 7.801], 1e-3);
}

#[test]
fn sibenik() {
    let Some((scene, report)) = load("sibenik", "sibenik/sibenik.obj") else { return };
    assert_eq!(report.degenerate_dropped, 7);
    assert_eq!(scene.triangle_count() + report.degenerate_dropped, 75_284);
    assert_eq!(scene.materials.len(), 15);
    assert_eq!(scene.textures.len(), 5, "3 colour maps and 2 bump maps");
    assert_eq!(material(&scene, "staklo").kind, MaterialKind::Glass);
    // `d 1` next to `Tr 0` is opaque; only the red rose-window glass has `d 0.8` (`Tr 0.2`).
    let see_through: Vec<_> = scene.materials.iter().filter(|m| m.transparency > 0.0).collect();
    assert_eq!(see_through.len(), 1);
    assert_eq!(see_through[0].name, "staklo_crveno");
    assert!((see_through[0].transparency - 0.2).abs() < 1e-6);
    assert_bounds(scene.bounds(), [-20.141, -15.312, -8.497], [20.141, 15.3, 8.497], 1e-3);
}

#[test]
fn lost_empire() {
    let Some((scene, report)) = load("lost_empire", "lost-empire/lost_empire.obj") else { return };
    assert_eq!(scene.triangle_count(), 224_998);
    assert_eq!(report.degenerate_dropped, 0);
    assert_eq!(scene.materials.len(), 45);
    assert_eq!(material(&scene, "Stationary_Lava").emission, Vec3::new(0.3, 0.05, 0.01));
    assert_eq!(material(&scene, "Torch").emission, Vec3::ZERO, "its Ke is commented out");
    assert_eq!(scene.emissive_triangle_count(), 162);
    assert_eq!(scene.textures.len(), 3, "RGB and RGBA atlases, and the alpha atlas of map_d");
    // Leaves, water, rails and the like cut out by lost_empire-Alpha.png, an RGBA image whose
    // alpha is opaque everywhere: the mask is its grey level.
    let masked: Vec<&igi_scene::Material> =
        scene.materials.iter().filter(|m| m.alpha_mask.is_some()).collect();
    assert!(masked.iter().any(|m| m.name == "Leaves") && masked.len() > 5, "{} masked", masked.len());
    assert!(masked.iter().all(|m| m.alpha_mask.unwrap().channel == igi_scene::CoverageChannel::Luminance));
    assert!(scene.meshes[0].normals.is_none(), "all normals are flat and are dropped");
    assert_bounds(scene.bounds(), [-37.0, 0.0, -82.0], [38.0, 49.0, 83.0], 1e-3);
}

#[test]
fn stanford_bunny() {
    let cases = [
        ("bun_zipper.ply", 69_451, [-0.0947, 0.0330, -0.0619], [0.0610, 0.1873, 0.0588]),
        ("bun_zipper_res2.ply", 16_301, [-0.0946, 0.0334, -0.0619], [0.0609, 0.1866, 0.0587]),
        ("bun_zipper_res3.ply", 3_851, [-0.0944, 0.0334, -0.0617], [0.0609, 0.1848, 0.0585]),
        ("bun_zipper_res4.ply", 948, [-0.0931, 0.0336, -0.0566], [0.0582, 0.1819, 0.0578]),
    ];
    for (file, triangles, min, max) in cases {
        let Some((scene, report)) = load("stanford_bunny", &format!("stanford-bunny/{file}")) else { return };
        assert_eq!(scene.triangle_count(), triangles, "{file}");
        assert_clean(&report);
        assert_eq!(report.files.len(), 1, "{file}");
        assert_eq!(scene.materials.len(), 1);
        assert_bounds(scene.bounds(), min, max, 1e-4);
    }
}

#[test]
fn stanford_armadillo() {
    let Some((scene, report)) = load("stanford_armadillo", "stanford-armadillo/Armadillo.ply") else {
        return;
    };
    assert_eq!(scene.triangle_count(), 345_944);
    assert_eq!(scene.meshes[0].positions.len(), 172_974);
    assert_clean(&report);
    assert_bounds(scene.bounds(), [-63.50, -54.24, -57.71], [63.50, 97.08, 57.71], 0.01);
}

/// What a glTF sample must load as.
struct Sample {
    file: &'static str,
    /// Triangles drawn by the default scene (instances counted).
    triangles: usize,
    meshes: usize,
    instances: usize,
    textures: usize,
    /// A warning the load must give; no warning at all if `None`.
    warning: Option<&'static str>,
}

const fn sample(
    file: &'static str,
    triangles: usize,
    meshes: usize,
    instances: usize,
    textures: usize,
) -> Sample {
    Sample { file, triangles, meshes, instances, textures, warning: None }
}

#[test]
fn gltf_samples() {
    let samples = [
        sample("Box/glTF-Binary/Box.glb", 12, 1, 1, 0),
        sample("Box/glTF-Embedded/Box.gltf", 12, 1, 1, 0),
        sample("BoxTextured/glTF/BoxTextured.gltf", 12, 1, 1, 1),
        sample("BoxTextured/glTF-Binary/BoxTextured.glb", 12, 1, 1, 1),
        sample("BoxTextured/glTF-Embedded/BoxTextured.gltf", 12, 1, 1, 1),
        sample("Duck/glTF/Duck.gltf", 4212, 1, 1, 1),
        sample("Duck/glTF-Binary/Duck.glb", 4212, 1, 1, 1),
        sample("CesiumMilkTruck/glTF/CesiumMilkTruck.gltf", 3624, 2, 3, 1),
        sample("BoxAnimated/glTF-Binary/BoxAnimated.glb", 254, 2, 2, 0),
        sample("InterpolationTest/glTF/InterpolationTest.gltf", 110, 10, 10, 1),
        // A perspective camera (a view) and an orthographic one, which igi cannot use.
        Sample {
            warning: Some("nodes[2]: orthographic camera skipped"),
            ..sample("Cameras/glTF-Embedded/Cameras.gltf", 2, 1, 1, 0)
        },
        sample("DracoSphereLights/glTF/sphere_lights.gltf", 224, 1, 1, 2),
        // Base colour, metallic-roughness, normal map and emissive map.
        sample("DamagedHelmet/glTF/DamagedHelmet.gltf", 15_452, 1, 1, 4),
        Sample {
            warning: Some("skinned mesh loaded in its bind pose"),
            ..sample("Fox/glTF/Fox.gltf", 576, 1, 1, 1)
        },
        Sample {
            warning: Some("morph targets ignored"),
            ..sample("AnimatedMorphCube/glTF/AnimatedMorphCube.gltf", 12, 1, 1, 0)
        },
    ];
    for expected in samples {
        let file = expected.file;
        let Some((scene, report)) = load("gltf_samples", &format!("gltf-samples/{file}")) else { return };
        assert_eq!(scene.triangle_count(), expected.triangles, "{file}");
        assert_eq!(
            (scene.meshes.len(), scene.instances.len()),
            (expected.meshes, expected.instances),
            "{file}"
        );
        assert_eq!(scene.textures.len(), expected.textures, "{file}");
        match expected.warning {
            Some(text) => assert!(report.warnings.iter().any(|w| w.contains(text)), "{file}: {report:?}"),
            None => assert!(report.warnings.is_empty(), "{file}: {report:?}"),
        }
    }
}

#[test]
fn gltf_hierarchies_cameras_lights_and_emission() {
    let Some((truck, _)) = load("gltf_details", "gltf-samples/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf")
    else {
        return;
    };
    assert_bounds(truck.bounds(), [-2.43, 0.0, -1.40], [2.44, 2.58, 1.40], 0.01);
    let wheels = truck.instances.iter().filter(|i| i.mesh == truck.instances[1].mesh).count();
    assert_eq!(wheels, 2, "the wheel mesh is instanced, not duplicated");

    let (duck, _) = load("gltf_details", "gltf-samples/Duck/glTF/Duck.gltf").unwrap();
    assert_bounds(duck.bounds(), [-0.69, 0.10, -0.61], [0.96, 1.64, 0.54], 0.01);
    let camera = duck.camera.expect("the Duck has a camera");
    assert!((camera.fov_y_deg - 0.660_593_f32.to_degrees()).abs() < 1e-3);
    let to_duck = (Vec3::new(0.13, 0.87, -0.04) - camera.position).normalize();
    assert!((camera.target - camera.position).normalize().dot(to_duck) > 0.95, "{camera:?}");

    let (cameras, _) = load("gltf_details", "gltf-samples/Cameras/glTF-Embedded/Cameras.gltf").unwrap();
    let camera = cameras.camera.expect("perspective camera");
    assert!((camera.position - Vec3::new(0.5, 0.5, 3.0)).length() < 1e-6);
    assert!((camera.fov_y_deg - 0.7f32.to_degrees()).abs() < 1e-4);

    let (lights, _) = load("gltf_details", "gltf-samples/DracoSphereLights/glTF/sphere_lights.gltf").unwrap();
    assert_eq!(lights.lights.len(), 4);
    let spots: Vec<_> = lights
        .lights
        .iter()
        .filter_map(|l| match l {
            igi_scene::Light::Spot { angle_deg, intensity, direction, .. } => {
                Some((*angle_deg, *intensity, *direction))
            }
            _ => None,
        })
        .collect();
    assert_eq!(spots.len(), 2);
    assert!((spots[0].0 - 2.0 * 0.8f32.to_degrees()).abs() < 1e-3, "full angle = 2 × outer cone");
    assert_eq!(spots[0].1, Vec3::new(0.72, 0.71, 1.0) * 3.0);
    assert!((spots[1].0 - 90.0).abs() < 1e-4, "default outer cone π/4");
    assert!((spots[0].2.length() - 1.0).abs() < 1e-5);

    let (helmet, _) = load("gltf_details", "gltf-samples/DamagedHelmet/glTF/DamagedHelmet.gltf").unwrap();
    // emissiveFactor [1, 1, 1] and the emissive map, which multiplies it per texel (sRGB).
    let m = &helmet.materials[0];
    assert_eq!(m.emission, Vec3::ONE);
    let emissive = &helmet.textures[m.emission_texture.expect("emissiveTexture") as usize];
    assert!(matches!(
        emissive.image.texels,
        igi_scene::Texels::Rgba8 { space: igi_scene::ColorSpace::Srgb, .. }
    ));
    let lit = (0..emissive.image.texels.len()).filter(|&i| emissive.image.texels.linear(i)[0] > 0.1).count();
    assert!(lit > 1000 && lit < emissive.image.texels.len() / 2, "{lit} glowing texels");
    assert_eq!(
        helmet.emissive_triangle_count(),
        15_452,
        "one emissive material; the renderer skips black texels"
    );
    // A glTF metallic-roughness material: factors 1 and 1, the linear metallic-roughness map
    // carrying the per-texel values (metal panels and rough paint both).
    let m = &helmet.materials[0];
    assert_eq!((m.kind, m.metallic, m.roughness), (igi_scene::MaterialKind::MetallicRoughness, 1.0, 1.0));
    let mr = &helmet.textures[m.metallic_roughness_texture.expect("metallicRoughnessTexture") as usize];
    let blue = |i: usize| mr.image.texels.linear(i)[2];
    let metal = (0..mr.image.texels.len()).filter(|&i| blue(i) > 0.9).count();
    let paint = (0..mr.image.texels.len()).filter(|&i| blue(i) < 0.1).count();
    assert!(metal > 1000 && paint > 1000, "{metal} metal and {paint} dielectric texels");
    // Its normal map is loaded (linear, scale 1) beside the base colour.
    let normal = m.normal_texture.expect("DamagedHelmet has a normalTexture") as usize;
    assert_ne!(Some(normal as u32), m.diffuse_texture);
    assert_eq!(m.normal_scale, 1.0);
    let t = &helmet.textures[normal];
    let mean_z = (0..t.image.texels.len()).map(|i| t.image.texels.linear(i)[2]).sum::<f32>()
        / t.image.texels.len() as f32;
    assert!(mean_z > 0.7, "a tangent-space normal map is mostly +Z (blue): {mean_z}");
}

#[test]
fn repository_conference_scene_file_lights_the_room_from_below_the_ceiling() {
    // `scenes/conference.toml` (in the repository) references the shared OBJ; its quad light
    // must face down into the room (a light wound upwards would light only the ceiling).
    let Some((scene, _)) = load_repository_scene("repository_conference_scene_file", "conference.toml")
    else {
        return;
    };
    assert_eq!(scene.triangle_count(), 331_179 + 2);
    assert_eq!(scene.emissive_triangle_count(), 2);
    let mesh = scene
        .meshes
        .iter()
        .find(|m| m.material_ids.iter().any(|&id| scene.materials[id as usize].is_emissive()));
    let mesh = mesh.expect("the light's mesh");
    for t in 0..mesh.indices.len() {
        if scene.materials[mesh.material_ids[t] as usize].is_emissive() {
            assert!((mesh.triangle_normal(t) - Vec3::NEG_Y).length() < 1e-6, "the light must face down");
        }
    }
}

#[test]
fn repository_sponza_scene_file_has_a_sun_through_the_roof_and_a_blue_sky() {
    // `scenes/sponza.toml` (in the repository) references the shared OBJ.
    let Some((scene, report)) = load_repository_scene("repository_sponza_scene_file", "sponza.toml") else {
        return;
    };
    assert_eq!(scene.triangle_count() + report.degenerate_dropped, 66_450);
    assert_eq!(scene.lights.len(), 1);
    let igi_scene::Light::Directional { direction, irradiance } = scene.lights[0] else {
        panic!("{:?}", scene.lights[0])
    };
    assert!(direction.y < -0.85, "a steep sun, within about 30° of straight down: {direction}");
    assert!(irradiance.min_element() > 0.0);
    let Some(igi_scene::Environment::Constant { radiance }) = scene.environment else {
        panic!("{:?}", scene.environment)
    };
    assert!(radiance.z > radiance.y && radiance.y > radiance.x, "a blue sky: {radiance}");
    let camera = scene.camera.expect("the scene file's camera");
    let bounds = scene.bounds();
    assert!(camera.position.cmpgt(bounds.min).all() && camera.position.cmplt(bounds.max).all());
    let view = (camera.target - camera.position).normalize();
    assert!(view.x > 0.9, "looking along the nave (+X): {view}");
}
