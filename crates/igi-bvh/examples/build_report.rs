//! Build report for the shared test scenes and random triangle soups: binned SAH build time
//! (median of 5 after a warm-up, on a 2-thread pool like the Embree numbers in
//! `shared/tools/embree-bench/measured/build_times.md`), the same with the triangle boxes
//! computed in the timing (as Embree's includes its buffer setup), refit time, SAH cost against
//! the full-sweep reference, and the BVH's size and shape.
//!
//! `cargo run --release -p igi-bvh --example build_report [-- --threads N] [-- --params]`
//! `--params` adds the SAH cost, size and build time over leaf sizes and bin counts.

#[path = "../benches/triangle_soup/mod.rs"]
mod triangle_soup;

use std::time::Instant;

use igi_bvh::{Aabb, BuildParams, build_binned_sah, build_sweep_sah};
use rayon::prelude::*;
use triangle_soup::{SCENES, Triangle, load_scene, random_triangles, triangle_bounds};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let threads =
        args.iter().position(|a| a == "--threads").map_or(2, |i| args[i + 1].parse().expect("--threads N"));
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");

    let mut inputs: Vec<(String, Vec<Triangle>)> =
        SCENES.iter().filter_map(|&(name, path)| Some((name.to_string(), load_scene(path)?))).collect();
    inputs.push(("random 100k".into(), random_triangles(100_000, 1)));
    inputs.push(("random 1M".into(), random_triangles(1_000_000, 2)));

    let params = BuildParams::default();
    println!("binned SAH build, {threads} threads, median of 5, {params:?}");
    println!(
        "{:<12} {:>9} {:>9} {:>10} {:>8} {:>9} {:>8} {:>8} {:>7} {:>6} {:>6} {:>8}",
        "input",
        "tris",
        "build ms",
        "+boxes ms",
        "Mtris/s",
        "refit ms",
        "SAH",
        "sweep",
        "ratio",
        "B/tri",
        "depth",
        "leaves"
    );
    for (name, triangles) in &inputs {
        let n = triangles.len();
        let bounds = triangle_bounds(triangles);
        let build_ms = median_ms(|| drop(pool.install(|| build_binned_sah(&bounds, &params))));
        let with_boxes_ms = median_ms(|| {
            pool.install(|| {
                let bounds: Vec<Aabb> = triangles.par_iter().map(|&t| Aabb::from_points(t)).collect();
                drop(build_binned_sah(&bounds, &params))
            })
        });
        let mut bvh = pool.install(|| build_binned_sah(&bounds, &params));
        let leaf_order: Vec<Aabb> = bvh.prim_order.iter().map(|&p| bounds[p as usize]).collect();
        let refit_ms = median_ms(|| bvh.refit(|i| leaf_order[i as usize]));
        let sah = bvh.sah_cost(&params);
        let sweep = build_sweep_sah(&bounds, &params).sah_cost(&params);
        println!(
            "{name:<12} {n:>9} {build_ms:>9.2} {with_boxes_ms:>10.2} {:>8.2} {refit_ms:>9.2} {sah:>8.2} {sweep:>8.2} \
             {:>7.4} {:>6.2} {:>6} {:>8}",
            n as f64 / build_ms / 1e3,
            sah / sweep,
            bvh.bytes() as f64 / n as f64,
            bvh.depth(),
            bvh.leaf_count(),
        );
    }

    if args.iter().any(|a| a == "--params") {
        println!("\nSAH cost (ratio to the full sweep), BVH bytes per triangle and build ms");
        for (name, triangles) in inputs.iter().filter(|(_, t)| t.len() <= 500_000) {
            let bounds = triangle_bounds(triangles);
            for max_leaf_size in [1, 2, 4, 8, 15] {
                let leaf_params = BuildParams { max_leaf_size, ..params };
                let sweep = build_sweep_sah(&bounds, &leaf_params).sah_cost(&leaf_params);
                let row: Vec<String> = [8, 16, 32]
                    .iter()
                    .map(|&bins| {
                        let p = BuildParams { bins, ..leaf_params };
                        let bvh = pool.install(|| build_binned_sah(&bounds, &p));
                        let ms = median_ms(|| drop(pool.install(|| build_binned_sah(&bounds, &p))));
                        let sah = bvh.sah_cost(&p);
                        let bytes = bvh.bytes() as f64 / triangles.len() as f64;
                        format!("bins {bins:>2}: {sah:>7.2} ({:.4}) {bytes:>5.2} B {ms:>6.2} ms", sah / sweep)
                    })
                    .collect();
                println!("{name:<12} leaf {max_leaf_size:>2} sweep {sweep:>7.2} | {}", row.join(" | "));
            }
        }
    }
}

/// Median wall time of 5 runs after one warm-up run, in milliseconds.
fn median_ms(mut f: impl FnMut()) -> f64 {
    f();
    let mut times: Vec<f64> = (0..5)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[2]
}
