//! Helpers shared by the integration tests.

// Every test crate includes this module and uses a different part of it.
#![allow(dead_code)]

use std::fs;
use std::path::PathBuf;

use glam::Vec3;
use igi_bvh::Aabb;

/// `shared/scenes` beside the repository, or `None` (with a message saying the test is
/// skipped) when this checkout has no shared scenes.
pub fn scenes_dir(test: &str) -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    if dir.is_dir() {
        Some(dir)
    } else {
        println!("{test}: skipped, {} not found", dir.display());
        None
    }
}

/// A fresh directory holding `files` (name, contents), named after `test`.
pub fn directory(test: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("igi-scene-{test}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    for (name, contents) in files {
        fs::write(dir.join(name), contents).unwrap();
    }
    dir
}

/// Asserts that `bounds` equals `min`..`max` to within `tolerance` per coordinate.
#[track_caller]
pub fn assert_bounds(bounds: Aabb, min: [f32; 3], max: [f32; 3], tolerance: f32) {
    let close = |a: Vec3, b: [f32; 3]| (a - Vec3::from(b)).abs().max_element() <= tolerance;
    assert!(
        close(bounds.min, min) && close(bounds.max, max),
        "bounds {:?}..{:?}, expected {min:?}..{max:?} (± {tolerance})",
        bounds.min,
        bounds.max
    );
}

/// Standard base64 with padding (for `data:` URIs in test documents).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(char::from(ALPHABET[(n >> (18 - 6 * i) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A one-mesh glTF document with the given triangles, and its binary buffer. With `embed`,
/// the buffer is a `data:` URI in the JSON; otherwise the buffer has no URI (a GLB's BIN).
pub fn gltf_document(positions: &[[f32; 3]], indices: &[u16], embed: bool) -> (String, Vec<u8>) {
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    let index_offset = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let uri = if embed {
        format!(r#","uri":"data:application/octet-stream;base64,{}""#, base64(&bin))
    } else {
        String::new()
    };
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"byteLength":{len}{uri}}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{index_offset}}},{{"buffer":0,"byteOffset":{index_offset},"byteLength":{index_len}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{count},"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},
{{"bufferView":1,"componentType":5123,"count":{index_count},"type":"SCALAR"}}]}}"#,
        len = bin.len(),
        count = positions.len(),
        index_len = indices.len() * 2,
        index_count = indices.len(),
    );
    (json, bin)
}

/// A binary glTF container of `json` and `bin`.
pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// The output of a hand-written animation sampler: raw little-endian bytes and their glTF
/// `componentType`, `type` and element count.
pub struct Output {
    pub bytes: Vec<u8>,
    pub component_type: u32,
    pub kind: &'static str,
    pub count: usize,
}

impl Output {
    /// Float vectors (`VEC3` for translation and scale, `VEC4` for rotation).
    pub fn floats<const N: usize>(values: &[[f32; N]]) -> Self {
        let kind = match N {
            1 => "SCALAR",
            3 => "VEC3",
            4 => "VEC4",
            _ => panic!("no glTF type of {N} components here"),
        };
        let bytes = values.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        Self { bytes, component_type: 5126, kind, count: values.len() }
    }
}

/// A one-triangle glTF document (embedded buffer) whose node 0 is animated by one channel:
/// key `times`, `output` values, the target `path` and the sampler's `interpolation`.
pub fn animated_gltf(times: &[f32], output: &Output, path: &str, interpolation: &str) -> String {
    let mut bin: Vec<u8> = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    bin.extend([0u16, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
    let times_offset = bin.len();
    bin.extend(times.iter().flat_map(|t| t.to_le_bytes()));
    let output_offset = bin.len();
    bin.extend(&output.bytes);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}},
{{"buffer":0,"byteOffset":{times_offset},"byteLength":{times_len}}},{{"buffer":0,"byteOffset":{output_offset},"byteLength":{output_len}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}},
{{"bufferView":2,"componentType":5126,"count":{times_count},"type":"SCALAR"}},
{{"bufferView":3,"componentType":{component_type},"normalized":{normalized},"count":{output_count},"type":"{kind}"}}],
"animations":[{{"samplers":[{{"input":2,"output":3,"interpolation":"{interpolation}"}}],
"channels":[{{"sampler":0,"target":{{"node":0,"path":"{path}"}}}}]}}]}}"#,
        len = bin.len(),
        data = base64(&bin),
        times_len = times.len() * 4,
        times_count = times.len(),
        output_len = output.bytes.len(),
        output_count = output.count,
        component_type = output.component_type,
        normalized = output.component_type != 5126,
        kind = output.kind,
    )
}

/// An animated document (see [`animated_gltf`]) whose key times are a sparse accessor without
/// a buffer view that claims a billion keys: zeros but for one sparse value, so the times
/// cannot increase, and no bytes back the count.
pub fn lying_key_times() -> String {
    let output = Output::floats(&[[0.0; 3], [0.0, 1.0, 0.0]]);
    animated_gltf(&[0.0, 1.0], &output, "translation", "LINEAR").replace(
        r#"{"bufferView":2,"componentType":5126,"count":2,"type":"SCALAR"}"#,
        concat!(
            r#"{"componentType":5126,"count":1000000000,"type":"SCALAR","sparse":{"count":1,"#,
            r#""indices":{"bufferView":2,"componentType":5125},"values":{"bufferView":2}}}"#
        ),
    )
}

/// One triangle with texture coordinates: positions, uvs, three u16 indices and padding.
const TEXTURED_TRIANGLE: &str =
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAIA/AAABAAIAAAA=";

/// A glTF file (JSON) with one textured triangle per material of `materials` (JSON objects)
/// and one texture, the image at `image`.
pub fn textured_triangle_gltf(image: &str, materials: &[&str]) -> String {
    let primitives: Vec<String> = (0..materials.len())
        .map(|i| {
            format!(r#"{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": {i}}}"#)
        })
        .collect();
    format!(
        r#"{{"asset": {{"version": "2.0"}},
            "buffers": [{{"byteLength": 68, "uri": "data:application/octet-stream;base64,{TEXTURED_TRIANGLE}"}}],
            "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
                            {{"buffer": 0, "byteOffset": 36, "byteLength": 24}},
                            {{"buffer": 0, "byteOffset": 60, "byteLength": 6}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                            "min": [0, 0, 0], "max": [1, 1, 0]}},
                          {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}},
                          {{"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"}}],
            "images": [{{"uri": "{image}"}}],
            "textures": [{{"source": 0}}],
            "materials": [{}],
            "meshes": [{{"primitives": [{}]}}],
            "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0}}"#,
        materials.join(", "),
        primitives.join(", ")
    )
}
