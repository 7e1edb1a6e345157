//! [`Session`]: one user's view of one scene. It turns [`Input`]s and the passing of time into
//! frames.
//!
//! Every frame recomputes the whole illumination (paper section 1). What a session adds is the
//! choice of frame: after any change (camera, settings, a moved object, the running clock) it
//! renders the instant one-frame solution with the frame's fixed VPL sets, so a moving scene
//! does not flicker; while nothing changes, it renders further frames with fresh VPL sets
//! and shows their running mean, which converges (progressive refinement).

use crate::camera_control::CameraController;
use crate::catalog::SceneCatalog;
use crate::input::{Button, CameraMode, Input, InputError};
use crate::light_control::{LightControl, LightKind};
use crate::refusals::quote_name;
use crate::selection::Selection;
use crate::settings::{MAX_ACCUMULATION, ViewerSettings};
use glam::{Affine3A, Vec3};
use igi_render::frame::{FrameSettings, SettingsError};
use igi_render::image::tonemap::LuminanceStats;
use igi_render::{
    CancelToken, Estimator, FrameError, FrameImage, FrameRenderer, FrameSource, FrameState, Motion, Phase,
    PinholeCamera, PixelFormat, PreparedScene, Progressive, ScenePose, Shown, SurfaceBuffer, TemporalHistory,
    start_camera,
};
use igi_scene::Camera;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// The most frames the history of a moving view stands for: each frame is then at least a
/// sixteenth of the image, so the history neither blurs nor lags for long
/// (ARCHITECTURE.md, "Temporal reuse while the view moves").
pub const MOVING_HISTORY: f32 = 15.0;

/// What a viewer shows beside a frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrameStats {
    /// Frame number of the session (1 for the first).
    pub id: u64,
    /// Inputs handled before this frame was rendered (see [`crate::RenderLoop::send`]).
    pub input_seq: u64,
    /// Scene clock, seconds.
    pub time: f32,
    /// Frames in the image's mean (1 right after a change; with temporal reuse the mean number
    /// of frames the pixels' history stands for).
    pub accumulated: u32,
    /// With temporal reuse, the share of pixels that kept their history in this frame: 0 at
    /// a cut (another scene, view, settings or light, the animation clock), below 1 where
    /// surfaces came into view or the light changed. `None` without temporal reuse.
    pub history_kept: Option<f64>,
    /// Render time of the frames in the image's mean, seconds.
    pub accumulated_seconds: f64,
    /// The image is the mean of as many frames as the settings' convergence target asks
    /// ([`ViewerSettings::converge_frames`], [`ViewerSettings::converge_seconds`]): nothing more
    /// is rendered until something changes.
    pub converged: bool,
    /// Wall time of this frame: posing the scene and rendering, ms.
    pub render_ms: f64,
    /// Frames per second of the session (a running average over the last frames).
    pub fps: f64,
    /// Wall time per phase, ms (thread time divided by the threads).
    pub phases_ms: Vec<(String, f64)>,
    /// Millions of rays per second of this frame.
    pub mrays_per_s: f64,
    /// VPLs of the frame.
    pub vpls: usize,
    /// Triangles in the scene.
    pub triangles: usize,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The selected object, its name and its outline on this frame.
    pub selected: Option<Selection>,
    /// The settings the frame was rendered with.
    pub settings: ViewerSettings,
    /// The camera mode.
    pub mode: CameraMode,
    /// The camera of the frame (the viewers' "save view" prints it as a scene-file snippet).
    pub camera: Camera,
    /// The names of the scene's views ([`Input::View`] picks one).
    pub views: Vec<String>,
    /// The name of the scene shown, as the viewer's list of scenes names it (none without
    /// a list).
    pub scene: Option<String>,
    /// The scene's light sources and their settings ([`Input::SelectLight`] and
    /// [`Input::EditLight`] name them by index).
    pub lights: Vec<LightControl>,
}

/// A frame to show.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Statistics.
    pub stats: FrameStats,
    /// The image: the display image, with the linear radiance (the mean of the accumulated
    /// frames, for EXR) unless a cluster sent the frame as 8-bit pixels.
    pub image: FrameImage,
}

/// How fast the fly camera starts in `scene`: 15 % of its diagonal per second.
fn fly_speed_for(scene: &PreparedScene) -> f32 {
    let diagonal = scene.bounds().diagonal();
    if diagonal.is_finite() && diagonal > 0.0 { 0.15 * diagonal } else { 1.0 }
}

/// What is selected, and the distance from the eye at which a drag moves it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Selected {
    /// An instance, picked in the image at this distance.
    Instance { instance: u32, distance: f32 },
    /// Light source `index` of the session's list (distance 0 for one without a position).
    Light { index: usize, distance: f32 },
}

impl Selected {
    /// What is selected, without the distance: a new selection if it differs.
    fn target(self) -> (bool, usize) {
        match self {
            Self::Instance { instance, .. } => (false, instance as usize),
            Self::Light { index, .. } => (true, index),
        }
    }
}

/// A scene, its camera, settings, clock and accumulation.
#[derive(Debug)]
pub struct Session {
    scene: PreparedScene,
    renderer: Box<dyn FrameSource>,
    controller: CameraController,
    home: Camera,
    fly_speed: f32,
    settings: ViewerSettings,
    progressive: Progressive,
    /// Render time of the frames in `progressive`, seconds.
    accumulated_seconds: f64,
    clock: f32,
    /// The selected object or light.
    selected: Option<Selected>,
    /// The scene's light sources and the user's changes to them.
    lights: Vec<LightControl>,
    /// World translations of instances the user moved.
    moved: BTreeMap<u32, Vec3>,
    /// The view changed since the last frame.
    changed: bool,
    /// The change was more than camera or object motion: the history cannot be reprojected.
    cut: bool,
    /// Temporal reuse: the running mean across motion.
    history: TemporalHistory,
    /// Frames since the last cut (the sample sequence's position with temporal reuse).
    since_cut: u32,
    /// Frames since the last change of any kind.
    since_change: u32,
    /// The selection changed since the last frame: the next frame shows it, and the mean
    /// goes on (what is rendered is the same).
    reselected: bool,
    inputs: u64,
    frames: u64,
    last_frame_end: Option<Instant>,
    fps: f64,
    /// The scenes the session may open, if any, and the name of the one shown.
    catalog: Option<(SceneCatalog, String)>,
}

impl Session {
    /// A session on `scene`, starting at `camera`, rendering with `threads` workers (0: one
    /// per core). The settings are checked.
    pub fn new(
        scene: PreparedScene,
        camera: Camera,
        settings: ViewerSettings,
        threads: usize,
    ) -> Result<Self, SettingsError> {
        Self::with_source(scene, camera, settings, Box::new(FrameRenderer::new(threads)))
    }

    /// A session whose frames `source` renders (a cluster, say). The settings are checked.
    pub fn with_source(
        scene: PreparedScene,
        camera: Camera,
        settings: ViewerSettings,
        source: Box<dyn FrameSource>,
    ) -> Result<Self, SettingsError> {
        settings.validate()?;
        let fly_speed = fly_speed_for(&scene);
        Ok(Self {
            renderer: source,
            controller: CameraController::new(&camera, fly_speed),
            home: camera,
            fly_speed,
            progressive: Progressive::new(settings.tone_map()),
            accumulated_seconds: 0.0,
            settings,
            clock: 0.0,
            selected: None,
            lights: LightControl::of(&scene),
            moved: BTreeMap::new(),
            changed: true,
            cut: true,
            history: TemporalHistory::new(),
            since_cut: 0,
            since_change: 0,
            reselected: false,
            inputs: 0,
            frames: 0,
            last_frame_end: None,
            fps: 0.0,
            catalog: None,
            scene,
        })
    }

    /// Lets the session open the scenes of `catalog` ([`Input::Open`]); `current` is the
    /// name of the scene it shows.
    pub fn set_catalog(&mut self, catalog: SceneCatalog, current: &str) {
        self.catalog = Some((catalog, current.to_string()));
    }

    /// The names of the scenes it may open (none without a catalog).
    pub fn scene_names(&self) -> &[String] {
        self.catalog.as_ref().map_or(&[], |(c, _)| c.names())
    }

    /// Shows `scene` instead, from its own start camera, with nothing moved or selected, its
    /// lights as loaded, the clock at 0 and the clamp distance the new scene's default; the
    /// other settings and the camera mode stay.
    fn replace_scene(&mut self, scene: PreparedScene) {
        let camera = start_camera(&scene);
        self.fly_speed = fly_speed_for(&scene);
        self.look_from(&camera, self.fly_speed);
        self.home = camera;
        self.settings.frame.clamp = FrameSettings::clamp_for(scene.bounds().diagonal());
        self.lights = LightControl::of(&scene);
        self.scene = scene;
        self.moved.clear();
        self.selected = None;
        self.clock = 0.0;
        self.cut_here();
    }

    /// Marks a change the history cannot follow (another scene, view, settings or light).
    fn cut_here(&mut self) {
        self.changed = true;
        self.cut = true;
    }

    /// Moves the camera to `camera` with fly speed `speed`, in the same camera mode.
    fn look_from(&mut self, camera: &Camera, speed: f32) {
        let mode = self.controller.mode();
        self.controller = CameraController::new(camera, speed);
        self.controller.handle(&Input::Mode { mode }, self.settings.frame.height);
    }

    /// The current settings.
    pub fn settings(&self) -> &ViewerSettings {
        &self.settings
    }

    /// The camera controller.
    pub fn camera(&self) -> &CameraController {
        &self.controller
    }

    /// The prepared scene.
    pub fn scene(&self) -> &PreparedScene {
        &self.scene
    }

    /// Scene clock, seconds.
    pub fn clock(&self) -> f32 {
        self.clock
    }

    /// Sets the scene clock (a viewer's time slider, or a test).
    pub fn set_clock(&mut self, t: f32) {
        if t.is_finite() && t >= 0.0 && t != self.clock {
            self.clock = t;
            self.cut_here();
        }
    }

    /// Inputs handled so far.
    pub fn inputs_handled(&self) -> u64 {
        self.inputs
    }

    /// True if the clock runs on a scene that has an animation.
    pub fn is_animating(&self) -> bool {
        self.settings.playing && self.settings.speed > 0.0 && !self.scene.animation().is_empty()
    }

    /// True if the next frame would show something new: a change is pending, something moves,
    /// or the accumulation has not converged.
    pub fn needs_frame(&self) -> bool {
        self.changed
            || self.reselected
            || self.is_animating()
            || self.controller.is_moving()
            || (self.settings.accumulate && !self.converged())
    }

    /// True once a still view has accumulated the frames, or the render time, its settings
    /// ask for.
    fn converged(&self) -> bool {
        let s = &self.settings;
        let frames = self.accumulated();
        frames >= s.converge_frames.min(MAX_ACCUMULATION)
            || (s.converge_seconds > 0.0
                && frames > 0
                && self.accumulated_seconds >= f64::from(s.converge_seconds))
    }

    /// Frames averaged since the view last changed.
    fn accumulated(&self) -> u32 {
        match self.settings.temporal {
            true => self.since_change,
            false => self.progressive.frames(),
        }
    }

    /// Counts an input the caller chose not to apply (an open that a later one replaces), so
    /// that the next frame's [`FrameStats::input_seq`] still includes it.
    pub fn pass_over(&mut self) {
        self.inputs += 1;
    }

    /// Applies an input. An input it cannot apply (invalid settings, a view or light the scene
    /// does not have, a scene that does not open) is refused with the reason and changes
    /// nothing.
    pub fn handle(&mut self, input: &Input) -> Result<(), InputError> {
        self.inputs += 1;
        if self.controller.handle(input, self.settings.frame.height) {
            self.changed = true;
        }
        match input {
            Input::Settings { settings } => {
                settings.validate()?;
                if *settings != self.settings {
                    self.settings = settings.clone();
                    self.progressive.set_tone_map(settings.tone_map());
                    self.cut_here();
                }
            }
            Input::Pick { x, y } => self.pick(*x, *y),
            Input::Drag { dx, dy, button: Button::Secondary } => self.drag_selected(*dx, *dy),
            Input::View { name } => {
                let Some(view) = self.scene.views().iter().find(|v| &v.name == name) else {
                    return Err(InputError::NoView(quote_name(name)));
                };
                let (camera, speed) = (view.camera, self.controller.speed());
                self.look_from(&camera, speed);
                self.cut_here();
            }
            Input::SelectLight { index } => {
                let light = self.lights.get(*index).ok_or_else(|| self.no_light(*index))?;
                let eye = self.controller.camera().position;
                let distance = light.position(&self.scene).map_or(0.0, |p| (p - eye).length());
                self.select(Some(Selected::Light { index: *index, distance }));
            }
            Input::EditLight { index, intensity, colour } => {
                let no_light = self.no_light(*index);
                let light = self.lights.get_mut(*index).ok_or(no_light)?;
                let before = (light.intensity, light.colour);
                light.set(*intensity, *colour).map_err(InputError::Light)?;
                if before != (light.intensity, light.colour) {
                    self.cut_here();
                }
            }
            Input::Open { name } => {
                let (catalog, current) = self.catalog.as_mut().ok_or_else(|| {
                    InputError::Open(
                        "this viewer opens no other scenes (a cluster's nodes hold theirs)".into(),
                    )
                })?;
                let scene = catalog.open(name).map_err(InputError::Open)?;
                name.clone_into(current);
                self.replace_scene(scene);
            }
            Input::Reset => {
                self.controller = CameraController::new(&self.home, self.fly_speed);
                self.moved.clear();
                self.lights = LightControl::of(&self.scene);
                self.selected = None;
                self.cut_here();
            }
            _ => {}
        }
        Ok(())
    }

    /// Selects the instance seen at pixel (x, y), or nothing.
    fn pick(&mut self, x: f32, y: f32) {
        let s = &self.settings;
        if !(x.is_finite()
            && y.is_finite()
            && x >= 0.0
            && y >= 0.0
            && x < s.frame.width as f32
            && y < s.frame.height as f32)
        {
            self.select(None);
            return;
        }
        let camera = PinholeCamera::new(&self.controller.camera(), s.frame.width, s.frame.height);
        let ray = camera.ray_at(x as u32, y as u32, x.fract(), y.fract());
        let hit = self.scene.accel().intersect(&ray);
        self.select(
            hit.t
                .is_finite()
                .then(|| Selected::Instance { instance: hit.instance, distance: hit.t * ray.dir.length() }),
        );
    }

    /// Selects `selected`, or nothing.
    fn select(&mut self, selected: Option<Selected>) {
        self.reselected |= selected.map(Selected::target) != self.selected.map(Selected::target);
        self.selected = selected;
    }

    /// The error for a light index the scene does not have.
    fn no_light(&self, index: usize) -> InputError {
        InputError::NoLight { index, count: self.lights.len() }
    }

    /// Moves the selection by a drag of (dx, dy) pixels: an object, or a point or spot
    /// light, in the view plane at the depth it was picked (so it follows the pointer); a
    /// sun turns, a full turn per image height as the orbit camera (about +Y for dx, about
    /// the view's horizontal axis for dy). An emissive material moves with its object.
    fn drag_selected(&mut self, dx: f32, dy: f32) {
        let Some(selected) = self.selected else { return };
        if !(dx.is_finite() && dy.is_finite()) {
            return;
        }
        let s = &self.settings;
        let camera = PinholeCamera::new(&self.controller.camera(), s.frame.width, s.frame.height);
        let in_view_plane = |distance: f32| {
            // One pixel spans 2·tan(fov/2)·distance / height at that distance.
            let per_pixel = 2.0 * camera.tan_half * distance / s.frame.height as f32;
            Some((camera.right * dx - camera.up * dy) * per_pixel)
                .filter(|o| o.is_finite() && *o != Vec3::ZERO)
        };
        // Each step is finite, but steps add up: a move that would take an object or a light
        // beyond the coordinates a scene may have (where 32-bit floats no longer hold its
        // distances, and repeated drags of 3.4e38 pixels made it vanish) is refused.
        let within = |p: Vec3| p.is_finite() && p.abs().max_element() <= igi_scene::MAX_COORDINATE;
        match selected {
            Selected::Instance { instance, distance } => {
                if let Some(offset) = in_view_plane(distance) {
                    let moved = self.moved.get(&instance).copied().unwrap_or(Vec3::ZERO) + offset;
                    if within(moved) {
                        self.moved.insert(instance, moved);
                        self.changed = true;
                    }
                }
            }
            Selected::Light { index, distance } => {
                let light = &mut self.lights[index];
                let step = match light.kind {
                    LightKind::Point => in_view_plane(distance).map(Affine3A::from_translation),
                    LightKind::Sun => {
                        let turn = std::f32::consts::TAU / s.frame.height as f32;
                        let about_up = glam::Quat::from_rotation_y(dx * turn);
                        let about_right = glam::Quat::from_axis_angle(camera.right, dy * turn);
                        Some(Affine3A::from_quat(about_up * about_right))
                    }
                    LightKind::Emissive => None,
                };
                if let Some(step) = step {
                    let transform = step * light.transform;
                    if within(transform.translation.into()) && transform.matrix3.is_finite() {
                        light.transform = transform;
                        self.cut_here();
                    }
                }
            }
        }
    }

    /// Renders the next frame, `dt` seconds of wall-clock time after the previous one (the
    /// clock and held keys advance by it).
    pub fn render(&mut self, dt: f32) -> Result<Frame, FrameError> {
        self.render_cancellable(dt, &CancelToken::new())
    }

    /// [`Session::render`], unless `cancel` stops the frame between tiles: then the error is
    /// [`FrameError::Cancelled`], nothing is accumulated, and the next frame is rendered as
    /// if this one had never started (the clock and held keys have still moved on).
    pub fn render_cancellable(&mut self, dt: f32, cancel: &CancelToken) -> Result<Frame, FrameError> {
        let start = Instant::now();
        let dt = if dt.is_finite() { dt.clamp(0.0, 0.25) } else { 0.0 };
        if self.is_animating() {
            // Animated lights move with the clock: their light must show at once.
            self.clock += dt * self.settings.speed;
            self.cut_here();
        }
        if self.controller.advance(dt) {
            self.changed = true;
        }
        let changed = std::mem::take(&mut self.changed);
        let cut = std::mem::take(&mut self.cut) || !self.settings.temporal;
        let reselected = std::mem::take(&mut self.reselected);
        let temporal = self.settings.temporal;
        if changed {
            self.progressive.reset();
            self.accumulated_seconds = 0.0;
        }
        let (since_cut, since_change) = match (cut, changed) {
            (true, _) => (0, 0),
            (false, true) => (self.since_cut, 0),
            (false, false) => (self.since_cut, self.since_change),
        };

        // Linear radiance where it is averaged: a cluster sends 8-bit pixels otherwise.
        let averaged = (self.settings.accumulate && !changed) || temporal;
        // A still view's frames after the first of its mean are still images, by the rule of
        // `igi render --frames N`: the clamp's bias is compensated, so the mean converges to
        // the unclamped solution, and the scene's default clamp (not one the user chose)
        // becomes the larger clamp of compensation, which keeps the VPLs' near-field spots
        // out of the mean (ARCHITECTURE.md, "Still images are bias-compensated"). The first
        // frame of a mean is the moving frame shown at once after a change, which keeps the
        // speed; on a cluster, whose moving frames come as 8-bit pixels outside the mean, the
        // mean's first frame is thereby the same as a local session's.
        let still = match temporal {
            true => !changed && since_cut > 0,
            false => self.progressive.frames() > 0,
        };
        let settings = match self.settings.accumulate && still {
            true => {
                let diagonal = self.scene.bounds().diagonal();
                let default_clamp = self.settings.frame.clamp == FrameSettings::clamp_for(diagonal);
                self.settings.frame.still_image(default_clamp.then_some(diagonal))
            }
            false => self.settings.frame,
        };
        let frame = FrameState {
            camera: self.controller.camera(),
            settings,
            // The path tracer: one path per pixel and frame, averaged like IGI frames.
            estimator: match self.settings.path_tracer {
                true => Estimator::PathTracer { spp: 1 },
                false => Estimator::Igi,
            },
            pose: ScenePose {
                sky: self.settings.sky,
                time: self.clock,
                moved: self.moved.iter().map(|(&i, &v)| (i, Affine3A::from_translation(v))).collect(),
                lights: self.lights.iter().filter_map(LightControl::edit).collect(),
            },
            tone_map: self.progressive.tone_mapper(),
            // Temporal reuse carries the diffuse light across a move and takes the rest
            // from each frame ([`igi_render::DiffuseLayer`]).
            pixels: if temporal {
                PixelFormat::Layered
            } else if self.renderer.prefers_srgb8() && !averaged {
                PixelFormat::Srgb8
            } else {
                PixelFormat::Linear
            },
            // With temporal reuse every frame after a cut brings fresh VPLs and samples (the
            // history averages their independent errors); without, a moving view keeps the
            // samples of its first frame, so it does not flicker.
            number: if temporal { since_cut } else { self.progressive.frames() },
            reseed_per_frame: self.settings.accumulate || temporal,
        };
        let out = match self.renderer.render_frame(&mut self.scene, &frame, cancel, &|_, _| {}) {
            Ok(out) => out,
            Err(e) => {
                // The change still has to be shown.
                self.changed |= changed;
                self.cut |= cut;
                self.reselected |= reselected;
                return Err(e);
            }
        };
        if cut {
            self.history.clear();
        }
        (self.since_cut, self.since_change) = (since_cut + 1, since_change + 1);
        let history_kept = match (temporal, out.image.film()) {
            (true, Some(film)) => {
                // After the render the scene stands in the frame's pose.
                let motion = match changed {
                    true => Motion::Moved(SurfaceBuffer::trace(
                        &self.scene,
                        PinholeCamera::new(&frame.camera, settings.width, settings.height),
                    )),
                    false => Motion::Still,
                };
                let limit = if changed { MOVING_HISTORY } else { f32::INFINITY };
                let mean = self.history.add(film, out.image.diffuse_layer(), motion, limit);
                let stats = LuminanceStats::of_pixels(mean.pixels());
                self.progressive.reset();
                self.progressive.add(FrameImage::from_film(mean, &frame.tone_map), stats);
                Some(self.history.kept())
            }
            _ => {
                self.progressive.add(out.image, out.stats);
                None
            }
        };
        let Shown { image, .. } = self.progressive.show();

        let elapsed = start.elapsed().as_secs_f64();
        self.accumulated_seconds += elapsed;
        let now = Instant::now();
        if let Some(last) = self.last_frame_end.replace(now) {
            let interval = now.duration_since(last).as_secs_f64().max(1e-6);
            self.fps = if self.fps == 0.0 { 1.0 / interval } else { 0.9 * self.fps + 0.1 / interval };
        }
        self.frames += 1;
        let threads = self.renderer.threads() as f64;
        let phases_ms = Phase::ALL
            .iter()
            .map(|&p| {
                let scale = if p == Phase::VplGeneration { 1.0 } else { 1.0 / threads };
                (p.name().to_string(), out.times.get(p).as_secs_f64() * 1e3 * scale)
            })
            .collect();
        let stats = FrameStats {
            id: self.frames,
            input_seq: self.inputs,
            time: self.clock,
            accumulated: match history_kept {
                Some(_) => self.history.mean_frames().round().max(1.0) as u32,
                None => self.progressive.frames().max(1),
            },
            history_kept,
            accumulated_seconds: self.accumulated_seconds,
            converged: self.settings.accumulate && !self.needs_frame(),
            render_ms: elapsed * 1e3,
            fps: self.fps,
            phases_ms,
            mrays_per_s: out.rays.total() as f64 * 1e-6 / elapsed.max(1e-9),
            vpls: out.vpls,
            triangles: self.scene.triangle_count(),
            width: settings.width,
            height: settings.height,
            // After the render the scene stands in the frame's pose.
            selected: self.selected.map(|selected| {
                let camera = PinholeCamera::new(&frame.camera, settings.width, settings.height);
                match selected {
                    Selected::Instance { instance, .. } => {
                        Selection::of_instance(&self.scene, instance, &camera)
                    }
                    Selected::Light { index, .. } => {
                        Selection::of_light(&self.scene, &self.lights, index, &camera)
                    }
                }
            }),
            settings: self.settings.clone(),
            mode: self.controller.mode(),
            camera: self.controller.camera(),
            views: self.scene.views().iter().map(|v| v.name.clone()).collect(),
            lights: self.lights.clone(),
            scene: self.catalog.as_ref().map(|(_, name)| name.clone()),
        };
        Ok(Frame { stats, image })
    }
}
