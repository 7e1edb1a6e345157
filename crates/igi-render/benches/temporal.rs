//! Criterion benchmarks of what temporal reuse adds to a viewer's frame (ARCHITECTURE.md,
//! "Temporal reuse while the view moves"), at the viewers' 640x480 in the built-in
//! `animated-room`: tracing the surfaces of the pixel centres, and adding a frame to the
//! history after a camera step (reprojection, the silhouette clamp and the blend) or in a
//! still view. `igi bench quality --orbit` measures the same work inside whole frames.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use glam::Vec3;
use igi_render::{DiffuseLayer, Film, Motion, PinholeCamera, PreparedScene, SurfaceBuffer, TemporalHistory};
use igi_scene::Camera;
use std::hint::black_box;

const W: u32 = 640;
const H: u32 = 480;

/// A frame whose radiance varies over the image (and its layer, a share of it), so the
/// silhouette clamp and the blend do real work.
fn frame(seed: f32) -> (Film, DiffuseLayer) {
    let pixels: Vec<Vec3> = (0..W * H)
        .map(|i| {
            let (x, y) = ((i % W) as f32, (i / W) as f32);
            Vec3::new((x * 0.05 + seed).sin() + 1.5, (y * 0.03).cos() + 1.5, 1.0)
        })
        .collect();
    let layer = pixels.iter().map(|&p| 0.7 * p).collect();
    (Film::from_pixels(W, H, pixels), DiffuseLayer(Film::from_pixels(W, H, layer)))
}

fn temporal(c: &mut Criterion) {
    let scene = PreparedScene::new(igi_scene::builtin("animated-room").expect("a built-in scene"));
    let camera = *scene.camera().expect("the room has a camera");
    // A viewer's orbit step: the eye moves sideways by a small share of the scene.
    let right = (camera.target - camera.position).cross(camera.up).normalize();
    let step = 0.005 * scene.bounds().diagonal() * right;
    let cameras = [camera, Camera { position: camera.position + step, ..camera }];
    let surfaces = cameras.map(|c| SurfaceBuffer::trace(&scene, PinholeCamera::new(&c, W, H)));
    let frames = [frame(0.0), frame(0.5)];

    let mut group = c.benchmark_group("temporal");
    group.sample_size(20);
    group.bench_function("surface buffer 640x480", |b| {
        b.iter(|| SurfaceBuffer::trace(&scene, PinholeCamera::new(black_box(&cameras[1]), W, H)))
    });
    let mut history = TemporalHistory::new();
    let mut k = 0;
    group.bench_function("add a moved frame", |b| {
        // The camera steps back and forth; copying its surfaces is not part of the work.
        b.iter_batched(
            || {
                k ^= 1;
                (k, surfaces[k].clone())
            },
            |(k, surfaces)| {
                let (film, layer) = &frames[k];
                history.add(film, Some(layer), Motion::Moved(surfaces), 15.0)
            },
            BatchSize::LargeInput,
        )
    });
    group.bench_function("add a still frame", |b| {
        b.iter(|| {
            let (film, layer) = &frames[0];
            history.add(film, Some(layer), Motion::Still, f32::INFINITY)
        })
    });
    group.finish();
}

criterion_group!(benches, temporal);
criterion_main!(benches);
