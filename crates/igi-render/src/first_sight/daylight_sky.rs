//! [`daylight_sky`]: the sky of the default sun and sky, as an equirectangular image of
//! radiance: blue overhead, pale toward the horizon, and a dim ground below it.
//!
//! A sky of one radiance in every direction hides clear glass and water: a lossless
//! dielectric reflects the share R of what lies on one side and passes T = 1 − R of what lies
//! on the other, and where both are the same radiance every pixel of it is that radiance
//! (the Cornell box's `water.obj` came out one pale cyan). Under daylight a surface faces
//! the bright sky on one side and the dark ground on the other, so glass and water show their
//! shape, and an object's underside is darker than its top, as outdoors.

use glam::Vec3;
use igi_scene::Texture;

/// The sky's radiance straight up (a clear blue).
const ZENITH: Vec3 = Vec3::new(0.17, 0.24, 0.40);
/// The sky's radiance at the horizon (a pale haze).
const HORIZON: Vec3 = Vec3::new(0.40, 0.42, 0.46);
/// The ground's radiance below the horizon (a dim warm grey: earth and grass at about a
/// fifth of the sky's light reflected).
const GROUND: Vec3 = Vec3::new(0.07, 0.065, 0.055);
/// How quickly the haze gives way to the blue with elevation: the blend toward the horizon
/// goes as (1 − sin elevation) to this power.
const HAZE: i32 = 3;
/// The sine of the elevation over which the sky fades into the ground below the horizon
/// (about 1.7°), so that the horizon is not a hard step between two rows.
const HORIZON_BLEND: f32 = 0.03;
/// Rows of the image (from straight up to straight down) and its columns (the sky is the
/// same in every azimuth).
const ROWS: u32 = 64;
const COLUMNS: u32 = 4;

/// The daylight sky as an equirectangular texture of linear radiance (row 0 straight up, as
/// [`igi_scene::Environment::Map`] reads it).
pub fn daylight_sky() -> Texture {
    let mut texels = Vec::with_capacity((ROWS * COLUMNS) as usize);
    for row in 0..ROWS {
        let theta = std::f32::consts::PI * (row as f32 + 0.5) / ROWS as f32;
        let radiance = radiance(theta.cos()).extend(1.0).to_array();
        texels.extend(std::iter::repeat_n(radiance, COLUMNS as usize));
    }
    Texture::from_linear("igi daylight sky", COLUMNS, ROWS, texels)
}

/// The radiance arriving from a direction whose unit vector has the vertical component `y`.
fn radiance(y: f32) -> Vec3 {
    let sky = ZENITH + (HORIZON - ZENITH) * (1.0 - y.max(0.0)).powi(HAZE);
    let ground = ((-y) / HORIZON_BLEND).clamp(0.0, 1.0);
    sky + (GROUND - sky) * ground
}
