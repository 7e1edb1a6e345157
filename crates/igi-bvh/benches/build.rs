//! Criterion benchmarks of the binned SAH builder on a 2-thread pool, the setting of the Embree
//! build times in `shared/tools/embree-bench/measured/build_times.md`: random soups of 100k and
//! 1M triangles, and the conference room and Sponza when the shared scenes are present.
//! Throughput is in triangles (elements) per second; the input is the triangles' boxes.
//! `cargo run --release -p igi-bvh --example build_report` adds SAH costs and sizes.

#[path = "triangle_soup/mod.rs"]
mod triangle_soup;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use igi_bvh::{BuildParams, build_binned_sah};
use std::hint::black_box;
use triangle_soup::{SCENES, Triangle, load_scene, random_triangles, triangle_bounds};

fn bench(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("2-thread pool");
    let params = BuildParams::default();
    let mut inputs: Vec<(&str, Vec<Triangle>)> =
        vec![("random_100k", random_triangles(100_000, 1)), ("random_1M", random_triangles(1_000_000, 2))];
    inputs.extend(SCENES.iter().filter_map(|&(name, path)| Some((name, load_scene(path)?))));

    let mut g = c.benchmark_group("binned_sah_2_threads");
    g.sample_size(10);
    for (name, triangles) in &inputs {
        let bounds = triangle_bounds(triangles);
        g.throughput(Throughput::Elements(bounds.len() as u64));
        g.bench_function(*name, |b| {
            b.iter(|| pool.install(|| build_binned_sah(black_box(&bounds), &params)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
