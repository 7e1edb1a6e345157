//! scratch
use glam::Vec3;
use igi_bvh::*;
fn main() {
    let cube = |c: Vec3, s: f32| Aabb::new(c - s, c + s);
    let prims: Vec<Aabb> =
        (0..200).map(|i| cube(Vec3::splat(1.5f32.powi(i - 100)), 1e-3 * 1.5f32.powi(i - 100))).collect();
    let params = BuildParams { max_leaf_size: 1, ..Default::default() };
    println!(
        "binned depth {} sweep depth {}",
        build_binned_sah(&prims, &params).depth(),
        build_sweep_sah(&prims, &params).depth()
    );
    let prims: Vec<Aabb> =
        (0..240).map(|i| cube(Vec3::splat(2f32.powi(i - 120)), 2f32.powi(i - 120) * 0.25)).collect();
    println!(
        "binned depth {} sweep depth {}",
        build_binned_sah(&prims, &params).depth(),
        build_sweep_sah(&prims, &params).depth()
    );
}
