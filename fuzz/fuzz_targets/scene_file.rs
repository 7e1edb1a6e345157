//! Scene files (TOML); mesh entries are checked but no mesh file is read.
#![no_main]

use igi_scene::{LoadReport, scene_file};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Err(error) = scene_file::parse(text, "fuzz.toml", None, &mut LoadReport::default()) {
        assert!(!error.to_string().is_empty());
    }
});
