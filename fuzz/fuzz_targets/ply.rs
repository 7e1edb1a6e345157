//! PLY files, ascii and binary.
#![no_main]

use igi_scene::{LoadReport, ply};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(error) = ply::parse(data, "fuzz.ply", &mut LoadReport::default()) {
        assert!(!error.to_string().is_empty());
    }
});
