//! Converged instant global illumination against the reference path tracer on the built-in
//! Cornell box (all Lambertian: both estimators compute the same light transport, see
//! `igi_shade::brdf`), and what the default VPL clamp costs.
//!
//! IGI runs unclamped (clamp 0, unbiased apart from the 32-bounce cap, which drops 0.8³² of
//! the indirect light) and accumulates frames with fresh VPLs; the path tracer is unbiased.
//! Unclamped VPLs near a crease (the floor next to a box face) give 1/d² spikes, so the IGI
//! error is heavy-tailed: single blocks of pixels can be 10-20 % off after a hundred frames
//! for some seeds and not for others, while the image means agree to about 1 %. The comparisons are
//! therefore on image means and on mean absolute differences, with bounds set from the spread
//! over seeds (see each assertion). The clamp's bias compensation is checked here too, on the
//! animated room's statue for its speckles (measured: 21 pixels over twice their 5 × 5
//! median when its light was added unfiltered, 5 with and without it once filtered).

mod common;

use common::*;
use glam::Vec3;
use igi_render::FrameSource;
use igi_render::image::tonemap::luminance;
use igi_render::{Film, FrameRenderer, FrameSettings, FrameState, PinholeCamera, PreparedScene};

const SIZE: u32 = 48;
/// IGI frames accumulated for the converged image.
const FRAMES: u32 = 256;
/// Paths per pixel of the reference.
const SPP: u32 = 512;

/// The frame these comparisons render: one filter level. The second level's 9-pixel window
/// covers a fifth of this 48-pixel image and averages irradiance gradients (the contact
/// shadows, the colour bleeding near the walls) into a bias a larger image does not have:
/// after 256 frames its worst 6 × 6 block was 26 % off the path tracer, against 4-6 % with one
/// level.
fn cornell_frame(camera: igi_scene::Camera) -> FrameState {
    let mut frame = igi_frame(camera, SIZE, SIZE);
    frame.settings.coarse_interleave = 1;
    frame
}

fn cornell() -> (PreparedScene, igi_scene::Camera) {
    let scene = igi_scene::builtin("cornell-box").expect("built-in cornell-box");
    let camera = scene.camera.expect("the Cornell box has its camera");
    (PreparedScene::new(scene), camera)
}

/// True for pixels any part of which sees the light (corners or centre hit an emitter). Those
/// show L_e = (17, 12, 4) in both renderers, which would dominate the image mean and hide the
/// reflected light the comparison is about.
fn light_pixels(scene: &PreparedScene, pin: &PinholeCamera) -> Vec<bool> {
    let points = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)];
    (0..pin.height)
        .flat_map(|y| (0..pin.width).map(move |x| (x, y)))
        .map(|(x, y)| {
            points.iter().any(|&(dx, dy)| {
                let hit = scene.accel().intersect(&pin.ray_at(x, y, dx, dy));
                hit.is_hit() && scene.is_emissive(hit.instance, hit.prim)
            })
        })
        .collect()
}

/// Mean over the pixels not flagged in `skip`.
fn masked_mean(film: &Film, skip: &[bool]) -> Vec3 {
    let (sum, n) = film
        .pixels()
        .iter()
        .zip(skip)
        .filter(|(_, s)| !**s)
        .fold((Vec3::ZERO, 0u32), |(sum, n), (p, _)| (sum + *p, n + 1));
    sum / n as f32
}

/// Mean over the unflagged pixels of |a − b| (luminance), relative to the mean luminance of b.
fn relative_mad(a: &Film, b: &Film, skip: &[bool]) -> f32 {
    let (sum, n) = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .zip(skip)
        .filter(|(_, s)| !**s)
        .fold((0.0f32, 0u32), |(sum, n), ((p, q), _)| (sum + (luminance(*p) - luminance(*q)).abs(), n + 1));
    sum / n as f32 / luminance(masked_mean(b, skip))
}

/// Largest |a − b| (luminance) over the 6 × 6 pixel blocks that hold no light pixel, relative
/// to the mean luminance of b: a local structural error (a wall lit wrongly, missing colour
/// bleeding) shows here even where the image means agree.
fn worst_block(a: &Film, b: &Film, skip: &[bool]) -> f32 {
    const B: u32 = 6;
    let mut worst = 0.0f32;
    for by in 0..SIZE / B {
        for bx in 0..SIZE / B {
            let pixels: Vec<u32> = (0..B * B).map(|k| (by * B + k / B) * SIZE + bx * B + k % B).collect();
            if pixels.iter().any(|&i| skip[i as usize]) {
                continue;
            }
            let diff: f32 = pixels
                .iter()
                .map(|&i| luminance(a.pixels()[i as usize]) - luminance(b.pixels()[i as usize]))
                .sum::<f32>()
                / (B * B) as f32;
            worst = worst.max(diff.abs());
        }
    }
    worst / luminance(masked_mean(b, skip))
}

/// `frames` IGI frames of `frame` with seed `seed`, accumulated.
fn accumulate(
    renderer: &mut FrameRenderer,
    scene: &mut PreparedScene,
    frame: &FrameState,
    seed: u32,
    frames: u32,
) -> Film {
    let frame = FrameState { settings: FrameSettings { seed, ..frame.settings }, ..frame.clone() };
    renderer
        .render_accumulated(scene, &frame, frames, &|_, _| {})
        .expect("valid settings")
        .image
        .into_film()
        .unwrap()
}

#[test]
fn converged_igi_matches_the_path_tracer_and_the_default_clamp_loses_little() {
    let (mut scene, camera) = cornell();
    let mut renderer = FrameRenderer::new(2);
    let frame = cornell_frame(camera);
    let skip = light_pixels(&scene, &PinholeCamera::new(&camera, SIZE, SIZE));
    assert!((10..60).contains(&skip.iter().filter(|s| **s).count()), "the light covers a few dozen pixels");
    let (pt, _) = path_traced(&mut scene, &frame, SPP, 2);
    let mp = masked_mean(&pt, &skip);

    // Unclamped IGI is unbiased: its image mean must match the path tracer's. Its error is
    // heavy-tailed (module documentation): one VPL beside a crease can move the mean of 256
    // frames by 3 % (seed 0 since whole pixels are shaded once, 0.994-1.013 for seeds 1-7),
    // so the mean is judged robustly, as a median of means: four independent runs of 64
    // frames (seeds 1-4), the median per channel of their image means. Bound 2 %. Indirect
    // light is about 40 % of the reflected light here, so a lost bounce order or a wrong VPL
    // power fails by far.
    let mut runs: Vec<Vec3> = (1..=4)
        .map(|seed| masked_mean(&accumulate(&mut renderer, &mut scene, &frame, seed, FRAMES / 4), &skip))
        .collect();
    let median = Vec3::from_array(std::array::from_fn(|c| {
        runs.sort_by(|a, b| a[c].total_cmp(&b[c]));
        0.5 * (runs[1][c] + runs[2][c])
    }));
    eprintln!(
        "Cornell {SIZE}², IGI median of 4 × {} frames vs PT {SPP} spp (light pixels excluded): {median} / {mp} = {}",
        FRAMES / 4,
        median / mp
    );
    assert!(rel_err(median, mp) < 0.02, "IGI median of means {median}, path-traced mean {mp}");
    let igi = accumulate(&mut renderer, &mut scene, &frame, frame.settings.seed, FRAMES);
    let mi = masked_mean(&igi, &skip);

    // The default clamp d_min = 2 % of the scene diagonal (7 cm here) bounds the 1/d² spikes.
    // With the same seed the VPLs and samples are the same, so the clamped image can only be
    // darker, pixel by pixel (the filter weights do not depend on the light); the energy it
    // loses is the light of VPLs closer than d_min: 0.19-0.53 % over seeds 5-7 and 1.8 % for
    // seed 0, whose unclamped mean carries the spike named above; bound 2 %.
    let mut clamped = frame;
    clamped.settings.clamp = FrameSettings::clamp_for(scene.bounds().diagonal());
    assert!(clamped.settings.clamp > 0.05 && clamped.settings.clamp < 0.1, "{}", clamped.settings.clamp);
    let igi_clamped = renderer
        .render_accumulated(&mut scene, &clamped, FRAMES, &|_, _| {})
        .expect("valid settings")
        .image
        .into_film()
        .unwrap();
    let mc = masked_mean(&igi_clamped, &skip);
    let loss = 1.0 - luminance(mc) / luminance(mi);
    eprintln!("default clamp {}: energy lost {:.3} %", clamped.settings.clamp, 100.0 * loss);
    assert!(loss > 0.0 && loss < 0.02, "the clamp lost {loss} of the reflected light");
    for (c, u) in igi_clamped.pixels().iter().zip(igi.pixels()) {
        assert!(c.cmple(*u).all(), "clamping brightened a pixel: {c} > {u}");
    }

    // Pixel by pixel, on the clamped image (bounded variance; the unclamped one has blocks
    // 10-20 % off for some seeds from single spikes). Clamped mean: ratios 0.987-1.003 over
    // seeds 0-7 (the clamp's own 0.3-0.6 % loss included), bound 2.5 %. Mean absolute
    // difference: mostly noise of both estimators, 3.8-4.2 % of the mean over seeds 0-7,
    // bound 6 %. Worst 6 × 6 block (a local structural error, such as a wall lit wrongly or
    // missing colour bleeding, shows here even where the image means agree): 4.4-6.0 % over
    // seeds 0-7, bound 10 %.
    let mad = relative_mad(&igi_clamped, &pt, &skip);
    let block = worst_block(&igi_clamped, &pt, &skip);
    eprintln!("clamped IGI vs PT: mean ratio {}, relative MAD {mad}, worst block {block}", mc / mp);
    assert!(rel_err(mc, mp) < 0.025, "clamped IGI mean {mc}, path-traced mean {mp}");
    assert!(mad < 0.06, "mean absolute difference {mad} of the mean");
    assert!(block < 0.10, "worst block difference {block} of the mean");
}

#[test]
fn bias_compensation_restores_what_a_large_clamp_removes() {
    // A clamp of 0.3 (9 % of the box's diagonal) removes about 3 % of the light, most of it near
    // the creases and the contact shadows; the compensation rays must bring the image mean
    // back to the path tracer's. Both runs use the same VPLs (same seed and frames), so the
    // difference is the compensation alone.
    let (mut scene, camera) = cornell();
    let mut renderer = FrameRenderer::new(2);
    let mut frame = cornell_frame(camera);
    let skip = light_pixels(&scene, &PinholeCamera::new(&camera, SIZE, SIZE));
    let (pt, _) = path_traced(&mut scene, &frame, SPP, 2);
    let mp = luminance(masked_mean(&pt, &skip));
    frame.settings.clamp = 0.3;
    let mut mean = |compensate: bool| {
        frame.settings.compensate_clamp = compensate;
        let film = renderer
            .render_accumulated(&mut scene, &frame, 128, &|_, _| {})
            .expect("valid settings")
            .image
            .into_film()
            .unwrap();
        luminance(masked_mean(&film, &skip))
    };
    let (plain, compensated) = (mean(false), mean(true));
    eprintln!("path tracer {mp}, clamped {plain}, compensated {compensated}");
    // Measured (128 frames): the clamp alone loses 2.9 %, the compensated mean is within 0.1 %.
    assert!(plain < 0.985 * mp, "the clamp of 0.3 should lose more than 1.5 %: {plain} vs {mp}");
    assert!((compensated / mp - 1.0).abs() < 0.01, "compensated mean {compensated} vs {mp}");
}

/// Pixels of `film` (outside `skip`) brighter than twice the median of their 5 × 5
/// neighbourhood: the single bright pixels a one-ray estimate leaves when nothing averages it.
fn speckles(film: &igi_render::Film, skip: &[bool]) -> usize {
    let (w, h) = (film.width() as i64, film.height() as i64);
    let lum = |x: i64, y: i64| luminance(film.pixels()[(y * w + x) as usize]);
    let mut count = 0;
    for y in 2..h - 2 {
        for x in 2..w - 2 {
            if skip[(y * w + x) as usize] {
                continue;
            }
            let mut around: Vec<f32> = (-2..=2)
                .flat_map(|dy| (-2..=2).map(move |dx| (dx, dy)))
                .map(|(dx, dy)| lum(x + dx, y + dy))
                .collect();
            around.sort_by(f32::total_cmp);
            count += usize::from(lum(x, y) > 2.0 * around[12]);
        }
    }
    count
}

#[test]
fn bias_compensation_leaves_no_single_bright_pixels() {
    // The compensation's one short ray per pixel is as noisy as one VPL set; its light joins
    // D and is filtered with it. Added unfiltered, it left single bright pixels along the
    // creases and contacts of every accumulated image (`igi render --frames N` turns it on
    // with a clamp of 5 % of the diagonal): here at the statue's foot and the room's corners.
    let mut scene = PreparedScene::new(igi_scene::builtin("animated-room").unwrap());
    let camera = scene.views()[0].camera;
    let settings = FrameSettings {
        width: 320,
        height: 240,
        aa: 1,
        clamp: FrameSettings::compensated_clamp_for(scene.bounds().diagonal()),
        ..FrameSettings::default()
    };
    let frame = FrameState { reseed_per_frame: true, ..FrameState::new(camera, settings) };
    let mut renderer = FrameRenderer::new(2);
    let skip = light_pixels(&scene, &PinholeCamera::new(&camera, 320, 240));
    let mut count = |compensate_clamp: bool| {
        let frame =
            FrameState { settings: FrameSettings { compensate_clamp, ..frame.settings }, ..frame.clone() };
        let out = renderer.render_accumulated(&mut scene, &frame, 8, &|_, _| {}).expect("valid settings");
        speckles(&out.image.into_film().unwrap(), &skip)
    };
    let (plain, compensated) = (count(false), count(true));
    eprintln!("pixels over 2x their 5x5 median, 8 frames: {plain} clamped, {compensated} compensated");
    assert!(compensated <= plain + 5, "{compensated} speckles with the compensation against {plain} without");
}
