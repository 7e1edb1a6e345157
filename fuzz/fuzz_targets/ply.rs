//! PLY files, ascii and binary.
#![no_main]

use igi_scene::{LoadReport, MeshFormat};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(error) = igi_scene::parse_mesh(MeshFormat::Ply, data, "fuzz.ply", None, &mut LoadReport::default()) {
        assert!(!error.to_string().is_empty());
    }
});
