//! OBJ and MTL text: `obj::parse` without files, and the same bytes as an MTL library.
#![no_main]

use igi_scene::{LoadReport, mtl, obj};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(error) = obj::parse(data, "fuzz.obj", None, &mut LoadReport::default()) {
        assert!(!error.to_string().is_empty());
    }
    if let Err(error) = mtl::parse(data, "fuzz.mtl") {
        assert!(!error.to_string().is_empty());
    }
});
