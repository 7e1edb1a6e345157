//! Property test: random bytes and byte-mutated real files, through every `parse` entry point,
//! never panic and end in a scene or an error with a message.
//!
//! The case count and seed are fixed so that CI is deterministic and takes a few seconds; the
//! open-ended search is the fuzz targets' job (`scripts/fuzz.sh`).

mod common;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::OnceLock;

use common::{gltf_document, scenes_dir};
use igi_scene::{LoadReport, SceneError, mtl, scene_file};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// One parser run on fixed input.
type Parser<'a> = Box<dyn Fn() -> Result<(), SceneError> + 'a>;

/// Runs every parser on `bytes`; `Err` describes a panic or an empty error message.
fn every_parser(bytes: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(bytes);
    let parsers: [(&str, Parser); 5] = [
        (
            "obj",
            Box::new(|| {
                igi_scene::parse_mesh(
                    igi_scene::MeshFormat::Obj,
                    bytes,
                    "p.obj",
                    None,
                    &mut LoadReport::default(),
                )
                .map(drop)
            }),
        ),
        ("mtl", Box::new(|| mtl::parse(bytes, "p.mtl").map(drop))),
        (
            "ply",
            Box::new(|| {
                igi_scene::parse_mesh(
                    igi_scene::MeshFormat::Ply,
                    bytes,
                    "p.ply",
                    None,
                    &mut LoadReport::default(),
                )
                .map(drop)
            }),
        ),
        (
            "gltf",
            Box::new(|| {
                igi_scene::parse_mesh(
                    igi_scene::MeshFormat::Gltf,
                    bytes,
                    "p.gltf",
                    None,
                    &mut LoadReport::default(),
                )
                .map(drop)
            }),
        ),
        ("toml", Box::new(|| scene_file::parse(&text, "p.toml", None, &mut LoadReport::default()).map(drop))),
    ];
    for (name, parse) in parsers {
        match catch_unwind(AssertUnwindSafe(parse)) {
            Err(_) => return Err(format!("the {name} parser panicked")),
            Ok(Err(error)) if error.to_string().trim().is_empty() => {
                return Err(format!("the {name} parser returned an empty message"));
            }
            Ok(_) => {}
        }
    }
    Ok(())
}

/// Small valid files of every format: written here, plus the small shared scenes if present.
fn seeds() -> &'static [Vec<u8>] {
    static SEEDS: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let triangle = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let (json, _) = gltf_document(&triangle, &[0, 1, 2], true);
        let (glb_json, bin) = gltf_document(&triangle, &[0, 1, 2], false);
        let mut seeds = vec![
            b"mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\nusemtl light\nf 1/1/1 2/1/1 3/1/1\nf -3 -2 -1\n".to_vec(),
            b"newmtl a\nKd 0.5 0.5 0.5 # grey\nKe 1\nNs 10\nd 0.5\nTr 0.5\nillum 7\nmap_Kd -s 1 1 1 a.png\n".to_vec(),
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty uchar flags\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 3 0 1 2\n".to_vec(),
            json.into_bytes(),
            common::glb(&glb_json, &bin),
            // A CUBICSPLINE rotation: (in-tangent, value, out-tangent) per key.
            common::animated_gltf(
                &[0.0, 1.0],
                &common::Output::floats(&[[0.0; 4], [0.0, 0.0, 0.0, 1.0], [0.0; 4], [0.0; 4], [0.0, 1.0, 0.0, 0.0], [0.0; 4]]),
                "rotation",
                "CUBICSPLINE",
            )
            .into_bytes(),
            br#"[camera]
position = [0, 1, 3.5]
target = [0, 1, 0]
fov = 39.3
[[mesh]]
file = "a.obj"
scale = [1, 2, 1]
instances = [ { translate = [1, 0, 0] }, { rotate = [0, 90, 0], scale = 2 } ]
material = { diffuse = [0.5, 0.5, 0.5] }
[[light]]
type = "quad"
position = [0, 1.9, 0]
u = [0.2, 0, 0]
v = [0, 0, 0.2]
radiance = [10, 10, 10]
[[light]]
type = "spot"
position = [0, 1, 0]
direction = [0, -1, 0]
angle = 30
intensity = [1, 1, 1]
"#
            .to_vec(),
        ];
        if let Some(dir) = scenes_dir("robustness seeds") {
            for file in [
                "cornell-box/CornellBox-Original.obj",
                "cornell-box/CornellBox-Original.mtl",
                "stanford-bunny/bun_zipper_res4.ply",
                "gltf-samples/Box/glTF-Binary/Box.glb",
                "gltf-samples/Cameras/glTF-Embedded/Cameras.gltf",
                "gltf-samples/BoxTextured/glTF-Binary/BoxTextured.glb",
            ] {
                seeds.push(std::fs::read(dir.join(file)).unwrap());
            }
        }
        seeds
    })
}

/// One edit of a seed file.
#[derive(Clone, Debug)]
enum Edit {
    Set(usize, u8),
    Insert(usize, u8),
    Remove(usize, usize),
    Truncate(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        4 => (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| Edit::Set(at, byte)),
        2 => (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| Edit::Insert(at, byte)),
        2 => (any::<usize>(), 1..64usize).prop_map(|(at, len)| Edit::Remove(at, len)),
        1 => any::<usize>().prop_map(Edit::Truncate),
    ]
}

fn apply(seed: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut bytes = seed.to_vec();
    for edit in edits {
        let at = |i: usize, len: usize| if len == 0 { 0 } else { i % len };
        match *edit {
            Edit::Set(i, byte) if !bytes.is_empty() => {
                let i = at(i, bytes.len());
                bytes[i] = byte;
            }
            Edit::Insert(i, byte) => bytes.insert(at(i, bytes.len() + 1), byte),
            Edit::Remove(i, len) if !bytes.is_empty() => {
                let start = at(i, bytes.len());
                bytes.drain(start..(start + len).min(bytes.len()));
            }
            Edit::Truncate(i) => bytes.truncate(at(i, bytes.len() + 1)),
            _ => {}
        }
    }
    bytes
}

fn config(cases: u32) -> Config {
    Config { cases, rng_seed: RngSeed::Fixed(2003), failure_persistence: None, ..Config::default() }
}

#[test]
fn seeds_are_valid() {
    for seed in seeds() {
        every_parser(seed).unwrap();
    }
}

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn random_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..2048)) {
        prop_assert_eq!(every_parser(&bytes), Ok(()));
    }
}

proptest! {
    #![proptest_config(config(3000))]

    #[test]
    fn mutated_files(seed in any::<prop::sample::Index>(), edits in proptest::collection::vec(edit(), 1..6)) {
        let seed = seed.get(seeds());
        prop_assert_eq!(every_parser(&apply(seed, &edits)), Ok(()));
    }
}
