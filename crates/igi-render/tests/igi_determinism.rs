//! Reproducibility of the IGI renderer (paper 3.4: any node renders any tile): a pixel depends only on the
//! scene, the [`FrameState`] and the pixel, so the image is the same bit for bit at any thread
//! count and tile size (the filter reads the apron's points from the neighbouring tiles, and a
//! render node's own apron computes them exactly as those tiles do),
//! with the filter on or off and with one or several samples per pixel. The seed (and, with
//! `reseed_per_frame`, the frame number) is the only source of sampling randomness.

mod common;

use common::*;
use glam::Vec3;
use igi_render::FrameSource;
use igi_render::frame::{FilterSettings, FrameState};
use igi_render::{Film, FrameOutput, FrameRenderer, PixelFormat};

/// A frame of the room at a size that is a multiple of neither the tile sizes, the 3 × 3
/// interleave nor the 4 × 2 packets.
fn frame(seed: u32) -> FrameState {
    let mut f = igi_frame(camera(Vec3::new(0.0, 1.0, 3.0), Vec3::new(0.0, 0.5, 0.0), 50.0), 47, 37);
    f.settings.seed = seed;
    f
}

/// Radiance bits, display bytes, luminance statistics (as bits) and VPL count.
type Fingerprint = (Vec<[u32; 3]>, Vec<u8>, (u64, u64, u32), usize);

/// Everything of a frame that must not depend on how it was computed: the radiance bits, the
/// display bytes, the luminance statistics and the VPL count.
fn fingerprint(out: &FrameOutput) -> Fingerprint {
    let s = out.stats;
    (
        film_bits(out.image.film().unwrap()),
        out.image.srgb8().to_vec(),
        (s.log_sum.to_bits(), s.count, s.max.to_bits()),
        out.vpls,
    )
}

#[test]
fn same_image_at_any_thread_count_and_tile_size() {
    let mut scene = every_path_room();
    let renderers = [FrameRenderer::new(1), FrameRenderer::new(2), FrameRenderer::new(3)];
    let cases = [(Some(FilterSettings::default()), 3), (Some(FilterSettings::default()), 1), (None, 3)];
    for (filter, coarse_interleave) in cases {
        for aa in [1, 4] {
            let mut f = frame(7);
            f.settings.set_discontinuity_filter(filter);
            f.settings.coarse_interleave = coarse_interleave;
            f.settings.aa = aa;
            f.settings.tile_size = 16;
            let what = format!("filter {}, coarse interleave {coarse_interleave}, aa {aa}", filter.is_some());
            let one = renderers[0].render(&mut scene, &f, &|_, _| {}).expect("valid settings");
            assert!(
                one.image.film().unwrap().pixels().iter().any(|p| p.max_element() > 0.0),
                "{what}: black image"
            );
            assert!(
                one.image.film().unwrap().pixels().iter().all(|p| p.is_finite()),
                "{what}: non-finite pixel"
            );
            let reference = fingerprint(&one);
            for r in &renderers[1..] {
                let many = r.render(&mut scene, &f, &|_, _| {}).expect("valid settings");
                assert!(reference == fingerprint(&many), "{what}: {} threads differ from 1", r.threads());
                // The same tiles are traced, whoever traces them.
                assert_eq!(one.rays, many.rays, "{what}: ray counts at {} threads", r.threads());
            }
            // Tile 64 covers the whole 47 × 37 image: tiled equals untiled.
            for tile_size in [7, 32, 64] {
                f.settings.tile_size = tile_size;
                let tiled = renderers[1].render(&mut scene, &f, &|_, _| {}).expect("valid settings");
                assert!(reference == fingerprint(&tiled), "{what}: tile size {tile_size} differs from 16");
            }
        }
    }
}

/// A renderer keeps its threads' scratch memory and its lit tiles from frame to frame: what an
/// earlier, larger frame left in them must not reach the next one.
#[test]
fn a_frame_does_not_depend_on_the_frames_before_it() {
    let mut scene = every_path_room();
    let mut next = frame(7);
    next.settings.tile_size = 16;
    let fresh = FrameRenderer::new(2).render(&mut scene, &next, &|_, _| {}).expect("valid settings");
    let used = FrameRenderer::new(2);
    let mut before = igi_frame(camera(Vec3::new(0.5, 1.2, 2.5), Vec3::new(0.0, 0.4, 0.0), 60.0), 61, 53);
    (before.settings.aa, before.settings.compensate_clamp, before.settings.tile_size) = (4, true, 24);
    used.render(&mut scene, &before, &|_, _| {}).expect("valid settings");
    let after = used.render(&mut scene, &next, &|_, _| {}).expect("valid settings");
    assert!(fingerprint(&fresh) == fingerprint(&after), "the frame differs after another one");
}

/// A chunk of eight shading points lit together mixes matte and glossy points wherever a
/// glossy object meets a matte one, and which points share a chunk depends on the tile. A matte
/// point's light must be summed the same way whatever its chunk-mates (it was not: a chunk
/// with a glossy point summed colour × g and then added, one without fused the two, and pixels
/// near tile borders differed in their last bit). The animated room has a point light, matte
/// walls and a glossy object.
#[test]
fn a_matte_points_light_does_not_depend_on_its_chunk_mates() {
    let scene = igi_scene::builtin("animated-room").expect("built-in animated-room");
    let camera = scene.camera.expect("the animated room has its camera");
    let mut scene = igi_render::PreparedScene::new(scene);
    let renderer = FrameRenderer::new(2);
    for aa in [1, 4] {
        let mut f = igi_frame(camera, 96, 72);
        f.settings.aa = aa;
        f.settings.seed = 3;
        f.pixels = PixelFormat::Linear;
        let mut image = |tile_size: u32| {
            f.settings.tile_size = tile_size;
            fingerprint(&renderer.render(&mut scene, &f, &|_, _| {}).expect("valid settings"))
        };
        // 96 × 72 is one tile of 96: untiled.
        let untiled = image(96);
        for tile_size in [16, 40] {
            assert!(image(tile_size) == untiled, "aa {aa}: tile size {tile_size} differs from untiled");
        }
    }
}

#[test]
fn display_bytes_are_the_tone_mapped_film() {
    // The compositor copies each tile's 8-bit pixels into place: they must be the frame's tone
    // map of the film at the same position (a misplaced tile row shows here).
    let mut scene = every_path_room();
    let mut f = frame(3);
    f.settings.tile_size = 7;
    f.tone_map.scale = 4.0;
    let renderer = FrameRenderer::new(2);
    let out = renderer.render(&mut scene, &f, &|_, _| {}).expect("valid settings");
    let want: Vec<u8> =
        out.image.film().unwrap().pixels().iter().flat_map(|&p| f.tone_map.to_srgb8(p)).collect();
    assert!(out.image.srgb8() == want, "the linear frame's display image is not its tone-mapped film");
    // The same frame as 8-bit tiles (what a render node sends): the same bytes.
    f.pixels = PixelFormat::Srgb8;
    let tiles = renderer.render(&mut scene, &f, &|_, _| {}).expect("valid settings");
    assert!(tiles.image.film().is_none());
    assert!(tiles.image.srgb8() == want, "8-bit image differs from the tone-mapped film");
    assert!(tiles.image.srgb8().iter().any(|&b| b > 0 && b < 255), "the test image should have mid tones");
}

#[test]
fn the_seed_and_the_reseeded_frame_number_are_the_only_randomness() {
    let mut scene = every_path_room();
    let r = FrameRenderer::new(2);
    let mut render = |f: &FrameState| {
        r.render(&mut scene, f, &|_, _| {}).expect("valid settings").image.into_film().unwrap()
    };
    let base = frame(7);
    let a = render(&base);
    assert!(film_bits(&a) == film_bits(&render(&base)), "the same frame twice must be identical");
    assert!(film_bits(&a) != film_bits(&render(&frame(8))), "another seed must give other VPLs");

    // A still scene without reseeding keeps its VPLs: no flicker from frame to frame.
    let mut later = base.clone();
    later.number = 3;
    assert!(film_bits(&a) == film_bits(&render(&later)), "frame 3 differs from frame 0 without reseeding");
    // With reseeding every frame draws fresh VPLs and sample patterns.
    let (mut r0, mut r3) = (base.clone(), later.clone());
    r0.reseed_per_frame = true;
    r3.reseed_per_frame = true;
    assert!(film_bits(&render(&r0)) != film_bits(&render(&r3)), "reseeded frames 0 and 3 are identical");

    // The noise changes, the light does not: image means of two seeds agree within 5 % (one
    // frame of 12 VPLs per pixel; measured 1-2 %).
    let (ma, mb) = (film_mean(&a), film_mean(&render(&frame(8))));
    assert!(rel_err(ma, mb) < 0.05, "image means {ma} and {mb}");
}

#[test]
fn accumulation_is_the_mean_of_the_reseeded_frames() {
    // render_accumulated(n) from frame k averages frames k .. k + n − 1 with fresh VPLs: the
    // same as rendering those frames with reseeding and averaging (sum in order, then × 1/n),
    // bit for bit; one frame is the plain render.
    let mut scene = every_path_room();
    let mut r = FrameRenderer::new(2);
    let mut f = frame(5);
    f.number = 10;
    let accumulated = r.render_accumulated(&mut scene, &f, 3, &|_, _| {}).expect("valid settings");
    let mut sum: Vec<Vec3> = vec![Vec3::ZERO; accumulated.image.film().unwrap().pixels().len()];
    let mut rays = igi_render::RayCounts::default();
    let mut g = f.clone();
    g.reseed_per_frame = true;
    for i in 0..3 {
        g.number = f.number + i;
        let one = r.render(&mut scene, &g, &|_, _| {}).expect("valid settings");
        rays += one.rays;
        let one = one.image.into_film().unwrap();
        sum.iter_mut().zip(one.pixels()).for_each(|(s, p)| *s += *p);
    }
    assert_eq!(accumulated.rays, rays, "the accumulated frame counts the rays of 3 frames");
    let mean = Film::from_pixels(47, 37, sum.into_iter().map(|p| p * (1.0 / 3.0)).collect());
    assert!(
        film_bits(accumulated.image.film().unwrap()) == film_bits(&mean),
        "accumulated image is not the mean of its frames"
    );

    let single = r.render_accumulated(&mut scene, &f, 1, &|_, _| {}).expect("valid settings");
    let plain = r.render(&mut scene, &f, &|_, _| {}).expect("valid settings");
    assert!(
        film_bits(single.image.film().unwrap()) == film_bits(plain.image.film().unwrap()),
        "one accumulated frame differs from render()"
    );
}
