//! Scene files: placement of mesh files (transforms, instances), lights, camera, material
//! overrides, and errors that name the scene file, line and field.

mod common;

use std::fs;

use common::{assert_bounds, directory, gltf_document, scenes_dir};
use glam::Vec3;
use igi_scene::{Light, SceneError, load, load_with_report};

/// A unit cube's corners, [0, 1]³, as one OBJ face list (only the bounds matter here).
const CUBE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                    f 1 2 3 4\nf 5 6 7 8\n";

#[test]
fn transforms_and_instances_place_meshes() {
    let scene_toml = r#"
[[mesh]]
file = "cube.obj"
scale = [2, 1, 1]
rotate = [0, 0, 90]
translate = [10, 0, 0]

[[mesh]]
file = "cube.obj"
translate = [0, 0, -1]
instances = [ { }, { translate = [0, 5, 0] }, { rotate = [90, 0, 0], scale = 3 } ]
"#;
    let dir = directory("placement", &[("cube.obj", CUBE), ("scene.toml", scene_toml)]);
    let scene = load(dir.join("scene.toml")).unwrap();
    assert_eq!(scene.meshes.len(), 2, "each [[mesh]] entry loads its file");
    assert_eq!(scene.instances.len(), 4);
    assert_eq!(scene.triangle_count(), 16);
    // First entry: S then Rz(90°) then T: x ∈ [0, 2] → y ∈ [0, 2]; y ∈ [0, 1] → x ∈ [-1, 0].
    let first = scene.meshes[scene.instances[0].mesh as usize].bounds();
    let placed = |i: usize| {
        let instance = &scene.instances[i];
        let mesh = &scene.meshes[instance.mesh as usize];
        mesh.positions
            .iter()
            .fold(igi_bvh::Aabb::EMPTY, |b, &p| b.grow(instance.transform.transform_point3(p)))
    };
    assert_eq!(first.extent(), Vec3::ONE);
    assert_bounds(placed(0), [9.0, 0.0, 0.0], [10.0, 2.0, 1.0], 1e-5);
    // Instances apply after the mesh's own transform: `instance · mesh`.
    assert_bounds(placed(1), [0.0, 0.0, -1.0], [1.0, 1.0, 0.0], 1e-5);
    assert_bounds(placed(2), [0.0, 5.0, -1.0], [1.0, 6.0, 0.0], 1e-5);
    // Translate by −1 in z first, then scale by 3 and rotate 90° about X (y → z, z → −y).
    assert_bounds(placed(3), [0.0, 0.0, 0.0], [3.0, 3.0, 3.0], 1e-5);
    assert_bounds(scene.bounds(), [-0.0, 0.0, -1.0], [10.0, 6.0, 3.0], 1e-5);
}

#[test]
fn lights_camera_and_material_override() {
    let scene_toml = r#"
[camera]
position = [0, 1, 3.5]
target = [0, 1, 0]
fov = 39.3

[[mesh]]
file = "cube.obj"
material = { diffuse = [0.2, 0.4, 0.6], emission = [1, 1, 1] }

[[light]]
type = "quad"
position = [350, 640, -210]
u = [400, 0, 0]
v = [0, 0, 200]
radiance = [10, 10, 10]

[[light]]
type = "spot"
position = [0, 5, 0]
direction = [0, -2, 0]
angle = 60
intensity = [5, 5, 5]

[[light]]
type = "directional"
direction = [0.3, -1, 0.2]
irradiance = [2, 2, 2]
"#;
    let dir = directory("lights", &[("cube.obj", CUBE), ("scene.toml", scene_toml)]);
    let scene = load(dir.join("scene.toml")).unwrap();
    let camera = scene.camera.unwrap();
    assert_eq!((camera.position, camera.up, camera.fov_y_deg), (Vec3::new(0.0, 1.0, 3.5), Vec3::Y, 39.3));
    // The override replaces the OBJ's own (default) material.
    let cube_material = &scene.materials[scene.meshes[0].material_ids[0] as usize];
    assert_eq!(cube_material.diffuse, Vec3::new(0.2, 0.4, 0.6));
    assert_eq!(cube_material.emission, Vec3::ONE);
    // The quad: 800 × 400 units at y = 640, facing u × v = −Y.
    let quad = scene.meshes.iter().position(|m| m.name == "light[0]").unwrap();
    let mesh = &scene.meshes[quad];
    assert_eq!(mesh.indices.len(), 2);
    for t in 0..2 {
        assert_eq!(mesh.triangle_normal(t), Vec3::NEG_Y);
    }
    assert_bounds(mesh.bounds(), [-50.0, 640.0, -410.0], [750.0, 640.0, -10.0], 1e-3);
    assert_eq!(scene.materials[mesh.material_ids[0] as usize].emission, Vec3::splat(10.0));
    assert_eq!(scene.emissive_triangle_count(), 4 + 2, "the emissive cube and the quad");
    assert_eq!(scene.lights.len(), 2);
    assert!(
        matches!(scene.lights[0], Light::Spot { direction, angle_deg: 60.0, .. } if direction == Vec3::NEG_Y)
    );
    let Light::Directional { direction, .. } = scene.lights[1] else { panic!("{:?}", scene.lights[1]) };
    assert!((direction.length() - 1.0).abs() < 1e-6);
}

#[test]
fn cameras_that_frame_no_image_are_refused_naming_the_field() {
    let cases = [
        ("up = [0, 0, 0]\nfov = 40", "line 5, field `camera.up`: must not be zero"),
        (
            "up = [0, 0, -1]\nfov = 40",
            "line 5, field `camera.up`: must not be parallel to the view direction",
        ),
        ("fov = 180", "line 5, field `camera.fov`: the vertical field of view"),
    ];
    for (field, expected) in cases {
        let scene_toml = format!("\n[camera]\nposition = [0, 1, 3.5]\ntarget = [0, 1, 0]\n{field}\n");
        let dir = directory("camera-up", &[("scene.toml", &scene_toml)]);
        let err = load(dir.join("scene.toml")).unwrap_err().to_string();
        assert!(err.contains(expected), "{err}");
    }
}

#[test]
fn gltf_files_bring_their_lights_and_camera_along() {
    let (json, _) = gltf_document(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[0, 1, 2], true);
    let json = json
        .replace(
            r#""nodes":[{"mesh":0}]"#,
            r#""nodes":[{"mesh":0},{"translation":[0,0,5],"camera":0},{"translation":[1,2,3],"extensions":{"KHR_lights_punctual":{"light":0}}}]"#,
        )
        .replace(r#""scenes":[{"nodes":[0]}]"#, r#""scenes":[{"nodes":[0,1,2]}]"#)
        .replace(
            r#""asset""#,
            r#""cameras":[{"type":"perspective","perspective":{"yfov":0.5,"znear":0.1}}],"extensionsUsed":["KHR_lights_punctual"],"extensions":{"KHR_lights_punctual":{"lights":[{"type":"point","intensity":4,"color":[1,0.5,0.25]}]}},"asset""#,
        );
    let scene_toml = "[[mesh]]\nfile = \"thing.gltf\"\ntranslate = [10, 0, 0]\ninstances = [ {}, { translate = [0, 100, 0] } ]\n";
    let dir = directory("gltf", &[("thing.gltf", &json), ("scene.toml", scene_toml)]);
    let (scene, report) = load_with_report(dir.join("scene.toml")).unwrap();
    assert!(report.warnings.is_empty(), "{report:?}");
    assert_eq!(scene.instances.len(), 2);
    let camera = scene.camera.expect("the glTF's camera, placed by the first instance");
    assert!((camera.position - Vec3::new(10.0, 0.0, 5.0)).length() < 1e-5);
    // It is a view too, named by its index (it has no name).
    assert_eq!(scene.views.len(), 1);
    assert_eq!((scene.views[0].name.as_str(), scene.views[0].camera), ("camera 0", camera));
    assert!((camera.fov_y_deg - 0.5f32.to_degrees()).abs() < 1e-4);
    let positions: Vec<Vec3> = scene
        .lights
        .iter()
        .map(|l| match l {
            Light::Point { position, intensity } => {
                assert_eq!(*intensity, Vec3::new(4.0, 2.0, 1.0), "colour × intensity");
                *position
            }
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(positions, vec![Vec3::new(11.0, 2.0, 3.0), Vec3::new(11.0, 102.0, 3.0)]);
}

#[test]
fn missing_mesh_file_names_scene_file_line_and_path() {
    let scene_toml = "[camera]\nposition = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n\n[[mesh]]\nfile = \"cube.obj\"\n\n[[mesh]]\nfile = \"gone.ply\"\n";
    let dir = directory("missing", &[("cube.obj", CUBE), ("scene.toml", scene_toml)]);
    let err = load(dir.join("scene.toml")).unwrap_err();
    assert!(matches!(err, SceneError::MissingFile { .. }), "{err}");
    let text = err.to_string();
    let scene_path = dir.join("scene.toml");
    assert_eq!(
        text,
        format!(
            "{}: line 10, field `mesh[1].file`: {} not found",
            scene_path.display(),
            dir.join("gone.ply").display()
        )
    );
}

#[test]
fn only_mesh_files_can_be_placed() {
    let dir = directory(
        "nested",
        &[("cube.obj", CUBE), ("inner.toml", ""), ("scene.toml", "[[mesh]]\nfile = \"inner.toml\"\n")],
    );
    let err = load(dir.join("scene.toml")).unwrap_err();
    assert!(
        err.to_string()
            .ends_with("line 2, field `mesh[0].file`: `inner.toml` is not an .obj, .gltf, .glb or .ply file"),
        "{err}"
    );
    let empty = "[[mesh]]\nfile = \"cube.obj\"\ninstances = []\n";
    let dir = directory("empty", &[("cube.obj", CUBE), ("scene.toml", empty)]);
    let (scene, report) = load_with_report(dir.join("scene.toml")).unwrap();
    assert!(scene.meshes.is_empty());
    assert_eq!(report.warnings.len(), 1, "{report:?}");
}

#[test]
fn shared_meshes_in_a_scene_file() {
    let Some(scenes) = scenes_dir("shared_meshes_in_a_scene_file") else { return };
    let scene_toml = format!(
        r#"
[[mesh]]
file = "{box}"

[[mesh]]
file = "{bunny}"
scale = 4
translate = [0, -0.13, 0]
material = {{ diffuse = [0.7, 0.7, 0.7] }}
"#,
        box = scenes.join("cornell-box/CornellBox-Original.obj").display(),
        bunny = scenes.join("stanford-bunny/bun_zipper_res4.ply").display(),
    );
    let dir = directory("shared", &[("scene.toml", &scene_toml)]);
    let scene = load(dir.join("scene.toml")).unwrap();
    assert_eq!(scene.triangle_count(), 36 + 948);
    assert_eq!(scene.materials.len(), 8 + 1);
    assert_eq!(scene.emissive_triangle_count(), 2);
    let bunny = &scene.instances[1];
    let bunny_bounds = scene.meshes[bunny.mesh as usize]
        .positions
        .iter()
        .fold(igi_bvh::Aabb::EMPTY, |b, &p| b.grow(bunny.transform.transform_point3(p)));
    assert_bounds(bunny_bounds, [-0.3724, 0.0044, -0.2264], [0.2328, 0.5976, 0.2312], 1e-3);
}

/// Two quads with materials `floor` and `stone` (from `room.mtl`).
const ROOM: &str = "mtllib room.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0 1 0\nv 1 1 0\n\
                    usemtl floor\nf 1 2 3 4\nusemtl stone\nf 1 2 6 5\n";
const ROOM_MTL: &str = "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl stone\nKd 0.7 0.7 0.7\n";

#[test]
fn shaders_target_materials_by_name_and_meshes_by_name() {
    let scene_toml = r#"
[[mesh]]
file = "room.obj"

[[mesh]]
file = "annex.obj"

[[shader]]
target = "floor"
type = "marble"
scale = 2.0
colors = [[0.9, 0.9, 0.85], [0.3, 0.3, 0.35]]

[[shader]]
target = "annex"
type = "brick"
"#;
    let dir = directory(
        "shader_targets",
        &[("room.obj", ROOM), ("annex.obj", ROOM), ("room.mtl", ROOM_MTL), ("scene.toml", scene_toml)],
    );
    let scene = load(dir.join("scene.toml")).unwrap();
    let pattern = |mesh: usize, triangle: usize| {
        let id = scene.meshes[mesh].material_ids[triangle] as usize;
        (scene.materials[id].name.as_str(), scene.materials[id].shader.as_ref().map(|s| s.pattern))
    };
    let marble = Some(igi_scene::Pattern::Marble { octaves: 4, turbulence: 5.0 });
    let brick = Some(igi_scene::Pattern::Brick { size: Vec3::new(3.0, 1.0, 1.5), mortar: 0.1 });
    // The OBJ mesh is named by its file's stem; each file brings its own materials.
    assert_eq!(scene.meshes[0].name, "room");
    assert_eq!(pattern(0, 0), ("floor", marble), "every `floor` material");
    assert_eq!(pattern(0, 2), ("stone", None));
    // The mesh target replaces the annex's materials with shaded copies; the `floor` copy is
    // made after the material entry ran, from the marble floor, and now carries the brick.
    assert_eq!(pattern(1, 0), ("floor", brick));
    assert_eq!(pattern(1, 2), ("stone", brick));
    assert_eq!(scene.materials.len(), 4 + 2);
    let shader = scene.materials[scene.meshes[0].material_ids[0] as usize].shader.as_ref().unwrap();
    assert_eq!((shader.scale, shader.colors[1]), (2.0, Vec3::new(0.3, 0.3, 0.35)));

    let missing = "[[mesh]]\nfile = \"room.obj\"\n\n[[shader]]\ntarget = \"roof\"\ntype = \"wood\"\n";
    fs::write(dir.join("missing.toml"), missing).unwrap();
    let err = load(dir.join("missing.toml")).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "{}: line 5, field `shader[0].target`: `roof` is neither a material nor a mesh name",
            dir.join("missing.toml").display()
        )
    );
    let bad =
        "[[mesh]]\nfile = \"room.obj\"\n\n[[shader]]\ntarget = \"floor\"\ntype = \"wood\"\nscale = -1\n";
    fs::write(dir.join("bad.toml"), bad).unwrap();
    let err = load(dir.join("bad.toml")).unwrap_err().to_string();
    assert!(err.starts_with(&format!("{}: line ", dir.join("bad.toml").display())), "{err}");
    assert!(err.contains("field `shader[0].scale`: must be finite and positive"), "{err}");
}

#[test]
fn image_environment_is_read_relative_to_the_scene_file() {
    // A 4 × 2 Radiance HDR with one bright texel, and a PNG (sRGB-decoded).
    let dir = directory("environment", &[]);
    fs::create_dir_all(dir.join("skies")).unwrap();
    let mut texels = vec![image::Rgb([0.25f32, 0.5, 1.0]); 8];
    texels[5] = image::Rgb([40.0, 30.0, 20.0]);
    let mut hdr = Vec::new();
    image::codecs::hdr::HdrEncoder::new(&mut hdr).encode(&texels, 4, 2).unwrap();
    fs::write(dir.join("skies/sky.hdr"), hdr).unwrap();
    image::RgbImage::from_pixel(2, 1, image::Rgb([255, 128, 0])).save(dir.join("sky.png")).unwrap();
    let scene_toml = "[[mesh]]\nfile = \"cube.obj\"\n\n[environment]\nfile = \"skies/sky.hdr\"\nintensity = 2\nrotate = 90\n";
    fs::write(dir.join("cube.obj"), CUBE).unwrap();
    fs::write(dir.join("scene.toml"), scene_toml).unwrap();
    let scene = load(dir.join("scene.toml")).unwrap();
    assert_eq!(
        scene.environment,
        Some(igi_scene::Environment::Map { texture: 0, intensity: 2.0, rotation_deg: 90.0 })
    );
    let sky = &scene.textures[0];
    assert_eq!((sky.image.width, sky.image.height), (4, 2));
    assert_eq!(sky.image.texels.linear(5), [40.0, 30.0, 20.0, 1.0], "HDR texels are linear radiance");
    assert_eq!(sky.image.texels.linear(0), [0.25, 0.5, 1.0, 1.0]);

    fs::write(dir.join("png.toml"), "[environment]\nfile = \"sky.png\"\n").unwrap();
    let scene = load(dir.join("png.toml")).unwrap();
    let texel = scene.textures[0].image.texels.linear(0);
    assert_eq!((texel[0], texel[2]), (1.0, 0.0));
    assert!((texel[1] - 0.2158605).abs() < 1e-6, "8-bit images are sRGB-decoded: {texel:?}");

    fs::write(dir.join("missing.toml"), "[environment]\nfile = \"clouds.exr\"\n").unwrap();
    let err = load(dir.join("missing.toml")).unwrap_err();
    assert!(matches!(err, SceneError::MissingFile { .. }), "{err}");
    assert_eq!(
        err.to_string(),
        format!(
            "{}: line 2, field `environment.file`: {} not found",
            dir.join("missing.toml").display(),
            dir.join("clouds.exr").display()
        )
    );
    fs::write(dir.join("broken.hdr"), "#?RADIANCE\nnot really\n").unwrap();
    fs::write(dir.join("broken.toml"), "[environment]\nfile = \"broken.hdr\"\n").unwrap();
    let err = load(dir.join("broken.toml")).unwrap_err().to_string();
    assert!(
        err.starts_with(&format!(
            "{}: line 2, field `environment.file`: `broken.hdr` could not be loaded: ",
            dir.join("broken.toml").display()
        )),
        "{err}"
    );
}

#[test]
fn gltf_textures_keep_their_sampler_wrap_modes_and_the_normal_map_its_scale() {
    // A base-colour texture whose sampler clamps u and mirrors v, and a normal map with the
    // default sampler (repeat) and scale 0.5.
    let png = |rgba: [u8; 4]| {
        let mut bytes = Vec::new();
        image::RgbaImage::from_pixel(2, 2, image::Rgba(rgba))
            .write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
            .expect("encode a PNG");
        format!("data:image/png;base64,{}", common::base64(&bytes))
    };
    let (json, _) = gltf_document(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[0, 1, 2], true);
    let json = json.replace(r#""indices":1}"#, r#""indices":1,"material":0}"#);
    let extra = format!(
        r#","materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}},"normalTexture":{{"index":1,"scale":0.5}}}}],
"textures":[{{"source":0,"sampler":0}},{{"source":1}}],"samplers":[{{"wrapS":33071,"wrapT":33648}}],
"images":[{{"uri":"{}"}},{{"uri":"{}"}}]}}"#,
        png([200, 100, 50, 255]),
        png([128, 128, 255, 255])
    );
    let json = format!("{}{extra}", json.trim_end().strip_suffix('}').expect("a JSON object"));
    let mut report = igi_scene::LoadReport::default();
    let scene =
        igi_scene::parse_mesh(igi_scene::MeshFormat::Gltf, json.as_bytes(), "wrap.gltf", None, &mut report)
            .unwrap_or_else(|e| panic!("{e}"));
    let m = &scene.materials[0];
    let base = &scene.textures[m.diffuse_texture.expect("base colour texture") as usize];
    assert_eq!(base.wrap, [igi_scene::Wrap::Clamp, igi_scene::Wrap::MirroredRepeat]);
    let normal = &scene.textures[m.normal_texture.expect("normal texture") as usize];
    assert_eq!(normal.wrap, [igi_scene::Wrap::Repeat; 2]);
    assert_eq!(m.normal_scale, 0.5);
    // The normal map is data: linear, (128, 128, 255) → about (0.5, 0.5, 1).
    assert!(
        (normal.image.texels.linear(0)[2] - 1.0).abs() < 1e-6
            && (normal.image.texels.linear(0)[0] - 128.0 / 255.0).abs() < 1e-6
    );
}

#[test]
fn views_are_named_cameras_checked_like_the_camera() {
    let views = "[camera]\nposition = [0, 1, 5]\ntarget = [0, 1, 0]\nfov = 40\n\n\
                 [[view]]\nname = \"door\"\nposition = [0, 1.6, 9]\ntarget = [0, 1, 0]\nfov = 50\n\n\
                 [[view]]\nname = \"top\"\nposition = [0, 10, 0]\ntarget = [0, 0, 0]\nup = [0, 0, -1]\nfov = 30\n";
    let dir = directory("views", &[("scene.toml", views)]);
    let scene = load(dir.join("scene.toml")).unwrap();
    let names: Vec<&str> = scene.views.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names, ["door", "top"]);
    assert_eq!(scene.views[0].camera.position, Vec3::new(0.0, 1.6, 9.0));
    assert_eq!((scene.views[1].camera.up, scene.views[1].camera.fov_y_deg), (Vec3::NEG_Z, 30.0));
    assert_eq!(scene.camera.unwrap().position, Vec3::new(0.0, 1.0, 5.0), "the scene camera stays");

    let cases = [
        (
            "[[view]]\nname = \"a\"\nposition = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n\
             [[view]]\nname = \"a\"\nposition = [0, 0, 6]\ntarget = [0, 0, 0]\nfov = 40\n",
            "line 7, field `view[1].name`: \"a\" is already the name of view[0]",
        ),
        (
            "[[view]]\nname = \"a\"\nposition = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 200\n",
            "line 5, field `view[0].fov`: the vertical field of view",
        ),
        (
            "[[view]]\nname = \" \"\nposition = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n",
            "field `view[0].name`: must not be empty",
        ),
        ("[[view]]\nposition = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n", "missing field `name`"),
    ];
    for (text, expected) in cases {
        let dir = directory("bad-views", &[("scene.toml", text)]);
        let err = load(dir.join("scene.toml")).unwrap_err().to_string();
        assert!(err.contains(expected), "{err}");
    }
}
