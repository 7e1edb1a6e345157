//! `igi bench quality --orbit N`: the error of what a viewer shows while the camera moves.
//! The camera orbits the view's target (or the point `--orbit-distance` ahead of it) by
//! `--orbit-degrees` per frame; a viewer's session (its
//! defaults: one primary ray per pixel, the frame settings of the command line) renders N frames
//! as it would while dragging, with temporal reuse and without; each frame from
//! `--orbit-from` on is measured (mean FLIP, blotch10) against the converged image of its own
//! view, the mean of `--view-reference-frames` compensated frames on samples the measured
//! frames do not use.

use super::quality::{Figures, display};
use crate::frame_args::FrameArgs;
use anyhow::{Context, Result, bail};
use igi_render::{Film, FrameRenderer, FrameSource, FrameState};
use igi_session::{Button, CameraMode, Input, Session, ViewerSettings};
use serde::Serialize;

/// The orbit's options.
#[derive(Clone, Copy, Debug)]
pub struct Orbit {
    /// Frames rendered.
    pub frames: u32,
    /// Degrees the camera turns about the target per frame.
    pub degrees: f32,
    /// The first frame measured (1-based): the history needs a few frames to build up.
    pub from: u32,
    /// Frames averaged for each view's converged image.
    pub reference_frames: u32,
    /// The distance of the point orbited, along the view direction; `None`: the camera's
    /// target.
    pub distance: Option<f32>,
}

/// The figures of an orbit, each the mean over the measured frames.
#[derive(Debug, Serialize)]
pub struct OrbitReport {
    /// Degrees per frame.
    pub degrees: f32,
    /// The measured frames, 1-based and inclusive.
    pub measured: [u32; 2],
    /// Frames as a viewer shows them with temporal reuse.
    pub temporal: OrbitFigures,
    /// The same frames without it (each frame on its own).
    pub single: OrbitFigures,
}

/// Mean figures of the measured frames of one way of showing them.
#[derive(Debug, Serialize)]
pub struct OrbitFigures {
    /// Mean of the frames' mean FLIP.
    pub flip: f64,
    /// Mean of the frames' blotch10.
    pub blotch10: f64,
    /// Mean time a viewer took per frame (render, history, display image), ms.
    pub frame_ms: f64,
    /// Mean share of pixels that kept their history (0 without temporal reuse).
    pub history_kept: f64,
    /// The least share of any measured frame: near 0 where the eye passed through a wall or
    /// the view turned to something new, which no history can help.
    pub history_kept_least: f64,
}

/// The frame number the references start at: far from the measured frames' samples.
const REFERENCE_FIRST_FRAME: u32 = 1 << 25;

/// Measures the orbit of `orbit` from the camera and settings of `args` in `scene`.
pub fn measure(args: &FrameArgs, scene_name: &str, orbit: Orbit) -> Result<OrbitReport> {
    if !(2..=10_000).contains(&orbit.frames) || !(1..=orbit.frames).contains(&orbit.from) {
        bail!("--orbit must be between 2 and 10000 frames, and --orbit-from at most --orbit");
    }
    if !(orbit.degrees.is_finite() && orbit.degrees.abs() <= 180.0) {
        bail!("--orbit-degrees must be between -180 and 180");
    }
    if !(1..=100_000).contains(&orbit.reference_frames) {
        bail!("--view-reference-frames must be between 1 and 100000");
    }
    let load =
        || -> Result<_> { Ok(args.prepare(igi_scene::load_named(scene_name).context("cannot load scene")?)) };
    let mut reference_scene = load()?;
    let mut first = args.frame_state(&reference_scene)?;
    if let Some(d) = orbit.distance {
        if !(d.is_finite() && d > 0.0) {
            bail!("--orbit-distance must be a positive distance");
        }
        let c = &mut first.camera;
        c.target = c.position + (c.target - c.position).normalize() * d;
    }
    let mut renderer = FrameRenderer::new(args.threads);
    let mut references: Vec<Film> = Vec::new();
    let mut run = |temporal: bool| -> Result<OrbitFigures> {
        let scene = load()?;
        let settings = ViewerSettings {
            frame: igi_render::FrameSettings { aa: args.aa.unwrap_or(1), ..first.settings },
            temporal,
            playing: false,
            ..ViewerSettings::for_scene(scene.bounds().diagonal())
        };
        let height = settings.frame.height;
        let mut session = Session::new(scene, first.camera, settings.clone(), args.threads)?;
        session.handle(&Input::Mode { mode: CameraMode::Orbit })?;
        let (mut flip, mut blotch, mut ms, mut kept, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let mut least: f64 = 1.0;
        for k in 1..=orbit.frames {
            // A drag over the image's height turns the orbit once around.
            let dx = orbit.degrees / 360.0 * height as f32;
            session.handle(&Input::Drag { dx, dy: 0.0, button: Button::Primary })?;
            let frame = session.render(0.2)?;
            if k < orbit.from {
                continue;
            }
            let film = frame.image.film().context("a viewer's frame without its radiance")?;
            // The converged image of this frame's view (both runs turn the camera alike).
            let at = (k - orbit.from) as usize;
            if references.len() == at {
                // Compensated frames, with the larger clamp of compensation unless `--clamp`
                // was given: the reference `igi render --frames N` would make of this view.
                let mut view = FrameState::new(frame.stats.camera, settings.frame);
                args.still_image(&mut view, &reference_scene);
                view.number = REFERENCE_FIRST_FRAME;
                let reference = renderer
                    .render_accumulated(&mut reference_scene, &view, orbit.reference_frames, &|_, _| {})?
                    .image
                    .into_film()
                    .context("a reference without its radiance")?;
                // A view of nothing (the eye left the scene, or stands in a wall) measures
                // nothing: every image of it is black.
                let lit = reference.pixels().iter().filter(|p| p.max_element() > 0.0).count();
                if lit * 20 < reference.pixels().len() {
                    bail!(
                        "frame {k} of the orbit sees almost nothing ({lit} lit pixels): the eye left the \
                         scene; orbit a nearer point (--orbit-distance) or turn the other way"
                    );
                }
                references.push(reference);
            }
            let reference = &references[at];
            let tone_map = settings.frame.tone_map();
            let figures = Figures::of(
                (reference, &display(reference, tone_map)),
                film,
                tone_map,
                frame.stats.accumulated,
                0.0,
            );
            flip += figures.flip;
            blotch += figures.blotch10;
            ms += frame.stats.render_ms;
            kept += frame.stats.history_kept.unwrap_or(0.0);
            least = least.min(frame.stats.history_kept.unwrap_or(0.0));
            n += 1.0;
        }
        Ok(OrbitFigures {
            flip: flip / n,
            blotch10: blotch / n,
            frame_ms: ms / n,
            history_kept: kept / n,
            history_kept_least: least,
        })
    };
    let temporal = run(true)?;
    let single = run(false)?;
    Ok(OrbitReport { degrees: orbit.degrees, measured: [orbit.from, orbit.frames], temporal, single })
}
