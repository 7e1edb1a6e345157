//! glTF JSON and GLB containers, with embedded data only (no files are read). A file that
//! loads must have a consistent animation, and is posed at a few times, so the keyframe
//! tracks it read are sampled too.
#![no_main]

use igi_scene::{LoadReport, MeshFormat};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    match igi_scene::parse_mesh(MeshFormat::Gltf, data, "fuzz.gltf", None, &mut LoadReport::default()) {
        Ok(scene) => {
            if let Err(error) = scene.animation.validate(scene.instances.len(), scene.lights.len()) {
                panic!("{error}");
            }
            for t in [0.0, 0.37, 2.5, 1e9] {
                scene.animation.pose(t);
            }
        }
        Err(error) => assert!(!error.to_string().is_empty()),
    }
});
