//! The small pieces: light-selection CDF, triangle sampling, tile grid, texture filtering.

use glam::Vec2;
use igi_render::sampling::{Cdf, Sobol2, hash_combine, pixel_seed, sobol4, uniform_triangle};
use igi_render::{PixelRect, Tile, TileGrid};

#[test]
fn cdf_picks_in_proportion_and_skips_zero_weights() {
    let cdf = Cdf::new([1.0, 0.0, 3.0, 0.0]);
    assert_eq!(cdf.len(), 4);
    assert_eq!(cdf.sample(0.0), (0, 0.25));
    assert_eq!(cdf.sample(0.2499), (0, 0.25));
    assert_eq!(cdf.sample(0.25), (2, 0.75));
    assert_eq!(cdf.sample(0.999_999_9), (2, 0.75));
    assert_eq!(cdf.pmf(1), 0.0);
    assert!(Cdf::new([0.0, -1.0, f32::NAN]).is_empty());
}

/// The anti-aliasing samples' shortcut (a seed's scrambles hashed once, an index's Sobol
/// point computed once for many seeds) gives the bits of the general sequence.
#[test]
fn sobol2_is_the_first_two_dimensions_of_sobol4() {
    for seed in [0, 1, 12345, 0x9e37_79b9, u32::MAX] {
        let sequence = Sobol2::new(seed);
        for index in (0..300).chain([4095, 65535]) {
            let [u, v, _, _] = sobol4(index, 0, seed);
            let [a, b] = sequence.point(Sobol2::unscrambled(index));
            assert_eq!((a.to_bits(), b.to_bits()), (u.to_bits(), v.to_bits()), "seed {seed}, index {index}");
        }
    }
}

#[test]
fn triangle_samples_are_uniform_barycentrics() {
    let n = 4096u32;
    let (mut mean, mut inside) = (Vec2::ZERO, 0);
    for i in 0..n {
        let [u, v, _, _] = sobol4(i, 0, 12345);
        let b = uniform_triangle(Vec2::new(u, v));
        if b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 {
            inside += 1;
        }
        mean += b;
    }
    mean /= n as f32;
    assert_eq!(inside, n);
    // The centroid has barycentrics (1/3, 1/3).
    assert!((mean - Vec2::splat(1.0 / 3.0)).length() < 2e-3, "{mean}");
}

#[test]
fn seeds_differ_between_neighbouring_pixels() {
    assert_ne!(pixel_seed(0, 0, 0), pixel_seed(1, 0, 0));
    assert_ne!(pixel_seed(1, 0, 0), pixel_seed(0, 1, 0));
    assert_ne!(pixel_seed(3, 4, 0), pixel_seed(3, 4, 1));
    assert_ne!(hash_combine(1, 2), hash_combine(2, 1));
}

#[test]
fn tile_grid_covers_every_pixel_once() {
    let grid = TileGrid::new(37, 21, 16);
    assert_eq!(grid.len(), 3 * 2);
    let mut covered = vec![0u8; 37 * 21];
    for Tile { rect: PixelRect { x0, y0, x1, y1 }, .. } in grid.tiles() {
        for y in y0..y1 {
            for x in x0..x1 {
                covered[(y * 37 + x) as usize] += 1;
            }
        }
    }
    assert!(covered.iter().all(|&c| c == 1));
    assert_eq!(grid.tile(5), Tile { index: 5, rect: PixelRect { x0: 32, y0: 16, x1: 37, y1: 21 } });
}

#[test]
fn geometry_bytes_count_what_the_meshes_and_bvh_hold() {
    // A 100 × 100 grid of quads on a bumpy height field (20,000 triangles sharing 10,201
    // vertices), no normals or texture coordinates: the vertices and index triples take 12 B
    // per triangle at least (the triples) and 36 B at most (no vertex shared); a binary BVH
    // over N triangles has at most 2N − 1 nodes of 32 B plus a 4 B order entry per triangle,
    // under 68 B per triangle; the shading data is the 4 B material index per triangle.
    let n = 100u32;
    let positions = (0..=n)
        .flat_map(|z| (0..=n).map(move |x| (x, z)))
        .map(|(x, z)| glam::Vec3::new(x as f32, ((x * 7 + z * 13) % 5) as f32 * 0.1, z as f32))
        .collect();
    let at = |x: u32, z: u32| z * (n + 1) + x;
    let indices: Vec<[u32; 3]> = (0..n)
        .flat_map(|z| (0..n).map(move |x| (x, z)))
        .flat_map(|(x, z)| {
            [[at(x, z), at(x, z + 1), at(x + 1, z)], [at(x + 1, z), at(x, z + 1), at(x + 1, z + 1)]]
        })
        .collect();
    let mesh = igi_scene::Mesh {
        name: "grid".into(),
        positions,
        normals: None,
        uvs: None,
        material_ids: vec![0; indices.len()],
        indices,
    };
    let prepared = igi_render::PreparedScene::new(igi_scene::Scene {
        meshes: vec![mesh],
        instances: vec![igi_scene::Instance { mesh: 0, transform: glam::Affine3A::IDENTITY }],
        materials: vec![igi_scene::Material::default()],
        ..igi_scene::Scene::default()
    });
    let g = prepared.geometry_bytes();
    assert_eq!(g.stored_triangles, 20_000);
    let per = |bytes: usize| bytes as f64 / 20_000.0;
    assert!((12.0..=36.0).contains(&per(g.triangles)), "{g:?}");
    assert!(per(g.bvh) > 4.0 && per(g.bvh) < 68.0, "{g:?}");
    assert_eq!(g.shading, 4 * 20_000, "{g:?}");
    assert_eq!(g.total(), g.triangles + g.bvh + g.shading);
}
