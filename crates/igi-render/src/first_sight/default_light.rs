//! [`DefaultLight`]: the light igi adds so that a scene shows on the first command when its
//! own lights cannot show it: a scene with no light at all, or one whose emitters light
//! nothing the camera sees (Lost Empire's lava burns inside its hill, and the torches of its
//! MTL file have their `Ke` commented out, so its outside is black in every pixel).
//!
//! Which light depends on where the camera stands. Where rays from the camera escape the
//! scene (an object in the open, or Sponza's atrium under its roof opening), a sun over the
//! camera's left shoulder and a sky, as an outdoor photograph would have; where geometry
//! encloses the camera (Sibenik's nave, the conference room), lamps under the ceiling of the
//! space it looks into ([`ceiling_lights`](mod@crate::first_sight::ceiling_lights)), as a
//! room in use is lit; only where no ceiling stands above the view, the headlight at the
//! camera, which goes where the viewer goes. The caller says what was added in one warning
//! ([`DefaultLight::warning`]) naming the flag that turns it off.
//!
//! The decision is made from the camera the user asked for (`--camera-*`, `--view`), else the
//! one the scene starts with: a hill seen from outside needs a sun though the scene's own
//! camera stands in a cave its lava lights.
//!
//! Whether the scene's own lights show it is judged on the picture: a small pilot frame,
//! tone-mapped as `igi render` does, must show at least [`READABLE_SHARE`] of its pixels of
//! geometry readably. The pilot is deterministic (fixed probe rays, the frame's own VPL
//! sequence, the same image at any thread count), so every node of a cluster comes to the
//! same decision from the same scene.

use crate::camera::PinholeCamera;
use crate::first_sight::ceiling_lights::ceiling_lights;
use crate::first_sight::daylight_sky::daylight_sky;
use crate::first_sight::start_camera::start_camera;
use crate::frame::{FrameSettings, FrameState};
use crate::image::tonemap::luminance;
use crate::image::tonemap::{ToneMap, ToneMapper};
use crate::prepared::PreparedScene;
use crate::prepared::lights::EmissiveTriangle;
use crate::sampling::fibonacci_sphere;
use crate::schedule::frame_renderer::FrameRenderer;
use glam::{Vec2, Vec3};
use igi_bvh::Ray;
use igi_scene::{Camera, Light};
use std::collections::HashMap;

/// Width of the pilot frame that tests whether the scene's lights show the view (4:3).
const PILOT_WIDTH: u32 = 96;
/// A pixel is readable at this display-linear luminance (sRGB 40 of 255) or brighter.
const READABLE: f32 = 0.02;
/// The view counts as shown when at least this share of the pixels of geometry is readable.
const READABLE_SHARE: f32 = 0.5;
/// A pixel whose own emission makes at least this share of its radiance shows an emitter,
/// not a surface lit.
const GLOWING: f32 = 0.5;
/// Rays from the camera in all directions that tell open scenes from enclosed ones.
const OPENNESS_PROBES: u32 = 256;
/// A camera from which at least this share of [`OPENNESS_PROBES`] escapes stands in the
/// open (Sponza's roof opening passes about 3 % from its courtyard).
const OPEN_SHARE: f32 = 0.01;
/// The default sun's elevation above the horizon (degrees).
const SUN_ELEVATION: f32 = 55.0;
/// The sun's azimuth away from straight behind the camera, toward its left (degrees): light
/// from the side shows shapes, light from behind the camera flattens them.
const SUN_AZIMUTH: f32 = 55.0;
/// The default sun's irradiance (slightly warm white): with the [`daylight_sky`], 23 % of the
/// light on an open horizontal surface comes from the sky (25 % from the constant sky it
/// replaced), and an object seen against the sky is not underexposed.
const SUN_IRRADIANCE: Vec3 = Vec3::new(3.5, 3.3, 3.0);

/// A light igi adds to a scene that cannot show itself.
#[derive(Clone, Debug, PartialEq)]
pub enum DefaultLight {
    /// A directional sun and the [`daylight_sky`], for a camera in the open.
    SunAndSky {
        /// The unit direction the sun's light travels in.
        direction: Vec3,
        /// The sun's irradiance on a surface facing it.
        irradiance: Vec3,
    },
    /// Lamps under the ceiling of the space an enclosed camera looks into
    /// ([`ceiling_lights`]).
    CeilingLamps(Vec<Light>),
    /// The headlight at the camera ([`crate::prepared::lights::eye_light`]), for an enclosed
    /// camera with no ceiling above its view.
    Headlight,
}

impl DefaultLight {
    /// The light to add to `scene` seen from `camera`, or `None` if the scene's own lights
    /// show what the camera sees.
    pub fn choose(scene: &mut PreparedScene, camera: &Camera) -> Option<Self> {
        if scene.has_lights() && readable_share(scene, camera) >= READABLE_SHARE {
            return None;
        }
        if is_open(scene, camera.position) {
            return Some(Self::sun_and_sky(camera));
        }
        let lamps = ceiling_lights(scene, camera);
        Some(if lamps.is_empty() { Self::Headlight } else { Self::CeilingLamps(lamps) })
    }

    /// A sun over the left shoulder of `camera` and the default sky.
    fn sun_and_sky(camera: &Camera) -> Self {
        let forward = camera.target - camera.position;
        let back = Vec3::new(-forward.x, 0.0, -forward.z).try_normalize().unwrap_or(Vec3::Z);
        let left = Vec3::Y.cross(back);
        let (elevation, azimuth) = (SUN_ELEVATION.to_radians(), SUN_AZIMUTH.to_radians());
        let horizontal = back * azimuth.cos() + left * azimuth.sin();
        let toward_sun = horizontal * elevation.cos() + Vec3::Y * elevation.sin();
        Self::SunAndSky { direction: -toward_sun, irradiance: SUN_IRRADIANCE }
    }

    /// The punctual lights this light brings: the sun, or the lamps.
    pub fn lights(&self) -> Vec<Light> {
        match self {
            &Self::SunAndSky { direction, irradiance } => vec![Light::Directional { direction, irradiance }],
            Self::CeilingLamps(lamps) => lamps.clone(),
            Self::Headlight => Vec::new(),
        }
    }

    /// Lights `scene` with this light besides its own lights: a sun or lamps join the
    /// punctual lights and the daylight sky becomes the environment (a scene with a sky has
    /// lights of its own, so none is replaced); the headlight is on for
    /// [`DefaultLight::Headlight`] only.
    pub fn add_to(&self, scene: &mut PreparedScene) {
        scene.set_headlight(*self == Self::Headlight);
        for light in self.lights() {
            scene.add_light(light);
        }
        if let Self::SunAndSky { .. } = self {
            scene.set_sky_image(daylight_sky());
        }
    }

    /// The one warning that says what was added, why, and how to turn it off; `had_lights`
    /// tells whether the scene had lights of its own.
    pub fn warning(&self, had_lights: bool) -> String {
        let why = if had_lights {
            "the scene's lights reach little of what the camera sees"
        } else {
            "the scene has no light source"
        };
        let what = match self {
            Self::SunAndSky { .. } => "added a sun and a sky".to_owned(),
            Self::CeilingLamps(lamps) => format!("added {} lamps under the ceiling", lamps.len()),
            Self::Headlight => "added a light at the camera".to_owned(),
        };
        format!("{why}: {what} (--no-default-light turns this off)")
    }
}

/// Fixes the camera `scene` starts with ([`start_camera`], so that it is chosen once),
/// decides its default light seen from `view` (the camera the user asked for) or, without
/// one, from the start camera, and adds it; returns the warning to show, or `None` if the
/// scene's own lights serve. With `enabled` false nothing is added, and a scene without
/// lights stays dark (no headlight either), which the warning says.
pub fn add_default_light(scene: &mut PreparedScene, enabled: bool, view: Option<&Camera>) -> Option<String> {
    let start = start_camera(scene);
    scene.set_camera(start);
    let camera = view.copied().unwrap_or(start);
    if !enabled {
        scene.set_headlight(false);
        return (!scene.has_lights())
            .then(|| "the scene has no light source and --no-default-light leaves it dark".to_owned());
    }
    let had_lights = scene.has_lights();
    let light = DefaultLight::choose(scene, &camera);
    scene.set_headlight(false);
    light.inspect(|l| l.add_to(scene)).map(|l| l.warning(had_lights))
}

/// True if rays from `eye` leave the scene in at least [`OPEN_SHARE`] of all directions.
fn is_open(scene: &PreparedScene, eye: Vec3) -> bool {
    let escaped = (0..OPENNESS_PROBES)
        .filter(|&i| !scene.accel().intersect(&Ray::new(eye, fibonacci_sphere(i, OPENNESS_PROBES))).is_hit())
        .count();
    tracing::debug!("{escaped} of {OPENNESS_PROBES} rays from the camera leave the scene");
    escaped as f32 >= OPEN_SHARE * OPENNESS_PROBES as f32
}

/// The share of the pixels showing geometry that a small pilot frame of `scene` from
/// `camera` shows readably ([`READABLE`] or brighter after igi render's tone map), or 1 if the
/// camera sees no geometry (0 if it sees only emitters). It measures the picture the user
/// would get: a scene lit by its own lights can still be unreadable, as Lost Empire's city by
/// its lava (a few bright pixels, the rest near black), and an emitter seen directly is not
/// lit by it. A pixel counts as an emitter's where the emission there (its texel: a glTF
/// model's emissive map is black but for its lamps) makes at least [`GLOWING`] of its
/// radiance: DamagedHelmet's emissive map covers the whole helmet, and a per-triangle test
/// took all of it for a lamp, so that the sun and grey sky of its scene file were judged to
/// show nothing.
fn readable_share(scene: &mut PreparedScene, camera: &Camera) -> f32 {
    let (width, height) = (PILOT_WIDTH, PILOT_WIDTH * 3 / 4);
    let settings =
        FrameSettings { width, height, aa: 1, ..FrameSettings::for_scene(scene.bounds().diagonal()) };
    let Ok(out) = FrameRenderer::new(0).render(scene, &FrameState::new(*camera, settings), &|_, _| {}) else {
        return 1.0;
    };
    let Some(film) = out.image.film() else { return 1.0 };
    let mapper = ToneMapper::for_film(ToneMap::default(), film);
    let pinhole = PinholeCamera::new(camera, width, height);
    let lights = scene.area_lights();
    let emitters: HashMap<(u32, u32), &EmissiveTriangle> =
        lights.triangles().iter().map(|t| ((t.instance, t.prim), t)).collect();
    let (mut seen, mut glowing, mut readable) = (0u32, 0u32, 0u32);
    for y in 0..height {
        for x in 0..width {
            let hit = scene.accel().intersect(&pinhole.ray(x, y));
            if !hit.is_hit() {
                continue;
            }
            let radiance = film.get(x, y);
            let emitted = emitters
                .get(&(hit.instance, hit.prim))
                .map_or(0.0, |tri| luminance(lights.emission_at(tri, Vec2::new(hit.u, hit.v))));
            if emitted > 0.0 && emitted >= GLOWING * luminance(radiance) {
                glowing += 1;
                continue;
            }
            seen += 1;
            readable += u32::from(luminance(mapper.map(radiance)) >= READABLE);
        }
    }
    tracing::debug!(
        "the scene's own lights show {readable} of {seen} pixels of geometry in a pilot frame ({glowing} emit)"
    );
    match (seen, glowing) {
        (0, 0) => 1.0,
        // Nothing but glowing surfaces: no shape shows.
        (0, _) => 0.0,
        _ => readable as f32 / seen as f32,
    }
}
