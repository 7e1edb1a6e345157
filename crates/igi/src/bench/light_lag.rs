//! `igi bench quality --lag T`: how many frames a viewer takes to show a change of the light.
//! The scene's animation moves its lights between `--time` and `--time` + T seconds; a
//! viewer's session (its defaults, temporal reuse on) shows the view still at the first time
//! until it has converged, then its clock jumps to the second. For every pixel whose converged
//! luminance changes by more than a tenth of the image's mean, the share of that change a frame
//! shows is (L_k − L_A)/(L_B − L_A), with A and B the converged images of the two times; the
//! lag is the first frame after the jump whose mean share over those pixels reaches 90 %.

use crate::frame_args::FrameArgs;
use anyhow::{Context, Result, bail};
use igi_render::image::tonemap::luminance;
use igi_render::{Film, FrameRenderer, FrameSource, FrameState, ScenePose};
use igi_session::{Session, ViewerSettings};
use serde::Serialize;

/// Frames measured after the jump; a lag beyond it is reported as `None`.
const FRAMES_AFTER: u32 = 16;

/// The frame number the references start at: far from the measured frames' samples.
const REFERENCE_FIRST_FRAME: u32 = 1 << 26;

/// The lag of a change of the light.
#[derive(Debug, Serialize)]
pub struct LagReport {
    /// Seconds of scene time between the two poses.
    pub seconds: f32,
    /// Pixels whose converged luminance changes by more than a tenth of the mean.
    pub changed_pixels: usize,
    /// Mean share of the change each frame after the jump shows, frame 1 first.
    pub shares: Vec<f64>,
    /// The first frame whose mean share reaches 90 % (1: the frame of the change itself).
    pub lag_frames: Option<u32>,
}

/// Measures the lag of the change between `args`' time and `seconds` later.
pub fn measure(args: &FrameArgs, scene_name: &str, seconds: f32, reference_frames: u32) -> Result<LagReport> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 1e6) {
        bail!("--lag must be a positive number of seconds");
    }
    let load =
        || -> Result<_> { Ok(args.prepare(igi_scene::load_named(scene_name).context("cannot load scene")?)) };
    let mut scene = load()?;
    if scene.animation().is_empty() {
        bail!("--lag needs a scene with an animation (its lights move over time)");
    }
    let first = args.frame_state(&scene)?;
    let settings = ViewerSettings {
        frame: igi_render::FrameSettings { aa: args.aa.unwrap_or(1), ..first.settings },
        playing: false,
        ..ViewerSettings::for_scene(scene.bounds().diagonal())
    };
    let (t0, t1) = (first.pose.time, first.pose.time + seconds);
    let mut renderer = FrameRenderer::new(args.threads);
    let mut converged = |time: f32| -> Result<Vec<f32>> {
        // As `igi render --frames N` would make it (see `FrameArgs::still_image`).
        let mut frame = FrameState::new(first.camera, settings.frame);
        args.still_image(&mut frame, &scene);
        frame.pose = ScenePose::at(time);
        frame.number = REFERENCE_FIRST_FRAME;
        let film = renderer.render_accumulated(&mut scene, &frame, reference_frames, &|_, _| {})?;
        Ok(luminances(&film.image.into_film().context("a reference without its radiance")?))
    };
    let (a, b) = (converged(t0)?, converged(t1)?);
    let mean = b.iter().map(|&l| f64::from(l)).sum::<f64>() / b.len().max(1) as f64;
    let changed: Vec<usize> = (0..a.len()).filter(|&i| f64::from((b[i] - a[i]).abs()) > 0.1 * mean).collect();
    if changed.is_empty() {
        bail!("the light changes nothing visible between {t0} s and {t1} s");
    }

    let mut session = Session::new(load()?, first.camera, settings.clone(), args.threads)?;
    session.set_clock(t0);
    while !session.render(0.0)?.stats.converged {}
    session.set_clock(t1);
    let mut shares = Vec::new();
    for _ in 0..FRAMES_AFTER {
        let frame = session.render(0.0)?;
        let l = luminances(frame.image.film().context("a viewer's frame without its radiance")?);
        let share =
            changed.iter().map(|&i| f64::from((l[i] - a[i]) / (b[i] - a[i])).clamp(-1.0, 2.0)).sum::<f64>()
                / changed.len() as f64;
        shares.push(share);
    }
    let lag_frames = shares.iter().position(|&s| s >= 0.9).map(|k| k as u32 + 1);
    Ok(LagReport { seconds, changed_pixels: changed.len(), shares, lag_frames })
}

fn luminances(film: &Film) -> Vec<f32> {
    film.pixels().iter().map(|&p| luminance(p)).collect()
}
