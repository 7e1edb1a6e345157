//! Build report for the shared test scenes and random soups: binned SAH build time (median of
//! 5 on a 2-thread pool), SAH cost against the full-sweep reference, BVH size and shape.
//!
//! `cargo run --release -p igi-bvh --example build_report [-- --threads N] [-- --params]`
//! `--params` adds a table of the SAH cost and size over leaf sizes and bin counts.

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
    let params_table = args.iter().any(|a| a == "--params");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();

    let mut inputs: Vec<(String, Vec<Triangle>)> =
        SCENES.iter().filter_map(|&(name, path)| Some((name.to_string(), load_scene(path)?))).collect();
    inputs.push(("random 100k".into(), random_triangles(100_000, 1)));
    inputs.push(("random 1M".into(), random_triangles(1_000_000, 2)));

    println!("binned SAH build, {threads} threads, median of 5 (default params)");
    println!(
        "{:<12} {:>9} {:>9} {:>12} {:>10} {:>9} {:>9} {:>9} {:>7} {:>6} {:>8}",
        "input",
        "tris",
        "build ms",
        "bounds+b ms",
        "Mtris/s",
        "SAH",
        "sweep",
        "ratio",
        "B/tri",
        "depth",
        "leaves"
    );
    let params = BuildParams::default();
    for (name, triangles) in &inputs {
        let n = triangles.len();
        let bounds = triangle_bounds(triangles);
        let build_ms = median_ms(|| pool.install(|| drop(build_binned_sah(&bounds, &params))));
        let total_ms = median_ms(|| {
            pool.install(|| {
                let bounds: Vec<Aabb> = triangles.par_iter().map(|&t| Aabb::from_points(t)).collect();
                drop(build_binned_sah(&bounds, &params))
            })
        });
        let bvh = pool.install(|| build_binned_sah(&bounds, &params));
        let sweep = build_sweep_sah(&bounds, &params);
        let (sah, sweep_sah) = (bvh.sah_cost(&params), sweep.sah_cost(&params));
        println!(
            "{name:<12} {n:>9} {build_ms:>9.2} {total_ms:>12.2} {:>10.2} {sah:>9.2} {sweep_sah:>9.2} {:>9.4} {:>7.2} {:>6} {:>8}",
            n as f64 / build_ms / 1e3,
            sah / sweep_sah,
            bvh.bytes() as f64 / n as f64,
            bvh.depth(),
            bvh.leaf_count(),
        );
    }

    if params_table {
        println!("\nSAH cost (binned / sweep) and BVH bytes per triangle over max_leaf_size and bins");
        for (name, triangles) in &inputs {
            let bounds = triangle_bounds(triangles);
            for max_leaf_size in [1, 2, 4, 8, 15] {
                let p = BuildParams { max_leaf_size, ..params };
                let sweep = build_sweep_sah(&bounds, &p).sah_cost(&p);
                let row: Vec<String> = [8, 16, 32]
                    .iter()
                    .map(|&bins| {
                        let p = BuildParams { bins, ..p };
                        let bvh = pool.install(|| build_binned_sah(&bounds, &p));
                        let ms = median_ms(|| pool.install(|| drop(build_binned_sah(&bounds, &p))));
                        format!(
                            "bins {bins:>2}: {:>8.2} ({:.4}) {:>5.2} B/tri {ms:>7.2} ms",
                            bvh.sah_cost(&p),
                            bvh.sah_cost(&p) / sweep,
                            bvh.bytes() as f64 / triangles.len() as f64
                        )
                    })
                    .collect();
                println!("{name:<12} leaf {max_leaf_size:>2} sweep {sweep:>8.2} | {}", row.join(" | "));
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
