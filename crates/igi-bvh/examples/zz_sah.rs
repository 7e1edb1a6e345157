//! scratch
#[path = "../benches/triangle_soup/mod.rs"]
#[allow(dead_code)]
mod triangle_soup;
use igi_bvh::*;
fn main() {
    let p = BuildParams::default();
    for sc in [
        "conference/conference.obj",
        "sponza-dabrovic/sponza.obj",
        "sibenik/sibenik.obj",
        "lost-empire/lost_empire.obj",
        "random:100000",
    ] {
        let t = if let Some(n) = sc.strip_prefix("random:") {
            triangle_soup::random_triangles(n.parse().unwrap(), 7)
        } else {
            triangle_soup::load_scene(sc).unwrap()
        };
        let b = triangle_soup::triangle_bounds(&t);
        let cache = format!("/tmp/sweep_{}.txt", sc.replace('/', "_"));
        let sweep: f32 =
            std::fs::read_to_string(&cache).ok().and_then(|s| s.trim().parse().ok()).unwrap_or_else(|| {
                let v = build_sweep_sah(&b, &p).sah_cost(&p);
                std::fs::write(&cache, v.to_string()).unwrap();
                v
            });
        let a = build_binned_sah(&b, &p);
        println!(
            "{sc:32} binned {:8.3} sweep {sweep:8.3} ratio {:.4}",
            a.sah_cost(&p),
            a.sah_cost(&p) / sweep
        );
    }
}
