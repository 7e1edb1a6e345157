//! Reproducibility (DESIGN.md section 4): the same settings give the same image bit for bit at
//! any thread count, a pixel rendered alone equals its value in the full image, and the seed
//! is the only source of sampling randomness.

mod common;

use common::*;
use glam::{Vec2, Vec3};
use igi_render::{Film, PreparedScene, RenderSettings, TileRenderer, render};
use igi_scene::Light;

/// A small room: floor, a down-facing area light, a blocker casting a soft shadow, and a point
/// light, so every code path (area samples, punctual light, shadow packets) runs.
fn room() -> PreparedScene {
    let meshes = vec![
        horizontal_square("floor", Vec3::new(0.0, 0.0, 0.0), Vec2::new(2.0, 2.0), true, 0),
        horizontal_square("light", Vec3::new(0.0, 1.9, 0.0), Vec2::new(0.4, 0.3), false, 1),
        horizontal_square("blocker", Vec3::new(0.2, 0.7, 0.1), Vec2::new(0.3, 0.3), true, 2),
        quad(
            "back",
            [
                Vec3::new(-2.0, 0.0, -1.5),
                Vec3::new(2.0, 0.0, -1.5),
                Vec3::new(2.0, 2.0, -1.5),
                Vec3::new(-2.0, 2.0, -1.5),
            ],
            3,
        ),
    ];
    let mut materials =
        vec![diffuse("floor", 0.7), emitter("light", Vec3::new(17.0, 12.0, 4.0)), diffuse("blocker", 0.5)];
    materials.push(igi_scene::Material { diffuse: Vec3::new(0.6, 0.1, 0.1), ..diffuse("red", 0.0) });
    let lights = vec![Light::Point { position: Vec3::new(-1.0, 1.5, 1.0), intensity: Vec3::splat(0.5) }];
    PreparedScene::new(scene(meshes, materials, lights))
}

fn settings(threads: usize) -> RenderSettings {
    // Sizes that are multiples of neither the tile size nor the 4×2 packet.
    RenderSettings { width: 97, height: 61, samples: 8, seed: 7, threads, tile_size: 16, exposure: None }
}

fn cam() -> igi_scene::Camera {
    camera(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.5, 0.0), 50.0)
}

fn bits(film: &Film) -> Vec<[u32; 3]> {
    film.pixels().iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

#[test]
fn same_image_for_any_thread_count() {
    let scene = room();
    let one = render(&scene, &cam(), &settings(1));
    assert!(one.pixels().iter().any(|p| p.max_element() > 0.0));
    for threads in [2, 3, 8] {
        let many = render(&scene, &cam(), &settings(threads));
        assert!(bits(&one) == bits(&many), "{threads} threads differ from 1");
    }
    // And the same again (no hidden state).
    assert!(bits(&one) == bits(&render(&scene, &cam(), &settings(1))));
}

#[test]
fn a_pixel_alone_equals_its_value_in_the_image() {
    let scene = room();
    let s = settings(2);
    let film = render(&scene, &cam(), &s);
    let tiles = TileRenderer::new(&scene, &cam(), &s);
    for (x, y) in [(0, 0), (48, 30), (96, 60), (13, 44), (70, 10), (50, 55)] {
        let alone = tiles.render_pixel(x, y);
        let full = film.get(x, y);
        assert!(
            (alone - full).abs().max_element() <= 1e-6 * full.max_element().max(1.0),
            "pixel ({x}, {y}): {alone} vs {full}"
        );
    }
}

#[test]
fn the_seed_changes_the_noise_only() {
    let scene = room();
    let a = render(&scene, &cam(), &settings(2));
    let b = render(&scene, &cam(), &RenderSettings { seed: 8, ..settings(2) });
    assert!(bits(&a) != bits(&b), "another seed should give another sample pattern");
    let mean = |f: &Film| {
        f.pixels().iter().map(|p| f64::from(p.x + p.y + p.z)).sum::<f64>() / f.pixels().len() as f64
    };
    let (ma, mb) = (mean(&a), mean(&b));
    assert!((ma - mb).abs() < 0.03 * ma, "means {ma} and {mb} should agree");
}
