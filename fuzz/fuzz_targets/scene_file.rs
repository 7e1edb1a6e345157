//! Scene files (TOML); mesh entries are checked but no mesh file is read. A scene that parses
//! is posed at a few times, so the keyframe tracks are sampled too.
#![no_main]

use igi_scene::{LoadReport, scene_file};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match scene_file::parse(text, "fuzz.toml", None, &mut LoadReport::default()) {
        Ok(scene) => {
            for t in [0.0, 0.37, 2.5, 1e9] {
                scene.animation.pose(t);
            }
        }
        Err(error) => assert!(!error.to_string().is_empty()),
    }
});
