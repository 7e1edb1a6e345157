//! [`ceiling_lights`]: the default light of an enclosed camera, lamps hanging under the
//! ceiling of the space it looks into, as a room is lit when it is in use.
//!
//! A light at the camera (the headlight) lights what the eye sees head-on and nothing from
//! the side: walls face-on glare, floors and edges fade, every shadow hides behind what casts
//! it, and Sibenik's nave or the conference room look photographed with a flash. Lamps above
//! the view light it from above, as a room's own lights would: floors and table tops bright,
//! walls graded from top to bottom, each object's shadow under it, the ceiling lit by the
//! light the room throws back. Each lamp lights the half space below it (a spot of
//! [`LAMP_ANGLE`]), so the ceiling it hangs just under shows no hot spot.
//!
//! The lamps stand in a row along the view, at shares [`ALONG`] of the free distance ahead of
//! the eye, each under the ceiling straight above its point (what an upward ray meets first:
//! a vault, a ceiling, a hanging fixture) and as strong as gives the floor below it the same
//! irradiance. Where no ceiling stands above any of them there are none, and the headlight
//! remains (see [`crate::first_sight::default_light`]).

use crate::prepared::PreparedScene;
use glam::Vec3;
use igi_bvh::{Ray, offset_ray_origin};
use igi_scene::{Camera, Light};

/// Where the lamps stand along the view: shares of the free distance ahead of the eye.
const ALONG: [f32; 3] = [0.15, 0.45, 0.75];
/// How far under the ceiling a lamp hangs: this share of the clearance between floor and
/// ceiling (off the surface, so that its light leaves it).
const HANG: f32 = 0.03;
/// A lamp's full opening angle (degrees): the half space below it.
const LAMP_ANGLE: f32 = 180.0;
/// The irradiance a lamp gives the floor straight below it (the exposure follows the image;
/// what matters is that lamps under high and low ceilings light their floors alike).
const FLOOR_IRRADIANCE: f32 = 1.0;

/// The lamps under the ceiling along the view of `camera` (see the module documentation);
/// empty where the eye sees no wall ahead or no ceiling stands above the view.
pub fn ceiling_lights(scene: &PreparedScene, camera: &Camera) -> Vec<Light> {
    let forward = camera.target - camera.position;
    let ahead_dir = Vec3::new(forward.x, 0.0, forward.z).try_normalize().unwrap_or(Vec3::Z);
    let eye = camera.position;
    let ahead = scene.accel().intersect(&Ray::new(eye, ahead_dir));
    if !ahead.is_hit() {
        return Vec::new();
    }
    ALONG
        .iter()
        .filter_map(|&share| {
            let p = eye + ahead_dir * (share * ahead.t);
            let up = scene.accel().intersect(&Ray::new(p, Vec3::Y));
            let down = scene.accel().intersect(&Ray::new(p, -Vec3::Y));
            if !(up.is_hit() && down.is_hit()) {
                return None;
            }
            let clearance = up.t + down.t;
            let ceiling = p + Vec3::Y * up.t;
            let position = offset_ray_origin(ceiling, -Vec3::Y) - Vec3::Y * (HANG * clearance);
            let height = position.y - (p.y - down.t);
            Some(Light::Spot {
                position,
                direction: -Vec3::Y,
                angle_deg: LAMP_ANGLE,
                intensity: Vec3::splat(FLOOR_IRRADIANCE * height * height),
            })
        })
        .collect()
}
