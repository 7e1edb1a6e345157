//! scratch
fn main() {
    for p in std::env::args().skip(1) {
        let t = std::time::Instant::now();
        match igi_scene::load_with_report(&p) {
            Ok((s, r)) => {
                println!(
                    "{p}: {:?} inst-tris {} meshes {} inst {} mats {} tex {} lights {:?} cam {:?} bounds {:?} emissive {} warn {:#?}",
                    t.elapsed(),
                    s.triangle_count(),
                    s.meshes.len(),
                    s.instances.len(),
                    s.materials.len(),
                    s.textures.len(),
                    s.lights,
                    s.camera,
                    s.bounds(),
                    s.emissive_triangle_count(),
                    r.warnings
                );
            }
            Err(e) => println!("{p}: ERR {e}"),
        }
    }
}
