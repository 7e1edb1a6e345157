//! OBJ and MTL text: `parse_mesh` of OBJ without files, and the same bytes as an MTL library.
#![no_main]

use igi_scene::{LoadReport, MeshFormat, mtl};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Err(error) = igi_scene::parse_mesh(MeshFormat::Obj, data, "fuzz.obj", None, &mut LoadReport::default()) {
        assert!(!error.to_string().is_empty());
    }
    if let Err(error) = mtl::parse(data, "fuzz.mtl") {
        assert!(!error.to_string().is_empty());
    }
});
