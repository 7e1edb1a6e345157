//! glTF JSON and GLB containers, with embedded data only (no files are read).
#![no_main]

use igi_scene::{LoadReport, gltf_loader};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(error) = gltf_loader::parse(data, "fuzz.gltf", None, &mut LoadReport::default()) {
        assert!(!error.to_string().is_empty());
    }
});
