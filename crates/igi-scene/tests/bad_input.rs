//! Broken input of every kind is an error (or a counted repair), never a panic, and the
//! message says where the problem is.

mod common;

use std::path::Path;

use common::{glb, gltf_document};
use igi_scene::{LoadReport, Scene, SceneError, load, scene_file};

fn obj(text: &str) -> Result<(Scene, LoadReport), SceneError> {
    let mut report = LoadReport::default();
    igi_scene::parse_mesh(igi_scene::MeshFormat::Obj, text.as_bytes(), "bad.obj", None, &mut report)
        .map(|s| (s, report))
}

fn ply(bytes: &[u8]) -> Result<(Scene, LoadReport), SceneError> {
    let mut report = LoadReport::default();
    igi_scene::parse_mesh(igi_scene::MeshFormat::Ply, bytes, "bad.ply", None, &mut report)
        .map(|s| (s, report))
}

fn gltf(bytes: &[u8]) -> Result<(Scene, LoadReport), SceneError> {
    let mut report = LoadReport::default();
    igi_scene::parse_mesh(igi_scene::MeshFormat::Gltf, bytes, "bad.gltf", None, &mut report)
        .map(|s| (s, report))
}

fn toml(text: &str) -> Result<Scene, SceneError> {
    scene_file::parse(text, "bad.toml", None, &mut LoadReport::default())
}

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

#[test]
fn missing_files_and_unknown_formats() {
    let err = load("/nonexistent/dir/scene.obj").unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    assert!(err.to_string().starts_with("/nonexistent/dir/scene.obj: "), "{err}");
    let err = load("model.stl").unwrap_err();
    assert!(matches!(err, SceneError::UnknownFormat { .. }), "{err}");
    assert!(err.to_string().contains("model.stl"), "{err}");
    let err = load(Path::new("/dev/null.ply")).unwrap_err();
    assert!(err.to_string().contains("/dev/null.ply"), "{err}");
}

#[test]
fn truncated_obj() {
    let err = obj(&format!("{SQUARE}v 0.5 0.")).unwrap_err();
    assert_eq!(
        err.to_string(),
        "bad.obj: line 5: `v` needs 3 coordinates (plus optional w and colour), found 2 values"
    );
    // A face cut after two vertices has no area: dropped and counted, not an error.
    let (scene, report) = obj(&format!("{SQUARE}f 1 2 3\nf 1 2")).unwrap();
    assert_eq!((scene.triangle_count(), report.degenerate_dropped), (1, 1));
    let err = obj(&format!("{SQUARE}f 1 2 3/x")).unwrap_err();
    assert!(err.to_string().starts_with("bad.obj: line 5: face vertex `3/x`"), "{err}");
}

#[test]
fn nan_coordinates() {
    let err = obj("v 0 0 0\nv 1 0 0\nv 0 NaN 0\nf 1 2 3\n").unwrap_err();
    assert_eq!(err.to_string(), "bad.obj: line 3: `NaN` is not a finite number");
    let err = obj("v 0 0 0\nv 1e39 0 0\n").unwrap_err();
    assert!(err.to_string().starts_with("bad.obj: line 2: `1e39`"), "{err}");
    let (json, _) = gltf_document(&[[0.0; 3], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]], &[0, 1, 2], true);
    let err = gltf(json.as_bytes()).unwrap_err();
    assert_eq!(err.to_string(), "bad.gltf: meshes[0].primitives[0]: vertex 1 has a NaN or infinite position");
}

#[test]
fn out_of_range_indices() {
    let err = obj(&format!("{SQUARE}f 1 2 5\n")).unwrap_err();
    assert!(
        err.to_string().starts_with("bad.obj: line 5: face vertex `5`: v index 5 is out of range"),
        "{err}"
    );
    let err = obj(&format!("{SQUARE}f -1 -2 -5\n")).unwrap_err();
    assert!(
        err.to_string().starts_with("bad.obj: line 5: face vertex `-5`: v index -5 is out of range"),
        "{err}"
    );
    let err = obj(&format!("{SQUARE}f 0 1 2\n")).unwrap_err();
    assert!(err.to_string().contains("v index 0"), "{err}");
    let (json, _) = gltf_document(&TRIANGLE, &[0, 1, 3], true);
    let err = gltf(json.as_bytes()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "bad.gltf: meshes[0].primitives[0]: triangle 0 refers to vertex 3, but there are only 3 vertices"
    );
    let faces = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    let err = ply(format!("{faces}3 0 1 -1\n").as_bytes()).unwrap_err();
    assert_eq!(err.to_string(), "bad.ply: face 0: negative or too large vertex index");
    let err = ply(format!("{faces}3 0 1 3\n").as_bytes()).unwrap_err();
    assert!(err.to_string().contains("refers to vertex 3, but there are only 3 vertices"), "{err}");
}

#[test]
fn zero_area_triangles_are_dropped_and_counted() {
    let (scene, report) = obj(&format!("{SQUARE}f 1 2 3\nf 1 2 2\nf 1 2 2 1\n")).unwrap();
    assert_eq!((scene.triangle_count(), report.degenerate_dropped), (1, 3));
    assert_eq!(report.warnings, vec!["bad.obj: dropped 3 zero-area triangle(s)".to_string()]);
    let (json, _) = gltf_document(
        &[[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[0, 1, 2, 0, 1, 3],
        true,
    );
    let (scene, report) = gltf(json.as_bytes()).unwrap();
    assert_eq!((scene.triangle_count(), report.degenerate_dropped), (1, 1), "collinear corners");
}

fn binary_ply(vertex_count: u64, payload_vertices: usize) -> Vec<u8> {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {vertex_count}\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    for i in 0..payload_vertices {
        for c in TRIANGLE[i % 3] {
            bytes.extend(c.to_le_bytes());
        }
    }
    bytes.push(3);
    for i in 0..3i32 {
        bytes.extend(i.to_le_bytes());
    }
    bytes
}

#[test]
fn truncated_and_lying_ply() {
    let good = binary_ply(3, 3);
    assert_eq!(ply(&good).unwrap().0.triangle_count(), 1);
    for cut in [good.len() - 1, good.len() - 13, 150] {
        let err = ply(&good[..cut]).unwrap_err();
        assert!(err.to_string().starts_with("bad.ply: "), "{err}");
    }
    let err = ply(&good[..good.len() - 1]).unwrap_err();
    assert_eq!(err.to_string(), "bad.ply: face 0: file ends early: the header declares 1 `face` elements");
    let err = ply(&binary_ply(4_000_000_000, 3)).unwrap_err();
    assert!(err.to_string().contains("declares 4000000000 `vertex` elements, which need at least"), "{err}");
    let header = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    let err = ply(format!("{header}0 0 0\n").as_bytes()).unwrap_err();
    assert!(err.to_string().contains("declares 2 `vertex` elements, which need at least 12 bytes"), "{err}");
    let err = ply(format!("{header}0 0 0 1 1 1\n").as_bytes()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "bad.ply: vertex 1: file ends early: the header declares 2 `vertex` elements"
    );
    let err = ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n").unwrap_err();
    assert!(err.to_string().contains("lacks one of the scalar properties x, y, z"), "{err}");
    assert!(ply(b"ply\nformat ascii 1.0\nelem").is_err());
}

#[test]
fn truncated_gltf_and_glb() {
    let (json, _) = gltf_document(&TRIANGLE, &[0, 1, 2], true);
    assert_eq!(gltf(json.as_bytes()).unwrap().0.triangle_count(), 1);
    for cut in [1, json.len() / 2, json.len() - 1] {
        let err = gltf(&json.as_bytes()[..cut]).unwrap_err();
        assert!(err.to_string().starts_with("bad.gltf: "), "{err}");
    }
    let (json, bin) = gltf_document(&TRIANGLE, &[0, 1, 2], false);
    let container = glb(&json, &bin);
    assert_eq!(gltf(&container).unwrap().0.triangle_count(), 1);
    for cut in [4, 12, 20, container.len() / 2, container.len() - 8, container.len() - 1] {
        assert!(gltf(&container[..cut]).is_err(), "cut at {cut}");
    }
    // Found by fuzzing: a declared length below the header's own 12 bytes.
    let err = gltf(b"glTF\xfe\xff\xff\xff\x02\0\0\0\x58\x12\0\0JSON{}").unwrap_err();
    assert_eq!(err.to_string(), "bad.gltf: GLB header declares a length shorter than itself");
}

#[test]
fn malformed_gltf_is_an_error_where_the_gltf_crate_panics() {
    let (json, _) = gltf_document(&TRIANGLE, &[0, 1, 2], true);
    let bad_position = json.replace(r#""POSITION":0"#, r#""POSITION":7"#);
    let err = gltf(bad_position.as_bytes()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "bad.gltf: meshes[0].primitives[0].attributes.POSITION: accessor 7 does not exist"
    );
    let float_indices = json.replace(r#""componentType":5123"#, r#""componentType":5126"#);
    assert!(gltf(float_indices.as_bytes()).is_err());
    let zero_count = json.replace(r#""count":3,"type":"SCALAR""#, r#""count":0,"type":"SCALAR""#);
    assert!(gltf(zero_count.as_bytes()).unwrap_err().to_string().contains("count is 0"));
    let too_long = json.replace(r#""count":3,"type":"VEC3""#, r#""count":300000000,"type":"VEC3""#);
    assert!(gltf(too_long.as_bytes()).unwrap_err().to_string().contains("extends past its buffer view"));
    let bad_uri = json.replace("data:application/octet-stream;base64,", "%FF%FE");
    assert!(gltf(bad_uri.as_bytes()).unwrap_err().to_string().contains("percent-encoded"));
    let cycle = json.replace(r#""nodes":[{"mesh":0}]"#, r#""nodes":[{"mesh":0,"children":[0]}]"#);
    assert!(gltf(cycle.as_bytes()).unwrap_err().to_string().contains("nodes[0]: node is reached twice"));
    // Found by fuzzing: the `gltf` crate unwraps these.
    let textured = json.replace(
        r#""asset""#,
        r#""materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],"textures":[{"source":0}],"images":[{"bufferView":0}],"asset""#,
    );
    let err = gltf(textured.as_bytes()).unwrap_err();
    assert_eq!(err.to_string(), "bad.gltf: images[0]: an image in a buffer view needs a mimeType");
    let err = gltf(textured.replace(r#"{"bufferView":0}"#, "{}").as_bytes()).unwrap_err();
    assert_eq!(err.to_string(), "bad.gltf: images[0]: an image needs a uri or a bufferView");
    let camera = json.replace(
        r#""nodes":[{"mesh":0}]"#,
        r#""nodes":[{"mesh":0,"camera":0}],"cameras":[{"type":"perspective","orthographic":{"xmag":1,"ymag":1,"znear":0,"zfar":1}}]"#,
    );
    let err = gltf(camera.as_bytes()).unwrap_err();
    assert_eq!(err.to_string(), "bad.gltf: cameras[0]: a perspective camera needs a `perspective` object");
    let draco = json.replace(
        r#""asset""#,
        r#""extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"],"asset""#,
    );
    assert_eq!(
        gltf(draco.as_bytes()).unwrap_err().to_string(),
        "bad.gltf: extensionsRequired: requires extension `KHR_draco_mesh_compression`, which igi does not support"
    );
}

#[test]
fn malformed_and_unknown_toml() {
    let err = toml("[camera]\nposition = [0, 1, 3.5\ntarget = [0, 1, 0]\n").unwrap_err();
    assert!(matches!(err, SceneError::Parse { .. }), "{err}");
    assert!(err.to_string().starts_with("bad.toml: line "), "{err}");
    let err = toml("[[mesh]]\nfile = \"a.obj\"\nrotation = [0, 90, 0]\n").unwrap_err();
    let text = err.to_string();
    assert!(
        text.starts_with("bad.toml: line 3, field `mesh[0].rotation`: unknown field `rotation`"),
        "{text}"
    );
    let err =
        toml("[camera]\nposition = [0, 1, 3.5]\ntarget = [0, 1, 0]\nfov = 39.3\n[lights]\n").unwrap_err();
    assert!(err.to_string().contains("unknown field `lights`"), "{err}");
}

/// A scene file placing a one-triangle OBJ `count` times.
fn instanced_scene(dir: &Path, count: usize) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let mut text = String::from("[[mesh]]\nfile = \"tri.obj\"\ninstances = [\n");
    for i in 0..count {
        text.push_str(&format!("  {{ translate = [{}, 0, 0] }},\n", i % 1000));
    }
    text.push_str("]\n");
    let path = dir.join(format!("instances-{count}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn instance_counts_are_capped() {
    let dir = std::env::temp_dir().join(format!("igi-instance-cap-{}", std::process::id()));
    let scene = load(instanced_scene(&dir, igi_scene::MAX_INSTANCES)).unwrap();
    assert_eq!(scene.instances.len(), igi_scene::MAX_INSTANCES);
    let err = load(instanced_scene(&dir, igi_scene::MAX_INSTANCES + 1)).unwrap_err().to_string();
    assert!(
        err.contains("line 3, field `mesh[0].instances`: the scene would have 100001 instances; it may have at most 100000"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();

    // Five million empty inline tables are refused before `toml` builds them (gigabytes).
    let text = format!("[[mesh]]\nfile = \"tri.obj\"\ninstances = [{}]\n", "{},".repeat(5_000_000));
    let err = toml(&text).unwrap_err().to_string();
    assert!(err.contains("5000001 tables"), "{err}");
    // And so are two million elements of table arrays (a 16 MiB file took 850 MB to refuse).
    let err = toml(&"[[x]]\n".repeat(2_000_000)).unwrap_err().to_string();
    assert!(err.contains("2000000 tables"), "{err}");
    // And so are the tables dotted keys make: 120,000 lines of `tN.a.a. ... .a = 1` (60 dots)
    // took 5.9 GB and aborted (issue 35).
    let text: String = (0..120_000).map(|i| format!("t{i}{} = 1\n", ".a".repeat(60))).collect();
    let err = toml(&text).unwrap_err().to_string();
    assert!(err.contains("7200000 tables"), "{err}");
    let err = toml(&" ".repeat(17 << 20)).unwrap_err().to_string();
    assert!(err.contains("a scene file may have at most 16777216"), "{err}");
    // On disk, a file that large is refused by its size before it is read.
    let big = std::env::temp_dir().join(format!("igi-big-scene-{}.toml", std::process::id()));
    std::fs::File::create(&big).unwrap().set_len(17 << 20).unwrap();
    let err = load(&big).unwrap_err().to_string();
    std::fs::remove_file(&big).unwrap();
    assert!(err.contains("more than the 16777216 allowed"), "{err}");
}

#[test]
fn huge_node_scales_are_named_for_what_they_are() {
    let (json, _) = gltf_document(&TRIANGLE, &[0, 1, 2], true);
    let huge = json.replace(r#""nodes":[{"mesh":0}]"#, r#""nodes":[{"mesh":0,"scale":[1e38,1e38,1e38]}]"#);
    let (scene, report) = gltf(huge.as_bytes()).unwrap();
    assert!(scene.instances.is_empty());
    let warning = report.warnings.join("\n");
    assert!(warning.contains("nodes[0]: world transform (scale"), "{warning}");
    assert!(warning.contains("cannot be inverted in single precision"), "{warning}");
    let zero = json.replace(r#""nodes":[{"mesh":0}]"#, r#""nodes":[{"mesh":0,"scale":[1,0,1]}]"#);
    let (_, report) = gltf(zero.as_bytes()).unwrap();
    assert!(report.warnings.join("\n").contains("nodes[0]: scale is zero"), "{report:?}");
}

#[test]
fn geometry_placed_beyond_the_float_range_is_refused() {
    // A scale of 3e38 is finite, but the renderer squares the scene's size: the bounds became
    // infinite and the image blank, without a word.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("square.obj"), format!("{SQUARE}f 1 2 3 4\n")).unwrap();
    let cases = [("scale = 3e38", false), ("translate = [2e15, 0, 0]", false), ("scale = 1e14", true)];
    for (placement, ok) in cases {
        let file = dir.path().join("huge.toml");
        std::fs::write(&file, format!("[[mesh]]\nfile = \"square.obj\"\n{placement}\n")).unwrap();
        match load(&file) {
            Ok(_) => assert!(ok, "{placement} is refused"),
            Err(err) => {
                assert!(!ok, "{placement}: {err}");
                let message = err.to_string();
                assert!(message.contains("huge.toml") && message.contains("1e15 scene units"), "{message}");
            }
        }
    }
}
